"""What the run's panels say: the metrics table, the EXTEND panel after a step; and where the
driving car is on a timed path. Pure functions of the run's records."""

from __future__ import annotations

import math

import numpy as np

from app.studio._extend import explain, near_note, render, until_note
from app.studio._worker import Step

__all__ = ["extend_html", "metrics_md", "pose_at_time"]


def extend_html(steps: list[Step | None]) -> str:
    """The EXTEND panel after a step: run A's line highlighted and explained; in the split, a
    line more on what run B's same iteration did."""
    step = steps[0]
    line, note = explain(step.info, step.star)
    notes = [until_note(*step.until), f"Iteration {step.info.iteration}: {note}",
             near_note(step.info, step.options)]
    if len(steps) > 1 and steps[1] is not None:
        notes.append(f"B, its iteration {steps[1].info.iteration}: "
                     f"{explain(steps[1].info, steps[1].star)[1]}")
    return render(line, *notes, star=step.star)


def pose_at_time(path: np.ndarray, t: float) -> tuple[float, float, float]:
    """The pose (x, y, θ) on a path's rows at time t, by their t column: through a wait (rows of
    one pose, t rising) the car stands still."""
    k = int(np.searchsorted(path[:, 5], t).clip(0, len(path) - 1))
    return tuple(float(v) for v in path[k, :3])


def _fmt(v, unit: str = "", digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return f"{v:.{digits}g}{unit}" if isinstance(v, float) else f"{v}{unit}"


def _metric_cells(m: dict) -> dict[str, str]:
    """One run's column of the metrics table, by row name."""
    if not m:
        return {}
    arrival = {} if m.get("arrival_s") is None else {  # timing optimal, once solved
        "arrives after": f"{_fmt(m['arrival_s'], ' s')} (waits {_fmt(m['waited_s'], ' s')})"}
    return {"iterations": f"{m['iterations']}", "nodes": f"{m['nodes']}",
            "rewires": f"{m['rewires']}",
            # The planner's own time, not the paced run's: at 20 it/s a 0.01 s solution takes
            # seconds to watch, so its iteration comes first.
            "first solution": "—" if m.get("first_solution_iteration") is None else (
                f"iteration {m['first_solution_iteration']:,} "
                f"({_fmt(m['time_to_first_solution_s'], ' s')} of planning)"),
            "cost": _fmt(m["cost"], " m", 4), **arrival,
            "min clearance": _fmt(m["min_clearance_m"], " m"),
            "iterations/s": _fmt(m["iterations_per_s"], "", 4)}


def metrics_md(*runs: dict) -> str:
    """The metrics table: a column per run, headed A and B in the split."""
    cols = [_metric_cells(m) for m in runs]
    if not any(cols):
        return "—"
    rows = [f"| {k} | " + " | ".join(c.get(k, "—") for c in cols) + " |"
            for k in dict.fromkeys(k for c in cols for k in c)]
    if len(cols) == 1:  # the first row heads the table
        return "\n".join([rows[0], "|---|---|", *rows[1:]])
    return "\n".join(["| | A | B |", "|---|---|---|", *rows])
