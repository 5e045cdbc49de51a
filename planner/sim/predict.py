"""The car's belief as a planning world: sensed movers extrapolated at constant velocity, each
grown by an uncertainty that widens with the look-ahead time.

`build_world` precomputes a static distance grid (tens of ms), so the static part is compiled
once and each replanning cycle only swaps the motion arrays (`World._replace`): every mover gets
a two-waypoint motion that puts it, at planner time τ (absolute time t0 + τ), where constant
velocity from its last sensing predicts, and a growth (`planner._world.growth`) of

    e_v·τ_s + ½·a·τ_s²,   τ_s = min(time since the sensing, T),

for a mover whose velocity estimate is off by at most e_v and that changes its velocity at most
at a (the `Uncertainty`): the set where it can be is its shape grown by that much. The growth is
held beyond the horizon T, so far look-aheads do not close every lane; the car re-checks what it
commits to every cycle (`planner.sim.guard`). ``geo[VMAX_OBS]`` is kept at the fastest predicted
speed plus the fastest growth, since the exact motion checks rely on it.

A mover whose timetable the car is told (`motion.known`: a door, a barrier, a train) keeps its
true motion, shifted into planner time, with no growth.

On a track whose movers keep to their lanes (`prediction.along_track`), constant velocity is
wrong in every bend: it sends a mover off along the tangent, so one that follows the car round
a curve is believed to leave. `Lanes` predicts each mover along the centreline instead, at its
sensed speed along it, at the distance beside the centreline where it was sensed; the growth is
the same.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planner._world import VELOCITY, VMAX_OBS, WAYPOINTS, World, only_movers
from planner.obstacles import reference_points
from planner.problem import resolve_track
from planner.sim.sensing import Sensing

__all__ = ["HORIZON_S", "REACH_S", "Agility", "Lanes", "Uncertainty", "believed_offsets",
           "likely_worlds", "predicted_world", "reach_rates", "reach_world", "turn_velocities",
           "without_growth"]

HORIZON_S = 1.0e4  # the predicted straight line is long enough for any run
LANE_SPACING = 0.05  # m between the centreline samples a lane prediction follows
LANE_STEP = 0.1  # m of arc between a lane prediction's waypoints (chord error ≤ 2.5 mm at ρ 0.5 m)
# s over which a reachable set widens, held beyond (`reach_world`). Widening until the car is
# at rest, the square's walkers left it crawling (16 of 72 runs out of time, 6 at 1 s); at
# 0.5 s a walker's turn 1 m ahead still hit it (docs/simulation.md).
REACH_S = 1.0
LANE_HORIZON_S = 30.0  # s of lane prediction; a mover is believed to stand beyond (re-predicted
# every cycle, and far beyond any commitment the guard checks)


@dataclass(frozen=True)
class Uncertainty:
    """How far a mover may stray from its constant-velocity prediction (all ≥ 0)."""

    accel: float = 1.0  # m/s²: the most a mover changes its velocity per second
    speed_error: float = 0.1  # m/s: the most the sensed velocity is off
    horizon: float = 1.5  # s of look-ahead over which the growth widens; held beyond

    def __post_init__(self) -> None:
        for name in ("accel", "speed_error", "horizon"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"--predict-{name.replace('_', '-')} must be a finite number "
                                 f">= 0, got {v}")

    def growth(self, tau):
        """The growth (m) at look-ahead ``tau`` (s) from a sensing."""
        tau = np.clip(tau, 0.0, self.horizon)
        return tau * (self.speed_error + 0.5 * self.accel * tau)

    @property
    def rate(self) -> float:
        """The fastest the growth widens (m/s)."""
        return self.speed_error + self.accel * self.horizon


@dataclass(frozen=True)
class Lanes:
    """A closed or open track's centreline, for predicting movers that keep to it."""

    s: np.ndarray  # (k,) arc length of the samples
    xy: np.ndarray  # (k, 2) centreline samples
    normal: np.ndarray  # (k, 2) unit normals, pointing left of the centreline's direction
    closed: bool
    anchors: np.ndarray  # (n_motions, 2) each mover's reference point at offset 0

    @classmethod
    def of(cls, scenario, load_track=None) -> Lanes | None:
        """The lanes of the scenario's track when its movers keep to them
        (`prediction.along_track`), else None; ``load_track`` as for `resolve_track`."""
        if not scenario.prediction.along_track:
            return None
        track = resolve_track(scenario, load_track)
        prof = track.sample(spacing=LANE_SPACING)
        return cls(prof.s, np.column_stack([prof.x, prof.y]),
                   np.column_stack([-np.sin(prof.heading), np.cos(prof.heading)]),
                   track.closed, reference_points(scenario.obstacles))

    def advance(self, offsets: np.ndarray, velocities: np.ndarray, lag: np.ndarray) -> np.ndarray:
        """(len(lag), n, 2): the offsets of movers sensed at ``offsets`` with ``velocities``,
        each driven ``lag`` seconds along the centreline at its speed along it, at the
        distance beside it where it was sensed (exactly there at lag 0)."""
        p = self.anchors + offsets
        a, ab = self.xy[:-1], np.diff(self.xy, axis=0)
        ab2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-18)
        w = np.clip(np.einsum("mkj,kj->mk", p[:, None] - a, ab) / ab2, 0.0, 1.0)
        near = np.argmin(np.sum((a + w[..., None] * ab - p[:, None]) ** 2, axis=2), axis=1)
        rows = np.arange(len(p))
        s0 = self.s[near] + w[rows, near] * np.sqrt(ab2[near])
        along = np.einsum("mj,mj->m", velocities, ab[near]) / np.sqrt(ab2[near])
        s = s0 + along * np.asarray(lag, dtype=float)[:, None]
        length = self.s[-1]
        s = np.mod(s, length) if self.closed else np.clip(s, 0.0, length)
        at, normal = self._point(s0, 0.0), self._normal(s0)
        beside = np.einsum("mj,mj->m", p - at, normal)
        off_lane = p - at - beside[:, None] * normal  # the sampling's along-lane slack, ~mm
        return self._point(s, beside) + off_lane - self.anchors

    def _normal(self, s: np.ndarray) -> np.ndarray:
        n = np.stack([np.interp(s, self.s, self.normal[:, k]) for k in (0, 1)], axis=-1)
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    def _point(self, s: np.ndarray, beside) -> np.ndarray:
        c = np.stack([np.interp(s, self.s, self.xy[:, k]) for k in (0, 1)], axis=-1)
        return c + np.asarray(beside)[..., None] * self._normal(s)


