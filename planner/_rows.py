"""A plan's path as its consumers see it: rows joined by straight chords.

A plan returns rows [x, y, θ, κ, direction, t] at most `SPACING_M` apart along the path. Whoever
uses them — a controller, a plot, OMPL's checker, a student's script — joins them with chords,
interpolating every column linearly. On a curve whose curvature is at most 1/ρ, the chord of a
piece of arc length L lies within L²/(8ρ) (its sagitta) of the curve at the same share of the way
along both, and on an arc the heading turns evenly, as the interpolation turns it. So the
footprint on the chord is the footprint on the curve moved by at most the sagitta, and a plan
whose checks keep that much clearance beyond its margin (`chord_sag`) is valid as written. On a
clothoid the heading turns unevenly, and a footprint point away from the pose moves by its
distance times the heading's error too (`heading_sag`). `polyline_clearance` measures what a
consumer sees.
"""

from __future__ import annotations

import numpy as np

from planner._world import REACH, World, least_clearance

__all__ = ["CHECK_M", "CHECK_S", "SPACING_M", "chord_sag", "chord_sharpness", "heading_sag",
           "polyline", "polyline_clearance"]

SPACING_M = 0.05  # m between rows, at most (docs/scenario-format.md)
CHECK_M, CHECK_S = 0.005, 0.01  # returned paths are re-checked every 5 mm (and 10 ms of a wait)


def chord_sag(rho: float, spacing: float = SPACING_M) -> float:
    """The farthest a chord between rows ``spacing`` m apart on arcs of radius ``rho`` strays
    from the arc: ρ(1 − cos(L/2ρ)) ≤ L²/(8ρ)."""
    return spacing * spacing / (8.0 * rho)


def heading_sag(sigma: float, reach: float, spacing: float = SPACING_M) -> float:
    """The farthest a footprint point ``reach`` m from the pose strays between rows
    ``spacing`` m apart on a clothoid of sharpness ``sigma``: there the heading is quadratic in
    the distance, and off its linear interpolation by at most σL²/8 (on an arc, by nothing)."""
    return reach * sigma * spacing * spacing / 8.0


def chord_sharpness(sigma: float, rho: float, spacing: float = SPACING_M) -> float:
    """The sharpness to plan with so that rows ``spacing`` m apart change κ by at most ``sigma``
    times their chord, not only times the arc between them: at curvature ≤ 1/ρ a chord is at
    least L(1 − (L/ρ)²/24) of its arc's length L."""
    return sigma * (1.0 - (spacing / rho) ** 2 / 24.0)


def polyline(rows: np.ndarray, step: float = CHECK_M, time_step: float = CHECK_S,
             reach: float = 0.0) -> np.ndarray:
    """The rows' chords, each cut into pieces of at most ``step`` m — of the position, and of
    a footprint point ``reach`` m from it as the heading turns — and ``time_step`` s of column
    5 (t). Columns are interpolated linearly, the heading unwrapped; the others are copied."""
    rows = np.asarray(rows, dtype=float)
    if len(rows) < 2:
        return rows.copy()
    rows = rows.copy()
    rows[:, 2] = np.unwrap(rows[:, 2])
    gap = np.diff(rows, axis=0)
    pieces = np.maximum.reduce([
        np.ceil(np.hypot(gap[:, 0], gap[:, 1]) / step),
        np.ceil(np.abs(gap[:, 2]) * reach / step),
        np.ceil(np.abs(gap[:, 5]) / time_step) if rows.shape[1] > 5 else np.zeros(len(gap)),
        np.ones(len(gap))]).astype(np.int64)
    chord = np.repeat(np.arange(len(gap)), pieces)
    starts = np.cumsum(pieces) - pieces
    share = (np.arange(len(chord)) - starts[chord]) / pieces[chord]
    out = rows[chord].copy()
    linear = [c for c in (0, 1, 2, 5) if c < rows.shape[1]]
    out[:, linear] += share[:, None] * gap[chord][:, linear]
    return np.vstack([out, rows[-1:]])


def polyline_clearance(world: World, rows: np.ndarray, timed: bool) -> float:
    """The least clearance of the rows' polyline (in space-time when ``timed``)."""
    fine = polyline(rows, reach=float(world.geo[REACH]))
    return float(least_clearance(world, fine, timed))
