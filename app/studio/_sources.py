"""Tracks and scenarios into and out of a tab: the library, an uploaded SVG or centreline CSV,
scenario JSON files and the server's scenario store.

`Sources` holds only the uploaded file, kept so that another of its paths can be chosen; what it
loads goes to ``set_track`` (the session's, which puts it on the stage and resets the rest).
"""

from __future__ import annotations

import itertools
import json

import httpx
import numpy as np

import planner
import tracks
from app.studio._custom import custom_scenario
from app.studio._scenario import default_scenario
from planner.problem import resolve_track

__all__ = ["Sources"]


class Sources:
    def __init__(self, client, ui, stage, api_url: str, set_track, notify) -> None:
        """``api_url`` is the REST API's base URL (it ends in /api/v1)."""
        self.client, self.ui, self.stage, self.api_url = client, ui, stage, api_url
        self._set_track, self.notify = set_track, notify
        self._upload = None  # the uploaded file (viser's UploadedFile: name, content)
        self._shown: str | None = None  # the shown track's name in the Track dropdown

    # -- tracks ---------------------------------------------------------------------------------
    def show_library(self, name: str) -> None:
        self._set_track(tracks.load_library_track(name), default_scenario(name))
        self._name_track(name)

    def track_chosen(self) -> None:
        """The Track dropdown changed: a library track other than the one shown is loaded."""
        if self._shown is not None and self.ui.track.value != self._shown:
            self.show_library(self.ui.track.value)

    def _name_track(self, name: str) -> None:
        """The Track dropdown names the shown track; one not in the library (uploaded, drawn,
        a scenario's) is offered next to the library's until another is shown."""
        library = tuple(tracks.library_names())
        self._shown = None  # changing the options resets the value: not a choice
        self.ui.track.options = library if name in library else (*library, name)
        self.ui.track.value = name
        self._shown = name

    def svg_uploaded(self) -> None:
        """Offer the file's paths (an SVG's elements, a CSV's one centreline); the first one is
        shown. A file with none says why, as importing it does."""
        upload = self.ui.svg_upload.value
        try:
            report = tracks.inspect_track(upload.content, filename=upload.name)
            if not report["paths"]:
                tracks.load_track(upload.content, filename=upload.name)  # raises the reason
        except (tracks.TrackError, ValueError, KeyError) as exc:
            self.notify(f"No track in {upload.name}", str(exc))
            return
        paths = [p["selector"] for p in report["paths"]]
        self._upload = upload
        self.ui.svg_path.options = tuple(paths)
        self.ui.svg_path.visible = len(paths) > 1
        if self.ui.svg_path.value == paths[0]:
            self.svg_path_chosen()
        else:
            self.ui.svg_path.value = paths[0]  # fires svg_path_chosen

    def svg_path_chosen(self) -> None:
        if self._upload is None or self.ui.svg_path.value not in self.ui.svg_path.options:
            return
        try:
            track = tracks.load_track(self._upload.content, path_id=self.ui.svg_path.value,
                                      filename=self._upload.name)
        except (tracks.TrackError, ValueError) as exc:
            self.notify("Track not loaded", str(exc))
            return
        self.use_track(track)

    def use_track(self, track: tracks.Track) -> None:
        """A track of no scenario (uploaded, drawn) with a start, a goal and no obstacles."""
        name = track.name or "custom"
        try:
            self._set_track(track, custom_scenario(track, name))
        except (planner.ScenarioError, ValueError, tracks.TrackError) as exc:
            self.notify("Track not usable", str(exc))
            return
        self._name_track(name)

    # -- scenarios ------------------------------------------------------------------------------
    def load_scenario(self, data: dict) -> None:
        """A scenario with a track (library or embedded) shows it; any other is drawn by its
        bounds."""
        scenario = planner.parse_scenario(data)  # raises ScenarioError with a one-line message
        if scenario.track is not None:
            self._set_track(resolve_track(scenario), data)
            self._name_track(scenario.track.name)
            return
        xmin, ymin, xmax, ymax = scenario.bounds
        box = [[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax], [xmin, ymin]]
        track = tracks.Track(name=scenario.name, closed=False, width_m=1e-3, segments=tuple(
            tracks.line(np.array(a), np.array(b)) for a, b in itertools.pairwise(box)))
        self._set_track(track, data)
        self._name_track(f"{scenario.name} (bounds)")

    def scenario_uploaded(self) -> None:
        try:
            self.load_scenario(json.loads(self.ui.scenario_upload.value.content))
        except (ValueError, UnicodeDecodeError) as exc:
            self.notify("Scenario not loaded", str(exc))

    def download_scenario(self) -> None:
        name = self._name()
        self.client.send_file_download(f"{name}.json", self.stage.scenario_json(name).encode(),
                                       save_immediately=True)

    def save_to_server(self) -> None:
        """POST to the server's scenario store."""
        try:
            r = httpx.post(f"{self.api_url}/scenarios",
                           json=json.loads(self.stage.scenario_json(self._name())), timeout=10.0)
            r.raise_for_status()
            self.client.add_notification("Saved", f"scenario '{r.json()['name']}' stored as "
                                         f"{r.json()['id']}", auto_close_seconds=4.0)
        except (httpx.HTTPError, KeyError, ValueError) as exc:
            self.notify("Not saved", f"the server's scenario store: {exc}")

    def load_from_server(self) -> None:
        """The newest scenario whose id or name is the Name field: a bundled one (slalom,
        crossing, …) or one saved to the server."""
        name = self.ui.scenario_name.value
        try:
            r = httpx.get(f"{self.api_url}/scenarios", timeout=10.0)
            r.raise_for_status()
            records = r.json()
            found = [rec for rec in records if name in (rec["id"], rec["name"])]
            if not found:
                bundled = ", ".join(rec["id"] for rec in records if rec["source"] == "library")
                raise ValueError(f"no scenario with id or name '{name}' (bundled: {bundled})")
            self.load_scenario(found[-1]["scenario"])
        except (httpx.HTTPError, KeyError, ValueError) as exc:
            self.notify("Not loaded", f"scenario '{name}' from the server: {exc}")

    def _name(self) -> str:
        """The `Name` field, which names saved and downloaded scenarios."""
        return self.ui.scenario_name.value or "studio"
