"""Writing a track as an Inkscape SVG: mm document, one layer, the centreline with its width.

Coordinates are written in the shortest form that reads back to the same float, and arcs are
cut into pieces of at most 90°: the endpoint form of an SVG arc is ill-conditioned near 180°
(the centre moves with the square root of a rounding error), so short pieces keep the round
trip within 1e-9 m.
"""

from __future__ import annotations

import math
import re
from xml.sax.saxutils import quoteattr

import numpy as np

from tracks._segments import Bezier, EllipticArc, Segment, arc_to_svg

_MM = 0.001
_COMMANDS = {2: "L", 3: "Q", 4: "C"}


def _num(value: float) -> str:
    return repr(float(value))


def _pt(p: np.ndarray) -> str:
    return f"{_num(p[0])},{_num(p[1])}"


def _arc_pieces(arc: EllipticArc) -> list[EllipticArc]:
    n = max(1, math.ceil(abs(arc.dtheta) / (math.pi / 2) - 1e-9))
    step = arc.dtheta / n
    return [EllipticArc(arc.center, arc.axes, arc.theta0 + k * step, step) for k in range(n)]


def _command(seg: Segment) -> str:
    if isinstance(seg, Bezier):
        return _COMMANDS[len(seg.ctrl)] + " " + " ".join(_pt(p) for p in seg.ctrl[1:])
    parts = []
    for piece in _arc_pieces(seg):
        rx, ry, rotation, large, sweep = arc_to_svg(piece)
        parts.append(
            f"A {_num(rx)},{_num(ry)} {_num(rotation)} {int(large)} {int(sweep)} {_pt(piece.end)}"
        )
    return " ".join(parts)


def path_data(segments: tuple[Segment, ...], closed: bool) -> str:
    """SVG path data for segments already in SVG user coordinates."""
    parts = [f"M {_pt(segments[0].start)}", *(_command(seg) for seg in segments)]
    return " ".join(parts + (["Z"] if closed else []))


def track_to_svg(track) -> str:
    """The SVG text; one user unit is 1 mm, so Inkscape shows the track at its true size."""
    to_user = np.diag([1 / _MM, -1 / _MM])
    segments = tuple(seg.transformed(to_user, np.zeros(2)) for seg in track.segments)
    xmin, ymin, xmax, ymax = track.bbox()
    margin = track.width_m / 2 + 0.05 * max(xmax - xmin, ymax - ymin, track.width_m)
    left, top = (xmin - margin) / _MM, -(ymax + margin) / _MM
    width, height = (xmax - xmin + 2 * margin) / _MM, (ymax - ymin + 2 * margin) / _MM
    ident = re.sub(r"[^A-Za-z0-9_.-]", "_", track.name) or "track"
    if not re.match(r"[A-Za-z_]", ident):
        ident = "track_" + ident
    stroke = f"fill:none;stroke:#4d4d4d;stroke-opacity:0.6;stroke-width:{_num(track.width_m / _MM)}"
    return f"""<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<svg
   width="{width:.6f}mm"
   height="{height:.6f}mm"
   viewBox="{_num(left)} {_num(top)} {width:.6f} {height:.6f}"
   version="1.1"
   id="svg1"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
   xmlns="http://www.w3.org/2000/svg"
   xmlns:svg="http://www.w3.org/2000/svg">
  <sodipodi:namedview
     id="namedview1"
     inkscape:document-units="mm" />
  <g
     inkscape:groupmode="layer"
     inkscape:label="Track"
     id="layer1">
    <path
       id={quoteattr(ident)}
       inkscape:label={quoteattr(track.name)}
       style="{stroke}"
       d="{path_data(segments, track.closed)}" />
  </g>
</svg>
"""
