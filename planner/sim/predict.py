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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planner._world import VMAX_OBS, WAYPOINTS, World
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
                    uncertainty: Uncertainty = Uncertainty()) -> World:
    """``base`` with its movers replaced by the grown constant-velocity prediction from
    ``sensing``, in a planner time that starts at absolute time ``t0``."""
    n = sensing.offsets.shape[0]
    if n == 0:
        return base
    start = sensing.offsets + sensing.velocities * (t0 - sensing.t)
    end = start + sensing.velocities * HORIZON_S
    wp = np.empty((2 * n, 3))
    wp[0::2, 0], wp[0::2, 1:] = 0.0, start
    wp[1::2, 0], wp[1::2, 1:] = HORIZON_S, end
    grow = np.empty((n, 5))
    grow[:] = (0.0, uncertainty.speed_error, uncertainty.accel, t0 - sensing.t,
               uncertainty.horizon)
    geo = base.geo.copy()
    geo[VMAX_OBS] = float(np.hypot(*sensing.velocities.T).max()) + uncertainty.rate
    return base._replace(geo=geo, m_kind=np.full(n, WAYPOINTS, np.int64),
                         m_vel=np.zeros((n, 2)), m_wp_start=np.arange(0, 2 * n + 1, 2),
                         m_wp=wp, m_grow=grow)
