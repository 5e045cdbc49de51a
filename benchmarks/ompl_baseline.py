"""OMPL baseline for the planner benchmark: one (scenario, planner, time limit, seed) run.

The problem is set up the way the shared scenarios' FORMAT.md defines it: Dubins steering, a
pure-Python pose validity checker with FORMAT.md's exact semantics, motions checked every 0.02 m, a
goal region with position and heading tolerances, path length as the objective.

OMPL's random seed is process-wide and takes effect only before the first random number is drawn, so
each run needs a fresh process: `run_ompl_isolated` (used by bench_planner.py) starts one; run as a
script, this file plans one run and prints its result as a JSON line:

    python benchmarks/ompl_baseline.py planner/scenarios/slalom.json --planner BITstar
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

__all__ = ["PLANNERS", "run_ompl", "run_ompl_isolated", "make_pose_checker", "turning_radius"]

PLANNERS: dict[str, Callable[[ob.SpaceInformation], ob.Planner]] = {
    "RRT": og.RRT,
    "RRTstar": og.RRTstar,
    "InformedRRTstar": og.InformedRRTstar,
    "BITstar": og.BITstar,
}
CHECK_STEP_M = 0.02  # OMPL's motion-check resolution, as FORMAT.md asks for comparisons
RECHECK_STEP_M = 0.005  # re-check of the returned path, to count clipped obstacle corners


def turning_radius(vehicle: dict) -> float:
    """Minimum turning radius: `min_turning_radius` if given, else wheelbase / tan(max steer)."""
    if "min_turning_radius" in vehicle:
        return float(vehicle["min_turning_radius"])
    return vehicle["wheelbase"] / math.tan(math.radians(vehicle["max_steer_deg"]))


def make_pose_checker(scenario: dict) -> Callable[[float, float], bool]:
    """Return `is_free(x, y)`, FORMAT.md's pose validity (heading never matters).

    Plain Python floats and precomputed tuples: OMPL calls this for every checked pose, and a
    numpy call per pose would cost more than the arithmetic it does.
    """
    r = float(scenario["vehicle"].get("radius", 0.0))
    xmin, ymin, xmax, ymax = scenario["bounds"]
    lo_x, lo_y, hi_x, hi_y = xmin + r, ymin + r, xmax - r, ymax - r
    obstacles = scenario["obstacles"]
    circles = [_circle(o, r) for o in obstacles if o["type"] == "circle"]
    polygons = [_polygon(o, r) for o in obstacles if o["type"] == "polygon"]
    r2 = r * r

    def is_free(x: float, y: float) -> bool:
        if not (lo_x <= x <= hi_x and lo_y <= y <= hi_y):
            return False
        for cx, cy, reach2 in circles:
            dx, dy = x - cx, y - cy
            if dx * dx + dy * dy <= reach2:
                return False
        for bx0, by0, bx1, by1, edges in polygons:
            if x < bx0 or x > bx1 or y < by0 or y > by1:
                continue
            if _inside(x, y, edges) or (r2 > 0.0 and _near_edge(x, y, edges, r2)):
                return False
        return True

    return is_free


def _circle(obstacle: dict, r: float) -> tuple[float, float, float]:
    """(cx, cy, (radius + r)^2): a pose collides when its squared distance is <= the last."""
    cx, cy = obstacle["center"]
    return float(cx), float(cy), (obstacle["radius"] + r) ** 2


def _polygon(obstacle: dict, r: float) -> tuple:
    """Bounding box grown by r (outside it a pose is farther than r) and the edge list.

    Each edge is (x1, y1, y2, dx/dy or None, ex, ey, |e|^2): the crossing test and the
    point-to-segment distance then need no division per call.
    """
    points = [(float(x), float(y)) for x, y in obstacle["points"]]
    edges = []
    for (x1, y1), (x2, y2) in zip(points, points[1:] + points[:1]):
        ex, ey = x2 - x1, y2 - y1
        edges.append((x1, y1, y2, ex / ey if ey else None, ex, ey, ex * ex + ey * ey))
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    return min(xs) - r, min(ys) - r, max(xs) + r, max(ys) + r, edges


def _inside(x: float, y: float, edges: list) -> bool:
    """Even-odd rule: count edges crossed by the ray from (x, y) towards +x."""
    inside = False
    for x1, y1, y2, dxdy, _, _, _ in edges:
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * dxdy:
            inside = not inside
    return inside


def _near_edge(x: float, y: float, edges: list, r2: float) -> bool:
    """True if (x, y) is within distance r (squared: r2) of some edge, touching included."""
    for x1, y1, _, _, ex, ey, length2 in edges:
        px, py = x - x1, y - y1
        t = (px * ex + py * ey) / length2 if length2 else 0.0
        t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
        dx, dy = px - t * ex, py - t * ey
        if dx * dx + dy * dy <= r2:
            return True
    return False


def _wrap(angle: float) -> float:
    """Angle wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


