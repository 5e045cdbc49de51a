"""OMPL's planners on our problems: the baseline of the benchmarks and the ``ompl:*`` targets
of studies (needs the ``bench`` extra: ``pip install 'trackstar[bench]'``).

The problem is set up as docs/scenario-format.md defines comparisons: Dubins (or
Reeds-Shepp) state space with our turning radius, poses checked every 0.02 m along motions, a
goal region with position and heading tolerances whose one goal sample is the exact goal pose,
path length as the objective with a cost threshold of 0 (the optimising planners use the whole
budget). Pose validity is a callable ``is_free(x, y, theta)``; for a study it is our own world's
clearance, so ours and OMPL plan on the same free space (ours also keeps the sag of its rows'
chords, a third of a millimetre: docs/planner.md "Valid as written").

OMPL's random seed is process-wide and takes effect only before the first random number is
drawn, so every seeded run needs a fresh process: `plan_isolated` starts one
(``python -m planner.ompl_bridge``).
"""

from __future__ import annotations

import itertools
import json
import math
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from planner._goal import goal_offset
from planner.steering import DEFAULT_STEERING, STEERINGS

__all__ = ["CHECK_STEP_M", "OMPL_PARAMETERS", "OMPL_PLANNERS", "OmplSetup", "available", "plan", "plan_isolated",
           "setup_from_problem"]

# Our target names → OMPL's class names (module ompl.geometric).
OMPL_PLANNERS = {"ompl:rrt": "RRT", "ompl:rrtstar": "RRTstar",
                 "ompl:informed-rrtstar": "InformedRRTstar", "ompl:bitstar": "BITstar"}
# The options each takes, under our names: eps is OMPL's range, goal_bias its goal bias.
OMPL_PARAMETERS = {"RRT": ("eps", "goal_bias"), "RRTstar": ("eps", "goal_bias"),
                   "InformedRRTstar": ("eps", "goal_bias"), "BITstar": ()}
STEERING_SPACES = {s.name: s.ompl_space for s in STEERINGS.values() if s.ompl_space}
CHECK_STEP_M = 0.02  # OMPL's motion checks, as docs/scenario-format.md asks for comparisons
RECHECK_STEP_M = 0.005  # re-check of the returned path: OMPL may clip a corner between samples


def available() -> bool:
    """True when OMPL's Python bindings can be imported."""
    try:
        import ompl.base  # noqa: F401
    except ImportError:
        return False
    return True


@dataclass(frozen=True)
class OmplSetup:
    """A static planning problem as OMPL needs it (SI units, radians)."""

    bounds: tuple[float, float, float, float]
    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    goal_position_tol: float
    goal_heading_tol: float
    rho: float
    is_free: Callable[[float, float, float], bool]
    clearance: Callable[[float, float, float], float] | None = None  # for min_clearance_m


def setup_from_problem(problem) -> OmplSetup:
    """A compiled `planner.Problem` with static obstacles, checked by our own world."""
    if problem.timed:
        raise ValueError("OMPL plans static scenes only: this scenario has moving obstacles")

    def clearance(x: float, y: float, theta: float) -> float:
        return problem.clearance(x, y, math.nan, theta)

    return OmplSetup(problem.bounds, problem.start, problem.goal, problem.goal_position_tol,
                     problem.goal_heading_tol, problem.rho,
                     lambda x, y, theta: clearance(x, y, theta) > problem.margin, clearance)


def _pose_goal(ob, si, setup: OmplSetup):
    """The goal region (docs/scenario-format.md) as an OMPL goal: distanceGoal <= 0 exactly inside
    it (threshold 0); its one sample is the exact goal pose, the goal bias of RRT*, and where BIT*
    (which reaches the goal only through goal samples) ends its paths."""

    region = np.array([*setup.goal, setup.goal_position_tol, setup.goal_heading_tol])

    class PoseGoal(ob.GoalSampleableRegion):
        def __init__(self) -> None:
            super().__init__(si)
            self.setThreshold(0.0)

        def distanceGoal(self, state) -> float:
            return goal_offset(state.getX(), state.getY(), state.getYaw(), region)

        def sampleGoal(self, state) -> None:
            _set_pose(state, setup.goal)

        def maxSampleCount(self) -> int:
            return 1

    return PoseGoal()


def _set_pose(state, pose) -> None:
    state.setX(float(pose[0]))
    state.setY(float(pose[1]))
    state.setYaw(float(pose[2]))


def _build(setup: OmplSetup, steering: str):
    """State space, space information and problem definition."""
    from ompl import base as ob

    if steering not in STEERING_SPACES:
        raise ValueError(f"OMPL has no '{steering}' steering here; use "
                         f"{' or '.join(STEERING_SPACES)}")
    space = getattr(ob, STEERING_SPACES[steering])(setup.rho)
    bounds = ob.RealVectorBounds(2)
    xmin, ymin, xmax, ymax = setup.bounds
    bounds.setLow(0, xmin)
    bounds.setLow(1, ymin)
    bounds.setHigh(0, xmax)
    bounds.setHigh(1, ymax)
    space.setBounds(bounds)

    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda s: setup.is_free(s.getX(), s.getY(), s.getYaw()))
    si.setStateValidityCheckingResolution(CHECK_STEP_M / space.getMaximumExtent())
    si.setup()

    pdef = ob.ProblemDefinition(si)
    start = space.allocState()
    _set_pose(start, setup.start)
    pdef.addStartState(start)
    pdef.setGoal(_pose_goal(ob, si, setup))
    objective = ob.PathLengthOptimizationObjective(si)
    objective.setCostThreshold(ob.Cost(0.0))  # never "good enough": use the whole budget
    pdef.setOptimizationObjective(objective)
    return space, si, pdef


