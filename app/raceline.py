"""Speed limits for racelines, one rule for every edge: explicit values, else the vehicle's.

`trackstar track raceline`, `trackstar plan --raceline`, the REST raceline route and the
studio's download all build their `tracks.Limits` here, so their defaults cannot drift.
"""

from __future__ import annotations

import numpy as np

import tracks

A_LAT_MAX = 4.0  # m/s², lateral
A_LONG_MAX = 2.0  # m/s², longitudinal


def raceline_limits(v_max: float | None = None, a_lat_max: float = A_LAT_MAX,
                    a_long_max: float = A_LONG_MAX, vehicle=None) -> tracks.Limits:
    """The limits; ``v_max`` defaults to the vehicle's max speed (else its speed), and the
    vehicle to the scenario format's default car."""
    if v_max is None:
        from planner.scenario import Vehicle

        vehicle = vehicle or Vehicle()
        v_max = vehicle.max_speed or vehicle.speed
    return tracks.Limits(v_max=v_max, a_lat=a_lat_max, a_long=a_long_max)


def path_raceline(path: list[list[float]], limits: tracks.Limits) -> str:
    """A planned or driven path's rows ([x, y, θ, …]) in the TUM raceline layout."""
    return tracks.raceline_csv(tracks.path_rows(np.asarray(path, float)[:, :3], limits))
