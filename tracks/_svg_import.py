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
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import defusedxml
import numpy as np
from defusedxml.ElementTree import DefusedXMLParser

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
DEFAULT_WIDTH_M = 0.5  # a track drawn with a zero stroke width (a hairline) gets this width
_MAX_USE_DEPTH = 32
# Elements walked, a <use> clone's elements counted each time they are shown: clones of clones
# fan out (two per level, 22 levels: 4 million walks from 1.2 KB), so the walk itself is bounded.
_MAX_WALKED = 50_000
_MAX_NESTING = 200  # elements inside elements; editors write a few levels, Python's stack ~1000
# Per document: each segment costs ~0.15 ms to measure, and one takes 1 to 7 numbers, so this
# bounds a load to a few seconds (counted without parsing, so small files stay fast).
_MAX_PATH_NUMBERS = 40_000
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")

Source = str | os.PathLike | bytes


@dataclass(frozen=True)
class _Element:
    """A rendered path-like element before its path data is parsed."""

    tag: str
    id: str | None
    label: str | None
    path_data: str
    matrix: np.ndarray  # 3×3, local user units → root user units
    stroke_width: float  # local user units


def read_source(source: Source) -> tuple[bytes, str]:
    if isinstance(source, bytes | bytearray):
        return bytes(source), "<bytes>"
    path = Path(source)
    try:
        return path.read_bytes(), path.name
    except OSError as exc:
        raise TrackError(f"cannot read {path}: {exc.strerror or exc}") from None


class _SafeParser(DefusedXMLParser):
    """defusedxml with a bare DOCTYPE allowed: editors write the W3C SVG 1.1 declaration, which
    names an external DTD that expat never loads; an internal subset (where entities would be
    declared) is still refused, as are entity declarations and external references."""

    def defused_start_doctype_decl(self, name, sysid, pubid, has_internal_subset):
        if has_internal_subset:
            super().defused_start_doctype_decl(name, sysid, pubid, has_internal_subset)


class _CountingBuilder(ET.TreeBuilder):
    """Stops the parse at the element after ``_MAX_WALKED``: no document needs more, and a few
    megabytes of empty groups would otherwise take seconds to build."""

    def __init__(self, name: str) -> None:
        super().__init__()
        self.name, self.count = name, 0

    def start(self, tag, attrs):
        self.count += 1
        if self.count > _MAX_WALKED:
            raise TrackError(f"{self.name}: more than {_MAX_WALKED} elements")
        return super().start(tag, attrs)


