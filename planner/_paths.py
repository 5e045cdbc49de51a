"""Local motions as a few segments — the one representation every steering writes.

A path is three arrays of one width (the steering's ``segments``, see `planner.steering`):

- ``kinds`` (int8): which way the segment turns, +1 left, 0 straight, -1 right, 2 turn on the
  spot — the letter of the path's word (`path_word`);
- ``lens`` (float64): its signed driven length in metres, negative = reversing; for a turn on
  the spot the signed angle in radians, which drives no length; unused slots are 0;
- ``curv`` (float64, two columns): its steering curvature κ0 where it starts (1/m, positive
  = the wheels turned left) and its sharpness σ = dκ/du (1/m², u the driven distance). An arc
  of radius ρ is (±1/ρ, 0), a straight (0, 0), a clothoid ramps κ at σ.

Everything downstream — sampling, collision checks, curvature profiles, re-rooting, drawing —
reads only this form through `advance` and `curvature_at`, so all steering functions share one
integrator. A turn on the spot is taken when the motion goes on past it: the pose at driven
length 0 is the start pose, the pose at the end of the last driven segment has not yet taken a
turn that follows it.

The pose update along a segment is exact (no numerical integration): for an arc of signed
length l and curvature κ, θ' = θ + κl, x' = x + (sin θ' − sin θ)/κ, y' = y − (cos θ' − cos θ)/κ;
a clothoid's is `planner._clothoid.clothoid_pose` (Fresnel integrals).
"""

from __future__ import annotations

import math

import numpy as np

from planner._clothoid import clothoid_pose
from planner._jit import njit

LEFT, STRAIGHT, RIGHT, TURN = 1, 0, -1, 2
_TWO_PI = 2.0 * math.pi
MIN_SEGMENT = 1e-9  # m: a shorter driven segment (a Dubins word's vanishing middle) is none
_LETTERS = {LEFT: "L", STRAIGHT: "S", RIGHT: "R", TURN: "T"}


def path_word(kinds, lens) -> str:
    """The path's steering word, one letter per turn or straight in driving order: L left, S
    straight, R right, T turn on the spot ("LSL", "RSR", "TST"); unused segments are left out,
    and segments of one letter driven one way make one letter (a continuous-curvature turn's
    clothoid, arc and clothoid are one L). A path that reverses anywhere gives each letter its
    direction, + forward and − reverse, as Reeds and Shepp write their words ("L+R−S−"): a
    forward-only word stays short, the way Dubins words are known. A turn on the spot drives no
    way and has no direction. A segment under `MIN_SEGMENT` has no letter, as it has no row in
    `sample_path`. The empty path (the root's) has the empty word.

    >>> import numpy as np
    >>> path_word(np.array([1, 0, 1, 0, 0]), np.array([0.5, 2.0, 0.3, 0.0, 0.0]))
    'LSL'
    >>> path_word(np.array([1, -1, 0, 0, 0]), np.array([0.4, -0.9, -1.0, 0.0, 0.0]))
    'L+R−S−'
    >>> path_word(np.array([1, 1, 1, 0, 0]), np.array([0.2, 0.5, 0.2, 1.0, 0.0]))
    'LS'
    """
    segs = [(int(k), float(v)) for k, v in zip(kinds, lens) if _sampled.py_func(k, v)]
    reverses = any(v < 0.0 and k != TURN for k, v in segs)
    letters = [_LETTERS[k] + ("" if not reverses or k == TURN else "+" if v > 0 else "−")
               for k, v in segs]
    return "".join(a for i, a in enumerate(letters)
                   if i == 0 or a != letters[i - 1] or a.startswith("T"))


@njit(cache=True, inline="always")
def advance(x: float, y: float, th: float, kind: int, length: float, k0: float, sigma: float):
    """Pose after driving ``length`` (signed) on one segment from (x, y, th): of ``kind`` (a
    turn on the spot turns by the angle ``length``), start curvature ``k0``, sharpness
    ``sigma``."""
    if kind == TURN:
        return x, y, th + length
    if sigma != 0.0:
        return clothoid_pose(x, y, th, k0, sigma, length)
    if k0 == 0.0:
        return x + length * math.cos(th), y + length * math.sin(th), th
    th2 = th + k0 * length
    return x + (math.sin(th2) - math.sin(th)) / k0, y - (math.cos(th2) - math.cos(th)) / k0, th2


@njit(cache=True, inline="always")
def curvature_at(kind: int, k0: float, sigma: float, u: float) -> float:
    """Steering curvature ``u`` metres into a segment (0 on the spot: the robot does not
    steer, its heading is free)."""
    return 0.0 if kind == TURN else k0 + sigma * u


@njit(cache=True, inline="always")
def peak_curvature(kind: int, length: float, k0: float, sigma: float) -> float:
    """The most |κ| a segment reaches: at one of its ends (κ is linear in u)."""
    return 0.0 if kind == TURN else max(abs(k0), abs(k0 + sigma * abs(length)))


@njit(cache=True, inline="always")
def path_buffers(segments: int):
    """Zeroed kinds, lens and curv for one path of ``segments`` segments."""
    return np.zeros(segments, np.int8), np.zeros(segments), np.zeros((segments, 2))


