"""Options → plan report: the one function behind `trackstar plan`, POST /plan and batch jobs.

`run_plan` compiles a scenario, plans it with `planner.PlanOptions` and builds the `PlanReport`.
It is a plain top-level function so that the server's worker processes can run it.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from pydantic import BaseModel

from planner.options import PlanOptions
from planner.report import PlanReport

if TYPE_CHECKING:
    from planner.rrt import Planner
    from planner.timing import TimeOptimalPlanner

__all__ = ["TrackSource", "advance_in_parts", "check_scenario", "run_plan", "track_loader"]

MIN_PLANNING_SHARE = 0.1  # of the time budget, however long compiling took


class TrackSource(BaseModel):
    """An uploaded track that a scenario may name (by ``id``) as its drivable region: the file
    (``svg`` holds an SVG or a centreline CSV) and the options it was uploaded with."""

    id: str
    svg: bytes
    path: str | None = None
    unit: str | None = None
    closed: bool | None = None


def track_loader(track: TrackSource | None):
    """``load_track(name)`` for `planner.compile_problem`: the uploaded track, else the library.
    The tracks package (svgpathtools, SciPy's splines) loads only for a scenario with a track."""

    def load_track(name: str):
        import tracks

        if track is not None and name == track.id:
            return tracks.load_track(track.svg, path_id=track.path, unit=track.unit,
                                     closed=track.closed)
        return tracks.load_library_track(name)

    return load_track


def _compile(scenario, track: TrackSource | None):
    import planner as core

    if not isinstance(scenario, core.Scenario):
        scenario = core.parse_scenario(scenario)
    return core.compile_problem(scenario, load_track=track_loader(track))


def advance_in_parts(planner: Planner | TimeOptimalPlanner, time_s: float | None, iterations: int | None,
                     parts: int, observe: Callable[[Planner], None] | None = None,
                     stop: Callable[[], bool] | None = None) -> None:
    """Spend the budget in ``parts`` equal parts, ``observe(planner)`` after each (an
    animation's frames): the iterations add up exactly, so the tree is that of one part."""
    for k in range(parts):
        part = None if time_s is None else time_s / parts
        share = None if iterations is None else (iterations * (k + 1) // parts
                                                 - iterations * k // parts)
        if share != 0:
            planner.advance(part, share, stop)
        if observe is not None:
            observe(planner)


def check_scenario(scenario, track: TrackSource | None = None) -> None:
    """Raise `planner.ScenarioError` unless the scenario can be planned (start and goal free)."""
    _compile(scenario, track)


def run_plan(scenario, options: PlanOptions, *, max_time: float | None = None,
             track: TrackSource | None = None, stop: Callable[[], bool] | None = None,
             observe: Callable[[Planner], None] | None = None, chunks: int = 1) -> PlanReport:
    """Plan a scenario (a `planner.Scenario` or its JSON object) and report the result.

    The time budget covers compiling the scenario too, so a run ends within it (plus at most
    one planner iteration), except that planning always gets a tenth of it: a scene whose
    compiling takes longer (bounded by `planner._world.GRID_WORK`) overruns by that much rather
    than not being planned. ``stop()`` ends planning early, e.g. when the client has gone.
    ``observe(planner)`` sees the run after each of ``chunks`` equal parts of the budget (an
    animation's frames); the tree is the same as in one part. Raises `planner.ScenarioError`
    (a ValueError) for scenarios that cannot be planned and ValueError for bad options, each
    with a message that names the problem.
    """
    import planner as core
    from planner.report import plan_report

    budget_time = planning_time = options.time_budget(max_time)
    started = time.perf_counter()
    problem = _compile(scenario, track)
    if budget_time is not None:
        planning_time = max(budget_time - (time.perf_counter() - started),
                            MIN_PLANNING_SHARE * budget_time)
    planner = core.planner_for(problem, options)
    advance_in_parts(planner, planning_time, options.iterations, chunks, observe, stop)
    result = planner.result()
    return plan_report(result, problem.scenario.name,
                       {"time": budget_time, "iterations": options.iterations})
