"""The C2 cubic spline through points, over cumulative chord length, as exact cubic Béziers.

Natural ends for a road, periodic for a loop. Each interval is the cubic Hermite piece with the
spline's slopes at its ends, i.e. the Bézier (p_i, p_i + h·d_i/3, p_{i+1} − h·d_{i+1}/3,
p_{i+1}). The slopes solve a (cyclic) tridiagonal system: the Thomas algorithm, with
Sherman–Morrison for the corners of a loop, in O(n) and plain numpy (no scipy at runtime).
"""

from __future__ import annotations

import numpy as np

from tracks._segments import Bezier


def _thomas(sub: np.ndarray, diag: np.ndarray, sup: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve the tridiagonal system (row i: sub[i]·x[i−1] + diag[i]·x[i] + sup[i]·x[i+1]);
    ``rhs`` (n, k) holds k right-hand sides. Diagonally dominant here, so no pivoting."""
    n = len(diag)
    c, d = np.empty(n), np.empty_like(rhs)
    c[0], d[0] = sup[0] / diag[0], rhs[0] / diag[0]
    for i in range(1, n):
        m = diag[i] - sub[i] * c[i - 1]
        c[i] = sup[i] / m
        d[i] = (rhs[i] - sub[i] * d[i - 1]) / m
    for i in range(n - 2, -1, -1):
        d[i] -= c[i] * d[i + 1]
    return d


def _cyclic(sub: np.ndarray, diag: np.ndarray, sup: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve the cyclic tridiagonal system (sub[0] in the top right, sup[-1] bottom left)."""
    gamma = -diag[0]
    bent = diag.copy()
    bent[0] -= gamma
    bent[-1] -= sup[-1] * sub[0] / gamma
    u = np.zeros((len(diag), 1))
    u[0], u[-1] = gamma, sup[-1]
    both = _thomas(sub, bent, sup, np.hstack([rhs, u]))
    x, z = both[:, :-1], both[:, -1:]
    factor = (x[0] + sub[0] * x[-1] / gamma) / (1.0 + z[0] + sub[0] * z[-1] / gamma)
    return x - z * factor


def spline_beziers(points: np.ndarray, closed: bool) -> list[Bezier]:
    """Cubic Béziers of the C2 spline through ``points`` (n, 2), distinct neighbours, n ≥ 3;
    a loop closes from the last point back to the first (which is not repeated)."""
    knots = np.vstack([points, points[:1]]) if closed else points
    chords = np.diff(knots, axis=0)
    h = np.hypot(chords[:, 0], chords[:, 1])
    secant = chords / h[:, None]
    if closed:  # row i: the intervals before (a) and after (b) knot i
        a, b = np.roll(h, 1), h
        sa, sb = np.roll(secant, 1, axis=0), secant
        rhs = 3.0 * (b[:, None] * sa + a[:, None] * sb)
        slopes = _cyclic(b, 2.0 * (a + b), a, rhs)
        slopes = np.vstack([slopes, slopes[:1]])
    else:
        a, b = h[:-1], h[1:]
        sub = np.concatenate([[0.0], b, [1.0]])
        diag = np.concatenate([[2.0], 2.0 * (a + b), [2.0]])
        sup = np.concatenate([[1.0], a, [0.0]])
        inner = b[:, None] * secant[:-1] + a[:, None] * secant[1:]
        rhs = 3.0 * np.vstack([secant[:1], inner, secant[-1:]])
        slopes = _thomas(sub, diag, sup, rhs)
    third = h[:, None] / 3.0
    return [
        Bezier(np.array([p, p + t * d0, q - t * d1, q]))
        for p, q, t, d0, d1 in zip(knots[:-1], knots[1:], third, slopes[:-1], slopes[1:])
    ]
