"""Simulated range sensors for behaviour state machines: rays cast into the true world at time t.

The sensors see what is physically there — the bounds, the drivable region's edges (track
boundaries), static obstacles and movers where their motion puts them at t — never the
planner's belief. All sensors sit at the car's reference point (the rear-axle centre, which is
also the centre of its collision disc), so a reading is the distance from there along the ray.

- wall sensors (``left`` / ``right``): a ray perpendicular to the heading and one 30° ahead of
  it, giving the wall's distance and the car's angle to it, for wall following;
- ultrasonic sensors ``left`` / ``front`` / ``right``: a narrow cone (a fan of rays, the shortest
  echo wins) pointing left, ahead and right;
- the lane ahead: parallel rays ahead across the car's width, for ``ObstacleAhead``.

Nothing within the maximum range reads ``inf``. Plain numpy: a few dozen rays against a few
hundred edges per tick.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from planner._world import World
from planner.sim.sensing import true_offsets

__all__ = ["MAX_RANGE", "Scene", "cast", "lane_ahead", "scene_at", "scene_of", "ultrasonic",
           "wall_estimate", "wall_range"]

MAX_RANGE = 4.0  # m, an ultrasonic sensor's reach
CONE_HALF = math.radians(15.0)  # half opening angle of an ultrasonic cone
CONE_RAYS = 7
LANE_SPACING = 0.05  # m at most between the lane's parallel rays: a 5 cm post cannot slip through
LANE_MARGIN = 0.1  # m beyond the car's widest disc on either side
WALL_AHEAD = math.radians(30.0)  # the wall sensor's second ray, from the perpendicular
DIRECTIONS = {"left": 0.5 * math.pi, "front": 0.0, "right": -0.5 * math.pi}


class Scene(NamedTuple):
    """What rays can hit, as arrays; movers at their position at t = 0 plus their motion index."""

    segments: np.ndarray  # (m, 4) x1, y1, x2, y2: bounds, region edges, polygon edges
    seg_motion: np.ndarray  # (m,) motion index, -1 when static
    circles: np.ndarray  # (n, 3) cx, cy, r
    circ_motion: np.ndarray  # (n,)


def scene_of(world: World) -> Scene:
    """The ray targets of a compiled world (built once per run)."""
    x0, y0, x1, y1 = world.geo[:4]
    box = np.array([[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]])
    per_poly = np.diff(world.poly_start)
    seg_motion = np.concatenate([np.full(4 + len(world.ring_edges), -1, np.int64),
                                 np.repeat(world.poly_motion, per_poly)])
    return Scene(np.vstack([box, world.ring_edges, world.poly_edges]), seg_motion,
                 world.circ.copy(), world.circ_motion.copy())


def scene_at(scene: Scene, world: World, t: float) -> tuple[np.ndarray, np.ndarray]:
    """(segments, circles) with every mover where it truly is at time t."""
    n_motions = len(world.m_kind)
    if n_motions == 0:
        return scene.segments, scene.circles
    off = true_offsets(world, np.arange(n_motions), [t])[0]  # (n_motions, 2)
    segs, circ = scene.segments.copy(), scene.circles.copy()
    moving = scene.seg_motion >= 0
    segs[moving] += np.tile(off[scene.seg_motion[moving]], 2)
    moving = scene.circ_motion >= 0
    circ[moving, :2] += off[scene.circ_motion[moving]]
    return segs, circ


def cast(segments: np.ndarray, circles: np.ndarray, ox, oy, angles,
         max_range: float = MAX_RANGE) -> np.ndarray:
    """Distance along each ray (origin (ox, oy), direction ``angles``) to the first hit, or inf
    when nothing lies within ``max_range``. Origins broadcast against angles."""
    ox, oy, angles = (np.atleast_1d(a) for a in np.broadcast_arrays(
        np.asarray(ox, float), np.asarray(oy, float), np.asarray(angles, float)))
    ox, oy = ox[:, None], oy[:, None]
    dx, dy = np.cos(angles)[:, None], np.sin(angles)[:, None]
    best = np.full(angles.shape[0], np.inf)
    if len(segments):
        ex, ey = segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1]
        px, py = segments[:, 0] - ox, segments[:, 1] - oy
        den = dx * ey - dy * ex
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (px * ey - py * ex) / den  # along the ray
            u = (px * dy - py * dx) / den  # along the segment
        s = np.where((den != 0.0) & (s >= 0.0) & (u >= 0.0) & (u <= 1.0), s, np.inf)
        best = np.minimum(best, s.min(axis=1))
    if len(circles):
        cx, cy = ox - circles[:, 0], oy - circles[:, 1]
        b = dx * cx + dy * cy
        c = cx * cx + cy * cy - circles[:, 2] ** 2
        disc = b * b - c
        with np.errstate(invalid="ignore"):
            s = np.where(c <= 0.0, 0.0, -b - np.sqrt(disc))  # inside a circle: range 0
        s = np.where((c <= 0.0) | ((disc >= 0.0) & (s >= 0.0)), s, np.inf)
        best = np.minimum(best, s.min(axis=1))
    return np.where(best <= max_range, best, np.inf)


def wall_range(segments, circles, pose, side: str, ahead: float = 0.0,
               max_range: float = MAX_RANGE) -> float:
    """The ray to ``side`` (left | right), turned ``ahead`` radians towards the front from the
    perpendicular: distance to the wall there."""
    x, y, th = pose
    turn = -ahead if side == "left" else ahead
    return float(cast(segments, circles, x, y, [th + DIRECTIONS[side] + turn], max_range)[0])


def wall_estimate(segments, circles, pose, side: str) -> tuple[float, float]:
    """(distance, angle) of a straight wall on ``side`` from the perpendicular ray b and one
    ``WALL_AHEAD`` further forward, a: the car heads towards the wall at ψ = atan((b − a·cos φ) /
    (a·sin φ)) and is b·cos ψ from it. The perpendicular reading alone, d / cos ψ, grows as the
    car turns either way, which would feed a PD turning towards the wall. Without an echo
    ahead (the wall ends) ψ reads 0; without a perpendicular one, the distance is inf."""
    b = wall_range(segments, circles, pose, side)
    a = wall_range(segments, circles, pose, side, WALL_AHEAD)
    if not math.isfinite(b) or not math.isfinite(a):
        return b, 0.0
    psi = math.atan2(b - a * math.cos(WALL_AHEAD), a * math.sin(WALL_AHEAD))
    return b * math.cos(psi), psi


def ultrasonic(segments, circles, pose, name: str, max_range: float = MAX_RANGE) -> float:
    """Ultrasonic sensor ``name`` (left | front | right): the nearest echo in its cone."""
    x, y, th = pose
    fan = th + DIRECTIONS[name] + np.linspace(-CONE_HALF, CONE_HALF, CONE_RAYS)
    return float(cast(segments, circles, x, y, fan, max_range).min())


def lane_ahead(segments, circles, pose, half_width: float,
               max_range: float = MAX_RANGE) -> float:
    """Free distance ahead in the car's lane: parallel rays across ±``half_width``."""
    x, y, th = pose
    n = math.ceil(2.0 * half_width / LANE_SPACING - 1e-9) + 1
    lateral = np.linspace(-half_width, half_width, n)
    ox, oy = x - lateral * math.sin(th), y + lateral * math.cos(th)
    return float(cast(segments, circles, ox, oy, th, max_range).min())
