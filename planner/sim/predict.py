"""The car's belief as a planning world: sensed movers extrapolated at constant velocity.

`build_world` precomputes a static distance grid (tens of ms), so the static part is compiled
once and each replanning cycle only swaps the motion arrays (`World._replace`): every mover gets
a two-waypoint motion that puts it, at planner time τ (absolute time t0 + τ), where constant
velocity from its last sensing predicts. ``geo[VMAX_OBS]`` is kept equal to the fastest
predicted speed, since the exact motion check relies on it.
"""

from __future__ import annotations

import numpy as np

from planner._world import VMAX_OBS, WAYPOINTS, World
from planner.sim.sensing import Sensing

__all__ = ["HORIZON_S", "predicted_world"]

HORIZON_S = 1.0e4  # the predicted straight line is long enough for any run


def predicted_world(base: World, sensing: Sensing, t0: float) -> World:
    """``base`` with its movers replaced by the constant-velocity prediction from ``sensing``."""
    n = sensing.offsets.shape[0]
    if n == 0:
        return base
    start = sensing.offsets + sensing.velocities * (t0 - sensing.t)
    end = start + sensing.velocities * HORIZON_S
    wp = np.empty((2 * n, 3))
    wp[0::2, 0], wp[0::2, 1:] = 0.0, start
    wp[1::2, 0], wp[1::2, 1:] = HORIZON_S, end
    geo = base.geo.copy()
    geo[VMAX_OBS] = float(np.hypot(*sensing.velocities.T).max())
    return base._replace(geo=geo, m_kind=np.full(n, WAYPOINTS, np.int64),
                         m_vel=np.zeros((n, 2)), m_wp_start=np.arange(0, 2 * n + 1, 2),
                         m_wp=wp)
