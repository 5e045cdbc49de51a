"""Exact Reeds-Shepp shortest paths (forward and reverse driving) for a car of turning radius ρ.

Why analytic: RRT/RRT* steer and measure distances thousands of times per iteration, so the
local planner must be exact (the path really ends at the goal pose) and cheap. Reeds & Shepp
(1990, "Optimal paths for a car that goes both forwards and backwards", Pacific J. Math. 145)
proved that a shortest path is one of 48 words of at most five arc/straight segments, in five
families (CSC, CCC, CCCC, CCSC, CCSCC; cusps allowed between segments). Each family has a
closed-form solution for its base words; the other words follow from two symmetries:

* timeflip — drive the word backwards: solve for (−x, y, −φ), negate every segment length;
* reflect — mirror across the start's x axis: solve for (x, −y, −φ), swap left and right;

and, for CCC and CCSC, the "backwards" word (the path read from the goal to the start), solved
for (x cos φ + y sin φ, x sin φ − y cos φ, φ) with the segment order reversed.

The formulas (equations 8.1-8.11 of the paper, with the paper's typos in 8.3/8.4 and 8.11
corrected) and the 18-entry segment table follow OMPL's ``ReedsSheppStateSpace.cpp``
(Mark Moll, BSD); this is an independent re-implementation, not a copy. As there, the problem is
solved in normalised coordinates: the goal expressed in the start's frame, divided by ρ, with
φ = θ1 − θ0, so every arc has unit radius and segment lengths are angles. Results are scaled
back to metres and written as ``planner._paths`` words (kinds +1/0/−1, signed lengths), whose
sign conventions coincide with OMPL's: a left arc of signed length l turns the heading by +l/ρ.

Departures from OMPL, for speed only (lengths agree with OMPL 2.0.1 to ~1e-14): each candidate
word is skipped before its trigonometry when a cheap lower bound on its length cannot beat the
best so far; two sums of atan2s are computed as one atan2; φ is wrapped to [−π, π] first.
All functions are numba-compiled and allocate nothing: the best word is carried as scalars and
written into caller-provided arrays at the end.
"""

from __future__ import annotations

import math

import numpy as np

from planner._jit import njit

PI = math.pi
TWO_PI = 2.0 * math.pi
HALF_PI = 0.5 * math.pi
# Acceptance slack on the sign conditions of the base formulas. OMPL's ZERO, 10 machine
# epsilons, lost R−S− from (1, 0, 0) to (−0.48, −0.39, 0.5) at ρ = 3 (hypothesis found it): its
# last arc came out as −2.4e-15 rad, and the next word was 5 % longer. Rounding in atan2 and
# the wrap of angles up to 2π is a few 1e-15; a segment of −1e-12 rad is none.
_ZERO = 1e-12
# Slack on the pruning bounds, so that rounding never prunes a word that would have won.
_SLACK = 1e-9

# Segment kinds of the 18 word shapes (same numbering as OMPL's reedsSheppPathType):
# +1 left, 0 straight, -1 right; unused trailing slots are 0 with length 0.
_L, _S, _R = 1, 0, -1
_WORDS = np.array(
    [
        [_L, _R, _L, 0, 0],  # 0  CCC
        [_R, _L, _R, 0, 0],  # 1
        [_L, _R, _L, _R, 0],  # 2  CCCC
        [_R, _L, _R, _L, 0],  # 3
        [_L, _R, _S, _L, 0],  # 4  CCSC
        [_R, _L, _S, _R, 0],  # 5
        [_L, _S, _R, _L, 0],  # 6  CSCC
        [_R, _S, _L, _R, 0],  # 7
        [_L, _R, _S, _R, 0],  # 8  CCSC
        [_R, _L, _S, _L, 0],  # 9
        [_R, _S, _R, _L, 0],  # 10 CSCC
        [_L, _S, _L, _R, 0],  # 11
        [_L, _S, _R, 0, 0],  # 12 CSC
        [_R, _S, _L, 0, 0],  # 13
        [_L, _S, _L, 0, 0],  # 14
        [_R, _S, _R, 0, 0],  # 15
        [_L, _R, _S, _L, _R],  # 16 CCSCC
        [_R, _L, _S, _R, _L],  # 17
    ],
    dtype=np.int8,
)


