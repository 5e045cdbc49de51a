"""One door for every track file: an Inkscape SVG or a centreline CSV.

Callers (CLI, REST, scenarios, studio) pass bytes or a path and never branch on the format: the
file name's suffix decides (so a broken .svg is reported as XML), else the content (an XML
document starts with "<", a CSV never does).
``closed`` is the CSV's choice (default: a loop); an SVG path decides for itself, so giving it
one that disagrees with the drawing is an error rather than a silent no-op.
"""

from __future__ import annotations

from pathlib import Path

from tracks._centerline_csv import read_centerline_csv
from tracks._errors import TrackError
from tracks._svg_import import Source, inspect_svg, load_svg, read_source
from tracks._track import Track


def is_svg(data: bytes, filename: str | None = None) -> bool:
    """True for an SVG (or something that is to fail as one), False for a centreline CSV."""
    suffix = Path(filename or "").suffix.lower()
    if suffix in (".svg", ".csv"):
        return suffix == ".svg"
    return data.lstrip(b"\xef\xbb\xbf \t\r\n").startswith(b"<")


def _read(source: Source, filename: str | None) -> tuple[bytes, str | None]:
    data, name = read_source(source)
    return data, filename or (None if isinstance(source, bytes | bytearray) else name)


def _csv_track(data: bytes, filename: str | None, path_id, unit, closed) -> Track:
    name = Path(filename).stem if filename else "centerline"
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
    filename: str | None = None,
) -> Track:
    """The track in an SVG (`load_svg`) or a centreline CSV (`read_centerline_csv`);
    ``filename`` names bytes (its suffix picks the format, its stem names a CSV's track)."""
    data, filename = _read(source, filename)
    if not is_svg(data, filename):
        return _csv_track(data, filename, path_id, unit, closed)
    track = load_svg(data, path_id=path_id, unit=unit)
    if closed is not None and closed != track.closed:
        kind = "a loop" if track.closed else "a road"
        raise TrackError(f"path {track.name!r} is {kind} in the SVG; choosing loop or road "
                         f"(closed, --open) is for centreline CSVs")
    return track


def inspect_track(source: Source, *, unit: str | None = None, closed: bool | None = None,
                  filename: str | None = None) -> dict:
    """`inspect_svg`'s report with its ``format`` ("svg" or "csv"); a CSV gives one entry (its
    width: the narrowest total width) in metres."""
    data, filename = _read(source, filename)
    if is_svg(data, filename):
        return {"format": "svg", **inspect_svg(data, unit=unit)}
    track = _csv_track(data, filename, None, unit, closed)
    return {"format": "csv", "unit_m": 1.0, "paths": [{
        "selector": track.name, "id": None, "label": None, "subpath": None,
        "closed": track.closed, "length_m": track.length_m, "length_user": track.length_m,
        "bbox_m": list(track.bbox()), "width_m": track.width_m}]}
