"""Run a study's remaining runs on a backend (this machine's pool or Ray), storing each the
moment it finishes, then write its table and report."""

from __future__ import annotations

import shutil
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

import planner
from app.planning import run_plan
from app.pool import first_line
from app.study.backends import open_backend
from app.study.report import write_report
from app.study.results import Results
from app.study.spec import Run, SimRun, Study
from planner.ompl_bridge import OMPL_PLANNERS, plan_isolated

__all__ = ["Summary", "execute", "run_study"]


@dataclass(frozen=True)
class Summary:
    """What `trackstar study --json` prints."""

    study: str
    out: str
    total: int
    done: int  # runs stored and finished, over all invocations
    skipped: int  # runs found already stored at the start
    failed: int
    wall_s: float
    results: str
    csv: str
    report: str


def execute(scenario: planner.Scenario, run: Run | SimRun, max_time: float | None = None,
            stop: Callable[[], bool] | None = None) -> tuple[dict, list]:
    """One run, in a worker: its outcome row and (planning runs) its cost curve (iteration,
    t_s, cost) — the numbers `trackstar plan --json` (`simulate --json`) prints for the same
    options. ``max_time`` caps a plan's time (a server's --max-plan-s); ``stop()`` ends our
    planners' runs early (a cancelled study)."""
    started = time.perf_counter()
    try:
        outcome, curve = (_simulate(scenario, run) if isinstance(run, SimRun) else
                          _plan(scenario, run, max_time, stop))
    except Exception as exc:  # noqa: BLE001  (stored with the run; the study goes on)
        outcome, curve = {"error": first_line(exc)}, []
    return outcome | {"wall_s": time.perf_counter() - started}, curve


def _plan(scenario: planner.Scenario, run: Run, max_time: float | None,
          stop: Callable[[], bool] | None) -> tuple[dict, list]:
    if run.planner in OMPL_PLANNERS:
        return _plan_ompl(scenario, run, max_time)
    report = run_plan(scenario, run.options(), max_time=max_time, stop=stop)
    rate = report.iterations / report.planning_time_s if report.planning_time_s > 0 else None
    outcome = {
        "solved": int(report.solved), "cost": report.cost,
        "time_to_first_solution_s": report.time_to_first_solution_s,
        "iterations": report.iterations, "nodes": report.nodes,
        "collision_checks": report.collision_checks, "min_clearance_m": report.min_clearance_m,
        "iterations_per_s": rate, "polish_s": report.polish_s}
    return outcome, [(i, t, cost) for t, cost, i in report.cost_over_time]


def _plan_ompl(scenario: planner.Scenario, run: Run,
               max_time: float | None) -> tuple[dict, list]:
    """OMPL's planner in a fresh process (its seed is process-wide), on our world's free space.
    It counts no motion checks of ours, so ``collision_checks`` stays empty."""
    limits = [t for t in (run.budget_time_s, max_time) if t is not None]
    r = plan_isolated(scenario.model_dump(mode="json"), OMPL_PLANNERS[run.planner],
                      steering=run.steering, seed=run.seed, iterations=run.budget_iterations,
                      time_limit=min(limits) if limits else None, **run.parameters)
    outcome = {"solved": int(r["solved"]), "collision_checks": None} | {
        k: r[k] for k in ("cost", "time_to_first_solution_s", "iterations", "nodes",
                          "min_clearance_m", "iterations_per_s")}
    return outcome, [tuple(point) for point in r["cost_over_time"]]


def _simulate(scenario: planner.Scenario, run: SimRun) -> tuple[dict, list]:
    from planner.sim import simulate

    problem = planner.compile_problem(scenario)
    s = simulate(problem.scenario, run.options().settings(), problem).summary
    return {"reached": int(s["reached_goal"]), "collisions": s["collisions"],
            "collisions_moving": s["collisions_moving"],
            "collisions_at_rest": s["collisions_at_rest"],
            "min_clearance_m": s["min_clearance_m"], "time_to_goal_s": s["time_to_goal_s"],
            "cycle_p50_ms": s["cycle_ms"]["p50"], "cycle_p99_ms": s["cycle_ms"]["p99"],
            "replans": s["replans"], "emergency_stops": s["emergency_stops"],
            "max_lateral_error_m": s["cross_track_error_m"]["max"]}, []


def run_study(study: Study, out: Path, workers: int, backend: str = "local") -> Summary:
    """Run what ``out`` does not hold yet on ``backend`` (`backends.BACKENDS`). Ctrl-C stops
    the workers and raises KeyboardInterrupt once every finished run is stored."""
    started = time.perf_counter()
    results = Results(out, study.name, study.kind, study.text)
    try:
        done = results.done()
        todo = [run for run in study.runs if run.key not in done]
        skipped = len(study.runs) - len(todo)
        if skipped:
            print(f"{skipped} of {len(study.runs)} runs already in {results.path}: skipped",
                  file=sys.stderr)
        if todo:
            try:
                runner = open_backend(backend, min(workers, len(todo)))
            except BaseException:
                results.discard()
                raise
            try:
                _run_on(runner, study, todo, results)
            finally:
                runner.close()
        stored, failed = results.count()
        results.write_csv(out / "results.csv")
    finally:
        results.close()
    report = write_report(results.path, study.kind, out)
    return Summary(study.name, str(out), len(study.runs), stored - failed, skipped, failed,
                   time.perf_counter() - started, str(results.path), str(out / "results.csv"),
                   str(report))


def _run_on(backend, study: Study, todo: list, results: Results) -> None:
    # A terminal that reports a size of 0 × 0 (a pty under script(1), some CI consoles) makes
    # tqdm count -1 rows and draw nothing at all; shutil falls back to 80 × 24 there.
    cols, rows = shutil.get_terminal_size()
    bar = tqdm(total=len(todo), desc=study.name, unit="run", file=sys.stderr,
               disable=not sys.stderr.isatty(), ncols=cols, nrows=rows)
    pending: dict = {}
    queue = iter(todo)
    solved = 0
    try:
        while True:
            while len(pending) < 2 * backend.workers:  # short: Ctrl-C cancels little work
                run = next(queue, None)
                if run is None:
                    break
                pending[backend.submit(execute, study.scenarios[run.scenario], run)] = run
            if not pending:
                break
            for handle in backend.finished(pending):
                run = pending.pop(handle)
                outcome, curve = backend.result(handle)
                results.add(run, outcome, curve)
                solved += outcome.get("solved", outcome.get("reached", 0)) or 0
                bar.update()
                bar.set_postfix({"solved" if study.kind == "plan" else "reached": solved},
                                refresh=False)
    finally:
        bar.close()
