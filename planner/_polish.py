"""Local optimisation of the best path's poses with the exact steering (compiled).

RRT*'s rewiring only chooses among poses it has sampled, so after a second its best path is
still 2–3 % longer than the best known (benchmarks/results/planner.md). Moving the path's own
poses closes most of that. Each pass splits every edge at its middle (more poses to move: a
chain of steered edges can hug an obstacle), then runs coordinate descent on the poses (x, y, θ)
with steps that halve every round — a move is taken when the steered edges it changes are
shorter together and free by the exact motion check — then drops every pose the path can skip. Late polishes also shift blocks of 2, 4 and 8 poses
together between two descents: a path bulging round an obstacle between poses too far apart
for any single one to move freely moves as a whole.
The start stays put; the end pose moves within the goal region, where the tree's first goal
node is seldom the best place to arrive (on open_field alone that was 1 % of the length).
Static worlds only: with moving obstacles a shorter edge changes every later arrival time,
which the kernel's rewiring handles.
"""

from __future__ import annotations

import math

import numpy as np

from planner._goal import in_goal
from planner._jit import njit
from planner._paths import pose_at, wrap_angle
from planner._steer import state, steer_length, steer_path
from planner._world import World, motion_free

PASSES = 2  # split, descend, prune
SPLIT_MIN = 0.25  # ρ: the shortest edge a split leaves
ROUNDS = 6  # step halvings per descent: from a quarter of the mean edge to 1/1000 of it
# Poses a pruned edge may skip at most: a path fresh from the tree has ~100 poses, and trying
# every later pose made pruning quadratic, 90 % of a polish's motion checks, for no shorter path.
LOOKAHEAD = 16
MOVES = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0],
                  [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
BLOCKS = (2, 4, 8)  # poses shifted together, after the single-pose descent
_D = math.sqrt(0.5)
SHIFTS = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0], [_D, _D], [-_D, _D],
                   [_D, -_D], [-_D, -_D]])


@njit(cache=True, inline="always")
def _state(q, rho):
    return state(q[0], q[1], q[2], math.cos(q[2]), math.sin(q[2]), rho)


@njit(cache=True, inline="always")
def _length(code: int, a, b, g, bound: float) -> float:
    return steer_length(code, _state(a, g[0]), _state(b, g[0]), g, bound)


@njit(cache=True)
def _free(w: World, code: int, a, b, g, speed: float, buf, counter) -> bool:
    kinds, lens, curv = buf
    steer_path(code, a[0], a[1], a[2], b[0], b[1], b[2], g, kinds, lens, curv)
    return motion_free(w, a[0], a[1], a[2], 0.0, kinds, lens, curv, speed, counter)


@njit(cache=True)
def polish_path(w: World, code: int, g, speed: float, poses: np.ndarray,
                goal: np.ndarray, buf, counter, blocks: bool, limit: int):
    """The path through ``poses`` ((n, 3)) shortened: (new poses, their length); with
    ``blocks``, each pass also shifts blocks of poses (`_shift_blocks`), which costs a polish
    about twice as much. It stops between two rounds once ``counter`` has passed ``limit``
    clearance evaluations: every step keeps the path free, so where it stops is a path.
    ``g``: the car's turning constants (`planner._cc_dubins.cc_constants`); ``buf``: (kinds,
    lens, curv), room for one local path (`planner._paths`)."""
    for _ in range(PASSES):
        poses = _split(code, g, poses, buf)
        _descend(w, code, g, speed, poses, goal, buf, counter, limit)
        if blocks:
            for width in BLOCKS:
                _shift_blocks(w, code, g, speed, poses, width, buf, counter, limit)
            _descend(w, code, g, speed, poses, goal, buf, counter, limit)
        if counter[0] > limit:
            break
        poses = _prune(w, code, g, speed, poses, buf, counter)
    total = 0.0
    for i in range(poses.shape[0] - 1):
        total += _length(code, poses[i], poses[i + 1], g, math.inf)
    return poses, total


@njit(cache=True)
def _split(code: int, g, poses: np.ndarray, buf) -> np.ndarray:
    """Every edge of `SPLIT_MIN`·2ρ or more cut in two at the pose halfway along it (the path
    itself is unchanged). Shorter edges stay whole: a polish that stops at its budget keeps its
    split poses, and splitting every edge each time grew a corridor's best path to 7 446 poses
    (5.8 mm apart) and its last polish to 0.3 s."""
    n = poses.shape[0]
    out = np.empty((2 * n - 1, 3))
    k = 0
    for i in range(n - 1):
        a, b = poses[i], poses[i + 1]
        out[k, :] = a
        k += 1
        length = steer_path(code, a[0], a[1], a[2], b[0], b[1], b[2], g, buf[0], buf[1], buf[2])
        if length >= 2.0 * SPLIT_MIN * g[0]:
            x, y, th, _, _ = pose_at(a[0], a[1], a[2], buf[0], buf[1], buf[2], 0.5 * length)
            out[k, 0] = x
            out[k, 1] = y
            out[k, 2] = wrap_angle(th)
            k += 1
    out[k, :] = poses[n - 1]
    return out[:k + 1].copy()


@njit(cache=True)
def _edges(code: int, poses: np.ndarray, g) -> tuple[np.ndarray, float]:
    """The lengths of the path's edges and their mean, summed here: ``edge.mean()`` would make
    every process that loads the kernels import numba's array math (0.05 s)."""
    n = poses.shape[0]
    edge = np.empty(n - 1)
    total = 0.0
    for i in range(n - 1):
        edge[i] = _length(code, poses[i], poses[i + 1], g, math.inf)
        total += edge[i]
    return edge, total / (n - 1)


