"""Continuous-curvature Dubins paths (Fraichard & Scheuer 2004), in the segment form of `_paths`.

A CC turn drives a clothoid of sharpness σ from κ = 0 up to κmax = 1/ρ, an arc at κmax and a
clothoid back down to 0. Whatever its arc's length, the turn starts and ends on one circle of
radius r around the arc's centre Ω, its heading there at the angle μ to the circle's tangent
(`cc_constants`): Ω lies r·sin μ ahead of a turn's start and behind its end. So CC paths are
planned with these circles as Dubins paths are with circles of radius ρ: a turn, a straight
tangent to both circles at the angle μ, and a turn (TST), or three turns (TTT).

Each turn (`cc_turn`) deflects the heading by δ. A CC turn cannot deflect less than 2·δmin, its
two clothoids' own turning (δmin = κmax²/2σ); a smaller deflection is an elementary path, two
clothoids of a lower sharpness σ0 that meet at κ = √(δσ0) ≤ κmax, where that exists and is
shorter than the loop round the circle (Scheuer & Fraichard 1997); no deflection is a straight.

The families are those of steering_functions' CC00-Dubins (Banzhaf et al. 2017), rewritten on
plain floats: start and end at κ = 0, within a few percent of the shortest CC path but not
always the shortest, so the triangle inequality may fail. As σ → ∞, μ → 0, r → ρ and δmin → 0:
the families become Dubins' six words.
"""

from __future__ import annotations

import math

from planner._clothoid import clothoid_pose, fresnel
from planner._dubins import mod2pi
from planner._jit import njit
from planner._paths import STRAIGHT

_TWO_PI = 2.0 * math.pi
_HALF_PI = 0.5 * math.pi
_ELEMENTARY_MAX = 4.5948  # rad: beyond this deflection no elementary path exists (ibid.)
_TINY = 1e-12


@njit(cache=True)
def cc_constants(rho: float, sigma: float):
    """The turning constants every steering reads, ρ first:
    (ρ, κmax, σ, r, sin μ, cos μ, δmin, lmin), lmin = κmax/σ the length of a full clothoid.

    Ω, the centre of a CC turn's arc, is where the clothoid from the origin (heading 0) ends,
    moved 1/κmax to its left; r = |Ω| and μ = atan(Ωx/Ωy). σ = ∞ is a Dubins turn."""
    kappa = 1.0 / rho
    lmin = kappa / sigma
    if lmin < _TINY * rho:
        return rho, kappa, sigma, rho, 0.0, 1.0, 0.0, 0.0
    xi, yi, thi = clothoid_pose(0.0, 0.0, 0.0, 0.0, sigma, lmin)
    xc, yc = xi - math.sin(thi) / kappa, yi + math.cos(thi) / kappa
    r = math.hypot(xc, yc)
    return rho, kappa, sigma, r, xc / r, yc / r, thi, lmin


@njit(cache=True, inline="always")
def _d1(alpha: float) -> float:
    """cos α·C(√(2α/π)) + sin α·S(√(2α/π)): an elementary path's chord, in units (Scheuer &
    Fraichard's D1)."""
    c, s = fresnel(math.sqrt(2.0 * alpha / math.pi))
    return math.cos(alpha) * c + math.sin(alpha) * s


# What `cc_turn` found: a straight, an elementary path, or clothoid-arc-clothoid.
_STRAIGHT, _ELEMENTARY, _DEFAULT = range(3)


@njit(cache=True)
def cc_turn(g, ax, ay, ath, bx, by, bth, d):
    """(length, shape, σ0) of the CC turn from pose a to pose b, both on one CC circle, whose
    heading turns the way ``d`` says (+1 to the left, −1 to the right: a left turn driven
    forward, or a right turn in reverse); σ0 is an elementary path's sharpness."""
    kappa, sigma, delta_min, lmin = g[1], g[2], g[6], g[7]
    delta = mod2pi(d * (bth - ath))
    chord = math.hypot(bx - ax, by - ay)
    if delta < _TINY:
        return chord, _STRAIGHT, 0.0
    # The arc turns what the clothoids leave of δ, once round more where they turn further
    # (as they do for 2δmin > 2π: a servo so slow that each clothoid spirals).
    default = 2.0 * lmin + mod2pi(delta - 2.0 * delta_min) / kappa
    if delta < 2.0 * delta_min and delta < _ELEMENTARY_MAX and chord > _TINY:
        s0 = 4.0 * math.pi * _d1(0.5 * delta) ** 2 / (chord * chord)
        length = 2.0 * math.sqrt(delta / s0)
        if s0 <= sigma * (1.0 + 1e-9) and length < default:
            return length, _ELEMENTARY, s0
    return default, _DEFAULT, 0.0


