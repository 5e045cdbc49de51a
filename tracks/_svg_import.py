"""Reading Inkscape SVG into tracks: the one place that knows about XML, px, viewBox and y-down.

Every path-like element that would be rendered is collected in document order with the product
of all its ancestors' transforms (``<use>`` clones included, ``display:none`` skipped). Its path
data goes through svgpathtools' parser, but transforms are applied here, exactly, to Bézier
control points and arc axes: svgpathtools 1.8.0's `transform` decides an arc's sweep flip by
the sign of a·d instead of det(M) and drops the ellipse's own rotation. The world frame is
world = diag(s, −s)·user, s = metres per user unit.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import defusedxml
import defusedxml.ElementTree as SafeET
import numpy as np

from tracks._errors import TrackError
from tracks._segments import Bezier, Segment, arc_from_endpoints, line
from tracks._shapes import SHAPE_TAGS, shape_path_data
from tracks._track import Track
from tracks._transforms import parse_transform
from tracks._units import document_unit_m, user_length

SVG = "{http://www.w3.org/2000/svg}"
XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
INKSCAPE_LABEL = "{http://www.inkscape.org/namespaces/inkscape}label"
_CONTAINERS = frozenset({"g", "svg", "a", "switch"})
_MAX_ELEMENTS = 20_000
_MAX_USE_DEPTH = 32
# Per document: each segment costs ~0.15 ms to measure, and one takes 1 to 7 numbers, so this
# bounds a load to a few seconds (counted without parsing, so small files stay fast).
_MAX_PATH_NUMBERS = 40_000
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")

Source = str | os.PathLike | bytes


@dataclass(frozen=True)
class _Element:
    """A rendered path-like element before its path data is parsed."""

    id: str | None
    label: str | None
    path_data: str
    matrix: np.ndarray  # 3×3, local user units → root user units
    stroke_width: float  # local user units


def _read(source: Source) -> tuple[bytes, str]:
    if isinstance(source, bytes | bytearray):
        return bytes(source), "<bytes>"
    path = Path(source)
    try:
        return path.read_bytes(), path.name
    except OSError as exc:
        raise TrackError(f"cannot read {path}: {exc.strerror or exc}") from None


def parse_document(source: Source) -> ET.Element:
    """The root <svg> element, parsed without DTDs, entities or external references."""
    data, name = _read(source)
    try:
        root = SafeET.fromstring(data, forbid_dtd=True)
    except defusedxml.DefusedXmlException as exc:
        raise TrackError(f"{name}: unsafe XML refused ({type(exc).__name__})") from None
    except ET.ParseError as exc:
        raise TrackError(f"{name}: malformed XML: {exc}") from None
    if root.tag != f"{SVG}svg":
        raise TrackError(f"{name}: not an SVG document (root element {root.tag!r})")
    return root


def _style(elem: ET.Element) -> dict[str, str]:
    """Presentation attributes overridden by the style attribute's declarations."""
    props = {
        k: elem.attrib[k] for k in ("display", "visibility", "stroke-width") if k in elem.attrib
    }
    for decl in elem.attrib.get("style", "").split(";"):
        key, sep, value = decl.partition(":")
        if sep:
            props[key.strip()] = value.strip()
    return props


def _translate(x: float, y: float) -> np.ndarray:
    return np.array([[1.0, 0.0, x], [0.0, 1.0, y], [0.0, 0.0, 1.0]])


class _Walker:
    """Depth-first, document-order collection of rendered path-like elements."""

    def __init__(self, root: ET.Element) -> None:
        self.by_id = {e.attrib["id"]: e for e in root.iter() if "id" in e.attrib}
        self.found: list[_Element] = []

    def walk(self, elem, matrix, inherited, clone=None, uses=()) -> None:
        if not elem.tag.startswith(SVG):
            return
        tag = elem.tag[len(SVG) :]
        props = {**inherited, **_style(elem)}
        if props.get("display") == "none":
            return
        props.pop("display", None)
        matrix = matrix @ parse_transform(elem.attrib.get("transform"))
        if tag == "use":
            self._use(elem, matrix, props, uses)
        elif tag in _CONTAINERS or (tag == "symbol" and clone is not None):
            for child in elem:
                self.walk(child, matrix, props, clone, uses)
        elif tag in SHAPE_TAGS and props.get("visibility", "visible") == "visible":
            self._shape(elem, tag, matrix, props, clone)

    def _use(self, elem, matrix, props, uses) -> None:
        href = elem.attrib.get(XLINK_HREF) or elem.attrib.get("href") or ""
        target = self.by_id.get(href.removeprefix("#"))
        if target is None or not href.startswith("#"):
            return
        if target in uses or len(uses) >= _MAX_USE_DEPTH:
            raise TrackError(f"<use> {elem.attrib.get('id')!r}: clone refers to itself")
        offset = _translate(user_length(elem.attrib.get("x")), user_length(elem.attrib.get("y")))
        self.walk(target, matrix @ offset, props, elem, (*uses, target))

    def _shape(self, elem, tag, matrix, props, clone) -> None:
        data = shape_path_data(tag, elem.attrib)
        if data is None:
            return
        if len(self.found) >= _MAX_ELEMENTS:
            raise TrackError(f"more than {_MAX_ELEMENTS} path-like elements")
        named = clone if clone is not None else elem
        self.found.append(
            _Element(
                id=named.attrib.get("id"),
                label=named.attrib.get(INKSCAPE_LABEL) or elem.attrib.get(INKSCAPE_LABEL),
                path_data=data,
                matrix=matrix,
                stroke_width=user_length(props.get("stroke-width"), default=1.0),
            )
        )