def believed_offsets(sensing: Sensing, t0: float, taus, lanes: Lanes | None = None) -> np.ndarray:
    """(len(taus), n_motions, 2): where the car believes each mover is (the centre of its grown
    shape) at absolute times ``t0 + taus``: on from its sensing at constant velocity, or along
    ``lanes``."""
    taus = np.asarray(taus, dtype=float)
    if lanes is None:
        now = sensing.offsets + sensing.velocities * (t0 - sensing.t)
        return now + sensing.velocities * taus[:, None, None]
    return lanes.advance(sensing.offsets, sensing.velocities, (t0 - sensing.t) + taus)


def predicted_world(base: World, sensing: Sensing, t0: float,
                    uncertainty: Uncertainty = Uncertainty(), known=None,
                    lanes: Lanes | None = None) -> World:
    """``base`` with its movers replaced by the grown prediction from ``sensing`` (at constant
    velocity, or along ``lanes``), in a planner time that starts at absolute time ``t0``; the
    movers where the boolean ``known`` (per motion, world order) is true keep their true
    motion."""
    n = sensing.offsets.shape[0]
    if n == 0:
        return base
    known = np.zeros(n, bool) if known is None else np.asarray(known, bool)
    if lanes is None:
        taus = np.array([0.0, HORIZON_S])
    else:
        fastest = float(np.hypot(*sensing.velocities.T).max())
        taus = np.linspace(0.0, LANE_HORIZON_S,
                           int(np.clip(fastest * LANE_HORIZON_S / LANE_STEP, 1, 2000)) + 1)
    believed = believed_offsets(sensing, t0, taus, lanes)
    wps = [_timetable(base, m, t0) if known[m] else np.column_stack([taus, believed[:, m]])
           for m in range(n)]
    grow = np.zeros((n, 5))
    grow[~known] = (0.0, uncertainty.speed_error, uncertainty.accel, t0 - sensing.t,
                    uncertainty.horizon)
    geo = base.geo.copy()
    if lanes is None:
        speeds = np.hypot(*sensing.velocities[~known].T)
    else:  # the fastest chord, as fast as the mover beside a bend's outside
        speeds = np.hypot(*np.diff(believed[:, ~known], axis=0).T) / np.diff(taus)[None, :]
    geo[VMAX_OBS] = max(float(speeds.max()) + uncertainty.rate if speeds.size else 0.0,
                        base.geo[VMAX_OBS] if known.any() else 0.0)
    return base._replace(geo=geo, m_kind=np.full(n, WAYPOINTS, np.int64),
                         m_vel=np.zeros((n, 2)),
                         m_wp_start=np.concatenate([[0], np.cumsum([len(w) for w in wps])]).astype(np.int64),
                         m_wp=np.vstack(wps), m_grow=grow)


