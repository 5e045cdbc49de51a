"""A track: an exact centreline in metres (world frame, y up), a width, loop or road."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from tracks._arclength import LengthTable, length_table, params_at
from tracks._chain import Chain
from tracks._errors import TrackError
from tracks._profile import Profile, driving_profile
from tracks._segments import Segment

STEERING_COLUMNS = ("s", "x", "y", "heading", "steering_deg")
MAX_DETAIL_POINTS = 5000


def _positive(name: str, value: float) -> float:
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise TrackError(f"{name} must be a positive number of metres, got {value!r}")
    return float(value)


def check_sampling(
    spacing: float, wheelbase: float = 0.44, max_steer_deg: float = 26.0
) -> tuple[float, float, float]:
    """The sampling parameters, validated: positive spacing and wheelbase, 0 < δmax < 90°."""
    if not (isinstance(max_steer_deg, int | float) and 0 < max_steer_deg < 90):
        raise TrackError(f"max steering angle must be in (0, 90) degrees, got {max_steer_deg!r}")
    return _positive("spacing", spacing), _positive("wheelbase", wheelbase), float(max_steer_deg)


@dataclass(frozen=True, eq=False)
class Track:
    """Centreline segments in metres, world frame; built by `load_svg` or from segments.

    Zero-length segments are dropped on construction; their lengths are measured once, by
    adaptive Gauss–Legendre quadrature. Profiles are cached per (spacing, wheelbase, δmax).
    """

    name: str
    closed: bool
    width_m: float
    segments: tuple[Segment, ...]
    # (right, left) widths from the centreline at each segment's start and the last end, as a
    # centreline CSV gives them (None: width_m/2 each side); linear in s between junctions.
    side_widths: np.ndarray | None = None
    chain: Chain = field(init=False, repr=False)
    table: LengthTable = field(init=False, repr=False)
    _profiles: dict = field(init=False, repr=False, default_factory=dict)
    _targets: dict = field(init=False, repr=False, default_factory=dict)

    def __post_init__(self) -> None:
        _positive("width", self.width_m)
        chain = Chain(self.segments)
        table = length_table(chain.velocity, chain.count, breaks=chain.kinks())
        if not np.isfinite(table.length):
            raise TrackError(f"track {self.name!r} has non-finite geometry (a degenerate arc?)")
        keep = table.segment_lengths(chain.count) > 1e-12 * table.length
        if not keep.any():
            raise TrackError(f"track {self.name!r} has zero length")
        if not keep.all():
            object.__setattr__(
                self, "segments", tuple(np.asarray(self.segments, dtype=object)[keep])
            )
            if self.side_widths is not None:
                object.__setattr__(
                    self, "side_widths", self.side_widths[np.concatenate([[True], keep])]
                )
            chain = Chain(self.segments)
            table = length_table(chain.velocity, chain.count, breaks=chain.kinks())
        object.__setattr__(self, "chain", chain)
        object.__setattr__(self, "table", table)

    @property
    def length_m(self) -> float:
        return self.table.length

    def with_width(self, width_m: float) -> Track:
        """The same centreline at another, constant width (a scenario's ``track.width_m``)."""
        return replace(self, width_m=width_m, side_widths=None)

    def widths_at(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Widths to the right and to the left of the driving direction at arc lengths ``s``."""
        s = np.atleast_1d(s)
        if self.side_widths is None:
            half = np.full(s.shape, self.width_m / 2.0)
            return half, half
        junctions = np.concatenate([[0.0], np.cumsum(self.table.segment_lengths(
            self.chain.count))])
        return (np.interp(s, junctions, self.side_widths[:, 0]),
                np.interp(s, junctions, self.side_widths[:, 1]))

    def points_at(self, s: np.ndarray) -> np.ndarray:
        """World points (n, 2) at arc lengths ``s`` from the start (clipped to the track)."""
        idx, t = params_at(self.chain.velocity, self.table, np.atleast_1d(s))
        return self.chain.point(idx, t)

    def bbox(self) -> tuple[float, float, float, float]:
        """Exact (xmin, ymin, xmax, ymax) of the centreline: ends and axis extrema of segments."""
        pts = np.concatenate(
            [
                seg.point(np.concatenate([[0.0, 1.0], seg.extremum_params()]))
                for seg in self.segments
            ]
        )
        (xmin, ymin), (xmax, ymax) = pts.min(axis=0), pts.max(axis=0)
        return float(xmin), float(ymin), float(xmax), float(ymax)

    def sample(
        self, spacing: float = 0.02, wheelbase: float = 0.44, max_steer_deg: float = 26.0
    ) -> Profile:
        """Target points every ``spacing`` metres with heading, curvature and steering angle."""
        key = check_sampling(spacing, wheelbase, max_steer_deg)
        if key not in self._profiles:
            self._profiles[key] = driving_profile(
                self.chain,
                self.table,
                closed=self.closed,
                spacing=spacing,
                wheelbase=wheelbase,
                max_steer_deg=max_steer_deg,
            )
        return self._profiles[key]

    def boundaries(self, spacing: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
        """Left and right edges (each (N, 2)): the centreline offset along the normal by the
        widths to each side (`widths_at`; width/2 unless the track has side widths).

        Where the curvature radius is below the offset an edge folds over itself; use
        `region_rings` for the drivable area itself.
        """
        prof = self.sample(spacing)
        right, left = self.widths_at(prof.s)
        centre = np.column_stack([prof.x, prof.y])
        normal = np.column_stack([-np.sin(prof.heading), np.cos(prof.heading)])
        return centre + left[:, None] * normal, centre - right[:, None] * normal

    def detail_spacing(self) -> float:
        """A sampling step that shows the track's shape: 5 cm, finer on a narrow track (a
        quarter of its width), so a 30 cm track drawn in millimetres keeps its curves; but
        never more than `MAX_DETAIL_POINTS` samples, so a long track, or a scenario's bounds
        drawn as a hairline frame, stays light to draw and to plan in."""
        return max(min(0.05, self.width_m / 4.0), self.length_m / MAX_DETAIL_POINTS)

    def region_rings(self, spacing: float | None = None) -> list[np.ndarray]:
        """The drivable region as polygon rings (each (N, 2), not repeating its first point),
        sampled every ``spacing`` m (default `detail_spacing`).

        The sampled centreline is buffered by width/2 (flat ends, mitred joins), which stays
        right where the offset curves fold; with side widths the region is the union of the
        quadrilaterals between consecutive edge points. A loop gives [outer, inner], a road one
        ring; any point is drivable iff it is inside an odd number of rings.
        """
        import shapely

        spacing = spacing or self.detail_spacing()
        if self.side_widths is None:
            prof = self.sample(spacing)
            centre = np.column_stack([prof.x, prof.y])
            line = shapely.LinearRing(centre[:-1]) if self.closed else shapely.LineString(centre)
            region = line.buffer(self.width_m / 2.0, cap_style="flat", join_style="mitre")
        else:
            left, right = self.boundaries(spacing)
            quads = np.stack([left[:-1], left[1:], right[1:], right[:-1]], axis=1)
            pieces = shapely.make_valid(shapely.polygons(quads))  # folds: bow ties
            region = shapely.union_all(pieces[shapely.area(pieces) > 0])
        polygons = getattr(region, "geoms", [region])
        rings = [ring for poly in polygons for ring in (poly.exterior, *poly.interiors)]
        return [np.asarray(ring.coords)[:-1] for ring in rings]

    def steering_commands(
        self,
        x: float,
        y: float,
        heading: float,
        n: int = 10,
        spacing: float = 0.02,
        wheelbase: float = 0.44,
    ) -> np.ndarray:
        """The next ``n`` target points ahead of a pose, columns `STEERING_COLUMNS`.

        The pose is projected onto the nearest resampled point, where distance is charged
        width²·(1 − cos Δheading)/2 extra so that at a crossing or a hairpin the branch the car
        is driving along wins. Targets are the following resampled points (wrapping on a loop,
        repeating the end on a road) with the feed-forward steering δ = atan(L·κ) there.
        """
        table = self._targets.get((spacing, wheelbase))
        if table is None:
            table = self._target_table(spacing, wheelbase)
        dx, dy = table[:, 1] - x, table[:, 2] - y
        facing = table[:, 5] * math.cos(heading) + table[:, 6] * math.sin(heading)
        cost = dx * dx + dy * dy + (0.5 * self.width_m**2) * (1.0 - facing)
        nearest = int(np.argmin(cost))
        ahead = dx[nearest] * table[nearest, 5] + dy[nearest] * table[nearest, 6] > 0
        first = nearest if ahead else nearest + 1
        idx = np.arange(first, first + n)
        if self.closed:
            idx %= len(table)
        else:
            idx = np.minimum(idx, len(table) - 1)
        return table[idx, :5]

    def _target_table(self, spacing: float, wheelbase: float) -> np.ndarray:
        """Profile columns plus cos/sin of the heading, the loop's repeated end point dropped."""
        prof = self.sample(spacing, wheelbase)
        table = np.column_stack(
            [
                prof.s,
                prof.x,
                prof.y,
                prof.heading,
                prof.steering_deg,
                np.cos(prof.heading),
                np.sin(prof.heading),
            ]
        )
        table = table[:-1] if self.closed else table
        self._targets[(spacing, wheelbase)] = table
        return table

    def to_svg(self) -> str:
        """An Inkscape SVG (mm document, one layer, stroke width = track width) of this track."""
        from tracks._svg_export import track_to_svg

        return track_to_svg(self)