@njit(cache=True, inline="always")
def _tangent(x0, y0, x1, y1, d, mu):
    """The pose where a turn of direction ``d`` on the circle centred (x0, y0) hands over to
    the opposite turn on the tangent circle centred (x1, y1): their midpoint, heading
    φ + d(π/2 − μ), φ the direction from the first centre to the second."""
    return (0.5 * (x0 + x1), 0.5 * (y0 + y1),
            math.atan2(y1 - y0, x1 - x0) + d * (_HALF_PI - mu))


@njit(cache=True)
def _best(g, x0, y0, th0, x1, y1, th1):
    """The shortest CC-Dubins path from pose 0 to pose 1 as (length, d1, d2, middle turns,
    qa, qb): a turn of direction d1 to qa = (x, y, θ), then to qb a straight (middle 0) or a
    turn of direction −d1 (middle 1), then a turn of direction d2 to pose 1."""
    r, smu, cmu = g[3], g[4], g[5]
    mu = math.atan2(smu, cmu)
    c0, s0, c1, s1 = math.cos(th0), math.sin(th0), math.cos(th1), math.sin(th1)
    dx, dy = x1 - x0, y1 - y0
    dist = math.hypot(dx, dy)
    # Aligned (pose 1 straight ahead, or the same pose): one straight
    if abs(mod2pi(th1 - th0 + math.pi) - math.pi) < _TINY and abs(c0 * dy - s0 * dx) \
            < _TINY * max(1.0, dist) and c0 * dx + s0 * dy >= 0.0:
        return dist, 1.0, 1.0, 0, x0, y0, th0, x1, y1, th1
    best = (math.inf, 1.0, 1.0, 0, x0, y0, th0, x1, y1, th1)
    for d1 in (1.0, -1.0):
        # start circle ahead of pose 0, on its d1 side; end circle behind pose 1
        ax, ay = x0 + r * (smu * c0 - d1 * cmu * s0), y0 + r * (smu * s0 + d1 * cmu * c0)
        for d2 in (1.0, -1.0):
            bx, by = x1 + r * (-smu * c1 - d2 * cmu * s1), y1 + r * (-smu * s1 + d2 * cmu * c1)
            ex, ey = bx - ax, by - ay
            big_d = math.hypot(ex, ey)
            angle = math.atan2(ey, ex)
            if d1 != d2 and big_d >= 2.0 * r:  # TiST: the inner tangent
                th = angle + d1 * math.asin(2.0 * r * cmu / big_d)
                c, s = math.cos(th), math.sin(th)
                qax, qay = ax + r * (smu * c + d1 * cmu * s), ay + r * (smu * s - d1 * cmu * c)
                qbx, qby = bx + r * (-smu * c - d1 * cmu * s), by + r * (-smu * s + d1 * cmu * c)
                straight = max(math.sqrt(big_d * big_d - 4.0 * r * r * cmu * cmu)
                               - 2.0 * r * smu, 0.0)
                length = (cc_turn(g, x0, y0, th0, qax, qay, th, d1)[0] + straight
                          + cc_turn(g, qbx, qby, th, x1, y1, th1, d2)[0])
                if length < best[0]:
                    best = (length, d1, d2, 0, qax, qay, th, qbx, qby, th)
            if d1 != d2:
                continue
            if big_d < _TINY * r:  # pose 1 ends a turn on the start circle: one turn
                length = cc_turn(g, x0, y0, th0, x1, y1, th1, d1)[0]
                if length < best[0]:
                    best = (length, d1, d2, 0, x1, y1, th1, x1, y1, th1)
                continue
            if big_d >= 2.0 * r * smu:  # TeST: the outer tangent
                c, s = math.cos(angle), math.sin(angle)
                qax, qay = ax + r * (smu * c + d1 * cmu * s), ay + r * (smu * s - d1 * cmu * c)
                qbx, qby = bx + r * (-smu * c + d1 * cmu * s), by + r * (-smu * s - d1 * cmu * c)
                length = (cc_turn(g, x0, y0, th0, qax, qay, angle, d1)[0] + big_d - 2.0 * r * smu
                          + cc_turn(g, qbx, qby, angle, x1, y1, th1, d1)[0])
                if length < best[0]:
                    best = (length, d1, d2, 0, qax, qay, angle, qbx, qby, angle)
            if big_d <= 4.0 * r:  # TTT: a middle circle tangent to both, on either side
                h = math.sqrt(max(4.0 * r * r - 0.25 * big_d * big_d, 0.0))
                for side in (1.0, -1.0):
                    mx = ax + 0.5 * ex - side * h * ey / big_d
                    my = ay + 0.5 * ey + side * h * ex / big_d
                    pax, pay, pth = _tangent(ax, ay, mx, my, d1, mu)
                    pbx, pby, qth = _tangent(mx, my, bx, by, -d1, mu)
                    length = (cc_turn(g, x0, y0, th0, pax, pay, pth, d1)[0]
                              + cc_turn(g, pax, pay, pth, pbx, pby, qth, -d1)[0]
                              + cc_turn(g, pbx, pby, qth, x1, y1, th1, d1)[0])
                    if length < best[0]:
                        best = (length, d1, d2, 1, pax, pay, pth, pbx, pby, qth)
    return best