def parse_document(source: Source) -> ET.Element:
    """The root <svg> element, parsed without DTD subsets, entities or external references."""
    data, name = read_source(source)
    try:
        parser = _SafeParser(target=_CountingBuilder(name), forbid_dtd=True)
        parser.feed(data)
        root = parser.close()
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
        self.walked = 0
        self.numbers = 0  # of the path data found, clones counted each time

    def walk(self, elem, matrix, inherited, clone=None, uses=(), depth=0) -> None:
        if not elem.tag.startswith(SVG):
            return
        self.walked += 1
        if self.walked > _MAX_WALKED:
            raise TrackError(f"the document shows more than {_MAX_WALKED} elements (<use> "
                             f"clones counted each time they are shown)")
        if depth > _MAX_NESTING:
            raise TrackError(f"elements nested more than {_MAX_NESTING} deep")
        tag = elem.tag[len(SVG) :]
        props = {**inherited, **_style(elem)}
        if props.get("display") == "none":
            return
        props.pop("display", None)
        if "transform" in elem.attrib:
            matrix = matrix @ parse_transform(elem.attrib["transform"])
        if tag == "use":
            self._use(elem, matrix, props, uses, depth)
        elif tag in _CONTAINERS or (tag == "symbol" and clone is not None):
            for child in elem:
                self.walk(child, matrix, props, clone, uses, depth + 1)
        elif tag in SHAPE_TAGS and props.get("visibility", "visible") == "visible":
            self._shape(elem, tag, matrix, props, clone)

    def _use(self, elem, matrix, props, uses, depth) -> None:
        href = elem.attrib.get(XLINK_HREF) or elem.attrib.get("href") or ""
        target = self.by_id.get(href.removeprefix("#"))
        if target is None or not href.startswith("#"):
            return
        if target in uses or len(uses) >= _MAX_USE_DEPTH:
            raise TrackError(f"<use> {elem.attrib.get('id')!r}: clone refers to itself")
        offset = _translate(user_length(elem.attrib.get("x")), user_length(elem.attrib.get("y")))
        self.walk(target, matrix @ offset, props, elem, (*uses, target), depth + 1)

    def _shape(self, elem, tag, matrix, props, clone) -> None:
        data = shape_path_data(tag, elem.attrib)
        if data is None:
            return
        if len(self.found) >= _MAX_ELEMENTS:
            raise TrackError(f"more than {_MAX_ELEMENTS} path-like elements")
        self.numbers += len(_NUMBER.findall(data))
        if self.numbers > _MAX_PATH_NUMBERS:
            raise TrackError(f"too many path segments: the path data holds more than "
                             f"{_MAX_PATH_NUMBERS} numbers")
        named = clone if clone is not None else elem
        self.found.append(
            _Element(
                tag=tag,
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
    return walker.found


def _path_parser():
    """svgpathtools' path parser, imported without SciPy: svgpathtools imports scipy.integrate
    (0.7 s, most of a track's first load) for arc lengths by quadrature, which it skips
    without SciPy and which we do not use (tracks/_arclength.py measures our segments)."""
    if "svgpathtools" not in sys.modules and "scipy.integrate" not in sys.modules:
        sys.modules["scipy.integrate"] = None  # importing it raises ImportError now
        try:
            import svgpathtools  # noqa: F401
        finally:
            del sys.modules["scipy.integrate"]
    from svgpathtools import Arc, Line, parse_path

    return Arc, Line, parse_path


def _segments(elem: _Element) -> list[list[Segment]]:
    """The element's subpaths in its local user units (split where the pen jumps)."""
    Arc, Line, parse_path = _path_parser()

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


@dataclass(frozen=True)
class _Entry:
    """A listed element: its selector, its subpaths as tracks (None: zero length) and width."""

    selector: str
    elem: _Element
    subpaths: list[Track | None]
    width_m: float | None  # None: the stroke width is zero or invalid

    @property
    def track(self) -> Track:
        """What selecting the element gives: its longest subpath."""
        return max((t for t in self.subpaths if t is not None), key=lambda t: t.length_m)


def _subpath_tracks(elem: _Element, unit_m: float, name: str, width_m: float) -> list:
    """The element's subpaths as tracks in metres, world frame (None where of zero length)."""
    world = np.diag([unit_m, -unit_m, 1.0]) @ elem.matrix
    linear, offset = world[:2, :2], world[:2, 2]
    out: list[Track | None] = []
    for sub in _segments(elem):
        segs = tuple(seg.transformed(linear, offset) for seg in sub)
        gap = np.hypot(*(segs[-1].end - segs[0].start)) if segs else 0.0
        # The size of the curve itself, not of its ends: one segment out and back is a loop.
        extent = max(np.ptp(np.vstack([s.point(np.linspace(0.0, 1.0, 5)) for s in segs]),
                            axis=0).max(), 1e-300) if segs else 0.0
        try:
            out.append(Track(name=name, closed=bool(gap <= 1e-9 * extent), width_m=width_m,
                             segments=segs))
        except TrackError:
            out.append(None)
    return out


def _selectors(elements: list[_Element]) -> list[str]:
    """A name per element, unique in the document: its id, else its label, else ``TAG-K``
    (the K-th rendered path-like element, from 1, e.g. ``path-3``), so that id-less drawings
    can be chosen too. Cheap: no path data is parsed."""
    ids = {e.id for e in elements if e.id}
    names: list[str] = []
    for k, elem in enumerate(elements, start=1):
        label = elem.label if elem.label not in ids else None  # never another element's id
        names.append(next((n for n in (elem.id, label, f"{elem.tag}-{k}")
                           if n and n not in names), f"#{k}"))
    return names


def _entry(elem: _Element, selector: str, unit_m: float) -> _Entry | None:
    """The element measured; None if no subpath has positive length."""
    det = abs(np.linalg.det(elem.matrix[:2, :2])) * unit_m**2
    width = elem.stroke_width * math.sqrt(det)
    width = width if math.isfinite(width) and width > 0 else None
    subpaths = _subpath_tracks(elem, unit_m, selector, width or DEFAULT_WIDTH_M)
    return _Entry(selector, elem, subpaths, width) if any(subpaths) else None


def _entries(elements: list[_Element], unit_m: float) -> list[_Entry]:
    """Every element with a subpath of positive length, in document order."""
    found = (_entry(e, n, unit_m) for e, n in zip(elements, _selectors(elements)))
    return [entry for entry in found if entry is not None]


_SUBPATH = re.compile(r"(.*):(\d+)")


def _choose(elements: list[_Element], unit_m: float, path_id: str) -> Track:
    """The track a selector names: an element's selector, id or label (its longest subpath),
    or ``NAME:K`` for its K-th subpath (from 0). Only the chosen element is parsed."""
    named = list(zip(elements, _selectors(elements)))
    match = _SUBPATH.fullmatch(path_id)
    keys = [(path_id, None)] + ([(match.group(1), int(match.group(2)))] if match else [])
    for name, k in keys:
        for lookup in (lambda e, n: n, lambda e, n: e.id, lambda e, n: e.label):
            elem, selector = next(((e, n) for e, n in named if lookup(e, n) == name),
                                  (None, None))
            if elem is None:
                continue
            entry = _entry(elem, selector, unit_m)
            if entry is None:
                raise TrackError(f"path {path_id!r} has zero length")
            if k is None:
                return entry.track
            if k < len(entry.subpaths) and entry.subpaths[k] is not None:
                return entry.subpaths[k]
            raise TrackError(f"path {name!r} has no subpath {k} of positive length "
                             f"(it has {len(entry.subpaths)} subpaths, from 0)")
    shown = ", ".join(n for _, n in named[:12]) + (", …" if len(named) > 12 else "")
    raise TrackError(f"no path with id or label {path_id!r}; available: {shown or 'none'}")


def load_svg(
    path_or_bytes: Source,
    *,
    path_id: str | None = None,
    unit: str | None = None,
    width_m: float | None = None,
) -> Track:
    """The track drawn in an SVG: the element that ``path_id`` selects (see `inspect_svg`),
    else the longest path. ``unit`` states what one user unit measures (default: from the
    document); ``width_m`` overrides the track width (default: the transformed stroke width,
    `DEFAULT_WIDTH_M` where that is zero).
    """
    root = parse_document(path_or_bytes)
    unit_m = document_unit_m(root.attrib, unit)
    elements = collect_elements(root)
    if path_id is not None:
        track = _choose(elements, unit_m, path_id)
    elif entries := _entries(elements, unit_m):
        track = max((e.track for e in entries), key=lambda t: t.length_m)
    else:
        raise TrackError("the document has no path of positive length")
    return track if width_m is None else track.with_width(width_m)


def _measures(track: Track, unit_m: float) -> dict:
    return {"closed": track.closed, "length_m": track.length_m,
            "length_user": track.length_m / unit_m, "bbox_m": list(track.bbox())}


def inspect_svg(path_or_bytes: Source, *, unit: str | None = None) -> dict:
    """Every rendered path-like element, `track inspect --json`: its selector (what ``path_id``
    takes), whole length (all subpaths, as a browser's getTotalLength), box and width (None
    where the stroke width is zero); an element with several subpaths is followed by one entry
    per subpath, selector ``NAME:K``.
    """
    root = parse_document(path_or_bytes)
    unit_m = document_unit_m(root.attrib, unit)
    paths = []
    for entry in _entries(collect_elements(root), unit_m):
        parts = [t for t in entry.subpaths if t is not None]
        boxes = np.array([t.bbox() for t in parts])
        base = {"selector": entry.selector, "id": entry.elem.id, "label": entry.elem.label,
                "subpath": None, "width_m": entry.width_m}
        length = sum(t.length_m for t in parts)
        paths.append({**base, "closed": entry.track.closed, "length_m": length,
                      "length_user": length / unit_m,
                      "bbox_m": [*boxes[:, :2].min(axis=0).tolist(),
                                 *boxes[:, 2:].max(axis=0).tolist()]})
        if len(entry.subpaths) > 1:
            paths += [{**base, "selector": f"{entry.selector}:{k}", "subpath": k,
                       **_measures(t, unit_m)}
                      for k, t in enumerate(entry.subpaths) if t is not None]
    return {"unit_m": unit_m, "paths": paths}
