"""The one place the compiled planner reaches a steering function: dispatch on its integer code.

Codes and names are registered in `planner.steering`; each function lives in its own module.
The kernel describes a pose as a `state` tuple — x, y, θ, cos θ, sin θ and the centres of its
left and right turning circles — so each steering takes what it needs (Dubins' bounds need the
circles, which the tree keeps per node) and nobody computes it twice. The car's turning
constants ``g`` (`cc_constants`: ρ, κmax, the sharpness σmax and the CC turn's circle) are
computed once per kernel call, not per path.

A continuous-curvature path is Dubins' or Reeds-Shepp's with clothoids in the turns: never
shorter, so their lengths and bounds are lower bounds of it, and a length that cannot beat a
bound costs a Dubins length.
"""

from __future__ import annotations

from planner._cc_dubins import cc_dubins_length, cc_dubins_path
from planner._cc_reeds_shepp import cc_reeds_shepp_length, cc_reeds_shepp_path
from planner._dubins import (
    dubins_length_cs,
    dubins_lower_bound,
    dubins_path,
    dubins_word_bound,
    turning_centres,
)
from planner._jit import njit
from planner._paths import arc_curvatures, rest_points, wrap_angle
from planner._reeds_shepp import reeds_shepp_length, reeds_shepp_lower_bound, reeds_shepp_path
from planner._straight import straight_heading, straight_length, straight_path
from planner.steering import CC_DUBINS, CC_REEDS_SHEPP, DUBINS, REEDS_SHEPP, STRAIGHT


@njit(cache=True, inline="always")
def state(x, y, th, c, s, rho):
    """The pose (x, y, th) with cos and sin c, s, as the steering functions read it."""
    lx, ly, rx, ry = turning_centres(x, y, c, s, rho)
    return x, y, th, c, s, lx, ly, rx, ry


@njit(cache=True)
def steer_path(code, x0, y0, th0, x1, y1, th1, g, kinds, lens, curv) -> float:
    """Shortest local path between two poses, written into kinds/lens/curv (`planner._paths`);
    returns its length."""
    if code == CC_DUBINS:
        return cc_dubins_path(x0, y0, th0, x1, y1, th1, g, kinds, lens, curv)
    if code == CC_REEDS_SHEPP:
        return cc_reeds_shepp_path(x0, y0, th0, x1, y1, th1, g, kinds, lens, curv)
    rho = g[0]
    if code == DUBINS:
        length = dubins_path(x0, y0, th0, x1, y1, th1, rho, kinds, lens)
    elif code == REEDS_SHEPP:
        length = reeds_shepp_path(x0, y0, th0, x1, y1, th1, rho, kinds, lens)
    else:
        length = straight_path(x0, y0, th0, x1, y1, th1, kinds, lens)
    arc_curvatures(kinds, rho, curv)
    return length


@njit(cache=True, inline="always")
def steer_length(code, a, b, g, bound) -> float:
    """Length of the shortest local path from state a to state b; any value ≥ ``bound`` once
    it cannot beat it."""
    rho = g[0]
    if code == DUBINS or code == CC_DUBINS:
        length = dubins_length_cs(a[0], a[1], a[3], a[4], b[0], b[1], b[3], b[4], rho, bound)
        if code == DUBINS or length >= bound:
            return length
        return cc_dubins_length(a[0], a[1], a[2], b[0], b[1], b[2], g)
    if code == REEDS_SHEPP or code == CC_REEDS_SHEPP:
        length = reeds_shepp_length(a[0], a[1], a[2], b[0], b[1], b[2], rho, bound)
        if code == REEDS_SHEPP or length >= bound:
            return length
        return cc_reeds_shepp_length(a[0], a[1], a[2], b[0], b[1], b[2], g, bound)
    return straight_length(a[0], a[1], b[0], b[1])


@njit(cache=True, inline="always")
def steer_bound(code, a, b, g) -> float:
    """A cheap lower bound of `steer_length` from state a to state b."""
    rho = g[0]
    if code == DUBINS or code == CC_DUBINS:
        return dubins_lower_bound(a[5], a[6], a[7], a[8], b[5], b[6], b[7], b[8],
                                  wrap_angle(b[2] - a[2]), rho)
    if code == REEDS_SHEPP or code == CC_REEDS_SHEPP:
        return reeds_shepp_lower_bound(a[0], a[1], a[2], b[0], b[1], b[2], rho)
    return straight_length(a[0], a[1], b[0], b[1])


@njit(cache=True, inline="always")
def steer_tight_bound(code, a, b, g) -> float:
    """A tighter, dearer lower bound than `steer_bound` where the steering has one (Dubins'
    `dubins_word_bound`); 0 leaves `steer_bound`'s standing."""
    if code == DUBINS or code == CC_DUBINS:
        return dubins_word_bound(a[5], a[6], a[7], a[8], a[3], a[4], b[5], b[6], b[7], b[8],
                                 b[3], b[4], wrap_angle(b[2] - a[2]), g[0])
    return 0.0


@njit(cache=True, inline="always")
def arrival_heading(code, x0, y0, th0, x1, y1, th1) -> float:
    """The heading a new node reached from (x0, y0, th0) towards the sample (x1, y1, th1) gets:
    the sample's for a car, the direction of travel for a robot whose heading is free."""
    if code == STRAIGHT:
        return straight_heading(x0, y0, th0, x1, y1)
    return th1


@njit(cache=True, inline="always")
def steer_cut(code, kinds, lens, curv, s, beyond) -> float:
    """Where to cut a path that is to end ``s`` metres along. A continuous-curvature path is cut
    only where its κ is 0, so that the node it ends at starts the next path with the κ it ends
    this one: at the last such point up to ``s`` or, if there is none and ``beyond``, the first
    after (0: nowhere)."""
    if code != CC_DUBINS and code != CC_REEDS_SHEPP:
        return s
    before, after = rest_points(kinds, lens, curv, s)
    return after if beyond and before <= 0.0 else before