@njit(cache=True)
def arc_curvatures(kinds: np.ndarray, rho: float, curv: np.ndarray) -> None:
    """``curv`` of a path of arcs of radius ρ and straights (Dubins, Reeds-Shepp, straight
    lines): κ0 = kind/ρ, σ = 0."""
    for i in range(kinds.shape[0]):
        curv[i, 0] = 0.0 if kinds[i] == TURN else kinds[i] / rho
        curv[i, 1] = 0.0


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
def pose_at(x: float, y: float, th: float, kinds: np.ndarray, lens: np.ndarray,
            curv: np.ndarray, s: float):
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
            x, y, th = advance(x, y, th, kind, direction * remaining, curv[i, 0], curv[i, 1])
            return x, y, th, kind, direction
        x, y, th = advance(x, y, th, kind, seg, curv[i, 0], curv[i, 1])
        remaining -= abs(seg)
    return x, y, th, kind, direction


@njit(cache=True)
def path_end(x: float, y: float, th: float, kinds: np.ndarray, lens: np.ndarray,
             curv: np.ndarray):
    """End pose of the path (heading not wrapped)."""
    for i in range(kinds.shape[0]):
        if lens[i] != 0.0:
            x, y, th = advance(x, y, th, kinds[i], lens[i], curv[i, 0], curv[i, 1])
    return x, y, th


@njit(cache=True)
def truncate(kinds: np.ndarray, lens: np.ndarray, s: float, out_lens: np.ndarray) -> None:
    """Write into ``out_lens`` the first ``s`` metres of the path (same kinds and curvatures:
    a segment cut short starts as it did)."""
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
def rest_points(kinds: np.ndarray, lens: np.ndarray, curv: np.ndarray, s: float):
    """(before, after): the driven lengths nearest to ``s``, before ≤ s ≤ after, where the
    path's steering curvature is 0 (−∞ or ∞ where there is none): anywhere on a straight,
    where a segment's κ0 + σu is 0 at one of its ends, at a turn on the spot."""
    before, after = -math.inf, math.inf
    u = 0.0
    for i in range(kinds.shape[0]):
        length = driven(kinds[i], lens[i])
        k0, sigma = curv[i, 0], curv[i, 1]
        end = u + length
        flat_start = kinds[i] == TURN or abs(k0) < 1e-12
        flat_end = kinds[i] == TURN or abs(k0 + sigma * length) < 1e-12
        if flat_start and sigma == 0.0 and u <= s <= end:
            return s, s  # on a straight
        if flat_start and u <= s:
            before = u
        if flat_end and end <= s:
            before = end
        if flat_end and end > s:
            return before, end
        u = end
    return before, after


@njit(cache=True)
def sample_path(x: float, y: float, th: float, kinds: np.ndarray, lens: np.ndarray,
                curv: np.ndarray, spacing: float) -> np.ndarray:
    """Poses every ≤ ``spacing`` metres, both ends and every segment joint included.

    Returns an (n, 6) array of x, y, theta, curvature (the steering curvature there; at a
    joint, the segment's that ends there), direction, and the driven length from the start.
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
    out = np.empty((n, 6))
    out[0, 5] = 0.0
    along = 0.0
    out[0, 0] = x
    out[0, 1] = y
    out[0, 2] = th
    out[0, 3] = curvature_at(kinds[first], curv[first, 0], 0.0, 0.0) if first >= 0 else 0.0
    out[0, 4] = _direction(kinds[first], lens[first]) if first >= 0 else 1.0
    k = 1
    for i in range(kinds.shape[0]):
        seg = lens[i]
        k0, sigma = curv[i, 0], curv[i, 1]
        if not _sampled(kinds[i], seg):
            x, y, th = advance(x, y, th, kinds[i], seg, k0, sigma)
            along += driven(kinds[i], seg)
            continue
        steps = max(1, int(math.ceil(driven(kinds[i], seg) / spacing - 1e-12)))
        for j in range(1, steps + 1):
            part = seg * j / steps
            px, py, pth = advance(x, y, th, kinds[i], part, k0, sigma)
            out[k, 0] = px
            out[k, 1] = py
            out[k, 2] = pth
            out[k, 3] = curvature_at(kinds[i], k0, sigma, abs(part))
            out[k, 4] = _direction(kinds[i], seg)
            out[k, 5] = along + driven(kinds[i], part)
            k += 1
        x, y, th = advance(x, y, th, kinds[i], seg, k0, sigma)
        along += driven(kinds[i], seg)
    return out


@njit(cache=True, inline="always")
def _sampled(kind: int, seg: float) -> bool:
    return seg != 0.0 and (kind == TURN or abs(seg) > MIN_SEGMENT)


@njit(cache=True, inline="always")
def _direction(kind: int, seg: float) -> float:
    """+1 forward, -1 reversing; a turn on the spot counts as forward."""
    return -1.0 if seg < 0.0 and kind != TURN else 1.0


@njit(cache=True, inline="always")
def wrap_angle(a: float) -> float:
    """Wrap to [-π, π): one rounding instruction and no branch (Python's floored ``%`` costs
    eight times as much, and a branch mispredicts on random headings)."""
    return a - _TWO_PI * math.floor(a * (1.0 / _TWO_PI) + 0.5)
