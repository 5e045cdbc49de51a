"""The SVG transform attribute as a 3×3 affine matrix (list applied left to right)."""

from __future__ import annotations

import math
import re

import numpy as np

from tracks._errors import TrackError

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_ITEM = re.compile(r"\s*,?\s*(matrix|translate|scale|rotate|skewX|skewY)\s*\(([^)]*)\)\s*")
_ARITY = {
    "matrix": (6,),
    "translate": (1, 2),
    "scale": (1, 2),
    "rotate": (1, 3),
    "skewX": (1,),
    "skewY": (1,),
}


def _affine(a: float, b: float, c: float, d: float, e: float, f: float) -> np.ndarray:
    return np.array([[a, c, e], [b, d, f], [0.0, 0.0, 1.0]])


def _one(kind: str, v: list[float]) -> np.ndarray:
    if kind == "matrix":
        return _affine(*v)
    if kind == "translate":
        return _affine(1, 0, 0, 1, v[0], v[1] if len(v) > 1 else 0.0)
    if kind == "scale":
        return _affine(v[0], 0, 0, v[1] if len(v) > 1 else v[0], 0, 0)
    if kind == "skewX":
        return _affine(1, 0, math.tan(math.radians(v[0])), 1, 0, 0)
    if kind == "skewY":
        return _affine(1, math.tan(math.radians(v[0])), 0, 1, 0, 0)
    cos, sin = math.cos(math.radians(v[0])), math.sin(math.radians(v[0]))
    cx, cy = (v[1], v[2]) if len(v) == 3 else (0.0, 0.0)
    return _affine(cos, sin, -sin, cos, cx - cos * cx + sin * cy, cy - sin * cx - cos * cy)


def parse_transform(text: str | None) -> np.ndarray:
    """'translate(10,20) rotate(30 5 5)' → the matrix T·R; None or '' is the identity."""
    matrix = np.eye(3)
    if not text or not text.strip() or text.strip() == "none":
        return matrix
    pos = 0
    while pos < len(text):
        match = _ITEM.match(text, pos)
        if match is None:
            raise TrackError(f"bad transform {text!r} at {text[pos : pos + 20]!r}")
        kind, args = match.groups()
        values = [float(x) for x in re.findall(_NUMBER, args)]
        if len(values) not in _ARITY[kind] or not all(map(math.isfinite, values)):
            raise TrackError(f"bad transform {kind}({args})")
        matrix = matrix @ _one(kind, values)
        pos = match.end()
    return matrix
