"""Arc length by adaptive Gauss–Legendre quadrature, and its inverse (parameter at a length).

The speed |B'(t)| of a cubic is the square root of a quartic: no closed form, but smooth, so a
10-point Gauss rule converges fast. Each interval is compared with the sum over its two halves
and halved until they agree; the accepted intervals, in order along the path, double as the
table that inverts s(t). Chord sums (the 2011 thesis) converge only quadratically, from below.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

Velocity = Callable[[np.ndarray, np.ndarray], np.ndarray]  # (segment index, t) → (n, 2)

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(10)
_MIN_DEPTH = 4  # at least 2**5 intervals per segment: a close first guess for the inversion
_MAX_DEPTH = 40
_MAX_ACTIVE = 1 << 15  # intervals still being refined; real tracks need a few hundred


def _speed(velocity: Velocity, idx: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.hypot(*velocity(idx, t).T)


def _gauss(velocity: Velocity, idx: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """10-point Gauss–Legendre ∫_a^b |velocity(idx, t)| dt for each triple."""
    half = (b - a) / 2.0
    t = ((a + b) / 2.0)[:, None] + half[:, None] * _NODES
    speed = _speed(velocity, np.repeat(idx, len(_NODES)), t.ravel()).reshape(t.shape)
    return half * (speed @ _WEIGHTS)


@dataclass(frozen=True)
class LengthTable:
    """Parameter intervals [a, b] of ``segment`` in path order; ``cumulative`` is the arc length
    from the path's start to each interval's start, with the total appended."""

    segment: np.ndarray
    a: np.ndarray
    b: np.ndarray
    cumulative: np.ndarray
    speed_a: np.ndarray
    speed_b: np.ndarray

    @property
    def length(self) -> float:
        return float(self.cumulative[-1])

    def segment_lengths(self, count: int) -> np.ndarray:
        return np.bincount(self.segment, weights=np.diff(self.cumulative), minlength=count)


def length_table(velocity: Velocity, count: int, rtol: float = 1e-12,
                 breaks: list[np.ndarray] | None = None) -> LengthTable:
    """Adaptive quadrature over [0, 1] of ``count`` segments, to ``rtol`` of the total length;
    ``breaks`` are parameters per segment where the first intervals must end (cusps)."""
    edges = [np.concatenate([[0.0], breaks[k] if breaks else [], [1.0]]) for k in range(count)]
    idx = np.concatenate([np.full(len(e) - 1, k) for k, e in enumerate(edges)])
    a = np.concatenate([e[:-1] for e in edges])
    b = np.concatenate([e[1:] for e in edges])
    whole = _gauss(velocity, idx, a, b)
    done_len = 0.0
    accepted = []
    for depth in range(_MAX_DEPTH + 1):
        total = done_len + whole.sum()
        mid = (a + b) / 2.0
        left, right = _gauss(velocity, idx, a, mid), _gauss(velocity, idx, mid, b)
        ok = np.abs(left + right - whole) <= rtol * total * (b - a)
        ok &= depth >= _MIN_DEPTH
        ok |= ~np.isfinite(left + right)  # NaN never converges: stop, the caller rejects it
        if depth == _MAX_DEPTH or len(idx) > _MAX_ACTIVE:
            ok[:] = True  # pathological input: give up refining rather than memory
        accepted += [(idx[ok], a[ok], mid[ok], left[ok]), (idx[ok], mid[ok], b[ok], right[ok])]
        done_len += left[ok].sum() + right[ok].sum()
        keep = ~ok
        if not keep.any():
            break
        idx = np.concatenate([idx[keep], idx[keep]])
        a, b = np.concatenate([a[keep], mid[keep]]), np.concatenate([mid[keep], b[keep]])
        whole = np.concatenate([left[keep], right[keep]])
    seg, lo, hi, lengths = (np.concatenate(col) for col in zip(*accepted))
    order = np.lexsort((lo, seg))
    seg, lo, hi = seg[order], lo[order], hi[order]
    return LengthTable(
        segment=seg,
        a=lo,
        b=hi,
        cumulative=np.concatenate([[0.0], np.cumsum(lengths[order])]),
        speed_a=_speed(velocity, seg, lo),
        speed_b=_speed(velocity, seg, hi),
    )


def _first_guess(table: LengthTable, k: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Cubic Hermite interpolation of t(s) in interval k, with dt/ds = 1/speed at its ends."""
    a, b = table.a[k], table.b[k]
    piece = table.cumulative[k + 1] - table.cumulative[k]
    u = np.divide(target, piece, out=np.zeros_like(target), where=piece > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        m0, m1 = piece / table.speed_a[k], piece / table.speed_b[k]
    linear = b - a
    m0 = np.where(np.isfinite(m0), m0, linear)
    m1 = np.where(np.isfinite(m1), m1, linear)
    u2, u3 = u * u, u * u * u
    t = (2 * u3 - 3 * u2 + 1) * a + (u3 - 2 * u2 + u) * m0 + (3 * u2 - 2 * u3) * b + (u3 - u2) * m1
    return np.clip(t, a, b)


def params_at(
    velocity: Velocity, table: LengthTable, s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(segment index, t) at arc lengths ``s`` along the path: safeguarded Newton.

    Newton's step is (s(t) − s)/|B'(t)| inside the table interval holding s; where the speed
    vanishes (a cusp) or a step leaves the bracket, bisection takes over.
    """
    s = np.clip(np.asarray(s, dtype=float), 0.0, table.length)
    k = np.clip(np.searchsorted(table.cumulative, s, side="right") - 1, 0, len(table.a) - 1)
    idx, start = table.segment[k], table.a[k]
    lo, hi = start.copy(), table.b[k].copy()
    target = s - table.cumulative[k]
    t = _first_guess(table, k, target)
    tol = 1e-13 * max(table.length, 1e-300)
    for _ in range(60):
        err = _gauss(velocity, idx, start, t) - target
        if not np.any(np.abs(err) > tol):
            break
        lo = np.where(err < 0, t, lo)
        hi = np.where(err > 0, t, hi)
        speed = _speed(velocity, idx, t)
        newton = t - np.divide(err, speed, out=np.full_like(err, np.inf), where=speed > 0)
        t = np.where((newton >= lo) & (newton <= hi), newton, (lo + hi) / 2.0)
    return idx, t
