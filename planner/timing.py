"""Time-optimal planning (``timing: optimal``): the earliest arrival, waiting for movers if that
is faster than going round them.

The car may drive at any speed up to ``vehicle.max_speed`` and may stand still. We decompose
path and speed (Kant & Zucker 1986): a path is chosen first, then the fastest schedule along it
through the movers (`planner._schedule`, exact in space-time). Two paths are timed:

* the *route*: the best path of an RRT* tree grown among the static obstacles alone — where the
  car could go if it waited for every mover (a gate that opens, a train that passes);
* the *detour*: the best path of the usual space-time tree at constant ``speed`` (the
  ``constant`` plan of the same seed), which goes round movers; it is kept as it was planned
  as well, so an optimal plan never arrives later than the constant plan of its trees.

The earlier arrival wins. What the decomposition cannot find is a path that needs both — going
round one mover and waiting for another — unless one of the two trees holds it; a space-time
tree with a speed choice (ST-RRT*, Grothe et al. 2022) would (docs/planner.md).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from planner._rows import SPACING_M, polyline_clearance
from planner._schedule import earliest_arrival, no_wait_needed, pose_on
from planner._world import without_movers
from planner.options import TIMINGS, PlanOptions
from planner.problem import Problem
from planner.rrt import Planner, Result, checked_world
from planner.scenario import ScenarioError

__all__ = ["TIMINGS", "Schedule", "TimeOptimalPlanner", "fastest_schedule", "planner_for",
           "warm_up"]

MAX_STEP_S = 0.1  # docs/scenario-format.md v1.3: entries at most `SPACING_M` and this apart
EXTRA_WAIT_S = 60.0  # how long past the top-speed arrival a schedule may wait, at least
MAX_WAIT_S = 600.0  # … and at most, whatever the waypoints' times
MAX_CELLS = 4_000_000  # s–t grid points; a longer path or horizon gets coarser stations
MAX_ROWS = 200_000  # path entries of a timed path (docs/scenario-format.md): about 10 MB of JSON
PROBE_SHARE = 0.2  # of a time budget, for each tree before the leader takes the rest


@dataclass(frozen=True)
class Schedule:
    """When the car is where on a tree's best path: at ``vmax`` between stations ``ds`` apart,
    standing ``waits[i]``·``dt`` at station i (None: never)."""

    planner: Planner
    vmax: float
    length_m: float
    ds: float = 0.0
    dt: float = 0.0
    waits: np.ndarray | None = None

    @property
    def waited_s(self) -> float:
        return 0.0 if self.waits is None else float(self.waits.sum() * self.dt)

    @property
    def spacing_m(self) -> float:
        """docs/scenario-format.md v1.3's: entries at most 0.05 m apart, and 0.1 s at vmax."""
        return min(SPACING_M, MAX_STEP_S * self.vmax)

    @property
    def arrival_s(self) -> float:
        return self.length_m / self.vmax + self.waited_s

    def rows(self) -> np.ndarray:
        """The path as rows x, y, θ, κ, direction, t (docs/scenario-format.md v1.3): at most
        `spacing_m` m and `MAX_STEP_S` s apart."""
        dense = self.planner.dense_path(self.spacing_m)
        s_rows = dense[:, 5] * self.planner.options.speed  # driven length
        if self.waits is None:
            return _with_times(dense, s_rows / self.vmax)
        ds, dt, waits, n = self.ds, self.dt, self.waits, len(self.waits) - 1
        # Station i is reached at arrive[i] and left at leave[i]; between stations, top speed.
        leave = (np.arange(n + 1) + np.cumsum(waits)) * dt
        arrive = leave - waits * dt
        i = np.minimum((s_rows / ds).astype(np.int64), n - 1)
        rows, arcs = [_with_times(dense, leave[i] + (s_rows - i * ds) / self.vmax)], [s_rows]
        for k in np.flatnonzero(waits):
            x, y, th = pose_on(*self.planner.best_path_segments(), k * ds)
            j = min(int(np.searchsorted(s_rows, k * ds)), len(dense) - 1)
            instants = np.linspace(arrive[k], leave[k], math.ceil(waits[k] * dt / MAX_STEP_S) + 1)
            wait = np.tile([x, y, th, dense[j, 3], dense[j, 4], 0.0], (len(instants), 1))
            wait[:, 5] = instants
            rows.append(wait)
            arcs.append(np.full(len(instants), k * ds))
        rows, arcs = np.vstack(rows), np.concatenate(arcs)
        rows = rows[np.lexsort((arcs, rows[:, 5]))]  # by time, then by arc
        repeated = np.all(np.diff(rows[:, [0, 1, 2, 5]], axis=0) == 0.0, axis=1)
        return rows[np.concatenate([[True], ~repeated])]