def _solve(algorithm, time_limit: float | None, iterations: int | None
           ) -> tuple[float, list[tuple[int, float, float]]]:
    """Plan until the time limit or the iteration count, whichever comes first; return the
    elapsed seconds and the cost curve [(iteration, t_s, cost)] at each improvement.

    The 2.0.1 bindings take no Python intermediate-solution callback, so the curve is read by a
    Python termination condition, which OMPL evaluates once per iteration: it counts the
    iterations and polls bestCost(). RRT has no bestCost(); it stops at its first solution.
    """
    from ompl import base as ob

    has_best_cost = hasattr(algorithm, "bestCost")
    curve: list[tuple[int, float, float]] = []
    calls = [0]
    start = time.perf_counter()
    deadline = start + time_limit if time_limit is not None else math.inf

    def done() -> bool:
        now = time.perf_counter()
        calls[0] += 1
        if has_best_cost:
            cost = algorithm.bestCost().value()
            if math.isfinite(cost) and (not curve or cost < curve[-1][2]):
                curve.append((calls[0] - 1, now - start, cost))
        return now >= deadline or (iterations is not None and calls[0] > iterations)

    algorithm.solve(ob.PlannerTerminationCondition(done))
    return time.perf_counter() - start, curve


def _path_poses(space, path, step: float):
    """The path's poses every ``step`` metres (OMPL itself checked every 0.02 m)."""
    pose = space.allocState()
    states = [path.getState(i) for i in range(path.getStateCount())]
    for a, b in itertools.pairwise(states):
        n = max(1, math.ceil(space.distance(a, b) / step))
        for i in range(n + 1):
            space.interpolate(a, b, i / n, pose)
            yield pose.getX(), pose.getY(), pose.getYaw()


def plan(setup: OmplSetup, planner: str, steering: str = DEFAULT_STEERING, *, seed: int = 0,
         time_limit: float | None = None, iterations: int | None = None,
         eps: float | None = None, goal_bias: float | None = None) -> dict:
    """Plan once with OMPL's ``planner`` (a class name of `OMPL_PLANNERS`); the seed is
    honoured once per process only (use `plan_isolated`). OMPL refuses seed 0, so its seed is
    ``seed + 1``.

    ``iterations`` is OMPL's own count where it has one (RRT* loop iterations, BIT* queue
    iterations), else the termination condition's; ``nodes`` counts tree vertices as edges + 1,
    because BIT*'s planner data also lists its unconnected samples. Cost is the path length of
    an exact solution; ``valid_5mm`` re-checks it every 5 mm and ``min_clearance_m`` is measured
    there too (when the set-up has a clearance).
    """
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    if time_limit is None and iterations is None:
        raise ValueError("give OMPL a time limit or an iteration count")
    ou.setLogLevel(ou.LOG_ERROR)
    ou.RNG.setSeed(seed + 1)
    space, si, pdef = _build(setup, steering)
    algorithm = getattr(og, planner)(si)
    if eps is not None:
        algorithm.setRange(eps)
    if goal_bias is not None:
        algorithm.setGoalBias(goal_bias)
    algorithm.setProblemDefinition(pdef)
    algorithm.setup()

    elapsed, curve = _solve(algorithm, time_limit, iterations)
    solved = pdef.hasExactSolution()
    path = pdef.getSolutionPath() if solved else None
    count = (algorithm.numIterations() if hasattr(algorithm, "numIterations")
             else curve[-1][0] if curve else None)
    if solved and not curve:  # RRT: its one solution, found at the end
        curve = [(count or 0, elapsed, path.length())]
    data = ob.PlannerData(si)
    algorithm.getPlannerData(data)
    poses = list(_path_poses(space, path, RECHECK_STEP_M)) if solved else []
    clearances = ([setup.clearance(*p) for p in poses]
                  if solved and setup.clearance is not None else [])
    return {
        "planner": planner, "steering": steering, "seed": seed, "time_limit_s": time_limit,
        "solved": solved,
        "cost": path.length() if solved else None,
        "time_to_first_solution_s": curve[0][1] if curve else None,
        "iterations": count,
        "iterations_per_s": count / elapsed if count is not None and elapsed > 0 else None,
        "nodes": data.numEdges() + 1,
        "valid_5mm": all(setup.is_free(*p) for p in poses) if solved else None,
        "min_clearance_m": min(clearances) if clearances else None,
        "planning_time_s": elapsed,
        "cost_over_time": curve,
    }


def plan_isolated(scenario: dict, planner: str, **options) -> dict:
    """`plan` in a fresh Python process on a scenario (its JSON object), checked by our world,
    so that the seed takes effect on every run. Raises RuntimeError with OMPL's message."""
    request = json.dumps({"scenario": scenario, "planner": planner, "options": options})
    done = subprocess.run([sys.executable, "-m", "planner.ompl_bridge"], input=request,
                          capture_output=True, text=True, check=False)
    if done.returncode != 0:
        lines = done.stderr.strip().splitlines() or [f"exit {done.returncode}"]
        raise RuntimeError(f"OMPL {planner}: {lines[-1]}")
    return json.loads(done.stdout.splitlines()[-1])


def _main() -> None:
    """Read a `plan_isolated` request on stdin, print the result as one JSON line."""
    import planner as core

    request = json.loads(sys.stdin.read())
    problem = core.compile_problem(core.parse_scenario(request["scenario"]))
    result = plan(setup_from_problem(problem), request["planner"], **request["options"])
    print(json.dumps(result), flush=True)


if __name__ == "__main__":
    _main()
