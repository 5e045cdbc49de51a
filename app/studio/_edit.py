"""Editing in the scene: gizmos that drag and turn obstacles, the start and the goal on the
ground plane; polygons and tracks drawn by clicking the ground; a drawn track's Bézier handles.

Gizmo callbacks are ``async`` so viser runs them in order on its event loop. A drag only moves
the drawn frame (one position update); the release commits the new pose to the scenario on a
thread, because compiling it and restarting the planner takes longer than a frame.
"""

from __future__ import annotations

import math
import threading

import numpy as np

from app.studio._scene import (
    Z,
    obstacle_shape,
    offset_at,
    polyline_segments,
    wxyz_yaw,
    yaw_wxyz,
)

__all__ = ["click_mode", "draft_changed", "moved_obstacle", "nearest_s", "place_gizmos",
           "show_gizmos", "show_polygon"]

GIZMO_PX = 70  # gizmos keep their size on screen, whatever the track's scale
DRAFT_RGB = (255, 120, 0)
TURN_ONLY_Z = ((0.0, 0.0), (0.0, 0.0), (-1000.0, 1000.0))


def _gizmo(s, name: str, pose, on_move, on_commit, rotate: bool = True, px: int = GIZMO_PX,
           visible: bool | None = None):
    """A ground-plane gizmo at pose (x, y, yaw): translate in x/y, turn about z only.
    ``on_move(x, y, yaw)`` runs on every change, ``on_commit(x, y, yaw)`` at release; shown
    with the `Drag handles` box unless ``visible`` says otherwise."""
    h = s.scene.add_transform_controls(
        name, scale=px, fixed=True, active_axes=(True, True, False), disable_rotations=not rotate,
        rotation_limits=TURN_ONLY_Z, depth_test=False, position=(pose[0], pose[1], Z["pose"]),
        wxyz=yaw_wxyz(pose[2]),
        visible=bool(s.ui.handles.value) if visible is None else visible)

    @h.on_update
    async def _(ev) -> None:
        x, y, _ = ev.target.position
        yaw = wxyz_yaw(ev.target.wxyz)
        on_move(x, y, yaw)
        if ev.phase == "end" and on_commit is not None:
            threading.Thread(target=on_commit, args=(x, y, yaw), daemon=True).start()

    return h


def _round(v) -> list[float]:
    return [round(float(c), 5) for c in v]


# -- obstacles, start, goal -------------------------------------------------------------------
def place_gizmos(s) -> None:
    """Gizmos for every obstacle, the start and the goal of the current scenario."""
    for h in s.gizmos:
        h.remove()
    s.gizmos = []
    parsed = s.parsed
    for i, ob in enumerate(parsed.obstacles):
        pose, _ = obstacle_shape(ob)
        s.gizmos.append(_gizmo(
            s, f"/edit/o{i}", pose, lambda x, y, yaw, i=i: _move_obstacle(s, i, x, y, yaw),
            lambda x, y, yaw, i=i: _commit_obstacle(s, i, x, y, yaw),
            rotate=ob.type != "circle"))
    for key in ("start", "goal"):
        pose = getattr(parsed, key)
        s.gizmos.append(_gizmo(
            s, f"/edit/{key}", pose,
            lambda x, y, yaw, key=key: _move_frame(s.pose_frames[key], x, y, yaw),
            lambda x, y, yaw, key=key: s.apply_scenario(
                dict(s.scenario, **{key: _round([x, y, math.remainder(yaw, 2 * math.pi)])}))))


def show_gizmos(s) -> None:
    for h in s.gizmos:
        h.visible = bool(s.ui.handles.value)


def _move_frame(frame, x: float, y: float, yaw: float) -> None:
    frame.position = (x, y, 0.0)
    frame.wxyz = yaw_wxyz(yaw)


def _move_obstacle(s, i: int, x: float, y: float, yaw: float) -> None:
    """The drawn obstacle follows the gizmo (plus its motion's offset at the scene time)."""
    frame, _, table = s.drawn[i]
    dx, dy = offset_at(table, s.ui.scene_time.value)
    _move_frame(frame, x + dx, y + dy, yaw)


def _commit_obstacle(s, i: int, x: float, y: float, yaw: float) -> None:
    obstacles = list(s.scenario["obstacles"])
    obstacles[i] = moved_obstacle(obstacles[i], s.parsed.obstacles[i], x, y, yaw, s.track)
    s.selected = i
    s.apply_scenario(dict(s.scenario, obstacles=obstacles))


def moved_obstacle(ob: dict, parsed, x: float, y: float, yaw: float, track) -> dict:
    """``ob`` (a scenario dict) with its pose set to (x, y, yaw); one that follows the track
    starts from the centreline point nearest its new place."""
    out = dict(ob)
    if ob["type"] == "polygon":
        _, local = obstacle_shape(parsed)
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


