"""Profile plots (uPlot through viser): curvature and steering along the best path beside the
track centreline, the ±δmax band shaded; the steering rate dδ/dt the path asks of the servo as
it is driven (its t column) against ±max_steer_rate — Dubins' steps are spikes off the chart,
continuous-curvature ramps stay inside; the same for the curvature's slope dκ/ds against ±σmax,
the sharpness a continuous-curvature steering plans with; the fastest speed the car may drive the path at under
its speed limit and lateral and longitudinal accelerations (`tracks.path_rows`, the raceline's
profile), under the shaded envelope min(v_max, √(a_lat/|κ|)); and the best cost over planning
time.

The current run's reverse stretches are shaded in the curvature and steering plots and its cusps
marked on the zero line; a caption says in plain words what the steering's curvature looks
like (Dubins: the bang-bang of arcs and straights).

The x axis is shared arc length, so the centreline is cut to the stretch from the start to the
goal — the part of the track the path is meant to follow. The other compared runs — the pins
(_compare.py) and, in the two-up split, run B — add their curvature, steering and cost curves
in their colours, and their reverse stretches shaded lightly in them; the current run is the
best path's pink (named A in the split).
"""

from __future__ import annotations

import math

import numpy as np

import tracks
from app.studio._compare import CURRENT, cost_curves, hex_rgb
from app.studio._scene import arc_length, cusp_rows, reversing
from planner.steering import DEFAULT_STEERING, STEERINGS

__all__ = ["Profiles"]

N = 240  # points per curve: enough to see arcs, small enough to stream


def _steer_deg(kappa: np.ndarray, wheelbase: float) -> np.ndarray:
    return np.degrees(np.arctan(wheelbase * kappa))


