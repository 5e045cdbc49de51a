"""Straight-line steering for a point or disc robot whose heading is free (LaValle 1998).

The robot turns on the spot to face the target, drives the straight line, and turns on the spot
to the target's heading: ``[TURN, STRAIGHT, TURN]`` in the segment form of `_paths`. Turns on the
spot drive no length, so the cost is the Euclidean distance — a metric, symmetric, with the
triangle inequality — and the edge still ends at the exact pose, so RRT*'s rewiring keeps every
child's state as it does for the car steerings.
"""

from __future__ import annotations

import math

from planner._jit import njit
from planner._paths import STRAIGHT, TURN, wrap_angle


@njit(cache=True, inline="always")
def straight_length(x0, y0, x1, y1) -> float:
    """The length of the straight path: the Euclidean distance (it is its own lower bound)."""
    return math.hypot(x1 - x0, y1 - y0)


@njit(cache=True, inline="always")
def straight_heading(x0, y0, th0, x1, y1) -> float:
    """The direction of travel from (x0, y0) to (x1, y1); ``th0`` when they coincide."""
    if x1 == x0 and y1 == y0:
        return th0
    return math.atan2(y1 - y0, x1 - x0)


@njit(cache=True)
def straight_path(x0, y0, th0, x1, y1, th1, kinds_out, lens_out) -> float:
    """Turn to face (x1, y1), drive there, turn to ``th1``; returns the driven length."""
    heading = straight_heading(x0, y0, th0, x1, y1)
    for i in range(kinds_out.shape[0]):
        kinds_out[i] = STRAIGHT
        lens_out[i] = 0.0
    kinds_out[0] = TURN
    lens_out[0] = wrap_angle(heading - th0)
    lens_out[1] = straight_length(x0, y0, x1, y1)
    kinds_out[2] = TURN
    lens_out[2] = wrap_angle(th1 - heading)
    return lens_out[1]
