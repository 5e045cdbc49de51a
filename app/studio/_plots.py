"""Profile plots (uPlot through viser): curvature and steering along the best path beside the
track centreline, the ±δmax band shaded, and the best cost over planning time.

The x axis is shared arc length, so the centreline is cut to the stretch from the start to the
goal — the part of the track the path is meant to follow.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["Profiles"]

N = 240  # points per curve: enough to see arcs, small enough to stream


def _steer_deg(kappa: np.ndarray, wheelbase: float) -> np.ndarray:
    return np.degrees(np.arctan(wheelbase * kappa))


def _on_grid(s_grid: np.ndarray, s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v(s) at the grid points, held flat beyond the data (uPlot wants equal lengths)."""
    if len(s) < 2:
        return np.zeros_like(s_grid)
    return np.interp(s_grid, s, v)


def _series(label: str, stroke: str | None = None, width: float = 1.5, dash=None) -> dict:
    out: dict = {"label": label}
    if stroke:
        out |= {"stroke": stroke, "width": width}
    if dash:
        out["dash"] = dash
    return out


class Profiles:
    """Three uPlot charts in a GUI container, refreshed when the best path changes."""

    def __init__(self, gui, centre_s, centre_kappa, goal_s: float, wheelbase: float,
                 max_steer_deg: float) -> None:
        self._cs, self._ck = np.asarray(centre_s), np.asarray(centre_kappa)
        self._goal_s = goal_s
        self._wb, self._dmax = wheelbase, max_steer_deg
        self._kmax = math.tan(math.radians(max_steer_deg)) / wheelbase
        band = ({"series": (3, 4), "fill": "rgba(80,200,120,0.12)"},)
        kappa, steer = self._profiles(np.zeros((0, 4)))
        common = {"aspect": 1.6, "bands": band, "legend": {"show": True}}
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
        self.cost = gui.add_uplot(
            (np.array([0.0, 1.0]), np.array([math.nan, math.nan])),
            (_series("planning time (s)"), _series("best cost (m)", "#8e44ad", 2.0)),
            title="Best cost over time", aspect=2.2)

    def _profiles(self, path: np.ndarray) -> tuple[tuple, tuple]:
        """(curvature data, steering data): x, centreline, path, +max, −max on one s grid."""
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
        return kappa, steer

    def show_path(self, path: np.ndarray) -> None:
        kappa, steer = self._profiles(path)
        self.curvature.data = kappa
        self.steering.data = steer

    def show_cost(self, cost_over_time: list[tuple[float, float, int]]) -> None:
        """The planner's best cost against its planning time."""
        if not cost_over_time:
            return
        t, c = np.array(cost_over_time)[:, :2].T
        if len(t) == 1:
            t, c = np.array([t[0], t[0] + 1e-3]), np.array([c[0], c[0]])
        self.cost.data = (t, c)
