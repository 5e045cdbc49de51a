"""Dubins shortest paths (forward-only car), analytic, in the shared segment form of `_paths`.

The six words LSL, RSR, RSL, LSR, RLR, LRL in the normalised frame of Shkel & Lumelsky (2001),
as OMPL's DubinsStateSpace writes them: distances are divided by ρ, the start frame is rotated so
the goal lies on the +x axis, α and β are the start and goal headings in that frame.
"""

from __future__ import annotations

import math

import numpy as np

from planner._jit import njit

_TWO_PI = 2.0 * math.pi
# Word table: the steering of the three segments of each word (+1 left, 0 straight, -1 right).
_WORDS = np.array(
    [[1, 0, 1], [-1, 0, -1], [-1, 0, 1], [1, 0, -1], [-1, 1, -1], [1, -1, 1]], dtype=np.int8
)


@njit(cache=True, inline="always")
def mod2pi(a: float) -> float:
    """Wrap to [0, 2π). Branches for the common |a| < 2π: Python's floored ``%`` costs about
    eight times as much, and a Dubins length takes up to 14 of these."""
    if a < 0.0:
        a += _TWO_PI
        if a < 0.0:
            a -= _TWO_PI * math.floor(a / _TWO_PI)
    elif a >= _TWO_PI:
        a -= _TWO_PI * math.floor(a / _TWO_PI)
    return 0.0 if a > _TWO_PI - 1e-12 or a < 0.0 else a


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
def _shortest_word(dx, dy, c0, s0, c1, s1, bound):
    """(word index, t, p, q) of the shortest word, lengths normalised by ρ. No allocation.

    (dx, dy) is the goal position relative to the start, divided by ρ; (c0, s0) and (c1, s1)
    are the cosines and sines of the start and goal headings, so a caller that keeps them per
    node pays no trigonometry here. Words that cannot beat ``bound`` (normalised) are skipped
    as soon as that is known: the middle segment p of a CSC word costs one square root, then
    lower bounds of its two arcs from their cosines and sines (`_arc_bound`) a few
    multiplications; the atan2 calls come only for words that can still beat the bound. A CCC
    word is never shorter than π. The result is index -1 when nothing beats the bound.
    """
    d = math.sqrt(dx * dx + dy * dy)
    ct, st = (dx / d, dy / d) if d > 1e-12 else (1.0, 0.0)
    ca, sa = c0 * ct + s0 * st, s0 * ct - c0 * st  # α = θ0 − atan2(dy, dx)
    cb, sb = c1 * ct + s1 * st, s1 * ct - c1 * st  # β = θ1 − atan2(dy, dx)
    cab = ca * cb + sa * sb
    a = b = -1.0  # not computed yet
    best = (-1, bound, 0.0, 0.0)
    # CSC words: tmp is p² written as a sum of squares (minus 4), which keeps short straight
    # paths exact to rounding where the textbook 2 + d² − 2 cos(α − β) + ... cancels.
    # LSL: t = θ − α, q = β − θ with θ the direction of (d + sa − sb, cb − ca), of norm p
    tmp = (d + sa - sb) ** 2 + (cb - ca) ** 2
    p = _sqrt0(tmp)
    if tmp >= _ZERO and p < best[1] + best[2] + best[3] and (p == 0.0 or p + _arcs_bound(
            (d + sa - sb) / p, (cb - ca) / p, ca, sa, cb, sb, -1.0, 1.0)
            < best[1] + best[2] + best[3]):
        a, b = _angles(a, b, ca, sa, cb, sb)
        th = math.atan2(cb - ca, d + sa - sb)
        best = _keep(best, 0, mod2pi(-a + th), _sqrt0(tmp), mod2pi(b - th))
    # RSR: t = α − θ, q = θ − β with θ the direction of (d − sa + sb, ca − cb)
    tmp = (d - sa + sb) ** 2 + (ca - cb) ** 2
    p = _sqrt0(tmp)
    if tmp >= _ZERO and p < best[1] + best[2] + best[3] and (p == 0.0 or p + _arcs_bound(
            (d - sa + sb) / p, (ca - cb) / p, ca, sa, cb, sb, 1.0, -1.0)
            < best[1] + best[2] + best[3]):
        a, b = _angles(a, b, ca, sa, cb, sb)
        th = math.atan2(ca - cb, d - sa + sb)
        best = _keep(best, 1, mod2pi(a - th), _sqrt0(tmp), mod2pi(-b + th))
    # RSL: t = α − θ, q = β − θ with θ = angle(d − sa − sb, ca + cb) − angle(p, 2); both
    # vectors have the norm √(p² + 4)
    tmp = (d - sa - sb) ** 2 + (ca + cb) ** 2 - 4.0
    p = _sqrt0(tmp)
    n2 = p * p + 4.0
    if tmp >= _ZERO and p < best[1] + best[2] + best[3] and p + _arcs_bound(
            ((d - sa - sb) * p + (ca + cb) * 2.0) / n2, ((ca + cb) * p - (d - sa - sb) * 2.0) / n2,
            ca, sa, cb, sb, 1.0, 1.0) < best[1] + best[2] + best[3]:
        a, b = _angles(a, b, ca, sa, cb, sb)
        th = math.atan2(ca + cb, d - sa - sb) - math.atan2(2.0, p)
        best = _keep(best, 2, mod2pi(a - th), p, mod2pi(b - th))
    # LSR: t = θ − α, q = θ − β with θ = angle(d + sa + sb, −ca − cb) − angle(p, −2)
    tmp = (d + sa + sb) ** 2 + (ca + cb) ** 2 - 4.0
    p = _sqrt0(tmp)
    n2 = p * p + 4.0
    if tmp >= _ZERO and p < best[1] + best[2] + best[3] and p + _arcs_bound(
            ((d + sa + sb) * p + (ca + cb) * 2.0) / n2, (-(ca + cb) * p + (d + sa + sb) * 2.0) / n2,
            ca, sa, cb, sb, -1.0, -1.0) < best[1] + best[2] + best[3]:
        a, b = _angles(a, b, ca, sa, cb, sb)
        th = math.atan2(-ca - cb, d + sa + sb) - math.atan2(-2.0, p)
        best = _keep(best, 3, mod2pi(-a + th), p, mod2pi(-b + th))
    if best[1] + best[2] + best[3] <= math.pi:
        return best  # CCC words are never shorter than π
    sab = sb * ca - cb * sa  # sin(β − α)
    # RLR
    tmp = 0.125 * (6.0 - d * d + 2.0 * cab + 2.0 * d * (sa - sb))
    if abs(tmp) <= 1.0 and _ccc_bound(tmp, cab, sab) < best[1] + best[2] + best[3]:
        a, b = _angles(a, b, ca, sa, cb, sb)
        p = _TWO_PI - math.acos(tmp)
        th = math.atan2(ca - cb, d - sa + sb)
        t = mod2pi(a - th + 0.5 * p)
        best = _keep(best, 4, t, p, mod2pi(a - b - t + p))
    # LRL
    tmp = 0.125 * (6.0 - d * d + 2.0 * cab + 2.0 * d * (-sa + sb))
    if abs(tmp) <= 1.0 and _ccc_bound(tmp, cab, -sab) < best[1] + best[2] + best[3]:
        a, b = _angles(a, b, ca, sa, cb, sb)
        p = _TWO_PI - math.acos(tmp)
        th = math.atan2(-ca + cb, d + sa - sb)
        t = mod2pi(-a + th + 0.5 * p)
        best = _keep(best, 5, t, p, mod2pi(b - a - t + p))
    return best


