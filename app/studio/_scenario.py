"""Scenarios the studio starts from: a library track gets a default start and goal.

A library track has no start or goal of its own; the studio puts the start on the centreline at
s = 0 heading along it and the goal three quarters of the way round (a loop) or near the end (a
road), so a newcomer can press Run at once.
"""

from __future__ import annotations

import math

import numpy as np

import tracks

__all__ = ["default_scenario", "goal_fraction", "pose_at"]


def goal_fraction(closed: bool) -> float:
    """How far along the track the default goal sits: 3/4 lap, or 90 % of a road."""
    return 0.75 if closed else 0.9


def pose_at(prof, s: float) -> list[float]:
    i = int(np.clip(np.searchsorted(prof.s, s), 0, len(prof.s) - 1))
    return [float(prof.x[i]), float(prof.y[i]), float(math.atan2(math.sin(prof.heading[i]),
                                                                 math.cos(prof.heading[i])))]


def default_scenario(track_name: str) -> dict:
    """A rich-schema scenario dict for a library track: no obstacles, start and goal on it."""
    track = tracks.load_library_track(track_name)
    prof = track.sample(spacing=0.05)
    start_s = 0.0 if track.closed else 0.05 * track.length_m
    return {
        "name": f"{track_name}-studio",
        "track": {"name": track_name},
        "start": pose_at(prof, start_s),
        "goal": pose_at(prof, goal_fraction(track.closed) * track.length_m),
        "goal_tolerance": {"position": min(0.25, track.width_m / 2), "heading_deg": 30},
        "obstacles": [],
    }
