"""What the session's controls do: one small handler per control, wired in `wire`.

Handlers run on viser's callback threads; they change the session's scenario or command its
worker, and leave the drawing of progress to the session's ticker.
"""

from __future__ import annotations

import itertools
import json
import math

import httpx
import numpy as np

import planner
import tracks
from app.studio._custom import custom_scenario, track_from_points
from app.studio._panel import SPEEDS
from app.studio._scene import Z, polyline_segments

__all__ = ["drive_step", "load_scenario", "wire"]


def wire(s) -> None:
    u = s.ui
    u.track.on_update(lambda _: s.load_library(u.track.value))
    u.svg_upload.on_upload(lambda _: _svg_uploaded(s))
    u.svg_path.on_update(lambda _: _svg_path_chosen(s))
    u.fit.on_click(lambda _: s.fit())
    u.draw.on_update(lambda _: _draw_mode(s))
    u.draw_undo.on_click(lambda _: _draft_changed(s, s.draft[:-1]))
    u.draw_use.on_click(lambda _: _use_drawn(s))
    u.draw_download.on_click(lambda _: _download_svg(s))
    u.add_circle.on_click(lambda _: _add_obstacle(s, "circle"))
    u.add_box.on_click(lambda _: _add_obstacle(s, "box"))
    u.clear_obstacles.on_click(lambda _: s.apply_scenario(dict(s.scenario, obstacles=[])))
    u.scene_time.on_update(lambda _: s.draw_scenario(u.scene_time.value))
    u.scenario_download.on_click(lambda _: s.client.send_file_download(
        f"{u.scenario_name.value or 'studio'}.json", s.scenario_json().encode()))
    u.scenario_upload.on_upload(lambda _: _scenario_uploaded(s))
    u.scenario_save.on_click(lambda _: _save_to_server(s))
    u.scenario_load.on_click(lambda _: _load_from_server(s))
    for control in (u.algorithm, u.steering, u.eps, u.gamma, u.k_rrt, u.goal_bias, u.budget,
                    u.seed, u.speed_v):
        control.on_update(lambda _: s.reset())
    u.rate.on_update(lambda _: setattr(s.worker, "rate", SPEEDS[u.rate.value]))
    u.run.on_click(lambda _: s.worker.run())
    u.pause.on_click(lambda _: s.worker.pause())
    u.step.on_click(lambda _: s.worker.step())
    u.reset.on_click(lambda _: s.reset())
    u.drive.on_click(lambda _: _start_drive(s))


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
        scenario, region = custom_scenario(track, track.name or "custom")
        s.set_track(track, scenario, region)
    except (planner.ScenarioError, ValueError, tracks.TrackError) as exc:
        s.notify("Track not usable", str(exc))


def _draw_mode(s) -> None:
    if s.ui.draw.value:
        s.scene.on_click()(lambda ev: _ground_click(s, ev))
    else:
        s.scene.remove_click_callback("all")


def _ground_click(s, ev) -> None:
    """Where the click ray meets the ground plane z = 0 becomes the next track point."""
    (ox, oy, oz), (dx, dy, dz) = ev.ray_origin, ev.ray_direction
    if abs(dz) < 1e-9 or -oz / dz < 0:
        return
    t = -oz / dz
    _draft_changed(s, [*s.draft, (ox + t * dx, oy + t * dy)])


def _draft_changed(s, draft: list) -> None:
    s.draft = draft
    pts = np.array(draft, dtype=float).reshape(-1, 2)
    m = s.marker()
    dots = [polyline_segments(p + m * np.array([[-1, -1], [1, 1], [-1, 1], [1, -1]]), Z["pose"])
            [[0, 2]] for p in pts]
    with s.client.atomic():
        s.scene.add_line_segments(
            "/draft/points", np.concatenate(dots) if dots else np.zeros((0, 2, 3)),
            (255, 120, 0), thickness=3.0, thickness_units="screen", visible=bool(dots))
        line = polyline_segments(pts, Z["pose"]) if len(pts) > 1 else np.zeros((0, 2, 3))
        s.scene.add_line_segments("/draft/line", line, (255, 120, 0), thickness=1.5,
                                  thickness_units="screen", visible=len(line) > 0)
    s.ui.draw.label = f"Draw (click the ground) — {len(draft)} points"


