"""The tracks shipped with Trackstar: Inkscape SVG files in tracks/library/, named by file stem.

Each file's track path has the library name as its id, so the name picks it out.
"""

from __future__ import annotations

from pathlib import Path

from tracks._errors import TrackError
from tracks._svg_import import load_svg
from tracks._track import Track

_DIR = Path(__file__).parent / "library"


def library_names() -> list[str]:
    """Names of the shipped tracks, sorted."""
    return sorted(p.stem for p in _DIR.glob("*.svg"))


def library_path(name: str) -> Path:
    """The SVG file of library track ``name`` (without .svg)."""
    path = _DIR / f"{name}.svg"
    if name not in library_names():
        raise TrackError(f"no library track {name!r}; choose from {', '.join(library_names())}")
    return path


def load_library_track(name: str) -> Track:
    """The library track ``name``, loaded like any SVG (its path's id is the name)."""
    return load_svg(library_path(name), path_id=name)
