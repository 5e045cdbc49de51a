"""Tracks: Inkscape SVG and centreline CSV import and export, exact Bézier/arc geometry,
driving profiles, racelines.

Everything is in SI units in the world frame (x right, y up, metres, radians); SVG units and the
y-flip exist only in the import/export modules.
"""

from tracks._bezier import de_casteljau, length_bounds, split
from tracks._centerline_csv import centerline_csv, read_centerline_csv
from tracks._errors import TrackError
from tracks._library import library_names, library_path, load_library_track
from tracks._load import inspect_track, is_svg, load_track
from tracks._profile import Profile
from tracks._raceline import Limits, path_rows, raceline_csv, raceline_rows, speed_profile
from tracks._segments import Bezier, EllipticArc, arc_from_endpoints, line
from tracks._svg_import import inspect_svg, load_svg
from tracks._track import STEERING_COLUMNS, Track, check_sampling
from tracks._units import UNIT_CHOICES

__all__ = [
    "STEERING_COLUMNS",
    "UNIT_CHOICES",
    "Bezier",
    "EllipticArc",
    "Limits",
    "Profile",
    "Track",
    "TrackError",
    "arc_from_endpoints",
    "centerline_csv",
    "check_sampling",
    "de_casteljau",
    "inspect_svg",
    "inspect_track",
    "is_svg",
    "length_bounds",
    "library_names",
    "library_path",
    "line",
    "load_library_track",
    "load_svg",
    "load_track",
    "path_rows",
    "raceline_csv",
    "raceline_rows",
    "read_centerline_csv",
    "speed_profile",
    "split",
]
