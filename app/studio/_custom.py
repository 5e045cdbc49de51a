"""Tracks that are not in the library (uploaded SVG or CSV, drawn): scenarios that embed them,
and the drawing itself (anchors with Bézier handles).

A custom track goes into the scenario as the Inkscape SVG `Track.to_svg` writes
(``track.svg``), or, when it has side widths (an uploaded centreline CSV), as the centreline CSV
`tracks.centerline_csv` writes (``track.csv``), so a saved or downloaded scenario loads back with
its track and the planner sees the same drivable region as for a library track.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

import tracks
from app.studio._scenario import goal_fraction, pose_at

__all__ = ["Draft", "custom_scenario"]


def custom_scenario(track: tracks.Track, name: str) -> dict:
    """A scenario embedding ``track`` (start at s = 0, goal 3/4 lap or 90 % along)."""
    prof = track.sample(track.detail_spacing())
    start_s = 0.0 if track.closed else 0.05 * track.length_m
    ref = ({"svg": track.to_svg()} if track.side_widths is None
           else {"csv": tracks.centerline_csv(track), "closed": track.closed})
    return {
        "name": name,
        "track": {"name": track.name or name, **ref},
        "start": pose_at(prof, start_s),
        "goal": pose_at(prof, goal_fraction(track.closed) * track.length_m),
        "goal_tolerance": {"position": min(0.25, track.width_m / 2), "heading_deg": 30},
        "obstacles": [],
    }


@dataclass
class Draft:
    """A track being drawn: anchors the curve passes through, each with a handle — the offset
    from the anchor to the next segment's first control point (the previous segment's last one
    mirrors it, so the curve stays smooth). A handle the user has not dragged is None and
    follows Catmull-Rom (a sixth of the neighbours' chord), so clicks alone give a smooth
    track."""

    points: list[np.ndarray] = field(default_factory=list)
    handles: list[np.ndarray | None] = field(default_factory=list)

    def add(self, p) -> None:
        self.points.append(np.asarray(p, dtype=float))
        self.handles.append(None)

    def undo(self) -> None:
        if self.points:
            self.points.pop()
            self.handles.pop()

    def handle(self, i: int, closed: bool) -> np.ndarray:
        """Anchor i's handle offset, given or Catmull-Rom."""
        if self.handles[i] is not None:
            return self.handles[i]
        n, p = len(self.points), self.points
        prev = p[(i - 1) % n] if (closed or i > 0) else p[i]
        nxt = p[(i + 1) % n] if (closed or i + 1 < n) else p[i]
        return (nxt - prev) / 6.0

    def beziers(self, closed: bool) -> list[np.ndarray]:
        """(4, 2) control points of each cubic segment (zero-length ones dropped)."""
        n, p = len(self.points), self.points
        out = []
        for i in range(n if closed else n - 1):
            j = (i + 1) % n
            if math.dist(p[i], p[j]) > 1e-9:
                out.append(np.array([p[i], p[i] + self.handle(i, closed),
                                     p[j] - self.handle(j, closed), p[j]]))
        return out

    def track(self, width: float, closed: bool, name: str = "drawn") -> tracks.Track:
        if len(self.points) < (3 if closed else 2):
            raise ValueError(f"draw at least {3 if closed else 2} points")
        return tracks.Track(name=name, closed=closed, width_m=width,
                            segments=tuple(tracks.Bezier(c) for c in self.beziers(closed)))