@njit(cache=True, inline="always")
def _arc_bound(c, s) -> float:
    """A lower bound of the angle φ in [0, 2π) with cos φ = c and sin φ = s, without atan2: in
    each quadrant φ exceeds the quadrant's start by at least the sine of the excess. Angles
    within 1e-9 of 0 or 2π count as 0, as `mod2pi` rounds them."""
    if s >= -1e-9:
        return max(s, 0.0) if c >= 0.0 else 0.5 * math.pi - c
    return math.pi - s if c < 0.0 else 1.5 * math.pi + c


@njit(cache=True, inline="always")
def _arcs_bound(ct, st, ca, sa, cb, sb, sign_t, sign_q) -> float:
    """Lower bound of t + q for a CSC word with middle direction θ = (ct, st): t = sign_t·(α − θ)
    and q = sign_q·(β − θ), taken mod 2π."""
    c_t, s_t = ca * ct + sa * st, sign_t * (sa * ct - ca * st)
    c_q, s_q = cb * ct + sb * st, sign_q * (sb * ct - cb * st)
    return _arc_bound(c_t, s_t) + _arc_bound(c_q, s_q)


@njit(cache=True, inline="always")
def _ccc_bound(x, cd, sd) -> float:
    """A lower bound of a CCC word's length t + p + q without acos or atan2, given x = cos p
    and the cosine and sine of the word's net turning ±(β − α) signed so that t + q ≡ p − it
    (mod 2π): then t + q ≥ (p − it) mod 2π, bounded by `_arc_bound`. The middle arc
    p = 2π − acos(x) is at least its bound below (acos(x) ≤ π/2 − x for x ≥ 0 and
    ≤ π/2 + (π/2)|x| for x < 0: asin is convex on [0, 1]). Without the outer arcs nearly every
    pose facing back at a node passed as a possible CCC word and paid for three atan2."""
    p_low = 1.5 * math.pi + x if x >= 0.0 else 1.5 * math.pi + 0.5 * math.pi * x
    sp = -math.sqrt(max(1.0 - x * x, 0.0))  # sin p ≤ 0 for p in [π, 2π]
    return p_low + _arc_bound(x * cd + sp * sd, sp * cd - x * sd)


