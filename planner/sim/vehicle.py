"""The simulated car: a kinematic bicycle advanced by the exact arc, with per-tick limits.

The pose (x, y, θ) is the rear-axle centre, which is also the centre of the collision disc.
Commands (v, δ) are held constant over a tick, so the motion over a tick is an exact circular
arc (or a straight line) — the same closed form the log replay test uses, no integration error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Limits", "arc_step", "limit_commands", "toward"]


@dataclass(frozen=True)
class Limits:
    """The car's geometry and actuator limits, SI units (angles in radians)."""

    wheelbase: float
    max_steer: float  # |δ| ≤ max_steer
    max_steer_rate: float  # rad/s
    max_speed: float
    max_accel: float  # m/s², speeding up and braking alike

    @classmethod
    def of(cls, vehicle) -> Limits:
        """From a scenario `Vehicle` (docs/scenario-format.md v1.2 fields, defaults applied)."""
        return cls(wheelbase=vehicle.wheelbase, max_steer=math.radians(vehicle.max_steer_deg),
                   max_steer_rate=math.radians(vehicle.max_steer_rate_deg_s),
                   max_speed=vehicle.max_speed if vehicle.max_speed is not None else vehicle.speed,
                   max_accel=vehicle.max_accel)


def limit_commands(v_prev: float, steer_prev: float, v_want: float, steer_want: float,
                   limits: Limits, dt: float) -> tuple[float, float]:
    """The commands the actuators can realise this tick, nearest to the wanted ones; a
    feasible command passes unchanged, bit for bit."""
    v = min(max(v_want, -limits.max_speed), limits.max_speed)
    s = min(max(steer_want, -limits.max_steer), limits.max_steer)
    return (toward(v_prev, v, limits.max_accel * dt),
            toward(steer_prev, s, limits.max_steer_rate * dt))


def toward(previous: float, wanted: float, step: float) -> float:
    """``wanted`` if it is within ``step`` of ``previous``, else ``previous`` moved by ``step``
    towards it. Decided on the difference, not on ``previous ± step`` (which rounds)."""
    if abs(wanted - previous) <= step:
        return wanted
    return previous + math.copysign(step, wanted - previous)


def arc_step(x, y, th, v, steer, wheelbase: float, dt: float):
    """Pose after holding (v, δ) for dt: the exact arc. Works on scalars and numpy arrays.

    Written as chord · (cos, sin)(θ + Δθ/2) with chord = v·dt·sinc(Δθ/2), which is the issue's
    (L / tan δ)(sin θ' − sin θ) form rearranged: equal for tan δ ≠ 0, exactly the straight step
    for δ = 0, and free of the cancellation that form suffers for tiny |δ|.
    """
    th = np.asarray(th, dtype=float)
    dth = np.asarray(v, dtype=float) * dt * np.tan(steer) / wheelbase
    chord = v * dt * np.sinc(dth / (2.0 * np.pi))  # np.sinc(u) = sin(πu) / (πu)
    mid = th + 0.5 * dth
    x2, y2, th2 = x + chord * np.cos(mid), y + chord * np.sin(mid), th + dth
    if np.ndim(x2) == 0:
        return float(x2), float(y2), float(th2)
    return x2, y2, th2