@njit(cache=True, inline="always")
def _wrap_pi(a: float) -> float:
    """Wrap to [−π, π] (OMPL's mod2pi: fmod, then one correction).

    The common cases |a| < 2π skip the fmod; the result is bit-identical either way.
    """
    if -PI <= a <= PI:
        return a
    if PI < a < TWO_PI:
        return a - TWO_PI
    if -TWO_PI < a < -PI:
        return a + TWO_PI
    v = np.fmod(a, TWO_PI)
    if v < -PI:
        v += TWO_PI
    elif v > PI:
        v -= TWO_PI
    return v


@njit(cache=True, inline="always")
def _slack(r):
    """Sign slack of an angle atan2(η, ξ) with r = |(ξ, η)|.

    ξ and η carry absolute rounding of a few 1e-16 (1 − cos φ), so the angle's error grows as
    1e-16/r: a path of 1e-5 ρ lost its CS word to a last arc of −1e-11 rad (hypothesis found
    it). Accepting such a sliver is safe: the signed segments still reach the goal exactly, and
    their absolute sum is the honest length.
    """
    return _ZERO + 4e-15 / max(r, 1e-300)


@njit(cache=True)
def _tau_omega(u, v, xi, eta, phi):
    delta = _wrap_pi(u - v)
    a = math.sin(u) - math.sin(delta)
    b = math.cos(u) - math.cos(delta) - 1.0
    t1 = math.atan2(eta * a - xi * b, xi * a + eta * b)
    t2 = 2.0 * (math.cos(delta) - math.cos(v) - math.cos(u)) + 3.0
    tau = _wrap_pi(t1 + PI) if t2 < 0.0 else _wrap_pi(t1)
    omega = _wrap_pi(tau - u + v - phi)
    return tau, omega


@njit(cache=True)
def _turn_opp(a):
    """Lower bound on |p| + |q| when p − q ≡ a (mod 2π), less a rounding slack."""
    return abs(_wrap_pi(a)) - _SLACK


@njit(cache=True)
def _turn_same(a):
    """Lower bound on p + q for p, q ≥ 0 (up to the acceptance slack) with p + q ≡ a (mod 2π)."""
    m = _wrap_pi(a)
    if m < 0.0:
        m += TWO_PI
    if m > TWO_PI - 1e-9:  # a ≡ −0: both may be (almost) zero
        return 0.0
    return m - _SLACK


# ---- base words ---------------------------------------------------------------------------
# Each gets the problem (x, y, φ, sin φ, cos φ) and the best length so far, and returns
# (ok, t, u, v). Before the trigonometry it compares a cheap lower bound on the word's length
# (its straight or middle arcs, plus the turning its outer arcs need to reach φ) with the best
# so far, and gives up early when the word cannot win.


@njit(cache=True)
def _lp_sp_lp(x, y, phi, sp, cp, lmin):
    """L+ S+ L+ (8.1)."""
    xi = x - sp
    eta = y - 1.0 + cp
    u = math.sqrt(xi * xi + eta * eta)
    if u + _turn_same(phi) >= lmin:  # t + v ≡ φ, t, v ≥ 0
        return False, 0.0, 0.0, 0.0
    t = math.atan2(eta, xi)
    zero = _slack(u)
    if t >= -zero:
        v = _wrap_pi(phi - t)
        if v >= -zero:
            return True, t, u, v
    return False, 0.0, 0.0, 0.0


