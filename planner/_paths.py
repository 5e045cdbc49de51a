"""Local motions as at most five segments — the one representation every steering writes.

``kinds`` (int8[5]: +1 left arc, 0 straight, -1 right arc, 2 turn on the spot) and ``lens``
(float64[5]: signed arc length in metres, negative = reversing; for a turn on the spot the
signed angle in radians, which drives no length; unused slots are 0). Arcs have radius ``rho``.
Everything downstream — sampling, collision checks, curvature profiles — reads only this form,
so all steering functions share one integrator. A turn on the spot is taken when the motion goes
on past it: the pose at driven length 0 is the start pose, the pose at the end of the last
driven segment has not yet taken a turn that follows it.

The pose update along a segment is exact (no numerical integration): for a left arc of signed
length l, θ' = θ + l/ρ, x' = x + ρ(sin θ' − sin θ), y' = y − ρ(cos θ' − cos θ).
"""

from __future__ import annotations

import math

import numpy as np

from planner._jit import njit

MAX_SEGMENTS = 5
LEFT, STRAIGHT, RIGHT, TURN = 1, 0, -1, 2
_TWO_PI = 2.0 * math.pi
MIN_SEGMENT = 1e-9  # m: a shorter driven segment (a Dubins word's vanishing middle) is none
_LETTERS = {LEFT: "L", STRAIGHT: "S", RIGHT: "R", TURN: "T"}


def path_word(kinds, lens) -> str:
    """The path's steering word, one letter per segment in driving order: L left arc, S
    straight, R right arc, T turn on the spot ("LSL", "RSR", "TST"); unused segments are left
    out. A path that reverses anywhere gives each driven segment its direction, + forward and
    − reverse, as Reeds and Shepp write their words ("L+R−S−"): a forward-only word stays short,
    the way Dubins words are known. A turn on the spot drives no way and has no direction. A
    segment under `MIN_SEGMENT` has no letter, as it has no row in `sample_path`. The empty path
    (the root's) has the empty word.

    >>> import numpy as np
    >>> path_word(np.array([1, 0, 1, 0, 0]), np.array([0.5, 2.0, 0.3, 0.0, 0.0]))
    'LSL'
    >>> path_word(np.array([1, -1, 0, 0, 0]), np.array([0.4, -0.9, -1.0, 0.0, 0.0]))
    'L+R−S−'
    """
    segs = [(int(k), float(v)) for k, v in zip(kinds, lens) if _sampled.py_func(k, v)]
    reverses = any(v < 0.0 and k != TURN for k, v in segs)
    return "".join(_LETTERS[k] + ("" if not reverses or k == TURN else "+" if v > 0 else "−")
                   for k, v in segs)


@njit(cache=True, inline="always")
def advance(x: float, y: float, th: float, kind: int, length: float, rho: float):
    """Pose after driving ``length`` (signed) on one segment of ``kind`` from (x, y, th); for
    a turn on the spot, ``length`` is its angle."""
    if kind == STRAIGHT:
        return x + length * math.cos(th), y + length * math.sin(th), th
    if kind == TURN:
        return x, y, th + length
    th2 = th + kind * length / rho
    x2 = x + kind * rho * (math.sin(th2) - math.sin(th))
    y2 = y - kind * rho * (math.cos(th2) - math.cos(th))
    return x2, y2, th2


@njit(cache=True, inline="always")
def driven(kind: int, seg: float) -> float:
    """The length a segment drives: |seg|, and 0 for a turn on the spot."""
    return 0.0 if kind == TURN else abs(seg)


@njit(cache=True)
def path_length(kinds: np.ndarray, lens: np.ndarray) -> float:
    """Driven length of a path: the sum of the segments' driven lengths."""
    total = 0.0
    for i in range(lens.shape[0]):
        total += driven(kinds[i], lens[i])
    return total


