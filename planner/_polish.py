"""Local optimisation of the best path's poses with the exact steering (compiled).

RRT*'s rewiring only chooses among poses it has sampled, so after a second its best path is
still 2–3 % longer than the best known (benchmarks/results/planner.md). Moving the path's own
poses closes much of that: coordinate descent on each inner pose (x, y, θ), with steps that
halve every round, takes a move when the two steered edges it changes are shorter together and
free by the exact motion check. Start and end stay put. Static worlds only: with moving
obstacles a shorter edge changes every later arrival time, which the kernel's rewiring handles.
"""

from __future__ import annotations

import math

import numpy as np

from planner._jit import njit
from planner._paths import wrap_angle
from planner._steer import state, steer_length, steer_path
from planner._world import World, motion_free

ROUNDS = 8  # step halvings: from a quarter of the mean edge to 1/1000 of it
MOVES = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0],
                  [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])


@njit(cache=True, inline="always")
def _state(q, rho):
    return state(q[0], q[1], q[2], math.cos(q[2]), math.sin(q[2]), rho)


@njit(cache=True)
def _free(w: World, code: int, a, b, rho: float, speed: float, kinds, lens, counter) -> bool:
    steer_path(code, a[0], a[1], a[2], b[0], b[1], b[2], rho, kinds, lens)
    return motion_free(w, a[0], a[1], a[2], 0.0, kinds, lens, rho, speed, counter)


@njit(cache=True)
def polish_path(w: World, code: int, rho: float, speed: float, poses: np.ndarray, kinds, lens,
                counter) -> float:
    """Shorten the path through ``poses`` ((n, 3), changed in place) and return its length."""
    n = poses.shape[0]
    edge = np.empty(n - 1)
    for i in range(n - 1):
        edge[i] = steer_length(code, _state(poses[i], rho), _state(poses[i + 1], rho), rho,
                               math.inf)
    step_xy = 0.25 * edge.mean()
    step_th = 0.25
    cand = np.empty(3)
    for _ in range(ROUNDS):
        for i in range(1, n - 1):
            for m in range(MOVES.shape[0]):
                cand[0] = poses[i, 0] + MOVES[m, 0] * step_xy
                cand[1] = poses[i, 1] + MOVES[m, 1] * step_xy
                cand[2] = wrap_angle(poses[i, 2] + MOVES[m, 2] * step_th)
                now = edge[i - 1] + edge[i]
                mid = _state(cand, rho)
                a = steer_length(code, _state(poses[i - 1], rho), mid, rho, now)
                if a >= now - 1e-9:
                    continue
                b = steer_length(code, mid, _state(poses[i + 1], rho), rho, now - a)
                if a + b >= now - 1e-9:
                    continue
                if not (_free(w, code, poses[i - 1], cand, rho, speed, kinds, lens, counter)
                        and _free(w, code, cand, poses[i + 1], rho, speed, kinds, lens,
                                  counter)):
                    continue
                poses[i, :] = cand
                edge[i - 1], edge[i] = a, b
        step_xy *= 0.5
        step_th *= 0.5
    return edge.sum()
