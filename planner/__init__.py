"""Trackstar's planning core: car steering, worlds with moving obstacles, RRT and RRT*.

Importable without any web dependency. Typical use::

    import planner
    scenario = planner.load_scenario("slalom")   # a bundled name or a scenario file
    result = planner.solve(scenario, planner="rrtstar", time_limit=1.0, seed=0)

The names below load on first use, so that ``import planner.options`` (the command line's
options) does not load numba and the compiled kernels.
"""

from __future__ import annotations

import importlib
import os
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from planner._paths import path_length, path_word
    from planner.options import PlanOptions
    from planner.problem import Problem, compile_problem
    from planner.rrt import Planner, Result
    from planner.scenario import (
        Scenario,
        ScenarioError,
        bundled_scenario_path,
        load_scenario,
        parse_scenario,
        scenario_names,
        scenario_schema,
    )
    from planner.steering import STEERINGS
    from planner.timing import TimeOptimalPlanner, planner_for
    from planner.tree import Rewire, TreeEvents, TreeSnapshot

_HOMES = {
    "PlanOptions": "options", "STEERINGS": "steering",
    "Problem": "problem", "compile_problem": "problem",
    "Planner": "rrt", "Result": "rrt",
    "Rewire": "tree", "TreeEvents": "tree", "TreeSnapshot": "tree",
    "Scenario": "scenario", "ScenarioError": "scenario", "bundled_scenario_path": "scenario",
    "load_scenario": "scenario", "parse_scenario": "scenario", "scenario_names": "scenario",
    "scenario_schema": "scenario", "TimeOptimalPlanner": "timing", "planner_for": "timing",
    "path_length": "_paths", "path_word": "_paths",
}

__all__ = [
    "STEERINGS", "PlanOptions", "Planner", "Problem", "Result", "Rewire", "Scenario",
    "ScenarioError", "TimeOptimalPlanner", "TreeEvents", "TreeSnapshot", "bundled_scenario_path",
    "compile_problem", "load_scenario", "parse_scenario", "path_length", "path_word",
    "planner_for", "scenario_names", "scenario_schema", "solve",
]


def __getattr__(name: str):
    if name not in _HOMES:
        raise AttributeError(f"module 'planner' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"planner.{_HOMES[name]}"), name)
    globals()[name] = value
    return value


def solve(scenario: Scenario | Problem | str | os.PathLike, *, time_limit: float | None = 1.0,
          iterations: int | None = None, **options) -> Result:
    """Plan a scenario once — a `Scenario`, a compiled `Problem`, a scenario file or a bundled
    scenario's name (``planner.solve("slalom", seed=3)``); ``options`` are `PlanOptions`
    fields (``planner="rrt"``, ``steering="straight"``, …)."""
    from planner.options import PlanOptions
    from planner.problem import Problem, compile_problem
    from planner.scenario import load_scenario
    from planner.timing import planner_for

    if isinstance(scenario, (str, os.PathLike)):
        scenario = load_scenario(scenario)
    problem = scenario if isinstance(scenario, Problem) else compile_problem(scenario)
    return planner_for(problem, PlanOptions(**options)).solve(time_limit, iterations)