@njit(cache=True)
def _lp_sp_rp(x, y, phi, sp, cp, lmin):
    """L+ S+ R+ (8.2)."""
    xi = x + sp
    eta = y - 1.0 - cp
    u1 = xi * xi + eta * eta
    if u1 >= 4.0:
        u = math.sqrt(u1 - 4.0)
        if u + _turn_opp(phi) >= lmin:  # t − v ≡ φ
            return False, 0.0, 0.0, 0.0
        # t = atan2(η, ξ) + atan2(2, u), as one atan2 of the product (ξ + iη)(u + 2i)
        t = math.atan2(eta * u + 2.0 * xi, xi * u - 2.0 * eta)
        v = _wrap_pi(t - phi)
        if t >= -_ZERO and v >= -_ZERO:
            return True, t, u, v
    return False, 0.0, 0.0, 0.0


@njit(cache=True)
def _lp_rm_l(x, y, phi, sp, cp, lmin):
    """L+ R− L (8.3/8.4, corrected)."""
    xi = x - sp
    eta = y - 1.0 + cp
    r = math.sqrt(xi * xi + eta * eta)
    if r <= 4.0 and 0.5 * r * (1.0 - 1e-9) < lmin:  # |u| = 2 asin(r/4) ≥ r/2
        theta = math.atan2(eta, xi)
        u = -2.0 * math.asin(0.25 * r)
        t = _wrap_pi(theta + 0.5 * u + PI)
        v = _wrap_pi(phi - t + u)
        if t >= -_slack(r) and u <= _ZERO:
            return True, t, u, v
    return False, 0.0, 0.0, 0.0


@njit(cache=True)
def _lp_rup_lum_rm(x, y, phi, sp, cp, lmin):
    """L+ R+u L−u R− (8.7)."""
    xi = x + sp
    eta = y - 1.0 - cp
    r = 0.25 * (2.0 + math.sqrt(xi * xi + eta * eta))
    if r <= 1.0:
        u = math.acos(r)
        if 2.0 * u >= lmin:
            return False, 0.0, 0.0, 0.0
        t, v = _tau_omega(u, -u, xi, eta, phi)
        if t >= -_ZERO and v <= _ZERO:
            return True, t, u, v
    return False, 0.0, 0.0, 0.0


@njit(cache=True)
def _lp_rum_lum_rp(x, y, phi, sp, cp, lmin):
    """L+ R−u L−u R+ (8.8)."""
    xi = x + sp
    eta = y - 1.0 - cp
    r = (20.0 - xi * xi - eta * eta) / 16.0
    if 0.0 <= r <= 1.0:
        u = -math.acos(r)
        if u >= -HALF_PI and -2.0 * u < lmin:
            t, v = _tau_omega(u, u, xi, eta, phi)
            if t >= -_ZERO and v >= -_ZERO:
                return True, t, u, v
    return False, 0.0, 0.0, 0.0


@njit(cache=True)
def _lp_rm_sm_lm(x, y, phi, sp, cp, lmin):
    """L+ R−(π/2) S− L− (8.9)."""
    xi = x - sp
    eta = y - 1.0 + cp
    rr = xi * xi + eta * eta
    if rr >= 4.0:
        r = math.sqrt(rr - 4.0)
        u = 2.0 - r
        if r - 2.0 + HALF_PI + _turn_opp(phi - HALF_PI) >= lmin:  # t + v ≡ φ − π/2, v ≤ 0
            return False, 0.0, 0.0, 0.0
        # t = atan2(η, ξ) + atan2(r, −2), as one atan2 of the product (ξ + iη)(−2 + ir)
        t = math.atan2(xi * r - 2.0 * eta, -2.0 * xi - eta * r)
        v = _wrap_pi(phi - HALF_PI - t)
        if t >= -_ZERO and u <= _ZERO and v <= _ZERO:
            return True, t, u, v
    return False, 0.0, 0.0, 0.0