# -- clicks on the ground ---------------------------------------------------------------------
def click_mode(s, mode: str) -> None:
    """Ground clicks add track points or polygon corners; ticking one mode unticks the other."""
    this, other = (s.ui.draw, s.ui.polygon) if mode == "track" else (s.ui.polygon, s.ui.draw)
    if this.value and other.value:
        other.value = False  # runs this again, which settles the mode
        return
    s.click_mode = "track" if s.ui.draw.value else "polygon" if s.ui.polygon.value else None
    s.scene.remove_click_callback("all")
    if s.click_mode is not None:
        s.scene.on_click()(lambda ev: _ground_click(s, ev))


def _ground_click(s, ev) -> None:
    """Where the click ray meets the ground plane z = 0."""
    (ox, oy, oz), (dx, dy, dz) = ev.ray_origin, ev.ray_direction
    if abs(dz) < 1e-12 or -oz / dz < 0:
        return
    t = -oz / dz
    p = (ox + t * dx, oy + t * dy)
    if s.click_mode == "polygon":
        s.polygon.append(p)
        show_polygon(s)
    elif s.click_mode == "track":
        s.draft.add(p)
        draft_changed(s)


def show_polygon(s) -> None:
    pts = np.array(s.polygon, dtype=float).reshape(-1, 2)
    seg = polyline_segments(pts, Z["pose"], closed=len(pts) > 2) if len(pts) > 1 else np.zeros(
        (0, 2, 3))
    s.scene.add_line_segments("/polygon_draft", seg, DRAFT_RGB, thickness=2.0,
                              thickness_units="screen", visible=len(seg) > 0)
    s.ui.polygon.label = f"Polygon (click the ground) — {len(pts)} corners"


# -- the drawn track --------------------------------------------------------------------------
def _bezier_points(ctrl: np.ndarray, n: int = 24) -> np.ndarray:
    t = np.linspace(0.0, 1.0, n)[:, None]
    return ((1 - t) ** 3 * ctrl[0] + 3 * (1 - t) ** 2 * t * ctrl[1]
            + 3 * (1 - t) * t ** 2 * ctrl[2] + t ** 3 * ctrl[3])


def _draw_draft_lines(s) -> None:
    """The curve through the anchors and each anchor's handle bar (mirrored both ways)."""
    d, closed = s.draft, bool(s.ui.draw_close.value)
    curves = [polyline_segments(_bezier_points(c), Z["pose"]) for c in d.beziers(closed)]
    bars = [polyline_segments(np.array([p - h, p + h]), Z["pose"])
            for p, h in ((d.points[i], d.handle(i, closed)) for i in range(len(d.points)))]
    empty = np.zeros((0, 2, 3), np.float32)
    s.scene.add_line_segments("/draft/line", np.concatenate(curves) if curves else empty,
                              DRAFT_RGB, thickness=2.0, thickness_units="screen",
                              visible=bool(curves))
    s.scene.add_line_segments("/draft/bars", np.concatenate(bars) if bars else empty,
                              (255, 200, 120), thickness=1.0, thickness_units="screen",
                              visible=bool(bars))


def _move_anchor(s, i: int, x: float, y: float) -> None:
    s.draft.points[i] = np.array([x, y])
    _place_handle_tips(s)
    _draw_draft_lines(s)


def _move_handle(s, i: int, x: float, y: float) -> None:
    s.draft.handles[i] = np.array([x, y]) - s.draft.points[i]
    _draw_draft_lines(s)


def _place_handle_tips(s) -> None:
    """Automatic handles follow their neighbours: keep their gizmos on the tips."""
    closed = bool(s.ui.draw_close.value)
    for i, (_, tip) in enumerate(s.draft_gizmos):
        if s.draft.handles[i] is None:
            tip.position = (*(s.draft.points[i] + s.draft.handle(i, closed)), Z["pose"])


def draft_changed(s) -> None:
    """Redraw the drawn track with a gizmo per anchor (drags the point) and per handle tip
    (drags the tangent, which stops following Catmull-Rom)."""
    for anchor, tip in s.draft_gizmos:
        anchor.remove()
        tip.remove()
    s.draft_gizmos = []
    closed = bool(s.ui.draw_close.value)
    for i, p in enumerate(s.draft.points):
        tip = p + s.draft.handle(i, closed)
        s.draft_gizmos.append((
            _gizmo(s, f"/draft/a{i}", (*p, 0.0), lambda x, y, _, i=i: _move_anchor(s, i, x, y),
                   None, rotate=False, px=60, visible=True),
            _gizmo(s, f"/draft/h{i}", (*tip, 0.0), lambda x, y, _, i=i: _move_handle(s, i, x, y),
                   None, rotate=False, px=35, visible=True)))
    _draw_draft_lines(s)
    s.ui.draw.label = f"Draw (click the ground) — {len(s.draft.points)} points"
