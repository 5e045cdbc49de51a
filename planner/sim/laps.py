"""Lap mode: a rolling goal ahead on a closed track's centreline, and the lap counter.

The car drives the track in the direction its start heading points along the centreline. Its
progress is the centreline arc length it has covered past the start (projections unwrapped
across the seam), so a lap is complete when the progress reaches the track's length; cutting a
corner cannot count as a lap, and a car that backs up loses progress. The replanner aims at a
goal pose ``ahead`` metres of arc beyond the car's progress, heading along the lane, or — when
an obstacle sits there — at the first free one of a few poses beside it and further on.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["LapCounter", "require_track"]

SPACING = 0.05  # m between centreline samples
WINDOW = 1.0  # m of arc searched either side of the last projection (tracks pass near themselves)
# Goal candidates: further along (m of arc beyond ``ahead``) × beside the centreline (shares
# of the half width), in this order of preference.
FURTHER = (0.0, 0.5, 1.0)
BESIDE = (0.0, 1 / 3, -1 / 3, 2 / 3, -2 / 3)


def require_track(scenario) -> None:
    """Lap mode needs a track to lap: say so in one line otherwise."""
    if scenario.track is None:
        raise ValueError("--laps needs a scenario with a closed track "
                         "(rich schema, e.g. \"track\": {\"name\": \"thesis\"})")


class LapCounter:
    """Progress along a closed centreline, completed laps with their times, the rolling goal."""

    def __init__(self, track, start, ahead: float) -> None:
        if not track.closed:
            raise ValueError(f"--laps needs a closed track, '{track.name}' is open")
        prof = track.sample(spacing=SPACING)
        # A closed profile ends where it starts, at s = length: drop that repeat.
        self.x, self.y = prof.x[:-1], prof.y[:-1]
        self.heading, self.s = prof.heading[:-1], prof.s[:-1]
        self.length = float(prof.s[-1])
        self.ahead = ahead
        self.half_width = track.width_m / 2.0
        x, y, th = start
        self.index = int(np.argmin((self.x - x) ** 2 + (self.y - y) ** 2))
        self.direction = 1.0 if math.cos(self.heading[self.index] - th) >= 0.0 else -1.0
        self.start_s = float(self.s[self.index])
        self.progress = 0.0  # metres of centreline arc covered past the start
        self.finished_at: list[float] = []  # simulated time at which each lap was completed

    @property
    def laps(self) -> int:
        return len(self.finished_at)

    @property
    def lap_times(self) -> list[float]:
        return [float(d) for d in np.diff([0.0, *self.finished_at])]

    def update(self, t: float, x: float, y: float) -> None:
        """Project the car's true position near the last projection; count a completed lap."""
        n = len(self.s)
        half = int(WINDOW / SPACING)
        idx = (self.index + np.arange(-half, half + 1)) % n
        i = int(idx[np.argmin((self.x[idx] - x) ** 2 + (self.y[idx] - y) ** 2)])
        step = math.remainder(float(self.s[i] - self.s[self.index]), self.length)
        self.progress += self.direction * step
        self.index = i
        if self.progress >= (self.laps + 1) * self.length:
            self.finished_at.append(t)

    def goals(self) -> list[tuple[float, float, float]]:
        """Goal poses, best first: on the centreline ``ahead`` metres of arc beyond the car's
        progress, then beside it, then further on; headed along the driving direction."""
        out = []
        for further in FURTHER:
            s = (self.start_s + self.direction * (self.progress + self.ahead + further))
            i = int(np.searchsorted(self.s, s % self.length)) % len(self.s)
            h = float(self.heading[i])
            th = math.remainder(h + (0.0 if self.direction > 0 else math.pi), 2.0 * math.pi)
            for share in BESIDE:
                d = share * self.half_width
                out.append((float(self.x[i]) - d * math.sin(h), float(self.y[i]) + d * math.cos(h),
                            th))
        return out