@njit(cache=True)
def _descend(w: World, code: int, g, speed: float, poses: np.ndarray,
             goal: np.ndarray, buf, counter, limit: int) -> None:
    """Coordinate descent on the inner poses and the end pose (within the goal), in place:
    each round moves every pose by the step that shortens its edges most and is free."""
    n = poses.shape[0]
    nm = MOVES.shape[0]
    edge, mean = _edges(code, poses, g)
    step_xy = 0.25 * mean
    step_th = 0.25
    cand = np.empty((nm, 3))
    gain = np.empty(nm)
    new_a = np.empty(nm)
    new_b = np.empty(nm)
    for _ in range(ROUNDS):
        if counter[0] > limit:
            return
        for i in range(1, n):
            last = i == n - 1
            now = edge[i - 1] + (0.0 if last else edge[i])
            for m in range(nm):
                cand[m, 0] = poses[i, 0] + MOVES[m, 0] * step_xy
                cand[m, 1] = poses[i, 1] + MOVES[m, 1] * step_xy
                cand[m, 2] = wrap_angle(poses[i, 2] + MOVES[m, 2] * step_th)
                gain[m] = 0.0
                if last and not in_goal(cand[m, 0], cand[m, 1], cand[m, 2], goal):
                    continue
                a = _length(code, poses[i - 1], cand[m], g, now)
                b = 0.0 if last else _length(code, cand[m], poses[i + 1], g, now - a)
                new_a[m], new_b[m] = a, b
                gain[m] = max(now - a - b, 0.0)
            for m in np.argsort(-gain):
                if gain[m] <= 1e-9:
                    break
                if not _free(w, code, poses[i - 1], cand[m], g, speed, buf, counter):
                    continue
                if not last and not _free(w, code, cand[m], poses[i + 1], g, speed, buf,
                                          counter):
                    continue
                poses[i, :] = cand[m]
                edge[i - 1] = new_a[m]
                if not last:
                    edge[i] = new_b[m]
                break
        step_xy *= 0.5
        step_th *= 0.5


@njit(cache=True)
def _shift_blocks(w: World, code: int, g, speed: float, poses: np.ndarray, width: int,
                  buf, counter, limit: int) -> None:
    """Coordinate descent on blocks of ``width`` inner poses shifted together, in place. A
    path that bulges round an obstacle between poses too far apart for any one of them to move
    freely can move as a whole; a shift keeps the steered edges inside the block."""
    n = poses.shape[0]
    if n - width < 2:
        return
    edge, mean = _edges(code, poses, g)
    step = 0.25 * mean
    a = np.empty(3)
    b = np.empty(3)
    moved = np.empty((width, 3))
    for _ in range(ROUNDS):
        if counter[0] > limit:
            return
        for i in range(1, n - width):
            j = i + width - 1
            now = edge[i - 1] + edge[j]
            best, pick, len_a, len_b = 1e-9, -1, 0.0, 0.0
            for m in range(SHIFTS.shape[0]):
                a[:] = poses[i]
                b[:] = poses[j]
                a[0] += SHIFTS[m, 0] * step
                a[1] += SHIFTS[m, 1] * step
                b[0] += SHIFTS[m, 0] * step
                b[1] += SHIFTS[m, 1] * step
                la = _length(code, poses[i - 1], a, g, now)
                lb = _length(code, b, poses[j + 1], g, now - la)
                if now - la - lb > best:
                    best, pick, len_a, len_b = now - la - lb, m, la, lb
            if pick < 0:
                continue
            for k in range(width):
                moved[k, 0] = poses[i + k, 0] + SHIFTS[pick, 0] * step
                moved[k, 1] = poses[i + k, 1] + SHIFTS[pick, 1] * step
                moved[k, 2] = poses[i + k, 2]
            free = (_free(w, code, poses[i - 1], moved[0], g, speed, buf, counter)
                    and _free(w, code, moved[width - 1], poses[j + 1], g, speed, buf,
                              counter))
            k = 0
            while free and k < width - 1:
                free = _free(w, code, moved[k], moved[k + 1], g, speed, buf, counter)
                k += 1
            if free:
                poses[i:j + 1, :] = moved
                edge[i - 1] = len_a
                edge[j] = len_b
        step *= 0.5


@njit(cache=True)
def _prune(w: World, code: int, g, speed: float, poses: np.ndarray, buf,
           counter) -> np.ndarray:
    """The poses the path can skip dropped: from each kept pose, straight on to the farthest
    later pose (of the next `LOOKAHEAD`) that one free steered edge reaches more shortly than
    the poses between."""
    n = poses.shape[0]
    along = np.zeros(n)  # driven length from the start to each pose
    for i in range(n - 1):
        along[i + 1] = along[i] + _length(code, poses[i], poses[i + 1], g, math.inf)
    keep = np.zeros(n, np.int64)
    kept = 1
    i = 0
    while i < n - 1:
        nxt = i + 1
        for j in range(min(n - 1, i + LOOKAHEAD), i + 1, -1):
            via = along[j] - along[i]
            if (_length(code, poses[i], poses[j], g, via) < via - 1e-9
                    and _free(w, code, poses[i], poses[j], g, speed, buf, counter)):
                nxt = j
                break
        keep[kept] = nxt
        kept += 1
        i = nxt
    out = np.empty((kept, 3))
    for k in range(kept):
        out[k, :] = poses[keep[k]]
    return out
