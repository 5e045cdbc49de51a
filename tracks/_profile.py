"""Resampling a chain of segments at a fixed arc-length spacing, with driving profiles.

Curvature is analytic, κ = (x'y'' − x''y') / |B'|³ (left turns positive), and the steering angle
is the single-track model's δ = atan(L·κ). Where the speed vanishes (coincident control points,
cusps) the derivatives are taken a hair inside the segment, so values stay finite.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tracks._arclength import LengthTable, params_at
from tracks._chain import Chain

_NUDGE = 1e-7


@dataclass(frozen=True, eq=False)
class Profile:
    """A track resampled every ``spacing`` metres: one row per target point, world frame.

    ``s`` runs from 0 (the path's start) to the length (its end; for a loop, the start again).
    ``feasible`` is |δ| ≤ δmax.
    """

    length_m: float
    closed: bool
    s: np.ndarray
    x: np.ndarray
    y: np.ndarray
    heading: np.ndarray
    curvature: np.ndarray
    steering_deg: np.ndarray
    feasible: np.ndarray

    COLUMNS = ("s", "x", "y", "heading", "curvature", "steering_deg", "feasible")

    def rows(self) -> list[dict]:
        """One dict per point with the keys of ``COLUMNS`` (plain Python numbers)."""
        columns = [getattr(self, name).tolist() for name in self.COLUMNS]
        return [dict(zip(self.COLUMNS, values)) for values in zip(*columns)]

    def to_dict(self) -> dict:
        """The object of ``trackstar track sample --json``."""
        return {"length_m": self.length_m, "closed": self.closed, "points": self.rows()}


def arc_length_stations(length: float, spacing: float) -> np.ndarray:
    """0, h, 2h, … and the length itself as the last station (never a sliver below 1e-9 h)."""
    count = math.floor(length / spacing * (1 + 1e-12)) + 1
    s = np.arange(count) * spacing
    if length - s[-1] > 1e-9 * spacing:
        return np.append(s, length)
    s[-1] = length
    return s


def sample_chain(
    chain: Chain, table: LengthTable, s: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points, first and second derivatives (each (n, 2)) at arc lengths ``s`` along the chain."""
    idx, t = params_at(chain.velocity, table, s)
    d1, d2 = chain.derivatives(idx, t)
    seg_length = table.segment_lengths(chain.count)[idx]
    stalled = np.hypot(*d1.T) <= 1e-9 * seg_length
    if stalled.any():
        t_inside = np.where(t < 0.5, t + _NUDGE, t - _NUDGE)[stalled]
        d1[stalled], d2[stalled] = chain.derivatives(idx[stalled], t_inside)
    return chain.point(idx, t), d1, d2


def driving_profile(
    chain: Chain,
    table: LengthTable,
    *,
    closed: bool,
    spacing: float,
    wheelbase: float,
    max_steer_deg: float,
) -> Profile:
    """Resample the chain every ``spacing`` metres and add heading, curvature and steering."""
    length = table.length
    s = arc_length_stations(length, spacing)
    points, d1, d2 = sample_chain(chain, table, s)
    speed = np.hypot(*d1.T)
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    curvature = np.divide(cross, speed**3, out=np.zeros_like(cross), where=speed > 0)
    steering = np.degrees(np.arctan(wheelbase * curvature))
    return Profile(
        length_m=length,
        closed=closed,
        s=s,
        x=points[:, 0],
        y=points[:, 1],
        heading=np.arctan2(d1[:, 1], d1[:, 0]),
        curvature=curvature,
        steering_deg=steering,
        feasible=np.abs(steering) <= max_steer_deg,
    )