@dataclass
class Agility:
    """What the car has seen each mover (per motion) do: the fastest it went, and whether it
    ever changed its velocity faster than the `Uncertainty` allows between two sensings — a
    walker turning at once at a waypoint, a shuttle reversing, a walker setting off — and
    whether it did so at the latest sensing (``jumped``, from velocity ``before``)."""

    fastest: np.ndarray
    turned: np.ndarray
    last_t: float = math.nan  # the previous sensing's time and velocities
    last_velocities: np.ndarray | None = None
    jumped: np.ndarray | None = None
    before: np.ndarray | None = None

    @classmethod
    def none(cls, n: int) -> Agility:
        return cls(np.zeros(n), np.zeros(n, bool))

    def see(self, sensing: Sensing, uncertainty: Uncertainty) -> None:
        self.fastest = np.maximum(self.fastest, np.hypot(*sensing.velocities.T))
        if self.last_velocities is not None:
            jump = np.hypot(*(sensing.velocities - self.last_velocities).T)
            allowed = uncertainty.accel * (sensing.t - self.last_t) + 2.0 * uncertainty.speed_error
            self.jumped, self.before = jump > allowed + 1e-9, self.last_velocities
            self.turned |= self.jumped
        self.last_t, self.last_velocities = sensing.t, sensing.velocities


TURN_SHARES = (0.5, 1.0)  # where on its ray a just-turned mover's new velocity is tried


def turn_velocities(sensing: Sensing, agility: Agility, known=None) -> list[np.ndarray]:
    """The velocities the movers that jumped at this sensing (`Agility.jumped`) may have now,
    besides the sensed one, each a full (n_motions, 2) array.

    A finite difference across a turn blends the velocities before and after it: the sensed
    v̂ = (1 − w)·v₀ + w·v₁, w the unknown share of the interval after the turn. So v₁ lies on
    the ray from v₀ through v̂, at or beyond v̂, and no faster than the mover has been seen to
    go: a walker that turned back mid-interval is sensed standing, and is tried walking back
    at its speed (`TURN_SHARES` of the way from v̂ to that end of the ray)."""
    if agility.jumped is None:
        return []
    who = agility.jumped if known is None else agility.jumped & ~np.asarray(known, bool)
    if not who.any():
        return []
    v0, v, top = agility.before[who], sensing.velocities[who], agility.fastest[who]
    d = v - v0
    # |v0 + k·d| = top, k ≥ 1: the ray's far end at the mover's top speed
    dd, vd, vv = (np.einsum("ij,ij->i", a, b) for a, b in ((d, d), (v0, d), (v0, v0)))
    k = (-vd + np.sqrt(np.maximum(vd * vd - dd * (vv - top * top), 0.0))) / np.maximum(dd, 1e-18)
    out = []
    for share in TURN_SHARES:
        alt = sensing.velocities.copy()
        alt[who] = v + share * (np.maximum(k, 1.0) - 1.0)[:, None] * d
        out.append(alt)
    return out


