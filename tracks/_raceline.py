"""Trajectories in the TUM raceline layout, with the fastest feasible speed profile.

``# s_m; x_m; y_m; psi_rad; kappa_radpm; vx_mps; ax_mps2``. TUM's heading psi is measured from
+y, counter-clockwise positive, in [−π, π): psi = heading − π/2 in our frame. The speed is the
largest that keeps vx ≤ V, the lateral acceleration vx²·|κ| ≤ A_lat and |ax| ≤ A_long: the
pointwise cap min(V, √(A_lat/|κ|)) lowered by a forward pass (acceleration) and a backward pass
(braking). On a loop the passes start at the lowest cap, which no neighbour can lower, so one
lap of each is periodic; a road starts and ends at rest. ax_i = (v_{i+1}² − v_i²)/(2Δs_i).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tracks._errors import TrackError

HEADER = "# s_m; x_m; y_m; psi_rad; kappa_radpm; vx_mps; ax_mps2"


@dataclass(frozen=True)
class Limits:
    """Speed [m/s], lateral and longitudinal acceleration [m/s²] limits, all positive."""

    v_max: float
    a_lat: float = 4.0
    a_long: float = 2.0

    def __post_init__(self) -> None:
        for name, value in (("v_max", self.v_max), ("a_lat_max", self.a_lat),
                            ("a_long_max", self.a_long)):
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise TrackError(f"{name} must be a positive number, got {value!r}")


def _passes(cap: np.ndarray, ds: np.ndarray, a_long: float) -> np.ndarray:
    """Forward then backward pass over len(cap) points joined by len(cap) − 1 intervals."""
    v = cap.copy()
    reach = 2.0 * a_long * ds
    for i in range(len(ds)):
        v[i + 1] = min(v[i + 1], math.sqrt(v[i] * v[i] + reach[i]))
    for i in range(len(ds) - 1, -1, -1):
        v[i] = min(v[i], math.sqrt(v[i + 1] * v[i + 1] + reach[i]))
    return v


def speed_profile(
    s: np.ndarray, curvature: np.ndarray, limits: Limits, *, closed: bool, length: float,
    stops: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Speed and acceleration at stations ``s`` (a loop's closing station s = length left out).

    ``stops`` marks stations where the car must stand still (a cusp of a planned path).
    """
    kappa = np.abs(curvature)
    cap = np.minimum(limits.v_max, np.sqrt(limits.a_lat / np.maximum(kappa, 1e-300)))
    if stops is not None:
        cap[stops] = 0.0
    if closed:
        ds = np.diff(np.append(s, length))
        first = int(np.argmin(cap))
        ring = np.roll(cap, -first)
        v = _passes(np.append(ring, ring[0]), np.roll(ds, -first), limits.a_long)
        v = np.roll(v[:-1], first)
        ax = (np.roll(v, -1) ** 2 - v**2) / (2.0 * ds)
    else:
        ds = np.diff(s)
        cap[0] = cap[-1] = 0.0
        v = _passes(cap, ds, limits.a_long)
        ax = np.append((v[1:] ** 2 - v[:-1] ** 2) / (2.0 * ds), 0.0)
    return v, ax


def psi(heading: np.ndarray) -> np.ndarray:
    """TUM's heading: 0 along +y, counter-clockwise positive, in [−π, π)."""
    return (np.asarray(heading) - math.pi / 2 + math.pi) % (2 * math.pi) - math.pi


def raceline_rows(profile, limits: Limits) -> np.ndarray:
    """(n, 7) rows of the layout along a `Profile` (a loop's repeated end left out)."""
    end = len(profile.s) - 1 if profile.closed else len(profile.s)
    s, kappa = profile.s[:end], profile.curvature[:end]
    vx, ax = speed_profile(s, kappa, limits, closed=profile.closed, length=profile.length_m)
    return np.column_stack([s, profile.x[:end], profile.y[:end], psi(profile.heading[:end]),
                            kappa, vx, ax])


def path_rows(poses: np.ndarray, limits: Limits) -> np.ndarray:
    """Rows of the layout along a planned path of poses (x, y, θ): s by chords, κ = dθ/ds; the
    car stops where it changes direction and vx is negative while it reverses."""
    xy, theta = poses[:, :2], np.unwrap(poses[:, 2])
    step = np.diff(xy, axis=0)
    ds = np.hypot(step[:, 0], step[:, 1])
    keep = np.concatenate([[True], ds > 1e-12])
    xy, theta, poses = xy[keep], theta[keep], poses[keep]
    if len(xy) < 2:
        raise TrackError("the path is a single point: no raceline")
    step = np.diff(xy, axis=0)
    ds = np.hypot(step[:, 0], step[:, 1])
    s = np.concatenate([[0.0], np.cumsum(ds)])
    sign = np.where(step[:, 0] * np.cos(theta[:-1]) + step[:, 1] * np.sin(theta[:-1]) >= 0,
                    1.0, -1.0)  # per interval: forward or reversing
    direction = np.append(sign, sign[-1])
    kappa = np.diff(theta) / ds * sign
    kappa = np.append(kappa, kappa[-1])
    stops = np.flatnonzero(np.diff(sign) != 0) + 1
    vx, ax = speed_profile(s, kappa, limits, closed=False, length=s[-1], stops=stops)
    return np.column_stack([s, xy[:, 0], xy[:, 1], psi(theta), kappa, direction * vx, ax])


def raceline_csv(rows: np.ndarray) -> str:
    """The ``;``-separated text of `HEADER` and ``rows``."""
    body = ["; ".join(f"{v:.7f}" for v in row) for row in rows]
    return "\n".join([HEADER, *body]) + "\n"