def collect_elements(root: ET.Element) -> list[_Element]:
    """Every rendered path-like element of the document, in document order."""
    walker = _Walker(root)
    walker.walk(root, np.eye(3), {})
    numbers = sum(len(_NUMBER.findall(elem.path_data)) for elem in walker.found)
    if numbers > _MAX_PATH_NUMBERS:
        raise TrackError(f"too many path segments: the path data holds {numbers} numbers, "
                         f"the limit is {_MAX_PATH_NUMBERS}")
    return walker.found


def _segments(elem: _Element) -> list[list[Segment]]:
    """The element's subpaths in its local user units (split where the pen jumps)."""
    from svgpathtools import Arc, Line, parse_path

    try:
        parsed = parse_path(elem.path_data)
    except (ValueError, IndexError, AssertionError, ZeroDivisionError) as exc:
        raise TrackError(
            f"element {elem.id!r}: bad path data: {exc or type(exc).__name__}"
        ) from None
    subpaths: list[list[Segment]] = []
    previous_end = None
    for seg in parsed:
        start, end = (
            np.array([seg.start.real, seg.start.imag]),
            np.array([seg.end.real, seg.end.imag]),
        )
        if isinstance(seg, Line):
            ours = line(start, end)
        elif isinstance(seg, Arc):
            ours = arc_from_endpoints(
                start,
                end,
                (seg.radius.real, seg.radius.imag),
                seg.rotation,
                seg.large_arc,
                seg.sweep,
            )
        else:
            ours = Bezier(np.array([[p.real, p.imag] for p in seg.bpoints()]))
        if previous_end is None or seg.start != previous_end:
            subpaths.append([])
        previous_end = seg.end
        if ours is not None:
            subpaths[-1].append(ours)
    return subpaths


def element_track(elem: _Element, unit_m: float) -> Track | None:
    """The element's longest subpath as a track in metres, world frame; None if it has none."""
    world = np.diag([unit_m, -unit_m, 1.0]) @ elem.matrix
    linear, offset = world[:2, :2], world[:2, 2]
    width = elem.stroke_width * math.sqrt(abs(np.linalg.det(linear)))
    if not width > 0:
        raise TrackError(f"element {elem.id!r}: stroke width must be positive, got {width}")
    best = None
    for sub in _segments(elem):
        segs = tuple(seg.transformed(linear, offset) for seg in sub)
        if not segs:
            continue
        gap = np.hypot(*(segs[-1].end - segs[0].start))
        extent = max(
            np.ptp(np.array([s.start for s in segs] + [segs[-1].end]), axis=0).max(), 1e-300
        )
        try:
            track = Track(
                name=elem.id or elem.label or "track",
                closed=bool(gap <= 1e-9 * extent),
                width_m=width,
                segments=segs,
            )
        except TrackError:
            continue
        if best is None or track.length_m > best.length_m:
            best = track
    return best


def _choose(elements: list[_Element], path_id: str) -> _Element:
    for key in ("id", "label"):
        for elem in elements:
            if getattr(elem, key) == path_id:
                return elem
    names = sorted({e.id or e.label for e in elements if e.id or e.label})
    shown = ", ".join(names[:12]) + (", …" if len(names) > 12 else "")
    raise TrackError(f"no path with id or label {path_id!r}; available: {shown or 'none'}")


def load_svg(
    path_or_bytes: Source,
    *,
    path_id: str | None = None,
    unit: str | None = None,
    width_m: float | None = None,
) -> Track:
    """The track drawn in an SVG: the element with id or inkscape:label ``path_id``, else the
    longest path. ``unit`` states what one user unit measures (default: from the document);
    ``width_m`` overrides the track width (default: the transformed stroke width).
    """
    root = parse_document(path_or_bytes)
    unit_m = document_unit_m(root.attrib, unit)
    elements = collect_elements(root)
    if path_id is not None:
        track = element_track(_choose(elements, path_id), unit_m)
        if track is None:
            raise TrackError(f"path {path_id!r} has zero length")
    else:
        tracks = [t for t in (element_track(e, unit_m) for e in elements) if t is not None]
        if not tracks:
            raise TrackError("the document has no path of positive length")
        track = max(tracks, key=lambda t: t.length_m)
    if width_m is not None:
        track = Track(
            name=track.name, closed=track.closed, width_m=width_m, segments=track.segments
        )
    return track


def inspect_svg(path_or_bytes: Source, *, unit: str | None = None) -> dict:
    """Every rendered path-like element with its length, box and width: `track inspect --json`."""
    root = parse_document(path_or_bytes)
    unit_m = document_unit_m(root.attrib, unit)
    paths = []
    for elem in collect_elements(root):
        track = element_track(elem, unit_m)
        if track is None:
            continue
        paths.append(
            {
                "id": elem.id,
                "label": elem.label,
                "closed": track.closed,
                "length_m": track.length_m,
                "length_user": track.length_m / unit_m,
                "bbox_m": list(track.bbox()),
                "width_m": track.width_m,
            }
        )
    return {"unit_m": unit_m, "paths": paths}
