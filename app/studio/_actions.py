"""What the session's controls do: one small handler per control, wired in `wire`.

Handlers run on viser's callback threads; they change the session's scenario or command its
worker, and leave the drawing of progress to the session's ticker.
"""

from __future__ import annotations

import itertools
import json
import math
import re

import httpx
import numpy as np

import planner
import tracks
from app.studio._custom import Draft, custom_scenario
from app.studio._edit import click_mode, draft_changed, nearest_s, show_gizmos, show_polygon
from app.studio._panel import SPEEDS
from planner.problem import resolve_track

__all__ = ["add_obstacle", "load_scenario", "parse_waypoints", "wire"]


def wire(s) -> None:
    u = s.ui
    u.track.on_update(lambda _: s.load_library(u.track.value))
    u.svg_upload.on_upload(lambda _: _svg_uploaded(s))
    u.svg_path.on_update(lambda _: _svg_path_chosen(s))
    u.fit.on_click(lambda _: s.fit())
    u.draw.on_update(lambda _: click_mode(s, "track"))
    u.draw_undo.on_click(lambda _: (s.draft.undo(), draft_changed(s)))
    u.draw_close.on_update(lambda _: draft_changed(s))
    u.draw_use.on_click(lambda _: _use_drawn(s))
    u.draw_download.on_click(lambda _: _download_svg(s))
    u.add_circle.on_click(lambda _: _add_obstacle(s, "circle"))
    u.add_box.on_click(lambda _: _add_obstacle(s, "box"))
    u.polygon.on_update(lambda _: click_mode(s, "polygon"))
    u.close_polygon.on_click(lambda _: _close_polygon(s))
    u.clear_obstacles.on_click(lambda _: s.apply_scenario(dict(s.scenario, obstacles=[])))
    u.handles.on_update(lambda _: show_gizmos(s))
    u.set_motion.on_click(lambda _: _set_motion(s))
    u.scene_time.on_update(lambda _: s.show_time(u.scene_time.value))
    u.scenario_download.on_click(lambda _: s.client.send_file_download(
        f"{u.scenario_name.value or 'studio'}.json", s.scenario_json().encode(),
        save_immediately=True))
    u.scenario_upload.on_upload(lambda _: _scenario_uploaded(s))
    u.scenario_save.on_click(lambda _: _save_to_server(s))
    u.scenario_load.on_click(lambda _: _load_from_server(s))
    for control in (u.planner_name, u.steering, u.eps, u.gamma, u.k_rrt, u.goal_bias, u.budget,
                    u.seed, u.speed_v):
        control.on_update(lambda _: s.reset())
    u.rate.on_update(lambda _: setattr(s.worker, "rate", SPEEDS[u.rate.value]))
    u.run.on_click(lambda _: s.worker.run())
    u.pause.on_click(lambda _: s.worker.pause())
    u.step.on_click(lambda _: s.worker.step())
    u.reset.on_click(lambda _: s.reset())
    u.drive.on_click(lambda _: s.drive())


# -- tracks -----------------------------------------------------------------------------------
def _svg_uploaded(s) -> None:
    data = s.ui.svg_upload.value.content
    try:
        paths = [p["id"] for p in tracks.inspect_svg(data)["paths"]]
    except (tracks.TrackError, ValueError, KeyError) as exc:
        s.notify("SVG not loaded", str(exc))
        return
    if not paths:
        s.notify("SVG not loaded", "the file has no path")
        return
    s.svg_data = data
    s.ui.svg_path.options = tuple(paths)
    s.ui.svg_path.visible = len(paths) > 1
    if s.ui.svg_path.value == paths[0]:
        _svg_path_chosen(s)
    else:
        s.ui.svg_path.value = paths[0]  # fires _svg_path_chosen


def _svg_path_chosen(s) -> None:
    data = getattr(s, "svg_data", None)
    if data is None or s.ui.svg_path.value not in s.ui.svg_path.options:
        return
    try:
        track = tracks.load_svg(data, path_id=s.ui.svg_path.value)
    except (tracks.TrackError, ValueError) as exc:
        s.notify("SVG not loaded", str(exc))
        return
    _use_track(s, track)


def _use_track(s, track: tracks.Track) -> None:
    try:
        s.set_track(track, custom_scenario(track, track.name or "custom"))
    except (planner.ScenarioError, ValueError, tracks.TrackError) as exc:
        s.notify("Track not usable", str(exc))


def _drawn_track(s) -> tracks.Track | None:
    try:
        return s.draft.track(float(s.ui.draw_width.value), bool(s.ui.draw_close.value))
    except (ValueError, tracks.TrackError) as exc:
        s.notify("Track not drawn", str(exc))
        return None


def _use_drawn(s) -> None:
    track = _drawn_track(s)
    if track is not None:
        s.ui.draw.value = False
        _use_track(s, track)
        s.draft = Draft()
        draft_changed(s)


def _download_svg(s) -> None:
    track = _drawn_track(s) if s.draft.points else s.track
    if track is not None:
        s.client.send_file_download(f"{track.name or 'track'}.svg", track.to_svg().encode(),
                                    save_immediately=True)


# -- obstacles --------------------------------------------------------------------------------
def _add_obstacle(s, kind: str) -> None:
    """A new obstacle on the centreline, between start and goal, away from the others."""
    track = s.track
    prof = track.sample(track.detail_spacing())
    n = len(s.scenario["obstacles"])
    frac = (0.2 + 0.15 * (n % 4)) * (0.75 if track.closed else 0.9)
    i = int(np.searchsorted(prof.s, frac * track.length_m))
    x, y, heading = float(prof.x[i]), float(prof.y[i]), float(prof.heading[i])
    size = 0.3 * track.width_m
    if kind == "circle":
        ob = {"type": "circle", "center": [x, y], "radius": round(size, 5)}
    else:
        ob = {"type": "box", "center": [x, y], "size": [round(2 * size, 5), round(size, 5)],
              "angle_deg": round(math.degrees(heading), 1)}
    add_obstacle(s, ob)


