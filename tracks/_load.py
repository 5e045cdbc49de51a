"""One door for every track file: an Inkscape SVG or a centreline CSV, told apart by content.

Callers (CLI, REST, scenarios, studio) pass bytes or a path and never branch on the format.
``closed`` is the CSV's choice (default: a loop); an SVG path decides for itself, so giving it
one that disagrees with the drawing is an error rather than a silent no-op.
"""

from __future__ import annotations

from pathlib import Path

from tracks._centerline_csv import read_centerline_csv
from tracks._errors import TrackError
from tracks._svg_import import Source, inspect_svg, load_svg, read_source
from tracks._track import Track


def is_svg(data: bytes) -> bool:
    """True for XML (an SVG, or something that is to fail as one), False for a CSV."""
    return data.lstrip(b"\xef\xbb\xbf \t\r\n").startswith(b"<")


def _csv_name(source: Source) -> str:
    return "centerline" if isinstance(source, bytes | bytearray) else Path(source).stem


def _csv_track(data: bytes, source: Source, path_id, unit, closed) -> Track:
    name = _csv_name(source)
    if unit is not None:
        raise TrackError(f"{name}: a centreline CSV is in metres; 'unit' is for SVG files")
    if path_id not in (None, name):
        raise TrackError(f"{name}: a centreline CSV holds one track; 'path' is for SVG files")
    return read_centerline_csv(data, closed=True if closed is None else closed, name=name)


def load_track(
    source: Source,
    *,
    path_id: str | None = None,
    unit: str | None = None,
    closed: bool | None = None,
) -> Track:
    """The track in an SVG (`load_svg`) or a centreline CSV (`read_centerline_csv`)."""
    data, _ = read_source(source)
    if not is_svg(data):
        return _csv_track(data, source, path_id, unit, closed)
    track = load_svg(data, path_id=path_id, unit=unit)
    if closed is not None and closed != track.closed:
        kind = "a loop" if track.closed else "a road"
        raise TrackError(f"path {track.name!r} is {kind} in the SVG; choosing loop or road "
                         f"(closed, --open) is for centreline CSVs")
    return track


def inspect_track(source: Source, *, unit: str | None = None, closed: bool | None = None) -> dict:
    """`inspect_svg`'s report; a CSV gives one entry (its width: the narrowest total width)."""
    data, _ = read_source(source)
    if is_svg(data):
        return inspect_svg(data, unit=unit)
    track = _csv_track(data, source, None, unit, closed)
    return {"unit_m": 1.0, "paths": [{
        "selector": track.name, "id": None, "label": None, "subpath": None,
        "closed": track.closed, "length_m": track.length_m, "length_user": track.length_m,
        "bbox_m": list(track.bbox()), "width_m": track.width_m}]}
