"""Tracks: Inkscape SVG import and export, exact Bézier/arc geometry, driving profiles.

Everything is in SI units in the world frame (x right, y up, metres, radians); SVG units and the
y-flip exist only in the import/export modules.
"""

from tracks._bezier import de_casteljau, length_bounds, split
from tracks._errors import TrackError
from tracks._library import library_names, library_path, load_library_track
from tracks._profile import Profile
from tracks._segments import Bezier, EllipticArc, arc_from_endpoints, line
from tracks._svg_import import inspect_svg, load_svg
from tracks._track import STEERING_COLUMNS, Track, check_sampling
from tracks._units import UNIT_CHOICES

__all__ = [
    "STEERING_COLUMNS",
    "UNIT_CHOICES",
    "Bezier",
    "EllipticArc",
    "Profile",
    "Track",
    "TrackError",
    "arc_from_endpoints",
    "check_sampling",
    "de_casteljau",
    "inspect_svg",
    "length_bounds",
    "library_names",
    "library_path",
    "line",
    "load_library_track",
    "load_svg",
    "split",
]
