"""A study's report: figures in the spirit of Planner Arena and one self-contained HTML file.

Everything is read back from ``results.sqlite``, so a finished study rebuilds its report without
planning. Per scenario and per setting (planner × steering × parameter point × budget): success
rate, time to first solution and final cost over seeds, the cost over iterations (or time), the
iteration rate, nodes and clearance; and a table of the best setting per scenario. The PNGs go
to ``figures/``; the HTML embeds the same images as data URIs, so it opens offline and can be
mailed.
"""

from __future__ import annotations

import base64
import html
import io
import json
import re
import sqlite3
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["write_report"]

BOXES = (("time_to_first_solution_s", "time to first solution (s)"),
         ("cost", "final cost (m)"), ("iterations_per_s", "iterations / s"),
         ("nodes", "nodes"), ("min_clearance_m", "minimum clearance (m)"))


@dataclass
class Setting:
    """The runs of one setting on one scenario (one per seed)."""

    label: str
    rows: list[dict] = field(default_factory=list)

    def values(self, column: str) -> np.ndarray:
        return np.array([r[column] for r in self.rows if r[column] is not None], dtype=float)

    @property
    def success(self) -> float:
        return sum(r["solved"] or 0 for r in self.rows) / len(self.rows)

    @property
    def median_cost(self) -> float:
        costs = self.values("cost")
        return float(np.median(costs)) if len(costs) else float("inf")


def _label(row: dict) -> str:
    params = json.loads(row["parameters"])
    budget = " ".join(f"{k}={v:g}" for k, v in (("K", row["budget_iterations"]),
                                                ("T", row["budget_time_s"])) if v is not None)
    values = (f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())
    words = [row["planner"], row["steering"], *values, budget]
    return " ".join(words)


def _order(row: dict) -> tuple:
    params = sorted(json.loads(row["parameters"]).items())
    values = [(k, (0, v, "") if isinstance(v, int | float) else (1, 0, str(v))) for k, v in params]
    return (row["planner"], row["steering"], values,
            row["budget_iterations"] or -1, row["budget_time_s"] or -1.0, row["seed"])


def _settings(db: sqlite3.Connection) -> dict[str, dict[str, Setting]]:
    """scenario → setting label → runs, settings in grid order (planner, steering, values)."""
    db.row_factory = sqlite3.Row
    out: dict[str, dict[str, Setting]] = {}
    rows = [dict(r) for r in db.execute("SELECT * FROM runs WHERE error IS NULL")]
    for row in sorted(rows, key=lambda r: (r["scenario"], _order(r))):
        label = _label(row)
        out.setdefault(row["scenario"], {}).setdefault(label, Setting(label)).rows.append(row)
    return out


def _curve(db: sqlite3.Connection, setting: Setting, by_time: bool, grid: np.ndarray):
    """Median and quartiles over seeds of the best cost at each grid point (NaN: unsolved)."""
    column = "t_s" if by_time else "iteration"
    curves = []
    for row in setting.rows:
        pts = db.execute(f"SELECT {column}, cost FROM cost_over_time WHERE run_id = ? ORDER BY "
                         f"{column}", (row["id"],)).fetchall()
        x = np.array([p[0] for p in pts], dtype=float)
        c = np.array([p[1] for p in pts], dtype=float)
        k = np.searchsorted(x, grid, side="right") - 1
        curves.append(np.where(k >= 0, c[np.maximum(k, 0)] if len(c) else np.nan, np.nan))
    stack = np.array(curves)
    with warnings.catch_warnings():  # before the first solution a column is all NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        return [np.nanpercentile(stack, q, axis=0) for q in (25, 50, 75)]


def _figures(db, scenario: str, settings: dict[str, Setting]):
    """(name, title, matplotlib Figure) of one scenario."""
    from matplotlib.figure import Figure

    labels = list(settings)
    height = 1.2 + 0.32 * len(labels)
    fig = Figure(figsize=(8, height), layout="constrained")
    ax = fig.subplots()
    ax.barh(labels, [100 * settings[k].success for k in labels], color="C2")
    ax.set_xlim(0, 100)
    ax.set_xlabel("solved (%)")
    ax.invert_yaxis()
    yield "success", "Success rate", fig
    for column, title in BOXES:
        fig = Figure(figsize=(8, height), layout="constrained")
        ax = fig.subplots()
        data = [settings[k].values(column) for k in labels]
        ax.boxplot([d if len(d) else [np.nan] for d in data], vert=False, tick_labels=labels)
        if not any(len(d) for d in data):
            ax.text(0.5, 0.5, "no solved run", transform=ax.transAxes, ha="center")
        ax.set_xlabel(title)
        ax.invert_yaxis()
        yield column, title, fig
    yield from _against_parameters(settings)
    by_time = all(r["budget_iterations"] is None for s in settings.values() for r in s.rows)
    end = max((r["budget_time_s"] if by_time else r["iterations"]) or 0
              for s in settings.values() for r in s.rows)
    grid = np.linspace(0, end, 200)
    fig = Figure(figsize=(8, 4.5), layout="constrained")
    ax = fig.subplots()
    for i, label in enumerate(labels):
        low, mid, high = _curve(db, settings[label], by_time, grid)
        ax.plot(grid, mid, color=f"C{i % 10}", label=label)
        ax.fill_between(grid, low, high, color=f"C{i % 10}", alpha=0.15)
    ax.set_xlabel("time (s)" if by_time else "iterations")
    ax.set_ylabel("best cost (m): median, quartiles\nover the seeds solved so far")
    ax.legend(fontsize="small")
    yield "cost_over_time", "Cost over " + ("time" if by_time else "iterations"), fig


