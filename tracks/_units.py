"""Physical lengths in SVG: CSS absolute units, and what one user unit of a document measures."""

from __future__ import annotations

import re

from tracks._errors import TrackError

METRES_PER_UNIT = {
    "m": 1.0,
    "cm": 0.01,
    "mm": 0.001,
    "q": 0.00025,
    "in": 0.0254,
    "pt": 0.0254 / 72,
    "pc": 0.0254 / 6,
    "px": 0.0254 / 96,
}
UNIT_CHOICES = ("m", "cm", "mm", "in", "pt", "pc", "px")

_LENGTH = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-zA-Z%]*)\s*$")


def metres_per(unit: str) -> float:
    """Metres in one ``unit`` (m, cm, mm, in, pt, pc, px); a clear error for anything else."""
    try:
        return METRES_PER_UNIT[unit.lower()]
    except KeyError:
        raise TrackError(f"unknown unit {unit!r}; use one of {', '.join(UNIT_CHOICES)}") from None


def parse_length(text: str) -> tuple[float, str]:
    """'210mm' → (210.0, 'mm'); a bare number is in px; '%' is returned as such."""
    match = _LENGTH.match(text)
    if not match:
        raise TrackError(f"not a length: {text!r}")
    return float(match.group(1)), (match.group(2) or "px").lower()


def user_length(text: str | None, default: float = 0.0) -> float:
    """An attribute length in user units (px-based CSS units: 1in = 96 user units)."""
    if text is None or not text.strip():
        return default
    value, unit = parse_length(text)
    if unit == "%":
        raise TrackError(f"percentage lengths are not supported: {text!r}")
    return value * metres_per(unit) / METRES_PER_UNIT["px"]


def document_unit_m(attrib: dict[str, str], unit: str | None = None) -> float:
    """Metres per user unit of the root coordinate system (the viewBox).

    ``unit`` overrides the document. Otherwise width/height with a unit over the viewBox size
    give the scale (preserveAspectRatio meet → the smaller, slice → the larger); without a
    viewBox, or without a physical width, a user unit is a CSS px (1/96 in).
    """
    if unit is not None:
        return metres_per(unit)
    px = METRES_PER_UNIT["px"]
    box = attrib.get("viewBox")
    if not box:
        return px
    try:
        _, _, box_w, box_h = (float(v) for v in box.replace(",", " ").split())
    except ValueError:
        raise TrackError(f"bad viewBox {box!r}") from None
    if box_w <= 0 or box_h <= 0:
        raise TrackError(f"viewBox must have a positive size, got {box!r}")
    scales = []
    for name, size in (("width", box_w), ("height", box_h)):
        value, length_unit = parse_length(attrib.get(name) or f"{size}px")
        if length_unit != "%":
            scales.append(value * metres_per(length_unit) / size)
    if not scales:
        return px
    aspect = attrib.get("preserveAspectRatio", "").split()
    if (
        aspect[:1] == ["none"]
        and len(scales) == 2
        and abs(scales[0] - scales[1]) > 1e-9 * scales[0]
    ):
        raise TrackError("width/height and viewBox scale x and y differently; pass --unit")
    return max(scales) if aspect[1:] == ["slice"] else min(scales)
