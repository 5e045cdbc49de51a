"""OMPL baseline for the planner benchmark: one (scenario, planner, time limit, seed) run.

The problem is set up by `planner.ompl_bridge` the way docs/scenario-format.md defines it
(Dubins steering, motions checked every 0.02 m, a goal region with position and heading
tolerances, path length as the objective); pose validity here is a pure-Python checker with
docs/scenario-format.md's exact semantics, so that this baseline does not depend on our
compiled world.

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
from collections.abc import Callable
from pathlib import Path

from planner.ompl_bridge import OMPL_PLANNERS, OmplSetup, plan

__all__ = ["PLANNERS", "run_ompl", "run_ompl_isolated", "make_pose_checker", "turning_radius"]

PLANNERS = sorted(OMPL_PLANNERS.values())


def turning_radius(vehicle: dict) -> float:
    """Minimum turning radius: `min_turning_radius` if given, else wheelbase / tan(max steer)."""
    if "min_turning_radius" in vehicle:
        return float(vehicle["min_turning_radius"])
    return vehicle["wheelbase"] / math.tan(math.radians(vehicle["max_steer_deg"]))


def make_pose_checker(scenario: dict) -> Callable[[float, float], bool]:
    """Return `is_free(x, y)`, docs/scenario-format.md's pose validity (heading never matters).

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


def ompl_setup(scenario: dict) -> OmplSetup:
    """A scenario (docs/scenario-format.md) as the bridge's set-up, checked by the pure-Python
    checker."""
    is_free = make_pose_checker(scenario)
    tolerance = scenario.get("goal_tolerance", {})
    return OmplSetup(tuple(scenario["bounds"]), tuple(scenario["start"]), tuple(scenario["goal"]),
                     float(tolerance.get("position", 0.25)),
                     math.radians(tolerance.get("heading_deg", 20.0)),
                     turning_radius(scenario["vehicle"]), lambda x, y, _theta: is_free(x, y))


def run_ompl(scenario: dict, planner: str, time_limit: float, seed: int) -> dict:
    """Plan one scenario with one OMPL planner (`planner.ompl_bridge.plan`); the seed is
    honoured once per process only."""
    result = plan(ompl_setup(scenario), planner, seed=seed, time_limit=time_limit)
    return {"scenario": scenario["name"], **result}


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
    parser.add_argument("scenario", 
                        help="scenario JSON file (docs/scenario-format.md), or - for stdin")
    parser.add_argument("--planner", choices=sorted(PLANNERS), default="RRTstar")
    parser.add_argument("--time-limit", type=float, default=1.0, help="seconds (default 1)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    text = sys.stdin.read() if args.scenario == "-" else Path(args.scenario).read_text()
    result = run_ompl(json.loads(text), args.planner, args.time_limit, args.seed)
    print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