def without_growth(world: World) -> World:
    """``world``'s movers where their predictions take them, not grown: their likely futures."""
    grow = world.m_grow.copy()
    grow[:, 1:3] = 0.0
    return world._replace(m_grow=grow)


def likely_worlds(believed: World, base: World, sensing: Sensing, t0: float, agility: Agility,
                  known=None, lanes: Lanes | None = None) -> list[World]:
    """The movers' likely futures: ``believed`` (`predicted_world`) without its growth, and
    one world more for each velocity a mover that just turned may have now
    (`turn_velocities`)."""
    return [without_growth(believed)] + [
        without_growth(predicted_world(base, Sensing(sensing.t, sensing.offsets, v), t0,
                                       known=known, lanes=lanes))
        for v in turn_velocities(sensing, agility, known)]


def reach_rates(agility: Agility, uncertainty: Uncertainty = Uncertainty(), known=None,
                lanes: Lanes | None = None) -> np.ndarray:
    """Per motion: how fast its reachable set (`reach_world`) widens, v̂ + e_v (m/s), v̂ the
    fastest it has been seen to go; NaN for a mover that has none.

    Only a mover that has turned at once (`Agility`) has one. Movers that have kept their
    course have only the grown prediction (`predicted_world`): a car that braked for every
    car behind it in a stream would be run into; so do the movers of a scene that says they
    keep to their lanes (``lanes``) and those whose timetable the car is told (``known``)."""
    known = np.zeros(len(agility.turned), bool) if known is None else np.asarray(known, bool)
    has = agility.turned & ~known & (lanes is None)
    return np.where(has, agility.fastest + uncertainty.speed_error, math.nan)


def reach_world(base: World, sensing: Sensing, t0: float, agility: Agility,
                uncertainty: Uncertainty = Uncertainty(), known=None,
                lanes: Lanes | None = None) -> World | None:
    """The movers' reachable sets (`reach_rates`), and no other shape: each mover that has
    turned at once where it was sensed, grown by (v̂ + e_v)·τ, τ the time since the sensing
    (held beyond `REACH_S`) — every place it can be, whatever it does next, for as long as the
    car needs to see a turn and act on it. None: no mover has one.

    A walker that turns at a waypoint has an acceleration no bound covers, but it walks no
    faster than it does: the guard (passive safety) has the car at rest before one of these
    sets reaches it."""
    rates = reach_rates(agility, uncertainty, known, lanes)
    has = np.isfinite(rates)
    if not has.any():
        return None
    velocities = np.where(has[:, None], 0.0, sensing.velocities)
    world = only_movers(predicted_world(base, Sensing(sensing.t, sensing.offsets, velocities),
                                        t0, uncertainty, known), has)
    grow = world.m_grow.copy()
    grow[has] = np.column_stack([np.zeros(has.sum()), rates[has], np.zeros(has.sum()),
                                 np.full(has.sum(), t0 - sensing.t), np.full(has.sum(), REACH_S)])
    geo = world.geo.copy()
    geo[VMAX_OBS] = float(rates[has].max())
    return world._replace(geo=geo, m_grow=grow)


def _timetable(base: World, m: int, t0: float) -> np.ndarray:
    """Motion ``m``'s true waypoints in a planner time that starts at absolute time ``t0``."""
    if base.m_kind[m] == VELOCITY:
        return np.array([[0.0, *(base.m_vel[m] * t0)],
                         [HORIZON_S, *(base.m_vel[m] * (t0 + HORIZON_S))]])
    wp = base.m_wp[base.m_wp_start[m]:base.m_wp_start[m + 1]].copy()
    wp[:, 0] -= t0
    return wp