def fastest_schedule(planner: Planner, world, vmax: float,
                     wait_s: float | None = None) -> Schedule | None:
    """``planner``'s best path with the earliest arrival among ``world``'s movers at speeds up
    to ``vmax``, or None if every schedule collides that arrives within ``wait_s`` of the
    top-speed arrival (default: `EXTRA_WAIT_S` or until the last waypoint's time, at most
    `MAX_WAIT_S`)."""
    if not planner.solved:
        return None
    length = float(planner.best_cost)
    if length == 0.0 or no_wait_needed(world):
        return Schedule(planner, vmax, length)
    if wait_s is None:
        last_wp = float(world.m_wp[:, 0].max()) if world.m_wp.shape[0] else 0.0
        wait_s = min(max(EXTRA_WAIT_S, last_wp), MAX_WAIT_S)
    horizon = length / vmax + wait_s
    ds = max(min(SPACING_M, MAX_STEP_S * vmax),
             math.sqrt(length * horizon * vmax / MAX_CELLS))
    n = max(1, math.ceil(length / ds))
    ds = length / n
    dt = ds / vmax
    waits = np.zeros(n + 1, np.int64)
    arrival = earliest_arrival(world, *planner.best_path_segments(), n, ds, dt,
                               math.ceil(horizon / dt), waits)
    return Schedule(planner, vmax, length, ds, dt, waits) if arrival >= 0 else None


def _with_times(dense: np.ndarray, t: np.ndarray) -> np.ndarray:
    out = dense.copy()
    out[:, 5] = t
    return out


