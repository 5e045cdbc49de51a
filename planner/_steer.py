"""Steering dispatch: Dubins (forward only) or Reeds-Shepp (forward and reverse)."""

from __future__ import annotations

from numba import njit

from planner._dubins import dubins_length, dubins_path
from planner._reeds_shepp import reeds_shepp_length, reeds_shepp_path


@njit(cache=True)
def steer_path(reverse, x0, y0, th0, x1, y1, th1, rho, kinds, lens) -> float:
    """Shortest local path between two poses, written into kinds/lens; returns its length."""
    if reverse > 0.0:
        return reeds_shepp_path(x0, y0, th0, x1, y1, th1, rho, kinds, lens)
    return dubins_path(x0, y0, th0, x1, y1, th1, rho, kinds, lens)


@njit(cache=True)
def steer_length(reverse, x0, y0, th0, x1, y1, th1, rho, bound) -> float:
    """Length of the shortest local path; any value ≥ ``bound`` once it cannot beat it."""
    if reverse > 0.0:
        return reeds_shepp_length(x0, y0, th0, x1, y1, th1, rho, bound)
    return dubins_length(x0, y0, th0, x1, y1, th1, rho, bound)
