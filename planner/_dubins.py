"""Dubins shortest paths (forward-only car), analytic, in the shared segment form of `_paths`.

The six words LSL, RSR, RSL, LSR, RLR, LRL in the normalised frame of Shkel & Lumelsky (2001),
as OMPL's DubinsStateSpace writes them: distances are divided by ρ, the start frame is rotated so
the goal lies on the +x axis, α and β are the start and goal headings in that frame.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_TWO_PI = 2.0 * math.pi
# Word table: the steering of the three segments of each word (+1 left, 0 straight, -1 right).
_WORDS = np.array(
    [[1, 0, 1], [-1, 0, -1], [-1, 0, 1], [1, 0, -1], [-1, 1, -1], [1, -1, 1]], dtype=np.int8
)


@njit(cache=True, inline="always")
def _mod2pi(a: float) -> float:
    r = a % _TWO_PI
    return 0.0 if r > _TWO_PI - 1e-12 else r


_ZERO = -1e-9  # tolerate rounding in exactly tangent cases (a pure arc: the straight is 0)


@njit(cache=True, inline="always")
def _sqrt0(v: float) -> float:
    return math.sqrt(max(v, 0.0))


@njit(cache=True, inline="always")
def _keep(best, i, t, p, q):
    """Keep word i if it is shorter than ``best`` = (index, t, p, q)."""
    if t + p + q < best[1] + best[2] + best[3]:
        return (i, t, p, q)
    return best


@njit(cache=True)
def _shortest_word(x0, y0, th0, x1, y1, th1, rho, bound):
    """(word index, t, p, q) of the shortest word, lengths normalised by ρ. No allocation.

    Words that cannot beat ``bound`` (normalised) are skipped as soon as that is known: the
    middle segment p of a CSC word costs one square root, its outer arcs two atan2 more, and a
    CCC word is never shorter than π. The result is index -1 when nothing beats the bound.
    """
    dx = (x1 - x0) / rho
    dy = (y1 - y0) / rho
    d = math.hypot(dx, dy)
    theta = math.atan2(dy, dx) if d > 1e-12 else 0.0
    a = _mod2pi(th0 - theta)
    b = _mod2pi(th1 - theta)
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    cab = ca * cb + sa * sb
    best = (-1, bound, 0.0, 0.0)
    # LSL
    tmp = 2.0 + d * d - 2.0 * cab + 2.0 * d * (sa - sb)
    if tmp >= _ZERO and _sqrt0(tmp) < best[1] + best[2] + best[3]:
        th = math.atan2(cb - ca, d + sa - sb)
        best = _keep(best, 0, _mod2pi(-a + th), _sqrt0(tmp), _mod2pi(b - th))
    # RSR
    tmp = 2.0 + d * d - 2.0 * cab + 2.0 * d * (sb - sa)
    if tmp >= _ZERO and _sqrt0(tmp) < best[1] + best[2] + best[3]:
        th = math.atan2(ca - cb, d - sa + sb)
        best = _keep(best, 1, _mod2pi(a - th), _sqrt0(tmp), _mod2pi(-b + th))
    # RSL
    tmp = d * d - 2.0 + 2.0 * cab - 2.0 * d * (sa + sb)
    if tmp >= _ZERO and _sqrt0(tmp) < best[1] + best[2] + best[3]:
        p = _sqrt0(tmp)
        th = math.atan2(ca + cb, d - sa - sb) - math.atan2(2.0, p)
        best = _keep(best, 2, _mod2pi(a - th), p, _mod2pi(b - th))
    # LSR
    tmp = -2.0 + d * d + 2.0 * cab + 2.0 * d * (sa + sb)
    if tmp >= _ZERO and _sqrt0(tmp) < best[1] + best[2] + best[3]:
        p = _sqrt0(tmp)
        th = math.atan2(-ca - cb, d + sa + sb) - math.atan2(-2.0, p)
        best = _keep(best, 3, _mod2pi(-a + th), p, _mod2pi(-b + th))
    if best[1] + best[2] + best[3] <= math.pi:
        return best  # CCC words are never shorter than π
    # RLR
    tmp = 0.125 * (6.0 - d * d + 2.0 * cab + 2.0 * d * (sa - sb))
    if abs(tmp) <= 1.0:
        p = _TWO_PI - math.acos(tmp)
        th = math.atan2(ca - cb, d - sa + sb)
        t = _mod2pi(a - th + 0.5 * p)
        best = _keep(best, 4, t, p, _mod2pi(a - b - t + p))
    # LRL
    tmp = 0.125 * (6.0 - d * d + 2.0 * cab + 2.0 * d * (-sa + sb))
    if abs(tmp) <= 1.0:
        p = _TWO_PI - math.acos(tmp)
        th = math.atan2(-ca + cb, d + sa - sb)
        t = _mod2pi(-a + th + 0.5 * p)
        best = _keep(best, 5, t, p, _mod2pi(b - a - t + p))
    return best


@njit(cache=True)
def dubins_path(x0, y0, th0, x1, y1, th1, rho, kinds_out, lens_out) -> float:
    """Shortest Dubins path from pose 0 to pose 1; fills kinds_out/lens_out, returns its length."""
    i, t, p, q = _shortest_word(x0, y0, th0, x1, y1, th1, rho, math.inf)
    kinds_out[:] = 0
    lens_out[:] = 0.0
    kinds_out[0] = _WORDS[i, 0]
    kinds_out[1] = _WORDS[i, 1]
    kinds_out[2] = _WORDS[i, 2]
    lens_out[0] = t * rho
    lens_out[1] = p * rho
    lens_out[2] = q * rho
    return (t + p + q) * rho


@njit(cache=True)
def dubins_length(x0, y0, th0, x1, y1, th1, rho, bound) -> float:
    """Length of the shortest Dubins path, or ``bound`` itself as soon as no word can beat it."""
    i, t, p, q = _shortest_word(x0, y0, th0, x1, y1, th1, rho, bound / rho)
    return bound if i < 0 else (t + p + q) * rho


@njit(cache=True, inline="always")
def dubins_to_point(x, y, th, px, py, rho) -> float:
    """Shortest forward path from a pose to a *point* (any final heading): a lower bound of
    every Dubins length to a pose at that point.

    Outside both turning circles the optimum is CS, turning towards the point's side first
    (Bui, Souères, Boissonnat & Laumond 1994); inside one we fall back to the straight line.
    """
    c, s = math.cos(th), math.sin(th)
    dx, dy = px - x, py - y
    u = c * dx + s * dy
    v = abs(-s * dx + c * dy)  # mirror to the left side
    dc = math.hypot(u, v - rho)
    if dc < rho or math.hypot(u, v) < 1e-9:
        # Inside a turning circle, or (nearly) at the point already, where the exact Dubins
        # code counts it as reached: the straight line is the bound.
        return math.hypot(u, v)
    phi = _mod2pi(math.atan2(v - rho, u) + 0.5 * math.pi - math.acos(min(rho / dc, 1.0)))
    if phi > 2.0 * math.pi - 1e-7:
        phi = 0.0  # rounding of "straight ahead": a smaller bound is always a valid one
    return rho * phi + math.sqrt(dc * dc - rho * rho)