def _against_parameters(settings: dict[str, Setting]):
    """Per swept parameter: success rate and median cost against its value, one line per
    planner × steering (medians over seeds and the other parameters' values)."""
    from matplotlib.figure import Figure

    rows = [r for s in settings.values() for r in s.rows]
    swept: dict[str, set] = {}
    for row in rows:
        for key, value in json.loads(row["parameters"]).items():
            swept.setdefault(key, set()).add(value)
    for key in (k for k, values in swept.items() if len(values) > 1):
        fig = Figure(figsize=(8, 3.6), layout="constrained")
        rate_ax, cost_ax = fig.subplots(1, 2)
        groups: dict[str, dict] = {}
        for row in rows:
            value = json.loads(row["parameters"]).get(key)
            if value is not None:
                group = groups.setdefault(f"{row['planner']} {row['steering']}", {})
                group.setdefault(value, []).append(row)
        for i, (name, by_value) in enumerate(groups.items()):
            xs = sorted(by_value)
            rate = [100 * np.mean([r["solved"] or 0 for r in by_value[x]]) for x in xs]
            cost = [np.median(c) if len(c := [r["cost"] for r in by_value[x] if r["cost"]])
                    else np.nan for x in xs]
            rate_ax.plot(xs, rate, "o-", color=f"C{i}", label=name)
            cost_ax.plot(xs, cost, "o-", color=f"C{i}", label=name)
        rate_ax.set(xlabel=key, ylabel="solved (%)", ylim=(-5, 105))
        cost_ax.set(xlabel=key, ylabel="median cost (m)")
        cost_ax.legend(fontsize="small")
        yield f"against_{key}", f"Against {key}", fig


def _best(settings: dict[str, Setting]) -> Setting:
    """Highest success rate, then lowest median cost."""
    return min(settings.values(), key=lambda s: (-s.success, s.median_cost))


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)


def _png(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    return buffer.getvalue()


def write_report(results: Path, out: Path) -> Path:
    """Write ``out/figures/*.png`` and ``out/report.html`` from ``results``; returns the
    report's path."""
    figures = out / "figures"
    figures.mkdir(exist_ok=True)
    with sqlite3.connect(results) as db:
        name, text, version = db.execute(
            "SELECT name, file, trackstar_version FROM study").fetchone()
        by_scenario = _settings(db)
        sections, best_rows = [], []
        for scenario, settings in by_scenario.items():
            parts = [f"<h2>{html.escape(scenario)}</h2>"]
            for key, title, fig in _figures(db, scenario, settings):
                png = _png(fig)
                (figures / f"{_slug(scenario)}_{key}.png").write_bytes(png)
                parts.append(f"<h3>{html.escape(title)}</h3><img alt='{html.escape(title)}' "
                             f"src='data:image/png;base64,{base64.b64encode(png).decode()}'>")
            sections.append("\n".join(parts))
            best = _best(settings)
            ttfs = best.values("time_to_first_solution_s")
            best_rows.append(
                f"<tr><td>{html.escape(scenario)}</td><td>{html.escape(best.label)}</td>"
                f"<td>{100 * best.success:.0f} %</td><td>{best.median_cost:.3f}</td>"
                f"<td>{np.median(ttfs) if len(ttfs) else float('nan'):.4f}</td>"
                f"<td>{len(best.rows)}</td></tr>")
        total, failed = db.execute("SELECT COUNT(*), COUNT(error) FROM runs").fetchone()
    page = _PAGE.format(
        name=html.escape(name), total=total, failed=failed, best="\n".join(best_rows),
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
<p>Highest success rate, then lowest median cost over seeds.</p>
<table><tr><th>scenario</th><th>setting</th><th>solved</th><th>median cost (m)</th>
<th>median first solution (s)</th><th>seeds</th></tr>
{best}
</table>
{sections}
<h2>The study</h2>
<pre>{study}</pre>
<p>Trackstar {version}</p>
</body></html>
"""
