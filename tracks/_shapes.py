"""SVG basic shapes (rect, circle, ellipse, line, polyline, polygon) as equivalent path data.

Written as the SVG spec defines each shape's path, so arcs stay arcs and one parser serves all.
Shapes with a zero or negative size are not rendered (None), as in a browser.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from tracks._errors import TrackError
from tracks._units import user_length

Attr = Callable[[str], float]


def _rect(a: Attr) -> str | None:
    x, y, w, h = a("x"), a("y"), a("width"), a("height")
    if w <= 0 or h <= 0:
        return None
    rx, ry = a("rx"), a("ry")
    rx, ry = (rx or ry), (ry or rx)
    rx, ry = min(rx, w / 2), min(ry, h / 2)
    if rx <= 0 or ry <= 0:
        return f"M {x},{y} H {x + w} V {y + h} H {x} Z"
    arc = f"A {rx},{ry} 0 0 1"
    return (
        f"M {x + rx},{y} H {x + w - rx} {arc} {x + w},{y + ry} V {y + h - ry} "
        f"{arc} {x + w - rx},{y + h} H {x + rx} {arc} {x},{y + h - ry} V {y + ry} "
        f"{arc} {x + rx},{y} Z"
    )


def _ellipse_path(cx: float, cy: float, rx: float, ry: float) -> str | None:
    if rx <= 0 or ry <= 0:
        return None
    arc = f"A {rx},{ry} 0 0 1"
    return (
        f"M {cx + rx},{cy} {arc} {cx},{cy + ry} {arc} {cx - rx},{cy} "
        f"{arc} {cx},{cy - ry} {arc} {cx + rx},{cy} Z"
    )


def _points(text: str | None) -> list[str]:
    numbers = re.findall(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", text or "")
    if len(numbers) % 2:
        raise TrackError(f"odd number of coordinates in points {text!r}")
    return [f"{numbers[i]},{numbers[i + 1]}" for i in range(0, len(numbers), 2)]


def _poly(attrib: dict[str, str], close: bool) -> str | None:
    pts = _points(attrib.get("points"))
    if len(pts) < 2:
        return None
    return "M " + " L ".join(pts) + (" Z" if close else "")


def shape_path_data(tag: str, attrib: dict[str, str]) -> str | None:
    """Path data for element ``tag`` with attributes ``attrib``; None if it draws nothing."""

    def a(name: str) -> float:
        return user_length(attrib.get(name))

    if tag == "path":
        return attrib.get("d") or None
    if tag == "rect":
        return _rect(a)
    if tag == "circle":
        return _ellipse_path(a("cx"), a("cy"), a("r"), a("r"))
    if tag == "ellipse":
        return _ellipse_path(a("cx"), a("cy"), a("rx"), a("ry"))
    if tag == "line":
        return f"M {a('x1')},{a('y1')} L {a('x2')},{a('y2')}"
    if tag in ("polyline", "polygon"):
        return _poly(attrib, close=tag == "polygon")
    return None


SHAPE_TAGS = frozenset({"path", "rect", "circle", "ellipse", "line", "polyline", "polygon"})
