"""Tracks that are not in the library (uploaded SVG, drawn): their region as plain obstacles.

The scenario schema names only library tracks, so a custom track becomes ``bounds`` plus
polygons covering everything outside the drivable region — the way the shared minimal format
writes tracks (see oval_track.json). Polygons have no holes there, so pieces with holes are cut
in two through each hole.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

import tracks

__all__ = ["custom_scenario", "outside_polygons", "track_from_points"]


def _without_holes(poly: shapely.Polygon) -> list[shapely.Polygon]:
    if not poly.interiors:
        return [poly]
    cx = shapely.Polygon(poly.interiors[0]).centroid.x
    xmin, ymin, xmax, ymax = poly.bounds
    left = poly.intersection(shapely.box(xmin - 1, ymin - 1, cx, ymax + 1))
    right = poly.intersection(shapely.box(cx, ymin - 1, xmax + 1, ymax + 1))
    return [q for half in (left, right) for p in shapely.get_parts(half)
            if isinstance(p, shapely.Polygon) and p.area > 1e-9 for q in _without_holes(p)]


def outside_polygons(track: tracks.Track, margin: float = 0.3):
    """(bounds, polygon point lists) covering the bounds minus the track's drivable region."""
    rings = track.region_rings()
    region = shapely.Polygon(rings[0], rings[1:]) if track.closed else shapely.Polygon(rings[0])
    region = region.buffer(0)
    xmin, ymin, xmax, ymax = region.bounds
    bounds = (xmin - margin, ymin - margin, xmax + margin, ymax + margin)
    outside = shapely.box(*bounds).difference(region).simplify(0.005)
    pieces = [q for p in shapely.get_parts(outside) if isinstance(p, shapely.Polygon)
              for q in _without_holes(p)]
    polys = [np.asarray(p.exterior.coords)[:-1].round(4).tolist() for p in pieces]
    return [float(v) for v in bounds], polys


def custom_scenario(track: tracks.Track, name: str) -> tuple[dict, list[dict]]:
    """A scenario for a custom track (start at s = 0, goal 3/4 lap or 90 % along) and the
    region's obstacles, kept apart so the studio draws them as track, not as obstacles."""
    from app.studio._scenario import goal_fraction, pose_at

    prof = track.sample(spacing=0.05)
    start_s = 0.0 if track.closed else 0.05 * track.length_m
    bounds, polys = outside_polygons(track)
    region = [{"type": "polygon", "points": p} for p in polys]
    scenario = {
        "name": name, "bounds": bounds,
        "start": pose_at(prof, start_s),
        "goal": pose_at(prof, goal_fraction(track.closed) * track.length_m),
        "goal_tolerance": {"position": min(0.25, track.width_m / 2), "heading_deg": 30},
        "obstacles": [],
    }
    return scenario, region


def track_from_points(points: list[tuple[float, float]], width: float, closed: bool,
                      name: str = "drawn") -> tracks.Track:
    """A smooth track through clicked points: Catmull-Rom as cubic Béziers (C1, through every
    point), so the drawn shape is what the car must follow."""
    p = np.asarray(points, dtype=float)
    if len(p) < (3 if closed else 2):
        raise ValueError(f"draw at least {3 if closed else 2} points")
    n = len(p)
    segs = []
    for i in range(n if closed else n - 1):
        p0 = p[(i - 1) % n] if (closed or i > 0) else p[i]
        p1, p2 = p[i], p[(i + 1) % n]
        p3 = p[(i + 2) % n] if (closed or i + 2 < n) else p2
        c1, c2 = p1 + (p2 - p0) / 6.0, p2 - (p3 - p1) / 6.0
        if math.dist(p1, p2) > 1e-9:
            segs.append(tracks.Bezier(np.array([p1, c1, c2, p2])))
    return tracks.Track(name=name, closed=closed, width_m=width, segments=tuple(segs))