class PoseGoal(ob.GoalSampleableRegion):
    """FORMAT.md's goal: within `position` metres and `heading` radians of the goal pose.

    distanceGoal is <= 0 exactly inside the region (threshold 0), so OMPL's isSatisfied means what
    FORMAT.md means. The only goal sample is the exact goal pose: that is the goal bias of RRT*,
    and BIT* (which reaches the goal only through goal samples) ends its paths there.
    """

    def __init__(self, si: ob.SpaceInformation, pose: list[float], tolerance: dict) -> None:
        super().__init__(si)
        self.setThreshold(0.0)
        self._x, self._y, self._theta = (float(v) for v in pose)
        self._position = float(tolerance.get("position", 0.25))
        self._heading = math.radians(tolerance.get("heading_deg", 20.0))

    def distanceGoal(self, state: ob.State) -> float:
        off_position = math.hypot(state.getX() - self._x, state.getY() - self._y) - self._position
        off_heading = abs(_wrap(state.getYaw() - self._theta)) - self._heading
        return max(off_position, off_heading)

    def sampleGoal(self, state: ob.State) -> None:
        state.setX(self._x)
        state.setY(self._y)
        state.setYaw(self._theta)

    def maxSampleCount(self) -> int:
        return 1


def _build_problem(scenario: dict, is_free: Callable[[float, float], bool]
                   ) -> tuple[ob.DubinsStateSpace, ob.SpaceInformation, ob.ProblemDefinition]:
    """Dubins space over the scenario bounds, the pose checker, start, goal region, path length."""
    space = ob.DubinsStateSpace(turning_radius(scenario["vehicle"]))
    bounds = ob.RealVectorBounds(2)
    xmin, ymin, xmax, ymax = scenario["bounds"]
    bounds.setLow(0, xmin)
    bounds.setLow(1, ymin)
    bounds.setHigh(0, xmax)
    bounds.setHigh(1, ymax)
    space.setBounds(bounds)

    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda state: is_free(state.getX(), state.getY()))
    si.setStateValidityCheckingResolution(CHECK_STEP_M / space.getMaximumExtent())
    si.setup()

    pdef = ob.ProblemDefinition(si)
    pdef.addStartState(_state(space, scenario["start"]))
    pdef.setGoal(PoseGoal(si, scenario["goal"], scenario.get("goal_tolerance", {})))
    objective = ob.PathLengthOptimizationObjective(si)
    objective.setCostThreshold(ob.Cost(0.0))  # never "good enough": optimise for the whole budget
    pdef.setOptimizationObjective(objective)
    return space, si, pdef


def _state(space: ob.DubinsStateSpace, pose: list[float]) -> ob.State:
    state = space.allocState()
    state.setX(float(pose[0]))
    state.setY(float(pose[1]))
    state.setYaw(float(pose[2]))
    return state


