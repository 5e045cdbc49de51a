"""Profile plots (uPlot through viser): curvature and steering along the best path beside the
track centreline, the ±δmax band shaded; the fastest speed the car may drive the path at under
its speed limit and lateral and longitudinal accelerations (`tracks.path_rows`, the raceline's
profile), under the shaded envelope min(v_max, √(a_lat/|κ|)); and the best cost over planning
time.

The x axis is shared arc length, so the centreline is cut to the stretch from the start to the
goal — the part of the track the path is meant to follow.
"""

from __future__ import annotations

import math

import numpy as np

import tracks

__all__ = ["Profiles"]

N = 240  # points per curve: enough to see arcs, small enough to stream


def _steer_deg(kappa: np.ndarray, wheelbase: float) -> np.ndarray:
    return np.degrees(np.arctan(wheelbase * kappa))


def _on_grid(s_grid: np.ndarray, s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v(s) at the grid points, held flat beyond the data (uPlot wants equal lengths)."""
    if len(s) < 2:
        return np.zeros_like(s_grid)
    return np.interp(s_grid, s, v)


def _for_uplot(data: tuple) -> tuple:
    """uPlot seeds a series' y range with its first value and takes NaN for a number: a series
    that starts with NaN (no path yet) leaves the chart empty. Such a series starts with its
    own first number instead (with none, the chart's first): one value before a gap, which
    draws no line."""
    x, *ys = data
    firsts = [v[np.isfinite(v)][:1] for v in ys]
    fallback = next((f[0] for f in firsts if len(f)), 0.0)
    out = []
    for v, first in zip(ys, firsts):
        if math.isnan(v[0]):
            v = v.copy()
            v[0] = first[0] if len(first) else fallback
        out.append(v)
    return (x, *out)


def _series(label: str, stroke: str | None = None, width: float = 1.5, dash=None) -> dict:
    out: dict = {"label": label}
    if stroke:
        out |= {"stroke": stroke, "width": width}
    if dash:
        out["dash"] = dash
    return out


# Arc length and seconds are plain numbers: uPlot's x axis would otherwise show dates.
NUMERIC_X = {"x": {"time": False}}


class Profiles:
    """Four uPlot charts in a GUI container, refreshed when the best path changes."""

    def __init__(self, gui, centre_s, centre_kappa, goal_s: float, wheelbase: float,
                 max_steer_deg: float, limits: tracks.Limits) -> None:
        self._cs, self._ck = np.asarray(centre_s), np.asarray(centre_kappa)
        self._goal_s = goal_s
        self._wb, self._dmax = wheelbase, max_steer_deg
        self._kmax = math.tan(math.radians(max_steer_deg)) / wheelbase
        self._limits = limits
        band = ({"series": (3, 4), "fill": "rgba(80,200,120,0.12)"},)
        kappa, steer, speed = map(_for_uplot, self._profiles(np.zeros((0, 4))))
        common = {"aspect": 1.6, "bands": band, "legend": {"show": True}, "scales": NUMERIC_X}
        self.curvature = gui.add_uplot(
            kappa, (_series("s (m)"), _series("centreline κ", "#4a90e2"),
                    _series("path κ", "#e8542f", 2.0), _series("+κmax", "#2e9e5b", 1, [4, 4]),
                    _series("−κmax", "#2e9e5b", 1, [4, 4])),
            title="Curvature κ (1/m) vs s", **common)
        self.steering = gui.add_uplot(
            steer, (_series("s (m)"), _series("centreline δ", "#4a90e2"),
                    _series("path δ", "#e8542f", 2.0), _series("+δmax", "#2e9e5b", 1, [4, 4]),
                    _series("−δmax", "#2e9e5b", 1, [4, 4])),
            title="Steering δ (deg) vs s", **common)
        self.speed = gui.add_uplot(
            speed, (_series("s (m)"), _series("path v", "#e8542f", 2.0),
                    _series(f"limit (v ≤ {limits.v_max:g}, a_lat ≤ {limits.a_lat:g}, "
                            f"|a_long| ≤ {limits.a_long:g})", "#2e9e5b", 1, [4, 4]),
                    _series("v = 0")),
            title="Fastest speed v (m/s) vs s",
            **common | {"bands": ({"series": (2, 3), "fill": "rgba(80,200,120,0.12)"},)})
        self.cost = gui.add_uplot(
            (np.array([0.0, 1.0]), np.array([math.nan, math.nan])),
            (_series("planning time (s)"), _series("best cost (m)", "#8e44ad", 2.0)),
            title="Best cost over time", aspect=2.2, scales=NUMERIC_X)

    @property
    def handles(self) -> tuple:
        return self.curvature, self.steering, self.speed, self.cost

    def _profiles(self, path: np.ndarray) -> tuple[tuple, tuple, tuple]:
        """(curvature, steering data): x, centreline, path, +max, −max on one s grid; (speed
        data): x, the path's speed, its envelope, 0."""
        if len(path) >= 2:
            ds = np.hypot(*np.diff(path[:, :2], axis=0).T)
            ps = np.concatenate([[0.0], np.cumsum(ds)])
            end = ps[-1]
        else:
            ps, end = np.zeros(0), self._goal_s
        grid = np.linspace(0.0, max(end, 1e-3), N)
        centre = _on_grid(grid, self._cs, self._ck)
        pk = _on_grid(grid, ps, path[:, 3]) if len(ps) else np.full(N, math.nan)
        one = np.ones(N)
        kappa = (grid, centre, pk, self._kmax * one, -self._kmax * one)
        steer = (grid, _steer_deg(centre, self._wb), _steer_deg(pk, self._wb),
                 self._dmax * one, -self._dmax * one)
        return kappa, steer, self._speed(grid, path)

    def _speed(self, grid: np.ndarray, path: np.ndarray) -> tuple:
        """The path's fastest speed profile and its envelope on the grid (NaN without one)."""
        try:
            rows = tracks.path_rows(path[:, :3], self._limits)
        except (tracks.TrackError, IndexError):  # no path yet, or a single pose
            return grid, np.full(N, math.nan), np.full(N, math.nan), np.zeros(N)
        s, kappa, v = rows[:, 0], np.abs(rows[:, 4]), np.abs(rows[:, 5])
        cap = np.minimum(self._limits.v_max,
                         np.sqrt(self._limits.a_lat / np.maximum(kappa, 1e-300)))
        return grid, _on_grid(grid, s, v), _on_grid(grid, s, cap), np.zeros(N)

    def show_path(self, path: np.ndarray) -> None:
        kappa, steer, speed = self._profiles(path)
        self.curvature.data = _for_uplot(kappa)
        self.steering.data = _for_uplot(steer)
        self.speed.data = _for_uplot(speed)

    def show_cost(self, cost_over_time: list[tuple[float, float, int]]) -> None:
        """The planner's best cost against its planning time."""
        if not cost_over_time:
            return
        t, c = np.array(cost_over_time)[:, :2].T
        if len(t) == 1:
            t, c = np.array([t[0], t[0] + 1e-3]), np.array([c[0], c[0]])
        self.cost.data = (t, c)
