"""Compare runs (issue 20): a pinned run stays drawn — its best path in the scene, its profiles
and best cost over time in the plots, all in one colour of its own — while the next runs grow
over it, so that RRT and RRT*, Dubins and Reeds-Shepp or two seeds are seen side by side; the
comparison goes out as numbers (CSV) and plots (PNG).

`Run` is what is compared of one run, pinned or current; `Pins` holds a tab's pinned runs and
draws their paths. The current run keeps the best path's pink everywhere.
"""

from __future__ import annotations

import csv
import html
import io
import math
from dataclasses import dataclass, replace

import numpy as np

import planner
from app.studio._live_view import PATH_RGB
from app.studio._panel import PLANNERS, TIMINGS
from app.studio._scene import Z, arc_length, path_layers
from planner.scenario import Vehicle

__all__ = ["CURRENT", "MAX_PINS", "PALETTE", "SPLIT_B", "Pins", "Run", "comparison_csv",
           "comparison_png", "cost_curves", "hex_rgb", "settings_words"]

# Violet, teal, sienna, olive: none is a colour another line in the scene has (the tree's
# blue, the path's pink, the rewire flashes' red and green, the centreline's blue, yellow and
# red, the step overlay's white, yellow and cyan), and each reads on the asphalt and on white.
PALETTE = ("#9d4edd", "#00a89d", "#a0522d", "#808000")
CURRENT = "#{:02x}{:02x}{:02x}".format(*PATH_RGB)  # the current run: the best path's pink
# Run B of the two-up split (_split.py): a lime, apart from the pink, the pins' colours, the
# tree's blue and the warm colours of obstacles, movers, goal and rewire flashes.
SPLIT_B = "#78c800"
MAX_PINS = len(PALETTE)  # a pin beyond these replaces the oldest
COLUMNS = ("run", "colour", "planner", "steering", "seed", "timing", "iterations", "cost",
           "cost_unit", "length_m", "time_to_first_solution_s", "min_clearance_m",
           "max_abs_curvature_per_m", "waited_s",
           # the car it planned for (pins stay across Vehicle edits, to compare cars)
           "wheelbase_m", "max_steer_deg", "turning_radius_m", "footprint", "disc_radius_m",
           "car_length_m", "car_width_m", "safety_margin_m")
_PLANNER_LABELS = {v: k for k, v in PLANNERS.items()}
_TIMING_LABELS = {v: k for k, v in TIMINGS.items()}