@njit(cache=True, inline="always")
def _angles(a, b, ca, sa, cb, sb):
    """α and β in [0, 2π) from their cosines and sines, once (negative means "not yet")."""
    if a < 0.0:
        a = mod2pi(math.atan2(sa, ca))
        b = mod2pi(math.atan2(sb, cb))
    return a, b


@njit(cache=True)
def dubins_path(x0, y0, th0, x1, y1, th1, rho, kinds_out, lens_out) -> float:
    """Shortest Dubins path from pose 0 to pose 1; fills kinds_out/lens_out, returns its length."""
    i, t, p, q = _shortest_word((x1 - x0) / rho, (y1 - y0) / rho, math.cos(th0),
                                math.sin(th0), math.cos(th1), math.sin(th1), math.inf)
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
    return dubins_length_cs(x0, y0, math.cos(th0), math.sin(th0), x1, y1, math.cos(th1),
                            math.sin(th1), rho, bound)


@njit(cache=True, inline="always")
def dubins_length_cs(x0, y0, c0, s0, x1, y1, c1, s1, rho, bound) -> float:
    """`dubins_length` with the headings given by their cosines and sines (kept per tree node,
    they make a pruned length cost a few multiplications and square roots)."""
    i, t, p, q = _shortest_word((x1 - x0) / rho, (y1 - y0) / rho, c0, s0, c1, s1, bound / rho)
    return bound if i < 0 else (t + p + q) * rho


@njit(cache=True, inline="always")
def turning_centres(x, y, c, s, rho):
    """Centres of the left and right turning circles of the pose (x, y) with heading cos and
    sin c, s: (left x, left y, right x, right y)."""
    return x - rho * s, y + rho * c, x + rho * s, y - rho * c


@njit(cache=True, inline="always")
def dubins_lower_bound(l0x, l0y, r0x, r0y, l1x, l1y, r1x, r1y, turn, rho) -> float:
    """A lower bound of the Dubins length from two square roots, given both poses' turning
    circle centres (`turning_centres`, kept per tree node) and ``turn`` = θ1 − θ0 wrapped to
    [−π, π].

    The centre of the car's left turning circle, p + ρ·n, moves at speed 1 − ρκ, the right
    one's at 1 + ρκ; over a forward path of length ℓ and net turning τ they give
    ℓ ≥ |Δc_left| + ρτ and ℓ ≥ |Δc_right| − ρτ. τ is ``turn`` + 2πk for an unknown k, so
    the bound is the least over k, attained at one of the two k nearest the balance point.
    It is never below the chord or ρ|Δθ|, and close to the length where the car has to turn
    round (a pose facing back at a node), where those two let every node through.
    """
    a = math.sqrt((l1x - l0x) * (l1x - l0x) + (l1y - l0y) * (l1y - l0y))
    b = math.sqrt((r1x - r0x) * (r1x - r0x) + (r1y - r0y) * (r1y - r0y))
    x = rho * turn
    y = x - math.copysign(_TWO_PI * rho, turn)  # the other side of 0
    return min(max(a + x, b - x), max(a + y, b - y))


@njit(cache=True, inline="always")
def _sweep_holds(hx0, hy0, vx, vy, hx1, hy1, sweep, tol) -> bool:
    """Does the direction (vx, vy) lie in the counter-clockwise sweep of angle ``sweep`` from
    the unit heading h0 to h1 (cross products within ``tol`` count as inside)?"""
    after0 = hx0 * vy - hy0 * vx >= -tol
    before1 = vx * hy1 - vy * hx1 >= -tol
    return (after0 and before1) if sweep <= math.pi else (after0 or before1)


