"""All segments of a path evaluated together, one numpy call per question.

Quadrature and resampling ask for thousands of (segment, t) pairs at a time; gathering each
pair's segment data as rows keeps that to a handful of array operations however many segments
there are. Béziers are raised to degree 3 (exactly), lines keep a flag so their curvature is 0.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tracks._bezier import de_casteljau, elevate_to_cubic, hodograph
from tracks._segments import EllipticArc, Segment, ellipse_point


class Chain:
    """Row-wise evaluation of segments: ``point``, ``velocity``, ``derivatives`` at (idx, t)."""

    def __init__(self, segments: Sequence[Segment]) -> None:
        self.count = len(segments)
        arc = np.array([isinstance(seg, EllipticArc) for seg in segments])
        self.is_arc = arc
        self.is_line = np.array([not a and len(seg.ctrl) == 2 for a, seg in zip(arc, segments)])
        self.ctrl = np.array(
            [np.zeros((4, 2)) if a else elevate_to_cubic(seg.ctrl) for a, seg in zip(arc, segments)]
        ).reshape(-1, 4, 2)
        self.first = hodograph(self.ctrl)
        self.second = hodograph(self.first)
        self.center = np.array([seg.center if a else np.zeros(2) for a, seg in zip(arc, segments)])
        self.axes = np.array([seg.axes if a else np.eye(2) for a, seg in zip(arc, segments)])
        self.theta0 = np.array([seg.theta0 if a else 0.0 for a, seg in zip(arc, segments)])
        self.dtheta = np.array([seg.dtheta if a else 0.0 for a, seg in zip(arc, segments)])
        self.has_arcs = bool(arc.any())

    def _arcs(self, idx: np.ndarray, t: np.ndarray, order: int) -> np.ndarray:
        theta = self.theta0[idx] + t * self.dtheta[idx]
        value = ellipse_point(self.axes[idx], theta, order) * self.dtheta[idx, None] ** order
        return value + self.center[idx] if order == 0 else value

    def _eval(self, rows: np.ndarray, idx: np.ndarray, t: np.ndarray, order: int) -> np.ndarray:
        out = de_casteljau(rows[idx], t)
        if self.has_arcs:
            arc = self.is_arc[idx]
            if arc.any():
                out[arc] = self._arcs(idx[arc], t[arc], order)
        return out

    def kinks(self) -> list[np.ndarray]:
        """Per segment, the parameters in (0, 1) where x' or y' vanishes.

        |B'| is smooth except where both vanish (a cusp), where it has a kink that slows
        quadrature and can fool its error estimate; splitting at every root of either component
        puts any cusp on an interval's end, where the integrand is smooth one-sidedly.
        """
        out = []
        for k in range(self.count):
            roots: list[float] = []
            if not self.is_arc[k] and np.isfinite(self.first[k]).all():
                for c in range(2):
                    p0, p1, p2 = self.first[k, :, c]
                    roots += [r.real for r in np.roots([p0 - 2 * p1 + p2, 2 * (p1 - p0), p0])
                              if abs(r.imag) < 1e-12 and 1e-9 < r.real < 1 - 1e-9]
            out.append(np.unique(roots))
        return out

    def point(self, idx: np.ndarray, t: np.ndarray) -> np.ndarray:
        return self._eval(self.ctrl, idx, t, 0)

    def velocity(self, idx: np.ndarray, t: np.ndarray) -> np.ndarray:
        return self._eval(self.first, idx, t, 1)

    def derivatives(self, idx: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d2 = self._eval(self.second, idx, t, 2)
        d2[self.is_line[idx]] = 0.0
        return self.velocity(idx, t), d2
