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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planner._world import VELOCITY, VMAX_OBS, WAYPOINTS, World
from planner.sim.sensing import Sensing

__all__ = ["HORIZON_S", "Uncertainty", "predicted_world"]

HORIZON_S = 1.0e4  # the predicted straight line is long enough for any run


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


def predicted_world(base: World, sensing: Sensing, t0: float,
                    uncertainty: Uncertainty = Uncertainty(), known=None) -> World:
    """``base`` with its movers replaced by the grown constant-velocity prediction from
    ``sensing``, in a planner time that starts at absolute time ``t0``; the movers where the
    boolean ``known`` (per motion, world order) is true keep their true motion."""
    n = sensing.offsets.shape[0]
    if n == 0:
        return base
    known = np.zeros(n, bool) if known is None else np.asarray(known, bool)
    start = sensing.offsets + sensing.velocities * (t0 - sensing.t)
    wps = [_timetable(base, m, t0) if known[m] else
           np.array([[0.0, *start[m]], [HORIZON_S, *(start[m] + sensing.velocities[m] * HORIZON_S)]])
           for m in range(n)]
    grow = np.zeros((n, 5))
    grow[~known] = (0.0, uncertainty.speed_error, uncertainty.accel, t0 - sensing.t,
                    uncertainty.horizon)
    geo = base.geo.copy()
    predicted = np.hypot(*sensing.velocities[~known].T)
    geo[VMAX_OBS] = max(float(predicted.max()) + uncertainty.rate if len(predicted) else 0.0,
                        base.geo[VMAX_OBS] if known.any() else 0.0)
    return base._replace(geo=geo, m_kind=np.full(n, WAYPOINTS, np.int64),
                         m_vel=np.zeros((n, 2)),
                         m_wp_start=np.concatenate([[0], np.cumsum([len(w) for w in wps])]).astype(np.int64),
                         m_wp=np.vstack(wps), m_grow=grow)


def _timetable(base: World, m: int, t0: float) -> np.ndarray:
    """Motion ``m``'s true waypoints in a planner time that starts at absolute time ``t0``."""
    if base.m_kind[m] == VELOCITY:
        return np.array([[0.0, *(base.m_vel[m] * t0)],
                         [HORIZON_S, *(base.m_vel[m] * (t0 + HORIZON_S))]])
    wp = base.m_wp[base.m_wp_start[m]:base.m_wp_start[m + 1]].copy()
    wp[:, 0] -= t0
    return wp