@njit(cache=True)
def _lp_rm_sm_rm(x, y, phi, sp, cp, lmin):
    """L+ R−(π/2) S− R− (8.10)."""
    xi = x + sp
    eta = y - 1.0 - cp
    r = math.sqrt(xi * xi + eta * eta)
    # t − v ≡ φ − π/2 with t ≥ 0 ≥ v
    if r >= 2.0 and r - 2.0 + HALF_PI + _turn_same(phi - HALF_PI) < lmin:
        t = math.atan2(xi, -eta)
        u = 2.0 - r
        v = _wrap_pi(t + HALF_PI - phi)
        if t >= -_ZERO and u <= _ZERO and v <= _ZERO:
            return True, t, u, v
    return False, 0.0, 0.0, 0.0


@njit(cache=True)
def _lp_rm_s_lm_rp(x, y, phi, sp, cp, lmin):
    """L+ R−(π/2) S L−(π/2) R+ (8.11, corrected)."""
    xi = x + sp
    eta = y - 1.0 - cp
    rr = xi * xi + eta * eta
    if rr >= 4.0:
        u = 4.0 - math.sqrt(rr - 4.0)
        if u <= _ZERO and PI - u + _turn_opp(phi) < lmin:  # t − v ≡ φ
            t = _wrap_pi(math.atan2((4.0 - u) * xi - 2.0 * eta, -2.0 * xi + (u - 4.0) * eta))
            v = _wrap_pi(t - phi)
            if t >= -_ZERO and v >= -_ZERO:
                return True, t, u, v
    return False, 0.0, 0.0, 0.0


# ---- search over the 48 words ------------------------------------------------------------


@njit(cache=True)
def _take(best, ok, length, word, a, b, c, d, e):
    """Keep the candidate if it is valid and strictly shorter than the best so far."""
    if ok and length < best[0]:
        return (length, word, a, b, c, d, e)
    return best


