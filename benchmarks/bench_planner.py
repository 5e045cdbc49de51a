"""Planner benchmark: Trackstar's RRT* against OMPL's RRT*, Informed RRT* and BIT*, Dubins steering.

    python benchmarks/bench_planner.py        # 5 static scenarios, budgets 0.1 s and 1 s, seeds 0-4

Ours also runs with continuous-curvature steering (--steerings, default dubins, cc-dubins,
reeds-shepp and cc-reeds-shepp): OMPL has no CC space, so a CC steering is measured against our
rate with its bang-bang kin (Dubins, Reeds-Shepp) and OMPL RRT*'s Dubins rate (the CC path is the
harder problem, so that ratio is conservative).

"Best known" costs come from benchmarks/results/best_known.json; a scenario missing there is first
run for --long-s seconds (default 20) with seeds 0-2 by ours and, with OMPL, by BIT*, and the
lowest cost any of them reached is stored with how it was found.

Each OMPL run is a fresh process (OMPL's seed is process-wide), one per budget. Ours runs in this
process after one untimed warm-up solve per scenario (compilation is not what we measure), once per
seed at the largest budget: its iterations do not depend on the budget, so its cost at a smaller
budget is read from cost_over_time. Runs are sequential, never two at once, so timings are fair.
Prints the table and writes it to benchmarks/results/planner.md.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from datetime import date
from pathlib import Path

import _harness
from tqdm import tqdm

STATIC_SCENARIOS = ["open_field", "hallway", "slalom", "parking", "oval_track"]
OMPL_PLANNERS = ["RRTstar", "InformedRRTstar", "BITstar"]
OURS = "ours"
BEST_KNOWN = Path(__file__).parent / "results" / "best_known.json"
AB_RECORD = "## A/B record"  # a hand-kept section below the tables, kept when they are rewritten
LONG_SEEDS = [0, 1, 2]


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", nargs="+", default=STATIC_SCENARIOS, metavar="NAME",
                        help="bundled scenario names or scenario files, e.g. "
                             "benchmarks/scenes/*.json (crossing has a moving obstacle OMPL "
                             "cannot express)")
    parser.add_argument("--seeds", nargs="+", type=int, default=list(range(5)))
    parser.add_argument("--budgets", nargs="+", type=float, default=[0.1, 1.0], metavar="SECONDS")
    parser.add_argument("--only", choices=[OURS, "ompl"], help="run only our planner or only OMPL")
    parser.add_argument("--steerings", nargs="+",
                        default=["dubins", "cc-dubins", "reeds-shepp", "cc-reeds-shepp"],
                        metavar="NAME", help="our steerings to run (OMPL's is Dubins)")
    parser.add_argument("--json", type=Path, metavar="OUT", help="also write every run's record")
    parser.add_argument("--ompl-from", type=Path, metavar="RECORDS",
                        help="take OMPL's runs from an earlier --json instead of running OMPL "
                             "again (12 minutes of fresh processes; OMPL does not change with "
                             "our commits), e.g. benchmarks/results/ompl_runs.json")
    parser.add_argument("--out", default="planner", metavar="NAME",
                        help="write the tables to benchmarks/results/NAME.md")
    parser.add_argument("--long-s", type=float, default=20.0, metavar="SECONDS",
                        help="budget of the long runs that find a missing best known cost")
    parser.add_argument("--renew-best-known", action="store_true",
                        help="run the long runs again for every scenario (after a planner "
                             "change); a stored cost that stays lower is kept")
    args = parser.parse_args(argv)
    args.budgets = sorted(args.budgets)
    return args


def ompl_runs(scenarios: dict[str, dict], seeds: list[int], budgets: list[float],
              bar: tqdm) -> list[dict]:
    """One fresh-process OMPL run per (scenario, planner, budget, seed)."""
    from ompl_baseline import run_ompl_isolated  # imports OMPL: only when OMPL is benchmarked

    records = []
    for scenario in scenarios.values():
        for name in OMPL_PLANNERS:
            for budget in budgets:
                for seed in seeds:
                    bar.set_postfix_str(f"{scenario['name']} {name} {budget:g}s seed {seed}")
                    records.append(run_ompl_isolated(scenario, name, budget, seed))
                    bar.update()
    return records


def kept_record(name: str) -> str:
    """The A/B record below the tables of results/NAME.md, if it has one."""
    path = _harness.RESULTS / f"{name}.md"
    text = path.read_text() if path.exists() else ""
    return "\n" + text[text.index(AB_RECORD):] if AB_RECORD in text else ""


def ompl_records(path: Path, args: argparse.Namespace) -> list[dict]:
    """OMPL's records in an earlier --json, for these scenarios, seeds and budgets."""
    return [r for r in json.loads(path.read_text())
            if r["planner"] != OURS and r["scenario"] in args.scenarios
            and r["seed"] in args.seeds and r["time_limit_s"] in args.budgets]


