"""A study's report: figures in the spirit of Planner Arena and one self-contained HTML file.

Everything is read back from ``results.sqlite``, so a finished study rebuilds its report without
running anything. Per scenario and per setting (planner × steering × parameter point × budget;
for driven studies the parameter point): the success rate, box plots over seeds, the cost over
iterations (planning), success and one outcome against each swept parameter, and a table of the
best setting per scenario. The PNGs go to ``figures/``; the HTML embeds the same images as data
URIs, so it opens offline and can be mailed.
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
import re
import sqlite3
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from app.study.results import TABLES

__all__ = ["write_report"]

MAX_CURVES = 8  # cost curves per plot: more is spaghetti


@dataclass(frozen=True)
class Kind:
    """What a study's report shows: its success column, its box plots, the outcome plotted
    against each parameter and how the best setting is chosen."""

    success: str  # a 0/1 column
    success_label: str
    boxes: tuple[tuple[str, str], ...]  # (column, title)
    against: tuple[str, str]  # (column, label): its median against each swept parameter
    best: str  # the column whose median breaks ties in success: lower is better


KINDS = {
    "plan": Kind("solved", "solved", (
        ("time_to_first_solution_s", "time to first solution (s)"),
        ("cost", "final cost (m; timing optimal: s)"), ("iterations_per_s", "iterations / s"),
        ("nodes", "nodes"), ("min_clearance_m", "minimum clearance (m)")),
        ("cost", "median cost (m; timing optimal: s)"), "cost"),
    "simulate": Kind("reached", "goal reached", (
        ("collisions", "collisions"), ("collisions_moving", "collisions while moving"),
        ("collisions_at_rest", "collisions at rest"),
        ("min_clearance_m", "minimum clearance (m)"),
        ("time_to_goal_s", "time to goal (s)"), ("cycle_p99_ms", "cycle time p99 (ms)"),
        ("max_lateral_error_m", "largest lateral error (m)"), ("replans", "replans")),
        ("min_clearance_m", "median minimum clearance (m)"), "collisions"),
}


@dataclass
class Setting:
    """The runs of one setting on one scenario (one per seed)."""

    label: str
    rows: list[dict] = field(default_factory=list)

    def values(self, column: str) -> np.ndarray:
        return np.array([r[column] for r in self.rows if r[column] is not None], dtype=float)

    def rate(self, column: str) -> float:
        return sum(r[column] or 0 for r in self.rows) / len(self.rows)

    def median(self, column: str) -> float:
        values = self.values(column)
        return float(np.median(values)) if len(values) else float("nan")


def _words(params: dict) -> list[str]:
    return [f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items()]


def _label(row: dict) -> str:
    params = json.loads(row["parameters"])
    if "planner" not in row:  # a driven run
        return " ".join(_words(params)) or "default"
    budget = " ".join(f"{k}={v:g}" for k, v in (("K", row["budget_iterations"]),
                                                ("T", row["budget_time_s"])) if v is not None)
    return " ".join([row["planner"], row["steering"], *_words(params), budget])


def _order(row: dict) -> tuple:
    params = sorted(json.loads(row["parameters"]).items())
    values = [(k, (0, v, "") if isinstance(v, int | float) else (1, 0, str(v))) for k, v in params]
    return (row.get("planner", ""), row.get("steering", ""), values,
            row.get("budget_iterations") or -1, row.get("budget_time_s") or -1.0, row["seed"])


def _settings(db: sqlite3.Connection, table: str) -> dict[str, dict[str, Setting]]:
    """scenario → setting label → runs, settings in grid order (planner, steering, values)."""
    db.row_factory = sqlite3.Row
    out: dict[str, dict[str, Setting]] = {}
    rows = [dict(r) for r in db.execute(f"SELECT * FROM {table} WHERE error IS NULL")]
    for row in sorted(rows, key=lambda r: (r["scenario"], _order(r))):
        label = _label(row)
        out.setdefault(row["scenario"], {}).setdefault(label, Setting(label)).rows.append(row)
    return out


def _curve(db: sqlite3.Connection, setting: Setting, by_time: bool, grid: np.ndarray):
    """Quartiles over all seeds of the best cost at each grid point, as Planner Arena draws
    them: a seed not solved yet counts as an infinite cost, so a quartile is drawn (not NaN)
    only once more than that share of the seeds is solved, and the median never rises."""
    column = "t_s" if by_time else "iteration"
    curves = []
    for row in setting.rows:
        pts = db.execute(f"SELECT {column}, cost FROM cost_over_time WHERE run_id = ? ORDER BY "
                         f"{column}", (row["id"],)).fetchall()
        x = np.array([p[0] for p in pts], dtype=float)
        c = np.array([p[1] for p in pts], dtype=float)
        k = np.searchsorted(x, grid, side="right") - 1
        curves.append(np.where(k >= 0, c[np.maximum(k, 0)] if len(c) else np.inf, np.inf))
    stack = np.array(curves)
    with warnings.catch_warnings():  # a quantile between a cost and infinity
        warnings.simplefilter("ignore", RuntimeWarning)
        quartiles = [np.percentile(stack, q, axis=0, method="higher") for q in (25, 50, 75)]
    return [np.where(np.isfinite(q), q, np.nan) for q in quartiles]


def _figures(db, kind: Kind, settings: dict[str, Setting]):
    """(name, title, matplotlib Figure) of one scenario."""
    from matplotlib.figure import Figure

    labels = list(settings)
    height = 1.2 + 0.32 * len(labels)
    fig = Figure(figsize=(8, height), layout="constrained")
    ax = fig.subplots()
    bars = ax.barh(labels, [100 * settings[k].rate(kind.success) for k in labels], color="C2")
    ax.bar_label(bars, fmt="%.0f", padding=3)  # a 0 % bar has no width: its label shows it
    ax.set(xlim=(0, 108), xlabel=f"{kind.success_label} (%)")
    ax.invert_yaxis()
    yield "success", f"Success: {kind.success_label}", fig
    for column, title in kind.boxes:
        fig = Figure(figsize=(8, height), layout="constrained")
        ax = fig.subplots()
        data = [settings[k].values(column) for k in labels]
        ax.boxplot([d if len(d) else [np.nan] for d in data], vert=False, tick_labels=labels)
        if not any(len(d) for d in data):
            ax.text(0.5, 0.5, "no values", transform=ax.transAxes, ha="center")
        ax.set_xlabel(title)
        ax.invert_yaxis()
        yield column, title, fig
    if kind is KINDS["plan"]:
        yield _cost_over_time(db, settings)
    yield from _against_parameters(kind, settings)


def _cost_over_time(db, settings: dict[str, Setting]):
    """One curve per setting at the largest budget: with a seed, a run of fewer iterations is
    the start of the longer one, so its curve adds nothing."""
    from matplotlib.figure import Figure

    rows = [r for s in settings.values() for r in s.rows]
    by_time = all(r["budget_iterations"] is None for r in rows)
    column = "budget_time_s" if by_time else "budget_iterations"
    largest = max(r[column] or 0 for r in rows)
    candidates = [s for s in settings.values() if s.rows[0][column] == largest]
    shown = sorted(candidates, key=lambda s: _rank(KINDS["plan"], s))[:MAX_CURVES]
    end = max((r["budget_time_s"] if by_time else r["iterations"]) or 0 for r in rows)
    grid = np.linspace(0, end, 200)
    fig = Figure(figsize=(8, 4.5 + 0.2 * len(shown)), layout="constrained")
    ax = fig.subplots()
    for i, setting in enumerate(shown):
        low, mid, high = _curve(db, setting, by_time, grid)
        ax.plot(grid, mid, color=f"C{i}", label=setting.label)
        ax.fill_between(grid, low, high, color=f"C{i}", alpha=0.12)
    ax.set_xlabel("time (s)" if by_time else "iterations")
    ax.set_ylabel("best cost (m; timing optimal: s)")
    fig.legend(loc="outside lower center", fontsize="small")
    title = ("Cost over " + ("time" if by_time else "iterations") + ": median and quartiles "
             "over all seeds, a seed not solved yet counting as infinite (so a line starts once "
             "more than half are solved)")
    if len(candidates) > len(shown):
        title += f": the best {len(shown)} of {len(candidates)} settings"
    return "cost_over_time", title, fig


def _against_parameters(kind: Kind, settings: dict[str, Setting]):
    """Per swept parameter: the success rate and the median of ``kind.against`` against its
    value, one line per planner × steering (medians over seeds and the other parameters)."""
    from matplotlib.figure import Figure

    rows = [r for s in settings.values() for r in s.rows]
    swept: dict[str, set] = {}
    for row in rows:
        for key, value in json.loads(row["parameters"]).items():
            swept.setdefault(key, set()).add(value)
    column, label = kind.against
    for key in (k for k, values in swept.items() if len(values) > 1):
        fig = Figure(figsize=(8, 3.6), layout="constrained")
        rate_ax, value_ax = fig.subplots(1, 2)
        groups: dict[str, dict] = {}
        for row in rows:
            params = json.loads(row["parameters"])
            if key in params:  # None, the default, is a value of its own
                name = f"{row['planner']} {row['steering']}" if "planner" in row else "runs"
                groups.setdefault(name, {}).setdefault(params[key], []).append(row)
        for i, (name, by_value) in enumerate(groups.items()):
            xs = sorted(by_value, key=lambda v: (0, v) if isinstance(v, int | float) else
                        (1, str(v)))
            rate = [100 * np.mean([r[kind.success] or 0 for r in by_value[x]]) for x in xs]
            values = [np.median(v) if len(v := [r[column] for r in by_value[x]
                                                if r[column] is not None]) else np.nan
                      for x in xs]
            numeric = all(isinstance(x, int | float) and not isinstance(x, bool) for x in xs)
            at = xs if numeric else [str(x) for x in xs]  # None (a default), names: categories
            rate_ax.plot(at, rate, "o-", color=f"C{i}", label=name)
            value_ax.plot(at, values, "o-", color=f"C{i}", label=name)
        rate_ax.set(xlabel=key, ylabel=f"{kind.success_label} (%)", ylim=(-5, 105))
        value_ax.set(xlabel=key, ylabel=label)
        value_ax.legend(fontsize="small")
        yield f"against_{key}", f"Against {key}", fig


def _rank(kind: Kind, s: Setting) -> tuple:
    """Highest success rate first, then the lowest median of ``kind.best``."""
    tie = s.median(kind.best)
    return (-s.rate(kind.success), tie if math.isfinite(tie) else math.inf)


def _best(kind: Kind, settings: dict[str, Setting]) -> Setting:
    return min(settings.values(), key=lambda s: _rank(kind, s))


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)


def _png(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    return buffer.getvalue()


def write_report(results: Path, kind_name: str, out: Path) -> Path:
    """Write ``out/figures/*.png`` and ``out/report.html`` from ``results``; returns the
    report's path."""
    kind = KINDS[kind_name]
    figures = out / "figures"
    figures.mkdir(exist_ok=True)
    with sqlite3.connect(results) as db:
        name, text, version = db.execute(
            "SELECT name, file, trackstar_version FROM study").fetchone()
        sections, best_rows = [], []
        for scenario, settings in _settings(db, TABLES[kind_name]).items():
            parts = [f"<h2>{html.escape(scenario)}</h2>"]
            for key, title, fig in _figures(db, kind, settings):
                png = _png(fig)
                (figures / f"{_slug(scenario)}_{key}.png").write_bytes(png)
                parts.append(f"<h3>{html.escape(title)}</h3><img alt='{html.escape(title)}' "
                             f"src='data:image/png;base64,{base64.b64encode(png).decode()}'>")
            sections.append("\n".join(parts))
            best = _best(kind, settings)
            cells = [scenario, best.label, f"{100 * best.rate(kind.success):.0f} %",
                     *(f"{best.median(c):.4g}" for c, _ in kind.boxes[:2]), len(best.rows)]
            best_rows.append("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in cells)
                             + "</tr>")
        total, failed = db.execute(f"SELECT COUNT(*), COUNT(error) FROM "
                                   f"{TABLES[kind_name]}").fetchone()
    head = ["scenario", "setting", kind.success_label,
            *(f"median {title}" for _, title in kind.boxes[:2]), "seeds"]
    page = _PAGE.format(
        name=html.escape(name), total=total, failed=failed,
        head="".join(f"<th>{html.escape(h)}</th>" for h in head), best="\n".join(best_rows),
        rule=html.escape(f"Highest {kind.success_label} rate, then the lowest median "
                         f"{kind.best.replace('_', ' ')} over seeds."),
        sections="\n".join(sections), study=html.escape(text), version=html.escape(version))
    report = out / "report.html"
    report.write_text(page, encoding="utf-8")
    return report


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Study {name}</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 60rem; margin: 2rem auto; color: #222; }}
table {{ border-collapse: collapse; }} td, th {{ border: 1px solid #ccc; padding: .3rem .6rem; }}
img {{ max-width: 100%; }} pre {{ background: #f4f4f4; padding: 1rem; }}
</style></head><body>
<h1>Study {name}</h1>
<p>{total} runs stored ({failed} ended in an error and are not shown).</p>
<h2>Best setting per scenario</h2>
<p>{rule}</p>
<table><tr>{head}</tr>
{best}
</table>
{sections}
<h2>The study</h2>
<pre>{study}</pre>
<p>Trackstar {version}</p>
</body></html>
"""
