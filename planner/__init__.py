"""Trackstar's planning core: car steering, worlds with moving obstacles, RRT and RRT*.

Importable without any web dependency. Typical use::

    import planner
    scenario = planner.load_scenario("slalom")   # a bundled name or a scenario file
    result = planner.solve(scenario, algorithm="rrtstar", time_limit=1.0, seed=0)
"""

from __future__ import annotations

from planner.problem import Problem, compile_problem
from planner.rrt import Planner, PlannerSettings, Result, TreeEvents, TreeSnapshot
from planner.rrt import solve as _solve_problem
from planner.scenario import (
    Scenario,
    ScenarioError,
    bundled_scenario_path,
    load_scenario,
    parse_scenario,
    scenario_names,
    scenario_schema,
)

__all__ = [
    "Planner", "PlannerSettings", "Problem", "Result", "Scenario", "ScenarioError",
    "TreeEvents", "TreeSnapshot", "bundled_scenario_path", "compile_problem", "load_scenario",
    "parse_scenario", "scenario_names", "scenario_schema", "solve",
]


def solve(scenario: Scenario | Problem, *, time_limit: float | None = 1.0,
          iterations: int | None = None, planner: str | None = None, **settings) -> Result:
    """Plan a scenario (or compiled problem). ``planner`` is an alias of ``algorithm``."""
    problem = scenario if isinstance(scenario, Problem) else compile_problem(scenario)
    if planner is not None:
        settings["algorithm"] = planner
    return _solve_problem(problem, time_limit=time_limit, iterations=iterations, **settings)