@njit(cache=True)
def _solve(x, y, phi, lmin):
    """Shortest word for the normalised problem; only words shorter than ``lmin`` are kept.

    Returns (length, word index or −1, five signed segment lengths in units of ρ).
    """
    sp = math.sin(phi)
    cp = math.cos(phi)
    best = (lmin, -1, 0.0, 0.0, 0.0, 0.0, 0.0)

    # CSC: base, timeflip, reflect, timeflip+reflect
    ok, t, u, v = _lp_sp_lp(x, y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 14, t, u, v, 0.0, 0.0)
    ok, t, u, v = _lp_sp_lp(-x, y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 14, -t, -u, -v, 0.0, 0.0)
    ok, t, u, v = _lp_sp_lp(x, -y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 15, t, u, v, 0.0, 0.0)
    ok, t, u, v = _lp_sp_lp(-x, -y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 15, -t, -u, -v, 0.0, 0.0)
    ok, t, u, v = _lp_sp_rp(x, y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 12, t, u, v, 0.0, 0.0)
    ok, t, u, v = _lp_sp_rp(-x, y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 12, -t, -u, -v, 0.0, 0.0)
    ok, t, u, v = _lp_sp_rp(x, -y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 13, t, u, v, 0.0, 0.0)
    ok, t, u, v = _lp_sp_rp(-x, -y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 13, -t, -u, -v, 0.0, 0.0)

    # CCC, then the backwards words (solved from the goal's point of view, order reversed)
    xb = x * cp + y * sp
    yb = x * sp - y * cp
    ok, t, u, v = _lp_rm_l(x, y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 0, t, u, v, 0.0, 0.0)
    ok, t, u, v = _lp_rm_l(-x, y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 0, -t, -u, -v, 0.0, 0.0)
    ok, t, u, v = _lp_rm_l(x, -y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 1, t, u, v, 0.0, 0.0)
    ok, t, u, v = _lp_rm_l(-x, -y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 1, -t, -u, -v, 0.0, 0.0)
    ok, t, u, v = _lp_rm_l(xb, yb, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 0, v, u, t, 0.0, 0.0)
    ok, t, u, v = _lp_rm_l(-xb, yb, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 0, -v, -u, -t, 0.0, 0.0)
    ok, t, u, v = _lp_rm_l(xb, -yb, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 1, v, u, t, 0.0, 0.0)
    ok, t, u, v = _lp_rm_l(-xb, -yb, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v), 1, -v, -u, -t, 0.0, 0.0)

    # CCCC: L+R+u|L-u R-  and  L+R-u|L-u R+  (middle arcs of equal length)
    ok, t, u, v = _lp_rup_lum_rm(x, y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + 2.0 * abs(u) + abs(v), 2, t, u, -u, v, 0.0)
    ok, t, u, v = _lp_rup_lum_rm(-x, y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + 2.0 * abs(u) + abs(v), 2, -t, -u, u, -v, 0.0)
    ok, t, u, v = _lp_rup_lum_rm(x, -y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + 2.0 * abs(u) + abs(v), 3, t, u, -u, v, 0.0)
    ok, t, u, v = _lp_rup_lum_rm(-x, -y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + 2.0 * abs(u) + abs(v), 3, -t, -u, u, -v, 0.0)
    ok, t, u, v = _lp_rum_lum_rp(x, y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + 2.0 * abs(u) + abs(v), 2, t, u, u, v, 0.0)
    ok, t, u, v = _lp_rum_lum_rp(-x, y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + 2.0 * abs(u) + abs(v), 2, -t, -u, -u, -v, 0.0)
    ok, t, u, v = _lp_rum_lum_rp(x, -y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + 2.0 * abs(u) + abs(v), 3, t, u, u, v, 0.0)
    ok, t, u, v = _lp_rum_lum_rp(-x, -y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + 2.0 * abs(u) + abs(v), 3, -t, -u, -u, -v, 0.0)

    # CCSC (a quarter-turn arc next to the straight), then the backwards CSCC words
    ok, t, u, v = _lp_rm_sm_lm(x, y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 4, t, -HALF_PI, u, v, 0.0)
    ok, t, u, v = _lp_rm_sm_lm(-x, y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 4, -t, HALF_PI, -u, -v, 0.0)
    ok, t, u, v = _lp_rm_sm_lm(x, -y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 5, t, -HALF_PI, u, v, 0.0)
    ok, t, u, v = _lp_rm_sm_lm(-x, -y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 5, -t, HALF_PI, -u, -v, 0.0)
    ok, t, u, v = _lp_rm_sm_rm(x, y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 8, t, -HALF_PI, u, v, 0.0)
    ok, t, u, v = _lp_rm_sm_rm(-x, y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 8, -t, HALF_PI, -u, -v, 0.0)
    ok, t, u, v = _lp_rm_sm_rm(x, -y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 9, t, -HALF_PI, u, v, 0.0)
    ok, t, u, v = _lp_rm_sm_rm(-x, -y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 9, -t, HALF_PI, -u, -v, 0.0)
    ok, t, u, v = _lp_rm_sm_lm(xb, yb, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 6, v, u, -HALF_PI, t, 0.0)
    ok, t, u, v = _lp_rm_sm_lm(-xb, yb, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 6, -v, -u, HALF_PI, -t, 0.0)
    ok, t, u, v = _lp_rm_sm_lm(xb, -yb, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 7, v, u, -HALF_PI, t, 0.0)
    ok, t, u, v = _lp_rm_sm_lm(-xb, -yb, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 7, -v, -u, HALF_PI, -t, 0.0)
    ok, t, u, v = _lp_rm_sm_rm(xb, yb, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 10, v, u, -HALF_PI, t, 0.0)
    ok, t, u, v = _lp_rm_sm_rm(-xb, yb, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 10, -v, -u, HALF_PI, -t, 0.0)
    ok, t, u, v = _lp_rm_sm_rm(xb, -yb, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 11, v, u, -HALF_PI, t, 0.0)
    ok, t, u, v = _lp_rm_sm_rm(-xb, -yb, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + HALF_PI, 11, -v, -u, HALF_PI, -t, 0.0)

    # CCSCC (two quarter-turn arcs around the straight)
    ok, t, u, v = _lp_rm_s_lm_rp(x, y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + PI, 16, t, -HALF_PI, u, -HALF_PI, v)
    ok, t, u, v = _lp_rm_s_lm_rp(-x, y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + PI, 16, -t, HALF_PI, -u, HALF_PI, -v)
    ok, t, u, v = _lp_rm_s_lm_rp(x, -y, -phi, -sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + PI, 17, t, -HALF_PI, u, -HALF_PI, v)
    ok, t, u, v = _lp_rm_s_lm_rp(-x, -y, phi, sp, cp, best[0])
    best = _take(best, ok, abs(t) + abs(u) + abs(v) + PI, 17, -t, HALF_PI, -u, HALF_PI, -v)
    return best


