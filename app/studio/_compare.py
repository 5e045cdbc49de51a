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
# What "Compare" measures each run against the first row by (the oldest pin; A without pins).
DIFFS = (("cost", "cost", "cost"), ("nodes", "nodes", "nodes"),
         ("first solution", "time_to_first_solution_s", "time_to_first_solution"))
COLUMNS = ("run", "colour", "planner", "steering", "seed", "timing", "iterations", "nodes",
           "cost", "cost_unit", "length_m", "time_to_first_solution_s", "min_clearance_m",
           "max_abs_curvature_per_m", "waited_s",
           # the difference against the first row: this row's value minus its, and in %
           "compared_with", *(f"{stem}_diff{suffix}" for _, _, stem in DIFFS
                              for suffix in ("", "_pct")),
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
        """Its result in words: cost, nodes, time to the first solution, iterations."""
        if self.cost is None:
            return "no path yet"
        m = self.metrics
        cost = (f"arrives after {self.cost:.3g} s (waits {m['waited_s']:.3g} s)"
                if self.optimal else f"cost {self.cost:.4g} m")
        first = m.get("time_to_first_solution_s")
        first = f", first solution {first:.3g} s" if first is not None else ""
        return f"{cost}, {m.get('nodes', 0)} nodes{first}, {m.get('iterations', 0)} iterations"

    def value(self, key: str) -> float | None:
        """A compared value (a `DIFFS` key of `row`): the cost, nodes or time to the first
        solution (None when the run has none, or has no path)."""
        v = self.cost if key == "cost" else self.metrics.get(key)
        return None if v is None or self.cost is None else float(v)

    def diffs(self, base: Run) -> dict[str, tuple[float, float | None]]:
        """Per compared value, (this run's minus ``base``'s, the same in % of ``base``'s; None
        where that is 0); only values both runs have, and costs of one unit."""
        out = {}
        for word, key, _ in DIFFS:
            a, b = self.value(key), base.value(key)
            if a is None or b is None or (key == "cost" and self.optimal != base.optimal):
                continue
            out[word] = (a - b, 100.0 * (a - b) / b if b else None)
        return out

    def versus(self, base: Run) -> str:
        """The differences against ``base`` in words: "vs pin 1: cost −0.26 m (−2.7 %), …"."""
        units = {"cost": " s" if self.optimal else " m", "nodes": "", "first solution": " s"}
        parts = [f"{word} {_signed(d, units[word], None if word == 'nodes' else 3)}"
                 + (f" ({_signed(pct, ' %', 2)})" if pct is not None else "")
                 for word, (d, pct) in self.diffs(base).items()]
        return f"vs {base.name}: " + (", ".join(parts) if parts else "nothing to compare yet")

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

    def row(self, base: Run | None = None) -> dict:
        """The run's line of the comparison CSV (see COLUMNS), with its differences against
        ``base``."""
        m, o, solved = self.metrics, self.options, len(self.path) > 1
        diffs = self.diffs(base) if base is not None else {}
        compared = {f"{stem}_diff{suffix}": diffs[word][k] if word in diffs else None
                    for word, _, stem in DIFFS for k, suffix in enumerate(("", "_pct"))}
        return {
            "run": self.name, "colour": self.colour, "planner": o.planner,
            "steering": o.steering, "seed": o.seed, "timing": o.timing,
            "iterations": m.get("iterations"), "nodes": m.get("nodes"), "cost": self.cost,
            "cost_unit": "s" if self.optimal else "m",
            "length_m": arc_length(self.path)[-1] if solved else None,
            "time_to_first_solution_s": m.get("time_to_first_solution_s"),
            "min_clearance_m": m.get("min_clearance_m"),
            "max_abs_curvature_per_m": np.abs(self.path[:, 3]).max() if solved else None,
            "waited_s": m.get("waited_s"),
            "compared_with": base.name if base is not None else None, **compared,
            **_car_cells(self.vehicle)}


def _signed(v: float, unit: str, digits: int | None = 3) -> str:
    """A difference with its sign, a minus sign for less: "+58", "−0.26 m", "±0 %" (``digits``
    None: a count)."""
    text = f"{abs(v):.0f}" if digits is None else f"{abs(v):.{digits}g}"
    sign = "±" if float(text) == 0 else "+" if v > 0 else "−"
    return f"{sign}{text}{unit}"


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

    def legend_html(self, current: tuple = ()) -> str:
        """Each pin's colour, settings, result and car, then the current runs' (``current``:
        `Run`s; A and B in the split) with their results; each after the first says how it
        differs from the first (pin 1)."""
        runs = [*self.runs, *current]
        rows = []
        for k, r in enumerate(runs):
            notes = [f"car: {r.car}"] if k < len(self.runs) else []
            notes += [r.versus(runs[0])] if k else []
            rows.append(f"{_swatch(r.colour)} <b>{html.escape(r.name)}</b>: {r.label} — "
                        f"{r.summary}" + "".join(
                            f"<br><span style='margin-left:2.2em;color:#777'>"
                            f"{html.escape(n)}</span>" for n in notes))
        return "<div style='font-size:12px;line-height:1.6'>" + "<br>".join(rows) + "</div>"


def _swatch(colour: str) -> str:
    return f"<span style='color:{colour};font-weight:bold'>━━</span>"


def hex_rgb(colour: str) -> tuple[int, int, int]:
    return tuple(int(colour[i:i + 2], 16) for i in (1, 3, 5))


def comparison_csv(runs: list[Run]) -> str:
    """One row per run (see COLUMNS), each after the first with its differences against the
    first; empty cells for what a run does not have."""
    out = io.StringIO()
    writer = csv.DictWriter(out, COLUMNS, lineterminator="\n")
    writer.writeheader()
    for k, run in enumerate(runs):
        writer.writerow({c: _cell(v) for c, v in run.row(runs[0] if k else None).items()})
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