@njit(cache=True)
def pose_at(x: float, y: float, th: float, kinds: np.ndarray, lens: np.ndarray, rho: float,
            s: float):
    """Pose at driven length ``s`` (0 ≤ s ≤ path length) along the path from (x, y, th).

    Returns (x, y, theta, kind, direction) where kind is the segment's steering (+1/0/-1) and
    direction +1 forward, -1 reverse at that point.
    """
    remaining = s
    kind = 0
    direction = 1.0
    for i in range(kinds.shape[0]):
        seg = lens[i]
        if seg == 0.0:
            continue
        if kinds[i] == TURN:
            if remaining > 0.0:
                th += seg
            continue
        kind = kinds[i]
        direction = 1.0 if seg > 0.0 else -1.0
        if remaining <= abs(seg):
            x, y, th = advance(x, y, th, kind, direction * remaining, rho)
            return x, y, th, kind, direction
        x, y, th = advance(x, y, th, kind, seg, rho)
        remaining -= abs(seg)
    return x, y, th, kind, direction


@njit(cache=True)
def path_end(x: float, y: float, th: float, kinds: np.ndarray, lens: np.ndarray, rho: float):
    """End pose of the path (heading not wrapped)."""
    for i in range(kinds.shape[0]):
        if lens[i] != 0.0:
            x, y, th = advance(x, y, th, kinds[i], lens[i], rho)
    return x, y, th


@njit(cache=True)
def truncate(kinds: np.ndarray, lens: np.ndarray, s: float, out_lens: np.ndarray) -> None:
    """Write into ``out_lens`` the first ``s`` metres of the path (same kinds)."""
    remaining = s
    for i in range(kinds.shape[0]):
        seg = lens[i]
        if kinds[i] == TURN:
            out_lens[i] = seg if remaining > 0.0 else 0.0
            continue
        take = min(abs(seg), max(remaining, 0.0))
        out_lens[i] = take if seg >= 0.0 else -take
        remaining -= take


@njit(cache=True)
def sample_path(x: float, y: float, th: float, kinds: np.ndarray, lens: np.ndarray, rho: float,
                spacing: float) -> np.ndarray:
    """Poses every ≤ ``spacing`` metres, both ends and every segment joint included.

    Returns an (n, 5) array of x, y, theta, curvature (steering curvature: kind/ρ), direction.
    A turn on the spot is one row: the same position, the new heading, curvature 0 (the robot
    does not steer; its heading is free). A segment under `MIN_SEGMENT` (a Dubins word's
    vanishing middle) moves the pose but gives no row: it would repeat the one before.
    """
    n = 1
    first = -1
    for i in range(kinds.shape[0]):
        if _sampled(kinds[i], lens[i]):
            n += max(1, int(math.ceil(driven(kinds[i], lens[i]) / spacing - 1e-12)))
            first = i if first < 0 else first
    out = np.empty((n, 5))
    out[0, 0] = x
    out[0, 1] = y
    out[0, 2] = th
    out[0, 3] = _curvature(kinds[first], rho) if first >= 0 else 0.0
    out[0, 4] = _direction(kinds[first], lens[first]) if first >= 0 else 1.0
    k = 1
    for i in range(kinds.shape[0]):
        seg = lens[i]
        if not _sampled(kinds[i], seg):
            x, y, th = advance(x, y, th, kinds[i], seg, rho)
            continue
        steps = max(1, int(math.ceil(driven(kinds[i], seg) / spacing - 1e-12)))
        for j in range(1, steps + 1):
            px, py, pth = advance(x, y, th, kinds[i], seg * j / steps, rho)
            out[k, 0] = px
            out[k, 1] = py
            out[k, 2] = pth
            out[k, 3] = _curvature(kinds[i], rho)
            out[k, 4] = _direction(kinds[i], seg)
            k += 1
        x, y, th = advance(x, y, th, kinds[i], seg, rho)
    return out


@njit(cache=True, inline="always")
def _sampled(kind: int, seg: float) -> bool:
    return seg != 0.0 and (kind == TURN or abs(seg) > MIN_SEGMENT)


@njit(cache=True, inline="always")
def _curvature(kind: int, rho: float) -> float:
    return 0.0 if kind == TURN else kind / rho


@njit(cache=True, inline="always")
def _direction(kind: int, seg: float) -> float:
    """+1 forward, -1 reversing; a turn on the spot counts as forward."""
    return -1.0 if seg < 0.0 and kind != TURN else 1.0


@njit(cache=True, inline="always")
def wrap_angle(a: float) -> float:
    """Wrap to [-π, π): one rounding instruction and no branch (Python's floored ``%`` costs
    eight times as much, and a branch mispredicts on random headings)."""
    return a - _TWO_PI * math.floor(a * (1.0 / _TWO_PI) + 0.5)
