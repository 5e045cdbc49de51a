"""The two exact segment kinds of a track: Bézier curves (lines included) and elliptic arcs.

Both are parametrised on t ∈ [0, 1] and answer the same questions — points, first and second
derivatives, an affine image, parameters of axis extrema — so everything downstream (length,
resampling, curvature, export) treats them alike. Arcs stay arcs: c + A·(cos θ, sin θ) with
θ = θ0 + t·Δθ. An affine map sends that to c' + M·A·(cos θ, sin θ) exactly, whatever M is
(rotation, skew, reflection), so no sweep flag or ellipse axes have to be re-derived.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tracks._bezier import de_casteljau, hodograph


@dataclass(frozen=True, eq=False)
class Bezier:
    """A Bézier curve of degree 1 (line), 2 or 3 with control points ``ctrl`` (k, 2)."""

    ctrl: np.ndarray

    @property
    def start(self) -> np.ndarray:
        return self.ctrl[0]

    @property
    def end(self) -> np.ndarray:
        return self.ctrl[-1]

    def point(self, t: np.ndarray) -> np.ndarray:
        return de_casteljau(self.ctrl, t)

    def transformed(self, matrix: np.ndarray, offset: np.ndarray) -> Bezier:
        return Bezier(self.ctrl @ matrix.T + offset)

    def extremum_params(self) -> np.ndarray:
        """Parameters in (0, 1) where x' or y' vanishes (the roots of the hodograph)."""
        first = hodograph(self.ctrl)
        roots = [_bernstein_roots(first[:, axis]) for axis in (0, 1)]
        found = np.concatenate(roots)
        return found[(found > 0.0) & (found < 1.0)]


@dataclass(frozen=True, eq=False)
class EllipticArc:
    """center + axes·(cos θ, sin θ), θ from ``theta0`` over ``dtheta`` (signed, radians).

    ``axes`` (2, 2) holds the images of the unit vectors as columns; for an SVG arc it is
    R(φ)·diag(rx, ry), after any affine map it is that map's matrix times it.
    """

    center: np.ndarray
    axes: np.ndarray
    theta0: float
    dtheta: float

    @property
    def start(self) -> np.ndarray:
        return self.point(np.zeros(1))[0]

    @property
    def end(self) -> np.ndarray:
        return self.point(np.ones(1))[0]

    def point(self, t: np.ndarray) -> np.ndarray:
        return self.center + ellipse_point(self.axes, self.theta0 + np.asarray(t) * self.dtheta)

    def transformed(self, matrix: np.ndarray, offset: np.ndarray) -> EllipticArc:
        return EllipticArc(
            matrix @ self.center + offset, matrix @ self.axes, self.theta0, self.dtheta
        )

    def extremum_params(self) -> np.ndarray:
        """Parameters in (0, 1) where x or y is extreme: θ = atan2(A[i,1], A[i,0]) + kπ."""
        if self.dtheta == 0.0:
            return np.empty(0)
        base = np.arctan2(self.axes[:, 1], self.axes[:, 0])
        lo, hi = sorted((self.theta0, self.theta0 + self.dtheta))
        found = [
            (b + k * math.pi - self.theta0) / self.dtheta
            for b in base
            for k in range(math.floor((lo - b) / math.pi), math.ceil((hi - b) / math.pi) + 1)
        ]
        params = np.array(found)
        return params[(params > 0.0) & (params < 1.0)]


Segment = Bezier | EllipticArc


def ellipse_point(axes: np.ndarray, theta: np.ndarray, order: int = 0) -> np.ndarray:
    """axes·(cos θ, sin θ) or its ``order``-th derivative in θ; axes (2, 2) or one per θ.

    The k-th derivative of (cos θ, sin θ) is the same vector turned by k·90°.
    """
    turned = np.asarray(theta, dtype=float) + order * (math.pi / 2)
    unit = np.stack([np.cos(turned), np.sin(turned)], axis=-1)
    return np.einsum("...ij,...j->...i", axes, unit)


def line(start: np.ndarray, end: np.ndarray) -> Bezier:
    """A straight segment: a degree-1 Bézier, so its second derivative is exactly zero."""
    return Bezier(np.array([start, end], dtype=float))


def _bernstein_roots(coeffs: np.ndarray) -> np.ndarray:
    """Real roots of a Bernstein polynomial of degree ≤ 2 given by its coefficients."""
    if coeffs.shape[0] == 3:
        a, b, c = coeffs
        poly = [a - 2 * b + c, 2 * (b - a), a]
    elif coeffs.shape[0] == 2:
        poly = [coeffs[1] - coeffs[0], coeffs[0]]
    else:
        return np.empty(0)
    while poly and poly[0] == 0.0:
        poly = poly[1:]
    if len(poly) < 2:
        return np.empty(0)
    roots = np.roots(poly)
    return roots[np.isreal(roots)].real


def arc_from_endpoints(
    start: np.ndarray,
    end: np.ndarray,
    radii: tuple[float, float],
    rotation_deg: float,
    large_arc: bool,
    sweep: bool,
) -> Segment | None:
    """The SVG arc command as an exact segment (SVG 1.1 implementation notes F.6.5–F.6.6).

    Returns None when the endpoints coincide (the spec omits such an arc) and a line when a
    radius is zero. Angles come from atan2, not acos, so short and near-half arcs stay accurate.
    """
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    if np.array_equal(start, end):
        return None
    rx, ry = abs(radii[0]), abs(radii[1])
    if rx == 0.0 or ry == 0.0:
        return line(start, end)
    phi = math.radians(rotation_deg)
    rot = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    x1, y1 = rot.T @ ((start - end) / 2.0)
    excess = (x1 / rx) ** 2 + (y1 / ry) ** 2
    if excess > 1.0:
        rx, ry = rx * math.sqrt(excess), ry * math.sqrt(excess)
        factor = 0.0
    else:
        den = (rx * y1) ** 2 + (ry * x1) ** 2
        if den == 0.0:  # endpoints a few 1e-160 apart: coincident to the arithmetic
            return None
        factor = math.sqrt(max(0.0, ((rx * ry) ** 2 - den) / den))
    if large_arc == sweep:
        factor = -factor
    cx, cy = factor * rx * y1 / ry, -factor * ry * x1 / rx
    center = rot @ np.array([cx, cy]) + (start + end) / 2.0
    u1 = np.array([(x1 - cx) / rx, (y1 - cy) / ry])
    u2 = np.array([(-x1 - cx) / rx, (-y1 - cy) / ry])
    theta0 = math.atan2(u1[1], u1[0])
    dtheta = math.atan2(u1[0] * u2[1] - u1[1] * u2[0], u1 @ u2)
    if sweep and dtheta < 0:
        dtheta += 2 * math.pi
    elif not sweep and dtheta > 0:
        dtheta -= 2 * math.pi
    return EllipticArc(center, rot @ np.diag([rx, ry]), theta0, dtheta)


def arc_to_svg(arc: EllipticArc) -> tuple[float, float, float, bool, bool]:
    """(rx, ry, rotation_deg, large_arc, sweep) of the SVG arc command tracing ``arc``.

    The SVD A = U·Σ·Vᵀ gives the radii (Σ) and the axis direction (U); the sweep is the sign
    of det(A)·Δθ, the turning sense of the traced curve — so reflections come out right.
    """
    u, sigma, _ = np.linalg.svd(arc.axes)
    rotation = math.degrees(math.atan2(u[1, 0], u[0, 0]))
    sweep = np.linalg.det(arc.axes) * arc.dtheta > 0
    return float(sigma[0]), float(sigma[1]), rotation, abs(arc.dtheta) > math.pi, bool(sweep)