def _solve_timed(planner: ob.Planner, time_limit: float) -> tuple[float, float | None]:
    """Plan until the time limit; return (elapsed s, time to first solution s or None).

    The 2.0.1 bindings cannot take a Python intermediate-solution callback, and RRT* publishes its
    solution to the problem definition only when it returns, so the first solution is seen by a
    Python termination condition, which OMPL evaluates once per iteration: it polls bestCost().
    RRT has no bestCost(), but it stops at its first solution.
    """
    has_best_cost = hasattr(planner, "bestCost")
    first: list[float] = []
    start = time.perf_counter()
    deadline = start + time_limit

    def done() -> bool:
        now = time.perf_counter()
        if has_best_cost and not first and math.isfinite(planner.bestCost().value()):
            first.append(now - start)
        return now >= deadline

    planner.solve(ob.PlannerTerminationCondition(done))
    elapsed = time.perf_counter() - start
    if not first and planner.getProblemDefinition().hasExactSolution():
        first.append(elapsed)
    return elapsed, (first[0] if first else None)


def _path_valid(space: ob.DubinsStateSpace, path: og.PathGeometric,
                is_free: Callable[[float, float], bool], step: float) -> bool:
    """Re-check every pose of the path `step` metres apart (OMPL itself checked every 0.02 m)."""
    pose = space.allocState()
    states = [path.getState(i) for i in range(path.getStateCount())]
    for a, b in zip(states, states[1:]):
        n = max(1, math.ceil(space.distance(a, b) / step))
        for i in range(n + 1):
            space.interpolate(a, b, i / n, pose)
            if not is_free(pose.getX(), pose.getY()):
                return False
    return True


def run_ompl(scenario: dict, planner: str, time_limit: float, seed: int) -> dict:
    """Plan one scenario with one OMPL planner; seeds are honoured once per process only.

    OMPL refuses seed 0, so OMPL's seed is `seed + 1` (seeds 0 and 1 would otherwise coincide).

    `iterations` is the planner's own count (RRT* loop iterations, BIT* queue iterations; None for
    RRT, which has no counter). `nodes` counts tree vertices as edges + 1, because BIT*'s planner
    data also lists its unconnected samples. Cost is the Dubins length of an exact solution.
    """
    ou.setLogLevel(ou.LOG_ERROR)
    ou.RNG.setSeed(seed + 1)
    is_free = make_pose_checker(scenario)
    space, si, pdef = _build_problem(scenario, is_free)
    algorithm = PLANNERS[planner](si)
    algorithm.setProblemDefinition(pdef)
    algorithm.setup()

    elapsed, first_s = _solve_timed(algorithm, time_limit)
    solved = pdef.hasExactSolution()
    path = pdef.getSolutionPath() if solved else None
    iterations = algorithm.numIterations() if hasattr(algorithm, "numIterations") else None
    data = ob.PlannerData(si)
    algorithm.getPlannerData(data)
    return {
        "scenario": scenario["name"],
        "planner": planner,
        "time_limit_s": time_limit,
        "seed": seed,
        "solved": solved,
        "cost": path.length() if solved else None,
        "time_to_first_solution_s": first_s,
        "iterations": iterations,
        "iterations_per_s": iterations / elapsed if iterations is not None else None,
        "nodes": data.numEdges() + 1,
        "valid_5mm": _path_valid(space, path, is_free, RECHECK_STEP_M) if solved else None,
    }


def run_ompl_isolated(scenario: dict, planner: str, time_limit: float, seed: int) -> dict:
    """`run_ompl` in a fresh Python process, so that the seed takes effect on every run."""
    command = [sys.executable, str(Path(__file__).resolve()), "-", "--planner", planner,
               "--time-limit", str(time_limit), "--seed", str(seed)]
    done = subprocess.run(command, input=json.dumps(scenario), capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"OMPL {planner} on {scenario['name']} failed:\n{done.stderr}")
    return json.loads(done.stdout.splitlines()[-1])


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", help="scenario JSON file (FORMAT.md), or - for stdin")
    parser.add_argument("--planner", choices=sorted(PLANNERS), default="RRTstar")
    parser.add_argument("--time-limit", type=float, default=1.0, help="seconds (default 1)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    text = sys.stdin.read() if args.scenario == "-" else Path(args.scenario).read_text()
    result = run_ompl(json.loads(text), args.planner, args.time_limit, args.seed)
    print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