def _our_planner():
    """The `planner` package, or exit with a hint while its solve() does not exist yet."""
    import planner

    if not hasattr(planner, "solve"):
        raise SystemExit("planner.solve is not available yet: run with --only ompl")
    return planner


def our_label(steering: str) -> str:
    """Ours with Dubins is "ours", as OMPL's rows are Dubins; another steering is named."""
    return OURS if steering == "dubins" else f"{OURS} {steering}"


def our_runs(trackstar, paths: dict[str, Path], seeds: list[int], budgets: list[float],
             steerings: list[str], bar: tqdm) -> list[dict]:
    """One run of ours per (scenario, steering, seed) at the largest budget, reported at every
    budget."""
    records = []
    for name, path in paths.items():
        scenario = trackstar.load_scenario(path)
        for steering in steerings:
            trackstar.solve(scenario, planner="rrtstar", steering=steering, time_limit=0.05,
                            seed=0)
            for seed in seeds:
                bar.set_postfix_str(f"{name} {our_label(steering)} seed {seed}")
                start = time.perf_counter()
                result = trackstar.solve(scenario, planner="rrtstar", steering=steering,
                                         time_limit=budgets[-1], seed=seed)
                setup_s = time.perf_counter() - start - result.planning_time_s
                records += [_our_record(result, name, our_label(steering), seed, budget,
                                        setup_s) for budget in budgets]
                bar.update()
    return records


def _our_record(result, scenario: str, label: str, seed: int, budget: float,
                setup_s: float) -> dict:
    """Our result as it stood at `budget`, in the record format of ompl_baseline.run_ompl.

    Iterations per second of planning, as for OMPL, whose problem set-up is not timed either;
    the set-up time of ours (solve()'s wall time outside planning) is kept as `setup_s`.
    """
    costs = [cost for t, cost, _ in result.cost_over_time if t <= budget]
    return {
        "scenario": scenario,
        "planner": label,
        "time_limit_s": budget,
        "seed": seed,
        "solved": bool(costs),
        "cost": min(costs) if costs else None,
        "time_to_first_solution_s": result.time_to_first_solution_s,
        "iterations": result.iterations,
        "iterations_per_s": result.iterations / result.planning_time_s,
        "nodes": result.nodes,
        "valid_5mm": None,
        "setup_s": setup_s,
    }


def best_known(trackstar, paths: dict[str, Path], scenarios: dict[str, dict], long_s: float,
               with_ompl: bool, renew: bool = False) -> dict[str, dict]:
    """{scenario: {"cost", "by"}}: stored ones, and long runs for the missing ones (for all
    with ``renew``, keeping a stored cost that stays lower); stored."""
    known = json.loads(BEST_KNOWN.read_text()) if BEST_KNOWN.exists() else {}
    missing = [name for name in paths if renew or name not in known]
    runs = len(missing) * len(LONG_SEEDS) * (2 if with_ompl else 1)
    with tqdm(total=runs, unit="long run", disable=not runs) as bar:
        for name in missing:
            found = [(known[name]["cost"], known[name]["by"])] if name in known else []
            for seed in LONG_SEEDS:
                bar.set_postfix_str(f"{name} ours seed {seed}")
                result = trackstar.solve(trackstar.load_scenario(paths[name]), time_limit=long_s,
                                         seed=seed)
                found.append((result.cost, f"ours, {long_s:g} s, seed {seed}"))
                bar.update()
                if with_ompl:
                    from ompl_baseline import run_ompl_isolated

                    bar.set_postfix_str(f"{name} BIT* seed {seed}")
                    r = run_ompl_isolated(scenarios[name], "BITstar", long_s, seed)
                    found.append((r["cost"], f"OMPL BIT*, {long_s:g} s, seed {seed}"))
                    bar.update()
            cost, by = min((c, b) for c, b in found if c is not None)
            known[name] = {"cost": cost, "by": by}
            BEST_KNOWN.write_text(json.dumps(known, indent=1) + "\n")
    return known


def best_known_table(summary: dict, scenarios: list[str], budgets: list[float],
                     known: dict[str, dict]) -> str:
    """Markdown table of our median cost at each budget over the best known cost."""
    cols = " | ".join(f"cost {b:g} s / best known" for b in budgets)
    lines = [f"| scenario | best known (how) | {cols} |", "|---|---|" + "---:|" * len(budgets)]
    for scenario in scenarios:
        ours = summary.get((scenario, OURS))
        if ours is None or scenario not in known:
            continue
        best = known[scenario]
        ratios = " | ".join(_ratio(ours["budgets"][b][0], best["cost"], ".3f") for b in budgets)
        lines.append(f"| {scenario} | {best['cost']:.3f} ({best['by']}) | {ratios} |")
    return "\n".join(lines)


