"""Editing the scenario in the scene: obstacles added from the panel or clicked as polygons,
gizmos that drag and turn obstacles, the start and the goal, and the motion of the selected
obstacle. Only the selected object shows its gizmo — a click on an obstacle, the start or the
goal selects it, a click elsewhere none; an obstacle added is selected — so that a scene with
many obstacles is not covered in handles.

`Editor` owns the gizmos, the selection, the polygon being clicked and what a ground click does;
it never changes the scenario itself: it hands a new scenario dict to ``apply`` (the session's,
which compiles it and restarts the planner) and draws drags through the stage's previews.
"""

from __future__ import annotations

import math
import re

import numpy as np

from app.studio._gizmo import gizmo
from app.studio._scene import (
    DRAFT_RGB,
    Z,
    ground_point,
    marker_size,
    obstacle_rings,
    polyline_segments,
)
from planner.obstacles import outline

__all__ = ["Editor", "moved_obstacle", "nearest_s", "parse_waypoints"]


class Editor:
    def __init__(self, scene, ui, stage, apply, track_click, notify) -> None:
        """``apply(scenario) -> bool`` shows a changed scenario; ``track_click((x, y))`` takes
        ground clicks while `Draw (click the ground)` is ticked."""
        self.scene, self.ui, self.stage = scene, ui, stage
        self._apply, self._track_click, self.notify = apply, track_click, notify
        # What shows its gizmo: "o{i}" (obstacle i, which `Set motion of selected` changes),
        # "start" or "goal"; None: nothing.
        self._selected: str | None = None
        self._gizmos: dict = {}
        self._hidden = False  # projector mode hides the gizmos once a run has started
        self._polygon: list[tuple[float, float]] = []  # corners of a polygon being clicked
        self._click_mode: str | None = None

    # -- gizmos: obstacles, start, goal ---------------------------------------------------------
    def place_gizmos(self) -> None:
        """Gizmos for every obstacle, the start and the goal of the stage's scenario (shown:
        the selected one's)."""
        for h in self._gizmos.values():
            h.remove()
        self._gizmos = {}
        parsed = self.stage.parsed
        for i, ob in enumerate(parsed.obstacles):
            pose, _ = outline(ob)
            self._gizmos[f"o{i}"] = gizmo(
                self.scene, f"/edit/o{i}", pose,
                lambda x, y, yaw, i=i: self.stage.preview_obstacle(i, x, y, yaw),
                lambda x, y, yaw, i=i: self._commit_obstacle(i, x, y, yaw),
                rotate=ob.type != "circle", visible=self._shows(f"o{i}"))
        for key in ("start", "goal"):
            self._gizmos[key] = gizmo(
                self.scene, f"/edit/{key}", getattr(parsed, key),
                lambda x, y, yaw, key=key: self.stage.preview_pose(key, x, y, yaw),
                lambda x, y, yaw, key=key: self._apply(dict(
                    self.stage.scenario,
                    **{key: _round([x, y, math.remainder(yaw, 2 * math.pi)])})),
                visible=self._shows(key))

    def forget_gizmos(self) -> None:
        """The scene was cleared, and the gizmos with it."""
        self._gizmos = {}

    def _shows(self, key: str) -> bool:
        return key == self._selected and bool(self.ui.handles.value) and not self._hidden

    def show_gizmos(self) -> None:
        for key, h in self._gizmos.items():
            h.visible = self._shows(key)

    def select_at(self, p) -> bool:
        """Select what a ground click at ``p`` (x, y) hits — an obstacle where it is drawn at
        t = 0, else the start or the goal within a few markers — and show its gizmo; a click
        on nothing selects nothing. Returns whether it hit something."""
        from matplotlib.path import Path

        stage = self.stage
        reach = 4.0 * marker_size(stage.problem.bounds)
        hits = [f"o{i}" for i, ring in enumerate(obstacle_rings(stage.parsed, 0.0, stage.track))
                if Path(ring).contains_point(p) or _ring_distance(ring, p) <= reach]
        hits += [k for k in ("start", "goal")
                 if math.dist(getattr(stage.parsed, k)[:2], p) <= 2.0 * reach]
        self._selected = hits[-1] if hits else None  # the topmost: drawn last
        self.show_gizmos()
        return bool(hits)

    @property
    def _obstacle(self) -> int | None:
        """The selected obstacle's index (None: none is)."""
        key = self._selected
        return int(key[1:]) if key is not None and key.startswith("o") else None

    def hide_gizmos(self, hidden: bool) -> None:
        """Hide the gizmos (projector mode, once a run has started), or show them again as
        `Drag handles` says."""
        if hidden != self._hidden:
            self._hidden = hidden
            self.show_gizmos()

    def _commit_obstacle(self, i: int, x: float, y: float, yaw: float) -> None:
        stage = self.stage
        obstacles = list(stage.scenario["obstacles"])
        obstacles[i] = moved_obstacle(obstacles[i], stage.parsed.obstacles[i], x, y, yaw,
                                      stage.track)
        self._selected = f"o{i}"
        self._apply(dict(stage.scenario, obstacles=obstacles))

    # -- obstacles from the panel ---------------------------------------------------------------
    def add_obstacle(self, kind: str) -> None:
        """A new circle or box on the centreline, between start and goal, away from the
        others."""
        track = self.stage.track
        prof = track.sample(track.detail_spacing())
        n = len(self.stage.scenario["obstacles"])
        frac = (0.2 + 0.15 * (n % 4)) * (0.75 if track.closed else 0.9)
        i = int(np.searchsorted(prof.s, frac * track.length_m))
        x, y, heading = float(prof.x[i]), float(prof.y[i]), float(prof.heading[i])
        size = 0.3 * track.width_m
        if kind == "circle":
            ob = {"type": "circle", "center": [x, y], "radius": round(size, 5)}
        else:
            ob = {"type": "box", "center": [x, y], "size": [round(2 * size, 5), round(size, 5)],
                  "angle_deg": round(math.degrees(heading), 1)}
        self._add(ob)

    def close_polygon(self) -> None:
        """The clicked corners become a polygon obstacle."""
        if len(self._polygon) < 3:
            self.notify("No polygon",
                        "tick 'Polygon (click the ground)' and click 3 or more corners")
            return
        ob = {"type": "polygon", "points": [[round(x, 5), round(y, 5)] for x, y in self._polygon]}
        self._polygon = []
        self._show_polygon()
        self.ui.polygon.value = False
        self._add(ob)

    def clear_obstacles(self) -> None:
        self._apply(dict(self.stage.scenario, obstacles=[]))

    def _add(self, ob: dict) -> None:
        """Add ``ob`` with the motion chosen in the panel; it becomes the selected obstacle."""
        try:
            motion = self._motion(ob)
        except ValueError as exc:
            self.notify("Obstacle not added", str(exc))
            return
        if motion is not None:
            ob = dict(ob, motion=motion)
        scenario = self.stage.scenario
        if self._apply(dict(scenario, obstacles=[*scenario["obstacles"], ob])):
            self._selected = f"o{len(self.stage.scenario['obstacles']) - 1}"
            self.show_gizmos()

    def set_motion(self) -> None:
        """The panel's motion for the selected obstacle (the last one clicked, added or
        dragged)."""
        obstacles = list(self.stage.scenario["obstacles"])
        i = self._obstacle
        if i is None or i >= len(obstacles):
            self.notify("No obstacle selected", "click an obstacle, or add one, first")
            return
        try:
            motion = self._motion(obstacles[i])
        except ValueError as exc:
            self.notify("Motion not set", str(exc))
            return
        ob = {k: v for k, v in obstacles[i].items() if k != "motion"}
        obstacles[i] = ob if motion is None else dict(ob, motion=motion)
        self._apply(dict(self.stage.scenario, obstacles=obstacles))

    def _motion(self, ob: dict) -> dict | None:
        """The `Motion` control as a scenario motion (planner/scenario.py Motion) for ``ob``."""
        u = self.ui
        kind = u.motion.value
        if kind == "velocity":
            return {"velocity": [float(v) for v in u.velocity.value]}
        if kind == "waypoints":
            return {"waypoints": parse_waypoints(u.waypoints.value)}
        if kind == "follow track":
            x, y = np.mean(np.reshape(ob.get("center", ob.get("points")), (-1, 2)), axis=0)
            return {"follow_track": {"speed": float(u.track_speed.value),
                                     "start_s": round(nearest_s(self.stage.track, x, y), 4)}}
        return None

    # -- clicks on the ground -------------------------------------------------------------------
    def click_mode(self, mode: str) -> None:
        """Ground clicks add track points or polygon corners; ticking one mode unticks the
        other."""
        u = self.ui
        this, other = (u.draw, u.polygon) if mode == "track" else (u.polygon, u.draw)
        if this.value and other.value:
            other.value = False  # runs this again, which settles the mode
            return
        self._click_mode = "track" if u.draw.value else "polygon" if u.polygon.value else None
        self.scene.remove_click_callback(self._ground_click)  # not the session's edge clicks
        if self._click_mode is not None:
            self.scene.on_click()(self._ground_click)

    @property
    def clicking(self) -> bool:
        """Whether ground clicks draw (track points or polygon corners) just now."""
        return self._click_mode is not None

    def _ground_click(self, ev) -> None:
        p = ground_point(ev)
        if p is None:
            return
        if self._click_mode == "polygon":
            self._polygon.append(p)
            self._show_polygon()
        elif self._click_mode == "track":
            self._track_click(p)

    def _show_polygon(self) -> None:
        pts = np.array(self._polygon, dtype=float).reshape(-1, 2)
        seg = (polyline_segments(pts, Z["pose"], closed=len(pts) > 2) if len(pts) > 1
               else np.zeros((0, 2, 3)))
        self.scene.add_line_segments("/polygon_draft", seg, DRAFT_RGB, thickness=2.0,
                                     thickness_units="screen", visible=len(seg) > 0)
        self.ui.polygon.label = f"Polygon (click the ground) — {len(pts)} corners"