@dataclass(frozen=True)
class Run:
    """One run as compared: its settings, its last metrics, its best path (rows x, y, θ, κ,
    direction, t), its best cost over planning time and the car it planned for (whose
    wheelbase turns κ into steering)."""

    options: planner.PlanOptions
    metrics: dict
    path: np.ndarray
    cost_over_time: list
    vehicle: Vehicle
    name: str = "this run"
    colour: str = CURRENT

    @property
    def optimal(self) -> bool:
        return self.options.timing == "optimal"

    @property
    def label(self) -> str:
        return ", ".join(settings_words(self.options))

    @property
    def car(self) -> str:
        """The car in short, for the legend: "wheelbase 0.44 m, δmax 26°, disc r 0.1 m"."""
        v, fp = self.vehicle, self.vehicle.footprint
        shape = (f"{fp.length:g} × {fp.width:g} m" if fp is not None
                 else f"disc r {v.radius:g} m" if v.radius > 0 else "point")
        margin = f", margin {v.safety_margin:g} m" if v.safety_margin > 0 else ""
        return f"wheelbase {v.wheelbase:g} m, δmax {v.max_steer_deg:g}°, {shape}{margin}"

    @property
    def cost(self) -> float | None:
        """The run's objective: the path's cost in m, or with fastest arrival the arrival in s."""
        return self.metrics.get("arrival_s" if self.optimal else "cost")

    @property
    def summary(self) -> str:
        if self.cost is None:
            return "no path yet"
        cost = (f"arrives after {self.cost:.3g} s (waits {self.metrics['waited_s']:.3g} s)"
                if self.optimal else f"cost {self.cost:.4g} m")
        return f"{cost}, {self.metrics.get('iterations', 0)} iterations"

    def steering_deg(self) -> np.ndarray:
        return np.degrees(np.arctan(self.vehicle.wheelbase * self.path[:, 3]))

    def cost_curve(self) -> tuple[np.ndarray, np.ndarray]:
        """(planning time, best cost) at each improvement, the last held to the planning time
        so far."""
        t = np.array([row[0] for row in self.cost_over_time], dtype=float)
        c = np.array([row[1] for row in self.cost_over_time], dtype=float)
        until = self.metrics.get("planning_time_s")
        if len(t) and until is not None and until > t[-1]:
            t, c = np.append(t, until), np.append(c, c[-1])
        return t, c

    def row(self) -> dict:
        """The run's line of the comparison CSV (see COLUMNS)."""
        m, o, solved = self.metrics, self.options, len(self.path) > 1
        return {
            "run": self.name, "colour": self.colour, "planner": o.planner,
            "steering": o.steering, "seed": o.seed, "timing": o.timing,
            "iterations": m.get("iterations"), "cost": self.cost,
            "cost_unit": "s" if self.optimal else "m",
            "length_m": arc_length(self.path)[-1] if solved else None,
            "time_to_first_solution_s": m.get("time_to_first_solution_s"),
            "min_clearance_m": m.get("min_clearance_m"),
            "max_abs_curvature_per_m": np.abs(self.path[:, 3]).max() if solved else None,
            "waited_s": m.get("waited_s"), **_car_cells(self.vehicle)}


def settings_words(options: planner.PlanOptions) -> list[str]:
    """A run's settings as the panel names them: planner, steering, seed (and timing when it
    is not constant speed)."""
    o = options
    words = [_PLANNER_LABELS[o.planner], planner.STEERINGS[o.steering].label, f"seed {o.seed}"]
    return words + ([_TIMING_LABELS[o.timing]] if o.timing == "optimal" else [])


def _car_cells(v: Vehicle) -> dict:
    """The car's columns of the comparison CSV."""
    fp = v.footprint
    return {"wheelbase_m": v.wheelbase, "max_steer_deg": v.max_steer_deg,
            "turning_radius_m": v.turning_radius,
            "footprint": "rectangle" if fp is not None else "disc" if v.radius > 0 else "point",
            "disc_radius_m": v.radius if fp is None else None,
            "car_length_m": fp.length if fp is not None else None,
            "car_width_m": fp.width if fp is not None else None,
            "safety_margin_m": v.safety_margin}


def cost_curves(runs: list[Run]) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each run's (planning time, best cost) on one time axis. RRT stops at its first
    solution, so its cost holds to the axis' end: a line to compare RRT* with, not a point."""
    own = [r.cost_curve() for r in runs]
    end = max((t[-1] for t, _ in own if len(t)), default=0.0)
    return [(np.append(t, end), np.append(c, c[-1]))
            if r.options.planner == "rrt" and len(t) and end > t[-1] else (t, c)
            for r, (t, c) in zip(runs, own)]