def _median(values: list) -> float | None:
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def summarise(records: list[dict], budgets: list[float]) -> dict[tuple[str, str], dict]:
    """Medians over seeds per (scenario, planner); speed, first solution from the longest runs."""
    groups: dict[tuple[str, str], list[dict]] = {}
    for record in records:
        groups.setdefault((record["scenario"], record["planner"]), []).append(record)
    summary = {}
    for key, runs in groups.items():
        longest = [r for r in runs if r["time_limit_s"] == budgets[-1]]
        solved = [r for r in longest if r["solved"]]
        summary[key] = {
            "runs": len(longest),
            "iterations_per_s": _median([r["iterations_per_s"] for r in longest]),
            "ttfs_s": _median([r["time_to_first_solution_s"] for r in solved]),
            "valid_5mm": (sum(bool(r["valid_5mm"]) for r in solved)
                          if key[1] in OMPL_PLANNERS else None),
            "solved": len(solved),
            "budgets": {b: _budget_summary([r for r in runs if r["time_limit_s"] == b])
                        for b in budgets},
        }
    return summary


def _budget_summary(runs: list[dict]) -> tuple[float | None, int]:
    """(median cost of the solved runs, number solved)."""
    return _median([r["cost"] for r in runs if r["solved"]]), sum(r["solved"] for r in runs)


def _fmt(value: float | None, spec: str) -> str:
    return "—" if value is None else format(value, spec)


def _ratio(ours: float | None, theirs: float | None, spec: str = ".2f") -> str:
    return "—" if ours is None or not theirs else format(ours / theirs, spec)


def results_table(summary: dict, scenarios: list[str], budgets: list[float]) -> str:
    """Markdown table: one row per (scenario, planner)."""
    budget_cols = " | ".join(f"cost {b:g} s (solved)" for b in budgets)
    lines = [f"| scenario | planner | it/s | first solution ms | {budget_cols} | valid at 5 mm |",
             "|---|---|---:|---:|" + "---:|" * len(budgets) + "---:|"]
    ours = sorted({p for _, p in summary if p not in OMPL_PLANNERS})
    for scenario in scenarios:
        for planner in [*OMPL_PLANNERS, *ours]:
            row = summary.get((scenario, planner))
            if row is None:
                continue
            costs = " | ".join(f"{_fmt(cost, '.2f')} ({n}/{row['runs']})"
                               for cost, n in (row["budgets"][b] for b in budgets))
            valid = "—" if row["valid_5mm"] is None else f"{row['valid_5mm']}/{row['solved']}"
            ttfs_ms = None if row["ttfs_s"] is None else row["ttfs_s"] * 1000
            lines.append(f"| {scenario} | {planner} | {_fmt(row['iterations_per_s'], '.0f')} | "
                         f"{_fmt(ttfs_ms, '.0f')} | {costs} | {valid} |")
    return "\n".join(lines)


def ratios_table(summary: dict, scenarios: list[str], budgets: list[float]) -> str:
    """Markdown table of ours against OMPL RRT* (speed, first solution) and the best OMPL cost."""
    lines = ["| scenario | it/s ours / RRT* | first solution ours / RRT* | "
             f"cost {budgets[-1]:g} s ours / best OMPL |", "|---|---:|---:|---:|"]
    for scenario in scenarios:
        ours, rrtstar = summary.get((scenario, OURS)), summary.get((scenario, "RRTstar"))
        if ours is None or rrtstar is None:
            continue
        best_cost, best = _best_ompl_cost(summary, scenario, budgets[-1])
        speed = _ratio(ours["iterations_per_s"], rrtstar["iterations_per_s"])
        lines.append(f"| {scenario} | {speed} | {_ratio(ours['ttfs_s'], rrtstar['ttfs_s'])} | "
                     f"{_ratio(ours['budgets'][budgets[-1]][0], best_cost)} ({best}) |")
    return "\n".join(lines)


def steering_table(summary: dict, scenarios: list[str], steering: str) -> str:
    """Markdown table of our rate with ``steering`` against ours with its bang-bang kin (a
    CC steering's; Dubins else) and OMPL RRT*'s with Dubins."""
    label = our_label(steering)
    kin = "reeds-shepp" if steering == "cc-reeds-shepp" else "dubins"
    lines = [f"| scenario | it/s {steering} | / ours {kin} | / OMPL RRT* Dubins |",
             "|---|---:|---:|---:|"]
    for scenario in scenarios:
        row = summary.get((scenario, label))
        if row is None:
            continue
        ours, rrtstar = summary.get((scenario, our_label(kin))), summary.get((scenario, "RRTstar"))
        rate = row["iterations_per_s"]
        lines.append(f"| {scenario} | {_fmt(rate, '.0f')} | "
                     f"{_ratio(rate, ours and ours['iterations_per_s'])} | "
                     f"{_ratio(rate, rrtstar and rrtstar['iterations_per_s'])} |")
    return "\n".join(lines)


