"""Obstacles as shapes in motion, in one place for the planner, the simulator, the studio and
the animation: an obstacle's outline in its own frame with the pose that places it, the world
corners the planner compiles, and its motion as a table of offsets over time.

An offset (dx, dy) translates the whole obstacle; the pose's point (a circle's or box's centre,
a polygon's centroid) is where the studio draws it from and where a lane prediction projects
it onto a track (`planner.sim.predict.Lanes`).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["VELOCITY_TABLE_S", "box_corners", "follow_waypoints", "motion_table", "outline",
           "reference_points", "table_offsets"]

CIRCLE_SIDES = 48  # a circle's drawn outline
VELOCITY_TABLE_S = 1.0e4  # a constant-velocity motion as a table: this long covers any run


def _box_local(size) -> list[tuple[float, float]]:
    hx, hy = size[0] / 2, size[1] / 2
    return [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]


def box_corners(center, size, angle_deg: float) -> list[tuple[float, float]]:
    """A box's corners in the world, counter-clockwise."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return [(center[0] + c * u - s * v, center[1] + s * u + c * v) for u, v in _box_local(size)]


def outline(ob) -> tuple[tuple[float, float, float], np.ndarray]:
    """An obstacle as a pose (x, y, yaw) and its outline in its own frame: dragging moves and
    turns the pose, a motion offsets it, and the outline is triangulated once."""
    if ob.type == "circle":
        a = np.linspace(0, 2 * math.pi, CIRCLE_SIDES, endpoint=False)
        return (*ob.center, 0.0), ob.radius * np.column_stack([np.cos(a), np.sin(a)])
    if ob.type == "box":
        return (*ob.center, math.radians(ob.angle_deg)), np.array(_box_local(ob.size))
    pts = np.array(ob.points, dtype=float)
    c = _centroid(pts)
    return (*c, 0.0), pts - c


def _centroid(pts: np.ndarray) -> np.ndarray:
    """A polygon's area centroid (shoelace); the mean vertex when it has no area."""
    x, y = pts[:, 0], pts[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    area = cross.sum() / 2.0
    if abs(area) < 1e-12 * max(1.0, float(np.ptp(pts)) ** 2):
        return pts.mean(axis=0)
    return np.array([((x + np.roll(x, -1)) * cross).sum(),
                     ((y + np.roll(y, -1)) * cross).sum()]) / (6.0 * area)


def reference_points(obstacles) -> np.ndarray:
    """(n_moving, 2): the pose points of the obstacles that move, in their order (the
    compiled world's motion order)."""
    return np.array([outline(ob)[0][:2] for ob in obstacles if ob.motion is not None],
                    dtype=float).reshape(-1, 2)


def follow_waypoints(track, follow, step_s: float = 0.05) -> np.ndarray:
    """A track-following motion as dense timed offsets from its position at t = 0."""
    prof = track.sample(spacing=0.02)
    times = np.arange(0.0, follow.horizon_s + step_s, step_s)
    s = follow.start_s + follow.speed * times
    s = np.mod(s, prof.s[-1]) if track.closed else np.clip(s, 0.0, prof.s[-1])
    x = np.interp(s, prof.s, prof.x)
    y = np.interp(s, prof.s, prof.y)
    return np.column_stack([times, x - x[0], y - y[0]])


def motion_table(motion, track=None) -> np.ndarray | None:
    """A motion as rows (t, dx, dy) whose linear interpolation, clamped at both ends, is the
    obstacle's offset at time t, as the planner reads it; None for a static obstacle
    (``track``: for a motion that follows it)."""
    if motion is None:
        return None
    if motion.velocity is not None:
        return np.array([[0.0, 0.0, 0.0],
                         [VELOCITY_TABLE_S, *(np.array(motion.velocity) * VELOCITY_TABLE_S)]])
    if motion.waypoints is not None:
        return np.array(motion.waypoints, dtype=float)
    return follow_waypoints(track, motion.follow_track)


def table_offsets(table: np.ndarray | None, times) -> np.ndarray:
    """(len(times), 2): the offsets a motion table gives at ``times`` (zeros: static)."""
    times = np.atleast_1d(np.asarray(times, dtype=float))
    if table is None:
        return np.zeros((len(times), 2))
    return np.column_stack([np.interp(times, table[:, 0], table[:, 1]),
                            np.interp(times, table[:, 0], table[:, 2])])
