"""Path tracking: the committed trajectory as a reference, and three steering controllers.

All three return the wanted steering angle δ (before the actuator limits). Pure pursuit
(Coulter 1992) steers the rear axle onto a point a look-ahead ahead; Stanley (Thrun et al. 2006)
corrects heading and the front axle's cross-track error; the seed thesis's PD acts on the lateral
error alone, y = p·e + d·(e − e_old)/Δt, with the path curvature as feed-forward.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["CONTROLLERS", "Reference", "Tracking", "steer_command"]

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
        self.rows = np.asarray(rows, dtype=float)
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
        lo = max(self.cursor - 20, self.bounds[self.stretch])
        hi = min(self.cursor + 400, self.bounds[self.stretch + 1] + 1)
        d2 = (self.rows[lo:hi, 0] - x) ** 2 + (self.rows[lo:hi, 1] - y) ** 2
        i = lo + int(np.argmin(d2))
        self.cursor = i
        rx, ry, rth = self.rows[i, :3]
        if i < self.bounds[self.stretch + 1]:  # refine towards the stretch's next row
            nx, ny = self.rows[i + 1, :2]
            den = (nx - rx) ** 2 + (ny - ry) ** 2
            if den > 0:
                u = ((x - rx) * (nx - rx) + (y - ry) * (ny - ry)) / den
                if 0.0 < u < 1.0:
                    rx, ry = rx + u * (nx - rx), ry + u * (ny - ry)
        e = -(x - rx) * math.sin(rth) + (y - ry) * math.cos(rth)
        return i, e

    def point_at(self, s: float) -> np.ndarray:
        """The row at arc length s (the nearest row at or after it)."""
        return self.rows[min(int(np.searchsorted(self.s, s)), len(self.rows) - 1)]

    def target(self, s: float) -> np.ndarray:
        """The point at arc s on the current stretch (x, y). Beyond the stretch's end it goes
        on straight the way the car drives there, so that a look-ahead near a cusp or the end
        still points along the final heading instead of cutting towards the end point."""
        end = self.stretch_end
        if s <= end:
            return self.point_at(s)[:2]
        row = self.rows[self.bounds[self.stretch + 1]]
        d = (s - end) * self.direction
        return np.array([row[0] + d * math.cos(row[2]), row[1] + d * math.sin(row[2])])


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


def steer_command(name: str, ref: Reference, i: int, e: float, e_old: float, pose, v: float,
                  wheelbase: float, dt: float, gains: Tracking) -> float:
    """The wanted steering angle from controller ``name`` at the projection (i, e)."""
    x, y, th = pose
    rth, kappa = ref.rows[i, 2], ref.rows[i, 3]
    # Reversing, the car is a forward car facing the other way that steers the other way
    # (the kinematic model is symmetric under v → -v, θ → θ + π, δ → -δ): Stanley steers that
    # mirror car. Pure pursuit's and the PD's laws come out the same both ways (sin(α - π)
    # = -sin α; κ is the steering's), given a target on the stretch the car drives.
    d = ref.direction
    if name == "pure-pursuit":
        ld = max(gains.lookahead_min, gains.lookahead_gain * abs(v))
        tx, ty = ref.target(ref.s[i] + ld)
        alpha = math.atan2(ty - y, tx - x) - th
        dist = max(math.hypot(tx - x, ty - y), 1e-6)
        return math.atan(2.0 * wheelbase * math.sin(alpha) / dist)
    if name == "stanley":
        th_m = th if d > 0 else th + math.pi
        fx, fy = x + wheelbase * math.cos(th_m), y + wheelbase * math.sin(th_m)
        j, ef = _front_projection(ref, i, fx, fy)
        dth = math.remainder(ref.rows[j, 2] - th, 2.0 * math.pi)
        return d * (dth + math.atan2(-gains.stanley_k * d * ef, gains.stanley_soft + abs(v)))
    if name == "pd":
        dth = math.remainder(th - rth, 2.0 * math.pi)
        # The lateral error's rate is v·sin(heading error) exactly; the finite difference of the
        # seed's PD is kept for its first tick only (e_old is NaN then).
        de = v * math.sin(dth) if math.isnan(e_old) else (e - e_old) / dt
        return math.atan(wheelbase * kappa) - gains.pd_p * e - gains.pd_d * de
    raise ValueError(f"unknown controller '{name}' (use one of {', '.join(CONTROLLERS)})")


def _front_projection(ref: Reference, i: int, fx: float, fy: float) -> tuple[int, float]:
    hi = min(i + 200, ref.bounds[ref.stretch + 1] + 1)
    d2 = (ref.rows[i:hi, 0] - fx) ** 2 + (ref.rows[i:hi, 1] - fy) ** 2
    j = i + int(np.argmin(d2))
    rx, ry, rth = ref.rows[j, :3]
    return j, -(fx - rx) * math.sin(rth) + (fy - ry) * math.cos(rth)
