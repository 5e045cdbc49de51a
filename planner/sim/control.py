"""Path tracking: the committed trajectory as a reference, and three steering controllers.

All three return the wanted steering angle δ (before the actuator limits). Pure pursuit
(Coulter 1992) steers the rear axle onto a point a look-ahead ahead; Stanley (Thrun et al. 2006)
corrects heading and the front axle's cross-track error; the seed thesis's PD acts on the lateral
error alone, y = p·e + d·(e − e_old)/Δt, with the path curvature as feed-forward. The laws are
compiled (`planner.sim._tracking`): the guard rolls them out along a plan every cycle.
"""

from __future__ import annotations

from dataclasses import astuple, dataclass

import numpy as np

from planner.sim import _tracking
from planner.sim.vehicle import Limits

__all__ = ["CONTROLLERS", "Reference", "Tracker", "Tracking", "steer_command", "warm_up"]

CONTROLLERS = ("pure-pursuit", "stanley", "pd")
CUSP_REACH = 0.1  # m before a cusp within which a car at rest counts as at it


class Reference:
    """A dense path (rows x, y, θ, κ, direction) with its arc length, and a projection cursor.

    A path that reverses (Reeds-Shepp) is driven stretch by stretch: the car stops at each
    cusp (the row where the direction changes) and only then goes on along the next stretch.
    The projection stays on the current stretch, since the rows on either side of a cusp lie
    on top of each other; a row's direction is how the car arrives at it.
    """

    def __init__(self, rows: np.ndarray) -> None:
        self.rows = np.ascontiguousarray(rows, dtype=float)
        step = np.hypot(*np.diff(self.rows[:, :2], axis=0).T)
        self.s = np.concatenate([[0.0], np.cumsum(step)])
        self.cursor = 0
        dirs = self.rows[:, 4] if self.rows.shape[1] > 4 else np.ones(len(self.rows))
        cusps = np.flatnonzero(dirs[2:] != dirs[1:-1]) + 1  # row 0's arrival is not driven
        self.bounds = np.concatenate([[0], cusps, [len(self.rows) - 1]])  # stretch k: rows
        self.signs = dirs[np.minimum(self.bounds[:-1] + 1, len(dirs) - 1)]  # bounds[k]..[k+1]
        self.stretch = 0

    @property
    def length(self) -> float:
        return float(self.s[-1])

    @property
    def direction(self) -> float:
        """+1 forward, -1 reversing: the current stretch's."""
        return float(self.signs[self.stretch])

    @property
    def stretch_end(self) -> float:
        """Arc of the current stretch's end: the next cusp, or the path's end."""
        return float(self.s[self.bounds[self.stretch + 1]])

    def turns(self, stretch: int, s: float, v: float) -> bool:
        """Does a car at arc s on ``stretch``, at speed v, go on along the next stretch? Yes
        near the cusp (`CUSP_REACH`; the rows before and after it lie on top of each other)
        at rest, or already moving the next one's way (a plan made before it stood there)."""
        return (stretch + 1 < len(self.signs)
                and self.s[self.bounds[stretch + 1]] - s <= CUSP_REACH
                and (abs(v) < 1e-9 or v * self.signs[stretch + 1] > 0.0))

    def advance(self, v: float) -> bool:
        """On to the next stretch where `turns` says so; whether it did."""
        turn = self.turns(self.stretch, float(self.s[self.cursor]), v)
        self.stretch += turn
        return turn

    def project(self, x: float, y: float) -> tuple[int, float]:
        """(index of the nearest row near the cursor, signed lateral error, left positive).

        The search window runs a little back and well ahead of the last projection, within the
        current stretch, so a path that passes near itself (a loop, a cusp) does not make the
        cursor jump.
        """
        i, e = _tracking.project(self.rows, self.bounds, self.stretch, self.cursor, x, y)
        self.cursor = i
        return i, e

    def point_at(self, s: float) -> np.ndarray:
        """The row at arc length s (the nearest row at or after it)."""
        return self.rows[min(int(np.searchsorted(self.s, s)), len(self.rows) - 1)]

@dataclass(frozen=True)
class Tracking:
    """Controller gains. Look-ahead of pure pursuit: max(lookahead_min, lookahead_gain·|v|).

    Pure pursuit cuts a bend's change of curvature Δκ by about look-ahead²·Δκ / 8; a plan's
    tightest S-bend (Δκ = 2/ρ, 2.2 /m for the model car) is cut by 9 cm at 0.6 m, more than
    the simulator's planning margin (5 cm; the guard trusts tracking to half of it), and by
    3 cm at 0.35 m (0.35 s at 1 m/s)."""

    lookahead_min: float = 0.35
    lookahead_gain: float = 0.35
    stanley_k: float = 1.5
    stanley_soft: float = 0.2
    pd_p: float = 2.0
    pd_d: float = 1.2


@dataclass(frozen=True)
class Tracker:
    """A controller as the car runs it: its law and gains, at ``dt`` s a control tick."""

    controller: str = "pure-pursuit"
    gains: Tracking = Tracking()
    dt: float = 0.01

    def rollout(self, ref: Reference, state, vs: np.ndarray, stretches: np.ndarray,
                limits: Limits, step: float) -> np.ndarray:
        """The poses (n × 3) of the car from ``state`` (x, y, θ, v, δ), ``step`` s apart, at
        the speeds ``vs``, tracking ``ref`` on ``stretches`` (per sample): where the steering's
        rate and lock let it be, not where the plan is."""
        x, y, th, _, steer = state
        return _tracking.rollout(CONTROLLERS.index(self.controller), ref.rows, ref.s,
                                 ref.bounds, ref.signs, stretches, ref.cursor, x, y, th, steer,
                                 vs, limits.wheelbase, limits.max_steer, limits.max_steer_rate,
                                 self.dt, max(1, round(step / self.dt)), astuple(self.gains))


def steer_command(name: str, ref: Reference, i: int, e: float, e_old: float, pose, v: float,
                  wheelbase: float, dt: float, gains: Tracking) -> float:
    """The wanted steering angle from controller ``name`` at the projection (i, e).

    Reversing, the car is a forward car facing the other way that steers the other way (the
    kinematic model is symmetric under v → -v, θ → θ + π, δ → -δ): Stanley steers that mirror
    car. Pure pursuit's and the PD's laws come out the same both ways (sin(α - π) = -sin α;
    κ is the steering's), given a target on the stretch the car drives.
    """
    if name not in CONTROLLERS:
        raise ValueError(f"unknown controller '{name}' (use one of {', '.join(CONTROLLERS)})")
    x, y, th = pose
    return _tracking.steer(CONTROLLERS.index(name), ref.rows, ref.s, ref.bounds, ref.signs,
                           ref.stretch, i, e, e_old, x, y, th, v, wheelbase, dt,
                           astuple(gains))


def warm_up() -> None:
    """Load (or compile) the tracking kernels once, so that no cycle time includes it."""
    rows = np.zeros((3, 5))
    rows[:, 0], rows[:, 4] = (0.0, 0.1, 0.2), 1.0
    ref = Reference(rows)
    for name in CONTROLLERS:
        Tracker(name).rollout(ref, (0.0, 0.0, 0.0, 0.0, 0.0), np.zeros(2), np.zeros(2, np.int64),
                              Limits(0.3, 0.5, 1.0, 1.0, 1.0), 0.02)
