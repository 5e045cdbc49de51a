"""Bézier curves by de Casteljau: evaluation, hodographs, subdivision and rigorous length bounds.

Control polygons are float arrays of shape (..., k, 2) for degree k - 1. De Casteljau (repeated
convex combination) is used rather than the expanded Bernstein form because it stays stable for
any control points and the same triangle yields the two halves of a subdivision.
"""

from __future__ import annotations

import numpy as np


def de_casteljau(ctrl: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points of the Bézier curve with control polygon ``ctrl`` at parameters ``t`` (n,).

    ``ctrl`` is one polygon (k, 2) for all t, or one per t (n, k, 2).

    Examples
    --------
    >>> de_casteljau(np.array([[0.0, 0.0], [1.0, 2.0], [2.0, 0.0]]), np.array([0.5]))
    array([[1., 1.]])
    """
    t = np.asarray(t, dtype=float)[:, None, None]
    pts = ctrl if ctrl.ndim == 3 else ctrl[None]
    while pts.shape[1] > 1:
        pts = (1.0 - t) * pts[:, :-1] + t * pts[:, 1:]
    return np.broadcast_to(pts[:, 0], (t.shape[0], 2)).copy()


def elevate_to_cubic(ctrl: np.ndarray) -> np.ndarray:
    """The same curve, same parametrisation, as a cubic: lines and quadratics raised exactly."""
    if len(ctrl) == 2:
        return np.array(
            [ctrl[0], (2 * ctrl[0] + ctrl[1]) / 3, (ctrl[0] + 2 * ctrl[1]) / 3, ctrl[1]]
        )
    if len(ctrl) == 3:
        return np.array(
            [ctrl[0], (ctrl[0] + 2 * ctrl[1]) / 3, (2 * ctrl[1] + ctrl[2]) / 3, ctrl[2]]
        )
    return np.asarray(ctrl, dtype=float)


def hodograph(ctrl: np.ndarray) -> np.ndarray:
    """Control polygon of the derivative curve: degree·(P[i+1] − P[i]); a point curve gives 0."""
    if ctrl.shape[-2] < 2:
        return np.zeros_like(ctrl)
    return (ctrl.shape[-2] - 1) * np.diff(ctrl, axis=-2)


def split(ctrl: np.ndarray, t: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """The two control polygons of the curve cut at ``t``: the two outer edges of the triangle.

    Works on stacks (..., k, 2), so a whole level of a subdivision is one call.
    """
    left, right = [ctrl[..., 0, :]], [ctrl[..., -1, :]]
    pts = ctrl
    while pts.shape[-2] > 1:
        pts = (1.0 - t) * pts[..., :-1, :] + t * pts[..., 1:, :]
        left.append(pts[..., 0, :])
        right.append(pts[..., -1, :])
    return np.stack(left, axis=-2), np.stack(right[::-1], axis=-2)


def length_bounds(ctrl: np.ndarray, depth: int = 12) -> tuple[float, float]:
    """Lower and upper bound of the arc length after ``depth`` halvings by de Casteljau.

    The chord of each piece is never longer than the piece and its control polygon never
    shorter, so the two sums bracket the true length; the gap shrinks by 4 per level for a
    smooth curve. This needs no quadrature, which makes it an independent check of it.
    """
    pieces = np.asarray(ctrl, dtype=float)[None]
    for _ in range(depth):
        pieces = np.concatenate(split(pieces))
    chords = np.hypot(*(pieces[:, -1] - pieces[:, 0]).T).sum()
    polygons = np.hypot(*np.diff(pieces, axis=1).transpose(2, 0, 1)).sum()
    return float(chords), float(polygons)
