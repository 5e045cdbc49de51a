"""The one place the compiled planner reaches a steering function: dispatch on its integer code.

Codes and names are registered in `planner.steering`; each function lives in its own module.
The kernel describes a pose as a `state` tuple — x, y, θ, cos θ, sin θ and the centres of its
left and right turning circles — so each steering takes what it needs (Dubins' bounds need the
circles, which the tree keeps per node) and nobody computes it twice.
"""

from __future__ import annotations

from planner._dubins import (
    dubins_length_cs,
    dubins_lower_bound,
    dubins_path,
    dubins_word_bound,
    turning_centres,
)
from planner._jit import njit
from planner._paths import arc_curvatures, wrap_angle
from planner._reeds_shepp import reeds_shepp_length, reeds_shepp_lower_bound, reeds_shepp_path
from planner._straight import straight_heading, straight_length, straight_path
from planner.steering import DUBINS, REEDS_SHEPP


@njit(cache=True, inline="always")
def state(x, y, th, c, s, rho):
    """The pose (x, y, th) with cos and sin c, s, as the steering functions read it."""
    lx, ly, rx, ry = turning_centres(x, y, c, s, rho)
    return x, y, th, c, s, lx, ly, rx, ry


@njit(cache=True)
def steer_path(code, x0, y0, th0, x1, y1, th1, rho, kinds, lens, curv) -> float:
    """Shortest local path between two poses, written into kinds/lens/curv (`planner._paths`);
    returns its length."""
    if code == DUBINS:
        length = dubins_path(x0, y0, th0, x1, y1, th1, rho, kinds, lens)
    elif code == REEDS_SHEPP:
        length = reeds_shepp_path(x0, y0, th0, x1, y1, th1, rho, kinds, lens)
    else:
        length = straight_path(x0, y0, th0, x1, y1, th1, kinds, lens)
    arc_curvatures(kinds, rho, curv)
    return length


@njit(cache=True, inline="always")
def steer_length(code, a, b, rho, bound) -> float:
    """Length of the shortest local path from state a to state b; any value ≥ ``bound`` once
    it cannot beat it."""
    if code == DUBINS:
        return dubins_length_cs(a[0], a[1], a[3], a[4], b[0], b[1], b[3], b[4], rho, bound)
    if code == REEDS_SHEPP:
        return reeds_shepp_length(a[0], a[1], a[2], b[0], b[1], b[2], rho, bound)
    return straight_length(a[0], a[1], b[0], b[1])


@njit(cache=True, inline="always")
def steer_bound(code, a, b, rho) -> float:
    """A cheap lower bound of `steer_length` from state a to state b."""
    if code == DUBINS:
        return dubins_lower_bound(a[5], a[6], a[7], a[8], b[5], b[6], b[7], b[8],
                                  wrap_angle(b[2] - a[2]), rho)
    if code == REEDS_SHEPP:
        return reeds_shepp_lower_bound(a[0], a[1], a[2], b[0], b[1], b[2], rho)
    return straight_length(a[0], a[1], b[0], b[1])


@njit(cache=True, inline="always")
def steer_tight_bound(code, a, b, rho) -> float:
    """A tighter, dearer lower bound than `steer_bound` where the steering has one (Dubins'
    `dubins_word_bound`); 0 leaves `steer_bound`'s standing."""
    if code == DUBINS:
        return dubins_word_bound(a[5], a[6], a[7], a[8], a[3], a[4], b[5], b[6], b[7], b[8],
                                 b[3], b[4], wrap_angle(b[2] - a[2]), rho)
    return 0.0


@njit(cache=True, inline="always")
def arrival_heading(code, x0, y0, th0, x1, y1, th1) -> float:
    """The heading a new node reached from (x0, y0, th0) towards the sample (x1, y1, th1) gets:
    the sample's for a car, the direction of travel for a robot whose heading is free."""
    if code == DUBINS or code == REEDS_SHEPP:
        return th1
    return straight_heading(x0, y0, th0, x1, y1)