class Pins:
    """A tab's pinned runs, oldest first, and their paths in the scene: above the tree (a
    dense tree would hide them), below the current best path."""

    def __init__(self, scene) -> None:
        self.scene = scene
        self.runs: list[Run] = []
        self._pinned = 0  # pins since the last clear: each is named by its number

    def add(self, run: Run) -> None:
        """Pin ``run`` in the first colour no pin has; beyond MAX_PINS it replaces the oldest."""
        self.runs = self.runs[-(MAX_PINS - 1):]  # room for one more
        colour = next(c for c in PALETTE if c not in {r.colour for r in self.runs})
        self._pinned += 1
        self.runs.append(replace(run, name=f"pin {self._pinned}", colour=colour))

    def clear(self) -> None:
        self.runs, self._pinned = [], 0

    def draw(self, marker: float, scale: float = 1.0) -> None:
        """The pinned paths, anew (also into a fresh scene, where the old ones are gone), lines
        ``scale`` times as wide (projector mode), reverse stretches and cusps marked as the
        current run's are (`path_layers`, cusps ``marker`` wide): line nodes per pin, since
        per-vertex colours would be drawn paler than the legend's."""
        self.scene.remove_by_name("/pins")
        if not self.runs:
            return
        self.scene.add_frame("/pins", show_axes=False)
        for i, run in enumerate(self.runs):
            for suffix, seg, rgb, px in path_layers(run.path, hex_rgb(run.colour), marker,
                                                    Z["pin"]):
                if len(seg):
                    self.scene.add_line_segments(f"/pins/{i}{suffix}", seg, rgb,
                                                 thickness=0.75 * px * scale,
                                                 thickness_units="screen")

    def legend_html(self, current: tuple = ((CURRENT, "this run"),)) -> str:
        """Each pin's colour, settings, result and car, then the current runs' colours and
        names (``current``: (colour, name) pairs; A and B in the split)."""
        rows = [f"{_swatch(r.colour)} <b>{r.name}</b>: {r.label} — {r.summary}<br>"
                f"<span style='margin-left:2.2em;color:#777'>car: {html.escape(r.car)}</span>"
                for r in self.runs]
        return ("<div style='font-size:12px;line-height:1.6'>"
                + "<br>".join([*rows, *(f"{_swatch(c)} {html.escape(name)}" for c, name in current)])
                + "</div>")


def _swatch(colour: str) -> str:
    return f"<span style='color:{colour};font-weight:bold'>━━</span>"


def hex_rgb(colour: str) -> tuple[int, int, int]:
    return tuple(int(colour[i:i + 2], 16) for i in (1, 3, 5))


def comparison_csv(runs: list[Run]) -> str:
    """One row per run (see COLUMNS); empty cells for what a run does not have."""
    out = io.StringIO()
    writer = csv.DictWriter(out, COLUMNS, lineterminator="\n")
    writer.writeheader()
    for run in runs:
        writer.writerow({k: _cell(v) for k, v in run.row().items()})
    return out.getvalue()


def _cell(v) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return ""
    return f"{v:.6g}" if isinstance(v, (float, np.floating)) else str(v)


def comparison_png(runs: list[Run], title: str) -> bytes:
    """Curvature and steering against arc length and best cost against planning time of each
    run, in its colour, with a legend naming it: the comparison for a slide."""
    from matplotlib.figure import Figure  # no pyplot: its global state is not thread-safe

    fig = Figure(figsize=(8.0, 9.0), dpi=100, layout="constrained")
    kappa, steer, cost = fig.subplots(3, 1)
    for run, (t, c) in zip(runs, cost_curves(runs)):
        style = {"color": run.colour, "linewidth": 2.0 if run.colour == CURRENT else 1.5,
                 "label": f"{run.name}: {run.label} — {run.summary}"}
        if len(run.path) > 1:
            s = arc_length(run.path)
            kappa.plot(s, run.path[:, 3], **style)
            steer.plot(s, run.steering_deg(), **style)
        cost.step(t, c, where="post", marker="o", markevery=[0], **style)  # o: first solution
    for ax, ylabel, xlabel in ((kappa, "curvature κ (1/m)", "arc length s (m)"),
                               (steer, "steering δ (deg)", "arc length s (m)"),
                               (cost, "best cost (m)", "planning time (s)")):
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
    fig.legend(handles=cost.get_lines(), loc="outside lower center", fontsize=8)
    fig.suptitle(title)
    out = io.BytesIO()
    fig.savefig(out, format="png")
    return out.getvalue()
