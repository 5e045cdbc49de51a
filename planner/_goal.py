"""The goal region, in one place: a pose is in it when its position is within the position
tolerance of the goal's and its heading within the heading tolerance of the goal's
(docs/scenario-format.md). ``goal`` = (x, y, θ, position tolerance, heading tolerance), as
`Problem.goal_region` builds it and the kernel's parameter vector holds it."""

from __future__ import annotations

import math

import numpy as np

from planner._jit import njit
from planner._paths import wrap_angle

__all__ = ["goal_offset", "in_goal", "in_goal_rows"]


@njit(cache=True, inline="always")
def goal_offset(x: float, y: float, th: float, goal: np.ndarray) -> float:
    """How far the pose is outside the goal region: the larger of its position and heading
    excesses (≤ 0: inside). OMPL's goal distance."""
    return max(math.hypot(x - goal[0], y - goal[1]) - goal[3],
               abs(wrap_angle(th - goal[2])) - goal[4])


@njit(cache=True, inline="always")
def in_goal(x: float, y: float, th: float, goal: np.ndarray) -> bool:
    """Whether the pose is in the goal region."""
    return goal_offset(x, y, th, goal) <= 0.0


@njit(cache=True)
def in_goal_rows(rows: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """`in_goal` of each row (x, y, θ, …)."""
    out = np.empty(rows.shape[0], np.bool_)
    for k in range(rows.shape[0]):
        out[k] = in_goal(rows[k, 0], rows[k, 1], rows[k, 2], goal)
    return out