@njit(cache=True, inline="always")
def _tangent_arcs(ux, uy, c0, s0, c1, s1, inv, sign) -> float:
    """Lower bound of t + q for a mixed CSC word (LSR: sign +1, RSL: −1) whose straight runs
    along u (|u|² = 1 / inv): t and q are the angles from the headings to u, counter-clockwise
    for LSR, clockwise for RSL (`_arc_bound` of each)."""
    return (_arc_bound((ux * c0 + uy * s0) * inv, sign * (c0 * uy - s0 * ux) * inv)
            + _arc_bound((ux * c1 + uy * s1) * inv, sign * (c1 * uy - s1 * ux) * inv))


@njit(cache=True)
def dubins_word_bound(l0x, l0y, r0x, r0y, c0, s0, l1x, l1y, r1x, r1y, c1, s1, turn,
                      rho) -> float:
    """A lower bound of the Dubins length from turning-circle centres (`turning_centres`),
    heading cosines and sines and ``turn`` = θ1 − θ0 wrapped to [−π, π], in the world frame:
    no normalisation and no atan2, tighter than `dubins_lower_bound` and dearer.

    The minimum over the six words of a bound of each: LSL and RSR exactly (their arcs add up
    to the turn mod 2π, plus a full loop when the straight's direction is not swept between
    the headings), LSR and RSL from the inner tangent's direction (`_tangent_arcs`), CCC words
    from `_ccc_bound`. A pose facing back at a nearby node is where this matters: the turning
    circles let such a node through at 5 ρ when its path is 7 ρ long.
    """
    tiny = 1e-9 * rho
    ccw = turn if turn > -1e-9 else turn + _TWO_PI  # LSL's turning, rounded like mod2pi
    cw = -turn if turn < 1e-9 else _TWO_PI - turn
    vx, vy = l1x - l0x, l1y - l0y
    a = math.sqrt(vx * vx + vy * vy)
    loop = 0.0 if a < 1e-6 * rho or _sweep_holds(c0, s0, vx, vy, c1, s1, ccw, 1e-9 * a) \
        else _TWO_PI
    best = a + rho * (ccw + loop)
    wx, wy = r1x - r0x, r1y - r0y
    b = math.sqrt(wx * wx + wy * wy)
    loop = 0.0 if b < 1e-6 * rho or _sweep_holds(c1, s1, wx, wy, c0, s0, cw, 1e-9 * b) \
        else _TWO_PI
    best = min(best, b + rho * (cw + loop))
    four = 4.0 * rho * rho
    vx, vy = r1x - l0x, r1y - l0y  # LSR: the straight is R1 − L0 turned left by asin(2ρ/D)
    d2 = vx * vx + vy * vy
    if d2 - four >= _ZERO * rho * rho:  # tangent circles within rounding count, as in LSR
        p = _sqrt0(d2 - four)
        arcs = _tangent_arcs(vx * p - 2.0 * rho * vy, vy * p + 2.0 * rho * vx, c0, s0, c1,
                             s1, 1.0 / d2, 1.0)
        best = min(best, p + rho * arcs)
    vx, vy = l1x - r0x, l1y - r0y  # RSL: L1 − R0 turned right
    d2 = vx * vx + vy * vy
    if d2 - four >= _ZERO * rho * rho:
        p = _sqrt0(d2 - four)
        arcs = _tangent_arcs(vx * p + 2.0 * rho * vy, vy * p - 2.0 * rho * vx, c0, s0, c1,
                             s1, 1.0 / d2, -1.0)
        best = min(best, p + rho * arcs)
    if best > math.pi * rho:  # CCC words are never shorter than π ρ
        ct, st = c0 * c1 + s0 * s1, c0 * s1 - s0 * c1  # cos and sin of the turn
        if b <= 4.0 * rho:
            best = min(best, rho * _ccc_bound(1.0 - b * b / (8.0 * rho * rho), ct, st))
        if a <= 4.0 * rho:
            best = min(best, rho * _ccc_bound(1.0 - a * a / (8.0 * rho * rho), ct, -st))
    return best - tiny


@njit(cache=True)
def dubins_lower_bound_cs(x0, y0, c0, s0, x1, y1, c1, s1, turn, rho) -> float:
    """`dubins_lower_bound` from the poses (headings by cos and sin)."""
    l0x, l0y, r0x, r0y = turning_centres(x0, y0, c0, s0, rho)
    l1x, l1y, r1x, r1y = turning_centres(x1, y1, c1, s1, rho)
    return dubins_lower_bound(l0x, l0y, r0x, r0y, l1x, l1y, r1x, r1y, turn, rho)