def _best_ompl_cost(summary: dict, scenario: str, budget: float) -> tuple[float | None, str]:
    """(lowest median OMPL cost at `budget`, the planner that reached it)."""
    costs = [(summary[(scenario, p)]["budgets"][budget][0], p) for p in OMPL_PLANNERS
             if (scenario, p) in summary]
    costs = [(cost, p) for cost, p in costs if cost is not None]
    return min(costs) if costs else (None, "—")


NOTES = (
    "Medians over seeds (cost and first solution over the solved runs); it/s and first solution "
    "come from the runs at the longest budget. Iterations: RRT* loop iterations, BIT* queue "
    "iterations (edges and vertices processed), ours as its solve() reports them; per second of "
    "planning, set-up not timed on either side. OMPL checks motions every 0.02 m; \"valid at "
    "5 mm\" re-checks its returned paths every 5 mm. OMPL's seed is the run's seed + 1 (OMPL "
    "refuses 0)."
)


def _revision() -> str:
    """The checkout's commit, `-dirty` when the working tree has changes: what was measured."""
    git = ["git", "describe", "--always", "--dirty"]
    done = subprocess.run(git, cwd=Path(__file__).parent, capture_output=True, text=True)
    return done.stdout.strip() or "(not a git checkout)"


def report(summary: dict, args: argparse.Namespace, command: str, seconds: float,
           known: dict[str, dict]) -> str:
    """The whole Markdown report: how it was run, the table, the ratios when both sides ran."""
    parts = [
        "# Planner benchmark: Trackstar vs OMPL (Dubins)",
        f"`{command}` — Trackstar {_revision()}, {date.today()}, {platform.machine()}, "
        f"Python {platform.python_version()}, seeds {args.seeds}, {seconds:.0f} s in all; load "
        f"average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs at the end (above ~1, other "
        "processes shared the CPU and the speeds are low)."
        + (f" OMPL's rows are its runs recorded in {args.ompl_from}, not run again."
           if args.ompl_from else ""),
        NOTES,
        results_table(summary, args.scenarios, args.budgets),
    ]
    if args.only is None:
        parts.append(ratios_table(summary, args.scenarios, args.budgets))
    for steering in args.steerings:
        if steering != "dubins" and args.only != "ompl":
            parts.append(steering_table(summary, args.scenarios, steering))
    if known:
        parts.append(f"Best known: the lowest cost in {BEST_KNOWN.name}, found by long runs "
                     f"(--long-s, seeds {LONG_SEEDS}) of ours and of OMPL BIT*.")
        parts.append(best_known_table(summary, args.scenarios, args.budgets, known))
    return "\n\n".join(parts) + "\n"


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    import planner

    files = [Path(a) if Path(a).is_file() else planner.bundled_scenario_path(a)
             for a in args.scenarios]
    scenarios = {(data := json.loads(f.read_text()))["name"]: data for f in files}
    paths = dict(zip(scenarios, files))
    args.scenarios = list(scenarios)
    runs_per_planner = len(paths) * len(args.seeds)
    n_ompl = (0 if args.only == OURS or args.ompl_from
              else runs_per_planner * len(OMPL_PLANNERS) * len(args.budgets))
    n_ours = 0 if args.only == "ompl" else runs_per_planner * len(args.steerings)

    ours = _our_planner() if n_ours else None  # fails before the OMPL runs, not after them
    start = time.perf_counter()
    records = ompl_records(args.ompl_from, args) if args.ompl_from else []
    with tqdm(total=n_ompl + n_ours, unit="run") as bar:
        if n_ours:
            records += our_runs(ours, paths, args.seeds, args.budgets, args.steerings, bar)
        if n_ompl:
            records += ompl_runs(scenarios, args.seeds, args.budgets, bar)
    options = sys.argv[1:] if argv is None else argv
    command = " ".join(["python benchmarks/bench_planner.py", *options])
    with_ompl = args.only is None and args.ompl_from is None
    known = (best_known(ours, paths, scenarios, args.long_s, with_ompl, args.renew_best_known)
             if ours is not None else {})
    text = report(summarise(records, args.budgets), args, command, time.perf_counter() - start,
                  known)

    print(text)
    _harness.write_result(args.out, text + kept_record(args.out))
    if args.json:
        args.json.write_text(json.dumps(records, indent=1))


if __name__ == "__main__":
    _harness.run(main)