@njit(cache=True)
def cc_dubins_length(x0, y0, th0, x1, y1, th1, g) -> float:
    """Length of the CC-Dubins path from pose 0 to pose 1 (`cc_constants` ``g``)."""
    return _best(g, x0, y0, th0, x1, y1, th1)[0]


@njit(cache=True)
def write_cc_turn(g, ax, ay, ath, bx, by, bth, d, gear, kinds, lens, curv, k) -> int:
    """Write the turn of steering direction ``d`` (+1 left) from pose a to pose b (`cc_turn`),
    driven forward (``gear`` +1) or in reverse (−1), from segment ``k`` on; returns the next."""
    length, shape, s0 = cc_turn(g, ax, ay, ath, bx, by, bth, d * gear)
    if shape == _STRAIGHT:
        kinds[k], lens[k], curv[k, 0], curv[k, 1] = STRAIGHT, gear * length, 0.0, 0.0
        return k + 1
    if shape == _ELEMENTARY:
        half = 0.5 * length
        kinds[k], lens[k], curv[k, 0], curv[k, 1] = d, gear * half, 0.0, d * s0
        kinds[k + 1], lens[k + 1], curv[k + 1, 0], curv[k + 1, 1] = d, gear * half, \
            d * s0 * half, -d * s0
        return k + 2
    kappa, sigma, lmin = g[1], g[2], g[7]
    kinds[k], lens[k], curv[k, 0], curv[k, 1] = d, gear * lmin, 0.0, d * sigma
    kinds[k + 1], lens[k + 1], curv[k + 1, 0], curv[k + 1, 1] = d, gear * (length - 2.0 * lmin), \
        d * kappa, 0.0
    kinds[k + 2], lens[k + 2], curv[k + 2, 0], curv[k + 2, 1] = d, gear * lmin, d * kappa, \
        -d * sigma
    return k + 3


@njit(cache=True)
def cc_dubins_path(x0, y0, th0, x1, y1, th1, g, kinds, lens, curv) -> float:
    """The CC-Dubins path from pose 0 to pose 1 written into kinds/lens/curv (9 segments: three
    turns of up to three); returns its length."""
    length, d1, d2, middle, ax, ay, ath, bx, by, bth = _best(g, x0, y0, th0, x1, y1, th1)
    kinds[:] = 0
    lens[:] = 0.0
    curv[:, :] = 0.0
    k = write_cc_turn(g, x0, y0, th0, ax, ay, ath, d1, 1.0, kinds, lens, curv, 0)
    if middle:
        k = write_cc_turn(g, ax, ay, ath, bx, by, bth, -d1, 1.0, kinds, lens, curv, k)
    else:
        kinds[k], lens[k] = STRAIGHT, math.hypot(bx - ax, by - ay)
        k += 1
    write_cc_turn(g, bx, by, bth, x1, y1, th1, d2, 1.0, kinds, lens, curv, k)
    return length