def _on_grid(s_grid: np.ndarray, s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v(s) at the grid points, held flat beyond the data (uPlot wants equal lengths)."""
    if len(s) < 2:
        return np.zeros_like(s_grid)
    return np.interp(s_grid, s, v)


def _along(s_grid: np.ndarray, s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v(s) along a path at the grid points, none beyond its end (a longer pin sets the grid)."""
    if len(s) < 2:
        return np.full(len(s_grid), math.nan)
    return np.interp(s_grid, s, v, right=math.nan)


def _for_uplot(data: tuple) -> tuple:
    """uPlot seeds a series' y range with its first value and takes NaN for a number: a series
    that starts with NaN (no path yet, a run solved later than another) leaves the chart
    empty. Such a series starts with its own first number instead (with none, the chart's
    first): one value before a gap, which draws no line (and no point: they are off)."""
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


def _rate(s_grid: np.ndarray, path: np.ndarray, wheelbase: float) -> np.ndarray:
    """dδ/dt (deg/s) along a path (columns x, y, θ, κ, direction, t) at the grid points: the
    change of δ between rows over the time between them; none where no time passes (a turn on
    the spot, which does not steer)."""
    if len(path) < 2:
        return np.full(len(s_grid), math.nan)
    dt = np.diff(path[:, 5])
    rate = np.diff(_steer_deg(path[:, 3], wheelbase)) / np.where(dt > 0, dt, math.nan)
    return _along(s_grid, arc_length(path)[1:], rate)


def _slope(s_grid: np.ndarray, path: np.ndarray) -> np.ndarray:
    """dκ/ds (1/m²) along a path (columns x, y, θ, κ, …) at the grid points: the change of κ
    between rows over the distance between them, the rate a continuous-curvature steering
    keeps within σmax; none where no distance passes (a turn on the spot)."""
    if len(path) < 2:
        return np.full(len(s_grid), math.nan)
    ds = np.diff(arc_length(path))
    slope = np.diff(path[:, 3]) / np.where(ds > 0, ds, math.nan)
    return _along(s_grid, arc_length(path)[1:], slope)


def _held(grid: np.ndarray, t: np.ndarray, c: np.ndarray) -> np.ndarray:
    """A best cost curve on the grid of times: each cost holds until the next, none before
    the first solution or after the run's end."""
    if not len(t):
        return np.full(len(grid), math.nan)
    k = np.searchsorted(t, grid, side="right") - 1
    out = c[k.clip(0)]
    out[(k < 0) | (grid > t[-1])] = math.nan
    return out


def _series(label: str, stroke: str | None = None, width: float = 1.5, dash=None) -> dict:
    out: dict = {"label": label, "points": {"show": False}}
    if stroke:
        out |= {"stroke": stroke, "width": width}
    if dash:
        out["dash"] = dash
    return out


# Arc length and seconds are plain numbers: uPlot's x axis would otherwise show dates.
NUMERIC_X = {"x": {"time": False}}
SHADE = 1.15  # the reverse shading reaches this times the limit, above and below


def _reverse_on(grid: np.ndarray, path: np.ndarray) -> np.ndarray:
    """Whether the path is driven in reverse at each grid point: on a reverse piece, or at
    either end of one (a cusp's point belongs to both sides)."""
    rev = reversing(path)
    if not rev.any():
        return np.zeros(len(grid), bool)
    s = arc_length(path)
    sides = [rev[(np.searchsorted(s, grid, side) - 1).clip(0, len(rev) - 1)]
             for side in ("left", "right")]
    return (sides[0] | sides[1]) & (grid <= s[-1])


def _shade(rev: np.ndarray, limit: float) -> np.ndarray:
    """The reverse shading's line: at the top where the path reverses, else at the bottom,
    where its fill (down to the bottom) has no height. uPlot fills across gaps (NaN), so
    the stretches cannot be cut out of the line."""
    return np.where(rev, SHADE * limit, -SHADE * limit)


def _other_shade(run, limit: float) -> dict:
    """A compared run's reverse shading (see `_shade`): its colour, light."""
    return _series(f"{run.name} reverse", "rgba(0,0,0,0)", 0) | {
        "fill": "rgba({},{},{},0.13)".format(*hex_rgb(run.colour)), "fillTo": -SHADE * limit}


def _reverse_series(limit: float) -> tuple[dict, dict]:
    """The reverse shading (a fill from +limit down to −limit under reverse stretches, see
    `_shade`) and the cusps (points on the zero line), as uPlot series."""
    shade = _series("reverse (shaded)", "rgba(0,0,0,0)", 0) | {
        "fill": "rgba(110,110,130,0.22)", "fillTo": -SHADE * limit}
    cusp = _series("cusp ◆", "rgba(0,0,0,0)", 0) | {
        "points": {"show": True, "size": 9, "width": 2, "stroke": "#222", "fill": "#fff",
                   "filter": ()}}
    return shade, cusp


class Profiles:
    """Four uPlot charts in a GUI container, refreshed when the best path changes."""

    def __init__(self, gui, centre_s, centre_kappa, goal_s: float, wheelbase: float,
                 max_steer_deg: float, max_steer_rate_deg_s: float,
                 limits: tracks.Limits) -> None:
        self._cs, self._ck = np.asarray(centre_s), np.asarray(centre_kappa)
        self._pins: list = []  # `_compare.Run`s
        self._split = None  # run B of the two-up split, a `_compare.Run`
        self._shown_series = None  # what the charts' series were made for
        self._path, self._current = np.zeros((0, 4)), None  # the current run, as shown
        self._goal_s = goal_s
        self._wb, self._dmax, self._rmax = wheelbase, max_steer_deg, max_steer_rate_deg_s
        self._kmax = math.tan(math.radians(max_steer_deg)) / wheelbase
        self._limits = limits
        band = ({"series": (3, 4), "fill": "rgba(80,200,120,0.12)"},)
        self._cusps: tuple = ()  # the grid indices of the current path's cusps
        self._sigma = math.nan  # σmax at the planned speed (`set_steering`)
        kappa, steer, rate, slope, speed = map(_for_uplot, self._profiles(np.zeros((0, 6))))
        common = {"aspect": 1.6, "bands": band, "legend": {"show": True}, "scales": NUMERIC_X}
        self.caption = gui.add_markdown(STEERINGS[DEFAULT_STEERING].curvature)
        self.curvature = gui.add_uplot(
            kappa, (_series("s (m)"), _series("centreline κ", "#4a90e2"),
                    _series("path κ", CURRENT, 2.0), _series("+κmax", "#2e9e5b", 1, [4, 4]),
                    _series("−κmax", "#2e9e5b", 1, [4, 4]), *_reverse_series(self._kmax)),
            title="Curvature κ (1/m) vs s (m)", **common)
        self.steering = gui.add_uplot(
            steer, (_series("s (m)"), _series("centreline δ", "#4a90e2"),
                    _series("path δ", CURRENT, 2.0), _series("+δmax", "#2e9e5b", 1, [4, 4]),
                    _series("−δmax", "#2e9e5b", 1, [4, 4]), *_reverse_series(self._dmax)),
            title="Steering δ (deg) vs s (m)", **common)
        self.rate = gui.add_uplot(
            rate, (_series("s (m)"), _series("path dδ/dt", CURRENT, 2.0),
                   _series("+servo", "#2e9e5b", 1, [4, 4]),
                   _series("−servo", "#2e9e5b", 1, [4, 4])),
            title="Steering rate dδ/dt (deg/s) vs s (m), as driven",
            **common | {"bands": ({"series": (2, 3), "fill": "rgba(80,200,120,0.12)"},),
                        "scales": NUMERIC_X | {"y": {"range": [-2 * self._rmax, 2 * self._rmax]}}})
        self.slope = gui.add_uplot(
            slope, (_series("s (m)"), _series("path dκ/ds", CURRENT, 2.0),
                    _series("+σmax", "#2e9e5b", 1, [4, 4]),
                    _series("−σmax", "#2e9e5b", 1, [4, 4])),
            title="Curvature slope dκ/ds (1/m²) vs s (m), against the servo's σmax",
            **common | {"bands": ({"series": (2, 3), "fill": "rgba(80,200,120,0.12)"},)})
        self.speed = gui.add_uplot(
            speed, (_series("s (m)"), _series("path v", CURRENT, 2.0),
                    _series(f"limit (v ≤ {limits.v_max:g}, a_lat ≤ {limits.a_lat:g}, "
                            f"|a_long| ≤ {limits.a_long:g})", "#2e9e5b", 1, [4, 4]),
                    _series("v = 0")),
            title="Fastest speed v (m/s) vs s (m)",
            **common | {"bands": ({"series": (2, 3), "fill": "rgba(80,200,120,0.12)"},)})
        self.cost = gui.add_uplot(
            (np.array([0.0, 1.0]), np.array([math.nan, math.nan])),
            (_series("planning time (s)"), _series("best cost (m)", CURRENT, 2.0)),
            title="Best cost over time", aspect=2.2, scales=NUMERIC_X)
        self._series = [h.series for h in (self.curvature, self.steering, self.cost)]  # no pins
        self._rate_series, self._slope_series = self.rate.series, self.slope.series

    @property
    def handles(self) -> tuple:
        return (self.caption, self.curvature, self.steering, self.rate, self.slope, self.speed,
                self.cost)

    def set_steering(self, name: str, b: str | None = None, sigma: float = math.inf) -> None:
        """The caption for paths of this steering (`planner.STEERINGS`' names) and, in the
        split, for run B's where it is another; a continuous-curvature one's says what its
        sharpness ``sigma`` (σmax, 1/m²) makes of a turn. ``sigma`` is also the slope chart's
        limit, for every steering: a bang-bang path's steps cross it."""
        self._sigma = sigma

        def said(steering) -> str:
            if not steering.continuous or not math.isfinite(sigma):
                return steering.curvature
            return (f"{steering.curvature} Here σmax = {sigma:.3g} 1/m²: from straight to full "
                    f"lock takes {self._kmax / sigma:.2g} m.")

        a = STEERINGS[name]
        if b is None or b == name:
            self.caption.content = said(a)
            return
        self.caption.content = (f"**A, {a.label}:** {said(a)}\n\n"
                                f"**B, {STEERINGS[b].label}:** {said(STEERINGS[b])}")

    @property
    def _others(self) -> list:
        """The compared runs besides the current one: the pins, then run B."""
        return [*self._pins, *([self._split] if self._split is not None else [])]

    def _profiles(self, path: np.ndarray) -> tuple[tuple, tuple, tuple, tuple, tuple]:
        """(curvature, steering data): x, centreline, path, +max, −max, the path's reverse
        shading and cusps, each other run's reverse shading, each other run (`_others`), on
        one s grid as long as the longest path (with the cusps' s in it); (rate data): x, the
        path's dδ/dt, ±the servo's limit, each other run's; (slope data): the same for dκ/ds
        and ±σmax; (speed data): x, the path's speed, its envelope, 0."""
        others = self._others
        paths = [path, *(r.path for r in others)]
        end = max((arc_length(p)[-1] for p in paths if len(p) >= 2), default=self._goal_s)
        cusps = arc_length(path)[cusp_rows(path)]
        grid = np.union1d(np.linspace(0.0, max(end, 1e-3), N), cusps)
        self._cusps = tuple(int(i) for i in np.searchsorted(grid, cusps))
        centre = _on_grid(grid, self._cs, self._ck)
        pk, *pins = [_along(grid, arc_length(p), p[:, 3]) for p in paths]
        one, rev = np.ones(len(grid)), _reverse_on(grid, path)
        marks = np.full(len(grid), math.nan)
        marks[list(self._cusps)] = 0.0
        revs = [_reverse_on(grid, r.path) for r in others]
        kappa = (grid, centre, pk, self._kmax * one, -self._kmax * one,
                 _shade(rev, self._kmax), marks, *(_shade(r, self._kmax) for r in revs), *pins)
        steer = (grid, _steer_deg(centre, self._wb), _steer_deg(pk, self._wb),
                 self._dmax * one, -self._dmax * one,
                 _shade(rev, self._dmax), marks, *(_shade(r, self._dmax) for r in revs),
                 *(_steer_deg(k, r.vehicle.wheelbase) for k, r in zip(pins, others)))
        rate = (grid, _rate(grid, path, self._wb), self._rmax * one, -self._rmax * one,
                *(_rate(grid, r.path, r.vehicle.wheelbase) for r in others))
        sigma = self._sigma if math.isfinite(self._sigma) else math.nan
        slope = (grid, _slope(grid, path), sigma * one, -sigma * one,
                 *(_slope(grid, r.path) for r in others))
        return kappa, steer, rate, slope, self._speed(grid, path)

    def _speed(self, grid: np.ndarray, path: np.ndarray) -> tuple:
        """The path's fastest speed profile and its envelope on the grid (NaN without one)."""
        try:
            rows = tracks.path_rows(path[:, :3], self._limits)
        except (tracks.TrackError, IndexError):  # no path yet, or a single pose
            return grid, *np.full((2, len(grid)), math.nan), np.zeros(len(grid))
        s, kappa, v = rows[:, 0], np.abs(rows[:, 4]), np.abs(rows[:, 5])
        cap = np.minimum(self._limits.v_max,
                         np.sqrt(self._limits.a_lat / np.maximum(kappa, 1e-300)))
        return grid, _along(grid, s, v), _along(grid, s, cap), np.zeros(len(grid))

    def show_path(self, path: np.ndarray, split=None) -> None:
        """The current run's best path and, in the split, run B (a `_compare.Run`)."""
        self._path, self._split = path, split
        kappa, steer, rate, slope, speed = self._profiles(path)
        # viser's client rebuilds a chart whose series change and keeps its x zoom relative
        # to the data: a rebuild with a new x range keeps a stale one. While the series are
        # as many, the data goes first, so that a rebuild finds its x range in place.
        first = len(self.curvature.series) == len(kappa)
        if not first:
            self._sync_series()
        self.curvature.data = _for_uplot(kappa)
        self.steering.data = _for_uplot(steer)
        self.rate.data = _for_uplot(rate)
        self.slope.data = _for_uplot(slope)
        self.speed.data = _for_uplot(speed)
        if first:
            self._sync_series()

    def _sync_series(self) -> None:
        """The charts' series anew when the runs compared or the cusps (drawn by uPlot's
        points.filter) changed."""
        key = (self._cusps, tuple((r.name, r.colour) for r in self._others))
        if key != self._shown_series:
            self._shown_series = key
            self._show_series()

    def _show_series(self) -> None:
        """Each chart's series: its own (the current run named A in the split), the cusps'
        points where they are now, the other runs' reverse shading and curves."""
        others = self._others
        for h, base, symbol, limit in zip((self.curvature, self.steering, self.cost),
                                          self._series, (" κ", " δ", ""),
                                          (self._kmax, self._dmax, None)):
            if self._split is not None:  # the current run's series: "path κ", "best cost (m)"
                at = 1 if h is self.cost else 2
                base = (*base[:at], base[at] | {"label": "A" + (symbol or " best cost (m)")},
                        *base[at + 1:])
            shades = ()
            if h is not self.cost:
                cusp = base[6]
                base = (*base[:6], cusp | {"points": cusp["points"] | {"filter": self._cusps}})
                shades = tuple(_other_shade(r, limit) for r in others)
            h.series = base + shades + tuple(_series(r.name + symbol, r.colour, 1.5)
                                             for r in others)
        for h, base, symbol in ((self.rate, self._rate_series, " dδ/dt"),
                                (self.slope, self._slope_series, " dκ/ds")):
            if self._split is not None:
                base = (base[0], base[1] | {"label": "A" + symbol}, *base[2:])
            h.series = base + tuple(_series(r.name + symbol, r.colour, 1.5) for r in others)

    def show_cost(self, current, split=None) -> None:
        """The current run's (a `_compare.Run`) best cost against planning time and the other
        runs' (the pins', B's in the split), on one time axis: each improvement's instant and
        the one just before it, so that every curve is a staircase."""
        self._current, self._split = current, split
        self._sync_series()
        curves = cost_curves([current, *self._others])
        t = np.unique(np.concatenate([np.r_[t, np.nextafter(t, -math.inf)] for t, _ in curves]))
        if not len(t):
            t = np.array([0.0, 1.0])
        elif t[-1] - t[0] < 1e-3:  # one instant: the browser keeps its zoom relative to the span
            t = np.r_[t, t[0] + 1e-3]
        self.cost.data = _for_uplot((t, *(_held(t, *c) for c in curves)))

    def set_pins(self, runs: list) -> None:
        """Pinned runs (`_compare.Run`) as series of their own, named and coloured as the
        pins; the caller sends it atomically, the series with the data that matches them."""
        self._pins = list(runs)
        self.show_path(self._path, self._split)
        if self._current is not None:
            self.show_cost(self._current, self._split)