def _ring_distance(ring: np.ndarray, p) -> float:
    """Distance from point ``p`` to the closed outline ``ring`` (its edges)."""
    a, b = ring, np.roll(ring, -1, axis=0)
    ab = b - a
    u = np.clip(np.einsum("ij,ij->i", np.asarray(p) - a, ab)
                / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-18), 0.0, 1.0)
    return float(np.hypot(*(a + u[:, None] * ab - p).T).min())


def _round(v) -> list[float]:
    return [round(float(c), 5) for c in v]


def moved_obstacle(ob: dict, parsed, x: float, y: float, yaw: float, track) -> dict:
    """``ob`` (a scenario dict) with its pose set to (x, y, yaw); one that follows the track
    starts from the centreline point nearest its new place."""
    out = dict(ob)
    if ob["type"] == "polygon":
        _, local = outline(parsed)
        c, si = math.cos(yaw), math.sin(yaw)
        out["points"] = [_round(p) for p in local @ np.array([[c, si], [-si, c]]) + [x, y]]
    else:
        out["center"] = _round([x, y])
    if ob["type"] == "box":
        out["angle_deg"] = round(math.degrees(math.remainder(yaw, 2 * math.pi)), 2)
    follow = (ob.get("motion") or {}).get("follow_track")
    if follow is not None:
        out["motion"] = {"follow_track": dict(follow, start_s=round(nearest_s(track, x, y), 4))}
    return out


def nearest_s(track, x: float, y: float) -> float:
    """Arc length of the centreline point nearest (x, y)."""
    prof = track.sample(track.length_m / 2000)
    return float(prof.s[np.argmin(np.hypot(prof.x - x, prof.y - y))])


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