class TimeOptimalPlanner:
    """`timing: optimal`: a route tree among the static obstacles and a detour tree in space
    time (module docstring), each timed at the end; the earlier arrival is the result. Drives
    like a `Planner` (``advance``, ``solve``, ``result``); ``route`` is the tree to watch."""

    def __init__(self, problem: Problem, options: PlanOptions) -> None:
        self.problem = problem
        self.options = options.resolved(problem)
        self.vmax = problem.top_speed
        static = dataclasses.replace(problem, world=without_movers(problem.world), timed=False)
        self.route = Planner(static, options)
        self.detour = Planner(problem, options) if problem.timed else None
        self._movers = checked_world(problem.world, problem, self.route.options)

    @property
    def planners(self) -> list[Planner]:
        return [p for p in (self.route, self.detour) if p is not None]

    @property
    def iterations(self) -> int:
        return sum(p.iterations for p in self.planners)

    @property
    def solved(self) -> bool:
        return any(p.solved for p in self.planners)

    @property
    def finished(self) -> bool:
        return all(p.finished for p in self.planners)

    def step(self, iterations: int = 1) -> None:
        """Each tree advances by ``iterations`` (the studio steps a run in small batches)."""
        for planner in self.planners:
            planner.step(iterations)

    def advance(self, time_limit: float | None = 1.0, iterations: int | None = None,
                stop: Callable[[], bool] | None = None) -> None:
        """Each tree gets the iteration budget (so the detour tree is the constant plan's own)
        and a share of the time: a time-only budget gives each `PROBE_SHARE` of it, then the
        rest to the tree whose path arrives first by then."""
        planners = self.planners
        if iterations is not None or len(planners) == 1:
            share = None if time_limit is None else time_limit / len(planners)
            for planner in planners:
                planner.advance(share, iterations, stop)
            return
        for planner in planners:
            planner.advance(PROBE_SHARE * time_limit, None, stop)
        arrival = {id(p): math.inf for p in planners}
        for schedule in self.schedules():
            key = id(schedule.planner)
            arrival[key] = min(arrival[key], schedule.arrival_s)
        leader = min(planners, key=lambda p: arrival[id(p)])
        leader.advance((1.0 - PROBE_SHARE * len(planners)) * time_limit, None, stop)

    def solve(self, time_limit: float | None = 1.0, iterations: int | None = None,
              stop: Callable[[], bool] | None = None) -> Result:
        self.advance(time_limit, iterations, stop)
        return self.result()

    def schedules(self) -> list[Schedule]:
        """Every candidate: the route and the detour timed, and the detour as planned."""
        out = [fastest_schedule(p, self._movers, self.vmax) for p in self.planners]
        if self.detour is not None and self.detour.solved:
            out.append(Schedule(self.detour, self.detour.options.speed,
                                float(self.detour.best_cost)))
        return [s for s in out if s is not None]

    def result(self) -> Result:
        results = [p.result() for p in self.planners]
        totals = {name: sum(getattr(r, name) for r in results) for name in (
            "iterations", "nodes", "collision_checks", "clearance_evaluations", "rewires",
            "refused_rewires", "planning_time_s", "polish_s")}
        first = min((r.time_to_first_solution_s for r in results if r.solved), default=None)
        candidates = self.schedules()
        if not candidates:
            return dataclasses.replace(
                results[0], **totals, solved=False, cost=None, path=np.zeros((0, 6)),
                max_abs_curvature=None, min_clearance_m=None, cost_over_time=[],
                time_to_first_solution_s=first, timed=True, objective="time", length_m=None,
                options=self.options)
        best = min(candidates, key=lambda c: c.arrival_s)
        entries = best.length_m / best.spacing_m + best.waited_s / MAX_STEP_S
        if entries > MAX_ROWS:
            raise ScenarioError(
                f"vehicle.max_speed: {best.vmax:g} m/s over {best.length_m:.1f} m needs about "
                f"{entries:.3g} path entries at most 0.05 m and 0.1 s apart, more than "
                f"{MAX_ROWS}: give a higher max_speed, or plan with timing constant")
        path = best.rows()
        return dataclasses.replace(
            results[self.planners.index(best.planner)], **totals, cost=float(path[-1, 5]),
            path=path, timed=True, time_to_first_solution_s=first,
            min_clearance_m=polyline_clearance(self.problem.world, path, True),
            cost_over_time=[(totals["planning_time_s"], best.arrival_s, totals["iterations"])],
            objective="time", length_m=best.length_m, waited_s=best.waited_s,
            options=self.options)


def planner_for(problem: Problem, options: PlanOptions | None = None):
    """The planner that ``options.timing`` asks for: a `Planner` (constant) or a
    `TimeOptimalPlanner`."""
    options = options or PlanOptions()
    if options.timing == "optimal":
        return TimeOptimalPlanner(problem, options)
    return Planner(problem, options)


_warm = False


def warm_up() -> None:
    """Compile (or load from numba's cache) every planning kernel once, the schedule's with
    the trees' (`planner.rrt.warm_up`), outside any timed budget."""
    global _warm
    if _warm:
        return
    from planner._world import build_world
    from planner.rrt import warm_up as warm_up_trees

    warm_up_trees()
    world = build_world((0, 0, 10, 10), 0.1, [(5, 5, 1, 0)], [], [("velocity", (0.0, 0.5))])
    problem = Problem(None, world, (0.5, 5.0, 0.0), (9.5, 5.0, 0.0), 0.5, 0.5, 1.0, 1.0, True,
                      max_speed=2.0)
    TimeOptimalPlanner(problem, PlanOptions(timing="optimal")).solve(None, 200)
    _warm = True