def _close_polygon(s) -> None:
    """The clicked corners become a polygon obstacle."""
    if len(s.polygon) < 3:
        s.notify("No polygon", "tick 'Polygon (click the ground)' and click 3 or more corners")
        return
    ob = {"type": "polygon", "points": [[round(x, 5), round(y, 5)] for x, y in s.polygon]}
    s.polygon = []
    show_polygon(s)
    s.ui.polygon.value = False
    add_obstacle(s, ob)


def add_obstacle(s, ob: dict) -> None:
    """Add ``ob`` with the motion chosen in the panel; it becomes the selected obstacle."""
    try:
        motion = _motion(s, ob)
    except ValueError as exc:
        s.notify("Obstacle not added", str(exc))
        return
    if motion is not None:
        ob = dict(ob, motion=motion)
    if s.apply_scenario(dict(s.scenario, obstacles=[*s.scenario["obstacles"], ob])):
        s.selected = len(s.scenario["obstacles"]) - 1


def _set_motion(s) -> None:
    """The panel's motion for the selected obstacle (the last one added or dragged)."""
    obstacles = list(s.scenario["obstacles"])
    if s.selected is None or s.selected >= len(obstacles):
        s.notify("No obstacle selected", "add an obstacle or drag one first")
        return
    try:
        motion = _motion(s, obstacles[s.selected])
    except ValueError as exc:
        s.notify("Motion not set", str(exc))
        return
    ob = {k: v for k, v in obstacles[s.selected].items() if k != "motion"}
    obstacles[s.selected] = ob if motion is None else dict(ob, motion=motion)
    s.apply_scenario(dict(s.scenario, obstacles=obstacles))


def _motion(s, ob: dict) -> dict | None:
    """The `Motion` control as a scenario motion (planner/scenario.py Motion) for ``ob``."""
    kind = s.ui.motion.value
    if kind == "velocity":
        return {"velocity": [float(v) for v in s.ui.velocity.value]}
    if kind == "waypoints":
        return {"waypoints": parse_waypoints(s.ui.waypoints.value)}
    if kind == "follow track":
        x, y = np.mean(np.reshape(ob.get("center", ob.get("points")), (-1, 2)), axis=0)
        return {"follow_track": {"speed": float(s.ui.track_speed.value),
                                 "start_s": round(nearest_s(s.track, x, y), 4)}}
    return None


def parse_waypoints(text: str) -> list[list[float]]:
    """'0 0 0; 3 0.5 0' → [[0, 0, 0], [3, 0.5, 0]]: rows t (s), dx, dy (m) from where the
    obstacle is drawn."""
    rows = [r for r in re.split(r"[;\n]", text) if r.strip()]
    try:
        out = [[float(v) for v in re.split(r"[\s,]+", r.strip())] for r in rows]
    except ValueError:
        out = []
    if not out or any(len(r) != 3 for r in out):
        raise ValueError(f"waypoints are rows 't dx dy' separated by ';', got {text!r}")
    return out


# -- scenarios --------------------------------------------------------------------------------
def _scenario_uploaded(s) -> None:
    try:
        data = json.loads(s.ui.scenario_upload.value.content)
        load_scenario(s, data)
    except (ValueError, UnicodeDecodeError) as exc:
        s.notify("Scenario not loaded", str(exc))


def load_scenario(s, data: dict) -> None:
    """A scenario with a track (library or embedded) shows it; any other is drawn by its
    bounds."""
    scenario = planner.parse_scenario(data)  # raises ScenarioError with a one-line message
    if scenario.track is not None:
        s.set_track(resolve_track(scenario), data)
        return
    xmin, ymin, xmax, ymax = scenario.bounds
    box = [[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax], [xmin, ymin]]
    track = tracks.Track(name=scenario.name, closed=False, width_m=1e-3, segments=tuple(
        tracks.line(np.array(a), np.array(b)) for a, b in itertools.pairwise(box)))
    s.set_track(track, data)


def _save_to_server(s) -> None:
    """POST to the server's scenario store (``api_url`` ends in /api/v1)."""
    try:
        r = httpx.post(f"{s.api_url}/scenarios", json=json.loads(s.scenario_json()), timeout=10.0)
        r.raise_for_status()
        s.client.add_notification("Saved", f"scenario '{r.json()['name']}' stored as "
                                  f"{r.json()['id']}", auto_close_seconds=4.0)
    except (httpx.HTTPError, KeyError, ValueError) as exc:
        s.notify("Not saved", f"the server's scenario store: {exc}")


def _load_from_server(s) -> None:
    """The newest scenario whose id or name is the Name field: a bundled one (slalom, crossing,
    …) or one saved to the server."""
    name = s.ui.scenario_name.value
    try:
        r = httpx.get(f"{s.api_url}/scenarios", timeout=10.0)
        r.raise_for_status()
        records = r.json()
        found = [rec for rec in records if name in (rec["id"], rec["name"])]
        if not found:
            bundled = ", ".join(rec["id"] for rec in records if rec["source"] == "library")
            raise ValueError(f"no scenario with id or name '{name}' (bundled: {bundled})")
        load_scenario(s, found[-1]["scenario"])
    except (httpx.HTTPError, KeyError, ValueError) as exc:
        s.notify("Not loaded", f"scenario '{name}' from the server: {exc}")