@njit(cache=True, inline="always")
def _normalise(x0, y0, th0, x1, y1, th1, rho):
    """Goal in the start's frame, in units of ρ; φ wrapped to [−π, π]."""
    c = math.cos(th0)
    s = math.sin(th0)
    dx = x1 - x0
    dy = y1 - y0
    return (c * dx + s * dy) / rho, (-s * dx + c * dy) / rho, _wrap_pi(th1 - th0)


@njit(cache=True)
def reeds_shepp_path(x0: float, y0: float, th0: float, x1: float, y1: float, th1: float,
                     rho: float, kinds_out: np.ndarray, lens_out: np.ndarray) -> float:
    """Shortest Reeds-Shepp path from (x0, y0, th0) to (x1, y1, th1) with turning radius ``rho``.

    Writes the word into ``kinds_out`` (int8[5]) and ``lens_out`` (float64[5], signed metres,
    negative = reversing, unused slots 0) and returns its length, the sum of |lens_out|.
    """
    x, y, phi = _normalise(x0, y0, th0, x1, y1, th1, rho)
    best = _solve(x, y, phi, math.inf)
    word = best[1]
    if word < 0:  # cannot happen for finite input; leave an empty path
        for i in range(5):
            kinds_out[i] = 0
            lens_out[i] = 0.0
        return math.inf
    segs = (best[2], best[3], best[4], best[5], best[6])
    total = 0.0
    for i in range(5):
        seg = segs[i] * rho
        kinds_out[i] = _WORDS[word, i]
        lens_out[i] = seg
        total += abs(seg)
    return total


@njit(cache=True)
def reeds_shepp_length(x0: float, y0: float, th0: float, x1: float, y1: float, th1: float,
                       rho: float, bound: float) -> float:
    """Length of the shortest Reeds-Shepp path, exact whenever it is ≤ ``bound``.

    When the length exceeds ``bound`` the result is only guaranteed to exceed ``bound`` too
    (it may be a lower bound or ``inf``): the straight-line distance and ρ·|Δθ| are checked
    first, and only words shorter than ``bound`` are considered. ``bound=math.inf`` gives the
    exact length always.
    """
    x, y, phi = _normalise(x0, y0, th0, x1, y1, th1, rho)
    # Lower bounds: a path is at least as long as the chord, and heading turns at ≤ 1/ρ.
    lower = rho * max(math.sqrt(x * x + y * y), abs(phi))
    if lower > bound:
        return lower
    # Keep a relative margin so that a word of length exactly ``bound`` (up to the rounding
    # of the division by ρ) is still found.
    lmin = bound / rho * (1.0 + 1e-12) + 1e-300 if bound < math.inf else math.inf
    best = _solve(x, y, phi, lmin)
    if best[1] < 0:
        return math.inf
    return best[0] * rho


@njit(cache=True, inline="always")
def reeds_shepp_lower_bound(x0, y0, th0, x1, y1, th1, rho) -> float:
    """A lower bound of the Reeds-Shepp length: the path is at least the straight line, and it
    turns the heading by at least |Δθ| at curvature ≤ 1/ρ."""
    return max(math.hypot(x1 - x0, y1 - y0), rho * abs(_wrap_pi(th1 - th0)))