def _drawn_track(s) -> tracks.Track | None:
    try:
        return track_from_points(s.draft, float(s.ui.draw_width.value), s.ui.draw_close.value)
    except (ValueError, tracks.TrackError) as exc:
        s.notify("Track not drawn", str(exc))
        return None


def _use_drawn(s) -> None:
    track = _drawn_track(s)
    if track is not None:
        s.ui.draw.value = False
        _use_track(s, track)
        s.draft = []


def _download_svg(s) -> None:
    track = _drawn_track(s) if s.draft else s.track
    if track is not None:
        s.client.send_file_download(f"{track.name or 'track'}.svg", track.to_svg().encode())


# -- obstacles --------------------------------------------------------------------------------
def _add_obstacle(s, kind: str) -> None:
    """A new obstacle on the centreline, between start and goal, away from the others."""
    track = s.track
    prof = track.sample(0.05)
    n = len(s.scenario["obstacles"])
    frac = (0.2 + 0.15 * (n % 4)) * (0.75 if track.closed else 0.9)
    i = int(np.searchsorted(prof.s, frac * track.length_m))
    x, y, heading = float(prof.x[i]), float(prof.y[i]), float(prof.heading[i])
    size = 0.3 * track.width_m
    if kind == "circle":
        ob = {"type": "circle", "center": [x, y], "radius": round(size, 3)}
    else:
        ob = {"type": "box", "center": [x, y], "size": [round(2 * size, 3), round(size, 3)],
              "angle_deg": round(math.degrees(heading), 1)}
    vx, vy = s.ui.velocity.value
    if vx or vy:
        ob["motion"] = {"velocity": [vx, vy]}
    s.apply_scenario(dict(s.scenario, obstacles=[*s.scenario["obstacles"], ob]))


# -- scenarios --------------------------------------------------------------------------------
def _scenario_uploaded(s) -> None:
    try:
        data = json.loads(s.ui.scenario_upload.value.content)
        load_scenario(s, data)
    except (ValueError, UnicodeDecodeError) as exc:
        s.notify("Scenario not loaded", str(exc))


def load_scenario(s, data: dict) -> None:
    """A library-track scenario keeps its track; any other is drawn by its bounds."""
    scenario = planner.parse_scenario(data)  # raises ScenarioError with a one-line message
    if scenario.track is not None:
        s.set_track(tracks.load_library_track(scenario.track.name), data, [])
        return
    xmin, ymin, xmax, ymax = scenario.bounds
    box = [[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax], [xmin, ymin]]
    track = tracks.Track(name=scenario.name, closed=False, width_m=1e-3, segments=tuple(
        tracks.line(np.array(a), np.array(b)) for a, b in itertools.pairwise(box)))
    s.set_track(track, data, [])


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
    """The newest stored scenario whose id or name is the Name field."""
    name = s.ui.scenario_name.value
    try:
        r = httpx.get(f"{s.api_url}/scenarios", timeout=10.0)
        r.raise_for_status()
        found = [rec for rec in r.json() if name in (rec["id"], rec["name"])]
        if not found:
            raise ValueError(f"no stored scenario with id or name '{name}'")
        load_scenario(s, found[-1]["scenario"])
    except (httpx.HTTPError, KeyError, ValueError) as exc:
        s.notify("Not loaded", f"scenario '{name}' from the server: {exc}")


# -- the car ----------------------------------------------------------------------------------
def _start_drive(s) -> None:
    import time

    s._drive_t0 = time.monotonic()


def drive_step(s, elapsed: float) -> None:
    """Put the car footprint where the best path is ``elapsed`` seconds after the start."""
    path = s.worker.live.best_path
    t = elapsed % max(path[-1, 5], 1e-3)
    k = int(np.searchsorted(path[:, 5], t).clip(0, len(path) - 1))
    x, y, th = path[k, :3]
    size = s.marker() * 4
    c, si = math.cos(th), math.sin(th)
    local = np.array([[-0.3, -0.25], [0.7, -0.25], [0.7, 0.25], [-0.3, 0.25]]) * size
    ring = np.column_stack([x + c * local[:, 0] - si * local[:, 1],
                            y + si * local[:, 0] + c * local[:, 1]])
    s.scene.add_line_segments("/live/car", polyline_segments(ring, Z["pose"], closed=True),
                              (20, 20, 20), thickness=3.0, thickness_units="screen")
