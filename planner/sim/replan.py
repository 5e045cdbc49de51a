"""One replanning cycle: commit, predict, re-root the tree, grow it, hand back a trajectory.

The replanner keeps the RRT* tree between cycles. Each cycle commits to the stretch of the
current trajectory the car will drive before the new plan can arrive, re-roots the tree at the
end of that stretch (keeping the still-valid subtree ahead: `Planner.adopt`), grows it for one
cycle's budget in the world the car believes in (sensed movers at constant velocity), and
returns the committed stretch followed by the tree's best path. It also reports how far the car
may drive on the trajectory before a predicted conflict, for the speed governor.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from planner._paths import pose_at
from planner._world import clearance, inflated, path_clearances, without_movers
from planner.options import PlanOptions
from planner.problem import Problem
from planner.rrt import Planner
from planner.sim.control import Reference
from planner.sim.predict import Lanes, Uncertainty, predicted_world
from planner.sim.sensing import Sensing, known_motions
from planner.steering import STEERINGS
from planner.timing import fastest_schedule

__all__ = ["Cycle", "Replanner", "warm_up"]

SPACING = 0.05  # m between reference rows
KEEP_BEHIND = 1.0  # m of driven reference kept (for the projection window)
# Plans end in the inner part of the goal region, so that the tracked pose, a few cm and
# degrees off the plan, still ends inside it.
GOAL_SHARE = 0.6
# Re-rooting keeps nodes that could lie on a path at most this much longer than the current
# plan (informed pruning with slack: alternatives for when the plan becomes blocked).
PRUNE_FACTOR, PRUNE_SLACK = 1.5, 2.0
# Timing optimal: the car waits for movers on its path if it can go on within this long;
# otherwise it plans round them, as with constant timing.
PATIENCE_S = 10.0
# A planned stop stands where the prediction keeps at least this clearance, checked this often.
REST_CLEARANCE, REST_STEP = 0.1, 0.25


@dataclass(frozen=True)
class Cycle:
    """What a cycle delivers. ``reference`` None: keep the committed one."""

    reference: Reference | None
    replaced: bool
    stop_s: float  # arc on the delivered (or kept) reference where the car must be at rest
    conflict: bool  # stop_s comes from a predicted conflict, not the end of the trajectory
    planned_wait: bool  # timing optimal: the plan waits at such a conflict, it is no emergency
    wall_s: float
    nodes: int


class Replanner:
    """The planning side of the car: its tree, its committed trajectory, its budget."""

    def __init__(self, problem: Problem, options: PlanOptions, *, seed: int,
                 budget_s: float | None, iterations: int | None, margin: float,
                 uncertainty: Uncertainty = Uncertainty(), lanes: Lanes | None = None,
                 horizon_s: float = 4.0) -> None:
        self.problem = problem
        self.options = options.resolved(problem)
        self.seed = seed
        self.budget_s = budget_s
        self.iterations = iterations
        self.margin = margin
        self.uncertainty = uncertainty
        self.known = known_motions(problem.scenario)
        self.lanes = lanes
        self.horizon_s = horizon_s
        self.planner: Planner | None = None
        self.attached = False  # the reference from root_s on is the planner's best path
        self.root_s = 0.0  # arc of the planner's root on the reference
        self.reference: Reference | None = None
        self.count = 0
        self.goals: list = []

    def aim(self, goals) -> None:
        """Lap mode's rolling goal: from the next cycle on, plan towards the first of ``goals``
        (poses, best first) that the believed world leaves free — a goal on an obstacle would
        leave the car without a plan. Kept goal nodes are re-registered when re-rooting."""
        self.goals = list(goals)

    # -- the cycle ---------------------------------------------------------------------------
    def cycle(self, t: float, sensing: Sensing, pose, v: float, s_now: float,
              lead_s: float, spent_s: float = 0.0) -> Cycle:
        """Plan from the state the car will be in ``lead_s`` seconds after t. ``spent_s``: time
        this cycle has already taken (the guard's check), off the planning budget — at most
        half of it, so that a car in danger still gets a plan."""
        started = time.perf_counter()
        self.count += 1
        vehicle = self.problem.scenario.vehicle
        a = vehicle.max_accel
        # Committed too: what the car drives while its steering swings from lock to lock. A
        # plan that bent nearer would ask the steering for what it cannot do (a drift wide).
        swing = 2.0 * vehicle.max_steer_deg / vehicle.max_steer_rate_deg_s
        # The speed along the plan: a car still moving against it (backing up after an
        # evasion) commits to nothing ahead.
        v = v * self.reference.direction if self.reference is not None else v
        commit = max(v, 0.0) * (lead_s + swing) + 0.5 * a * lead_s ** 2 if v > 1e-9 else 0.0
        root, anchor, skip, s_c = self._commit_point(pose, s_now, commit)
        believed = predicted_world(self.problem.world, sensing, t + lead_s, self.uncertainty,
                                   self.known, self.lanes)
        plan_world = inflated(believed, self.margin)
        if clearance(plan_world, root[0], root[1], 0.0) <= 0.0:
            plan_world = believed  # already inside the margin: plan with the bare disc
        self._s_c = s_c
        if self.goals:
            free = [g for g in self.goals if clearance(plan_world, g[0], g[1], 0.0) > 0.0]
            self.problem = dataclasses.replace(self.problem, goal=(free or self.goals)[0])
        old, old_cost = self.planner, self._remaining_cost(s_c)
        spent_s = min(spent_s, 0.5 * self.budget_s) if self.budget_s else 0.0
        planner, waits = self._plan(plan_world, root, old, anchor, skip, started - spent_s)
        replaced = False
        self.shift = 0.0
        if planner.solved:
            # The first plan replaces nothing; later ones do unless the tree kept the old one.
            replaced = self.reference is not None and not (
                self.attached and abs(planner.best_cost - old_cost) < 1e-9)
            path = planner.dense_path(SPACING)[:, :5]
            self.reference = self._joined(s_c, path, s_now)
            self.attached, self.planner = True, planner
        else:
            self.attached, self.planner = False, planner
            self.root_s = s_c
        stop_s, conflict = self._stop_point(believed, t, lead_s, s_now)
        return Cycle(self.reference if planner.solved else None, replaced, stop_s, conflict,
                     waits and conflict, time.perf_counter() - started, planner.nodes)

    def _plan(self, world, root, old, anchor: int, skip: float, started: float):
        """(the cycle's tree, whether its path waits for movers). With timing optimal the tree
        is grown among the static obstacles, and the car stops for a mover on its path (the
        governor's conflict stop) as long as a schedule along it goes on within `PATIENCE_S`;
        otherwise the cycle plans round the movers in space-time after all."""
        if self.options.timing == "optimal":
            planner = self._new_planner(without_movers(world), root, old, anchor, skip)
            self._grow(planner, started)
            if not planner.solved or fastest_schedule(planner, world, self.options.speed,
                                                      PATIENCE_S) is not None:
                return planner, planner.solved
            started = time.perf_counter()  # planning round them gets a budget of its own
        planner = self._new_planner(world, root, old, anchor, skip)
        self._grow(planner, started)
        return planner, False

    def _commit_point(self, pose, s_now: float, commit: float):
        """(root pose, anchor node, skip, arc) of the state ``commit`` metres ahead."""
        ref = self.reference
        if ref is None:
            return tuple(pose), 0, 0.0, 0.0
        s_c = min(s_now + commit, ref.length)
        if self.attached and self.planner is not None:
            s_c = max(s_c, self.root_s)  # never behind the tree's root (the last commit)
            if STEERINGS[self.options.steering].continuous:  # where κ = 0, as at every root
                s_c = self.root_s + self.planner.rest_from(s_c - self.root_s)
            pose, anchor, skip = self.planner.best_path_at(s_c - self.root_s)
            return pose, anchor, skip, s_c
        return tuple(ref.point_at(s_c)[:3]), -1, 0.0, s_c

    def _remaining_cost(self, s_c: float) -> float:
        if not (self.attached and self.planner is not None and self.planner.solved):
            return math.inf
        return self.planner.best_cost - (s_c - self.root_s)

    def _new_planner(self, world, root, old: Planner | None, anchor: int, skip: float):
        """A tree rooted at ``root`` holding what is still valid of the old one."""
        same_root = (old is not None and not self.attached
                     and np.allclose(old.root, root, rtol=0.0, atol=1e-12))
        keep = old is not None and ((self.attached and anchor >= 0) or same_root)
        capacity = max(4096, 2 * old.nodes) if keep else 4096
        problem = dataclasses.replace(
            self.problem, world=world, start=tuple(root), timed=True,
            goal_position_tol=GOAL_SHARE * self.problem.goal_position_tol,
            goal_heading_tol=GOAL_SHARE * self.problem.goal_heading_tol)
        options = self.options.model_copy(update={"seed": self.seed * 1_000_003 + self.count})
        planner = Planner(problem, options, capacity=capacity)
        if keep:
            remaining = self._remaining_cost(self._s_c)
            bound = PRUNE_FACTOR * remaining + PRUNE_SLACK if math.isfinite(remaining) else math.inf
            planner.adopt(old, 0 if same_root else anchor, 0.0 if same_root else skip, bound)
        return planner

    def _grow(self, planner: Planner, started: float) -> None:
        if self.iterations is not None:
            planner.step(self.iterations)
            return
        batch = 8
        while time.perf_counter() - started < self.budget_s:
            t0 = time.perf_counter()
            planner.step(batch)
            took = time.perf_counter() - t0
            batch = max(1, min(512, int(batch * (0.001 / took if took > 0 else 2.0))))

    def _joined(self, s_c: float, path: np.ndarray, s_now: float) -> Reference:
        """The committed stretch (from a little behind the car) followed by the new plan."""
        ref = self.reference
        if ref is None:
            self.root_s = 0.0
            return Reference(path)
        lo = int(np.searchsorted(ref.s, s_now - KEEP_BEHIND))
        # Not back across a cusp: the car's stretch is the new reference's first.
        lo = max(lo, int(ref.bounds[ref.stretch]))
        hi = int(np.searchsorted(ref.s, s_c - 1e-9))
        if hi > lo:  # the root is reached the way the committed rows go (a row's direction)
            path = path.copy()
            path[0, 4] = ref.rows[hi - 1, 4]
        rows = np.vstack([ref.rows[lo:hi], path]) if hi > lo else path
        out = Reference(rows)
        self.shift = float(ref.s[lo]) if hi > lo else s_c
        self.root_s = float(out.s[hi - lo]) if hi > lo else 0.0
        out.cursor = max(int(np.searchsorted(out.s, s_now - self.shift)) - 1, 0)
        return out

    def _stop_point(self, believed, t: float, lead_s: float, s_now: float):
        """Arc where the car must stop: before the first predicted conflict within the horizon
        on the reference it will follow, else at the reference's end."""
        ref = self.reference
        if ref is None:
            return 0.0, False
        s_now = max(s_now - self.shift, 0.0)  # in the arcs of the reference just built
        speed = self.options.speed
        i0 = int(np.searchsorted(ref.s, s_now))
        i1 = int(np.searchsorted(ref.s, s_now + speed * self.horizon_s))
        rows = ref.rows[i0:i1 + 1]
        if len(rows) == 0:
            return ref.length, False
        samples = np.zeros((len(rows), 6))
        samples[:, :5] = rows
        samples[:, 5] = (ref.s[i0:i0 + len(rows)] - s_now) / speed - lead_s
        c = path_clearances(believed, samples, True)
        hit = np.flatnonzero(c <= 0.02)
        if len(hit):
            # Wait where no predicted mover comes while the car stands: the last row before
            # the conflict that stays clear from its arrival to the horizon's end.
            rest = self._rest_clearances(believed, samples[:hit[0]])
            ok = np.flatnonzero(rest > REST_CLEARANCE)
            last = ok[-1] if len(ok) else 0
            return float(ref.s[i0 + last]) - (0.15 if len(ok) else 0.0), True
        return ref.length, False

    def _rest_clearances(self, believed, samples: np.ndarray) -> np.ndarray:
        """Per row, the least clearance of the car standing there from its arrival (column 5)
        on, at instants `REST_STEP` s apart up to the horizon."""
        out = np.full(len(samples), np.inf)
        rest = samples.copy()
        for tau in np.arange(0.0, self.horizon_s + REST_STEP / 2, REST_STEP):
            later = samples[:, 5] <= tau
            if not later.any():
                continue
            rest[:, 5] = tau
            out[later] = np.minimum(out[later], path_clearances(believed, rest[later], True))
        return out


_warm = False


def warm_up() -> None:
    """Load (or compile) the re-rooting kernel once, so that no cycle time includes it."""
    global _warm
    if _warm:
        return
    from planner._world import build_world

    world = build_world((0, 0, 10, 10), 0.1, [(5, 5, 1, 0)], [], [("velocity", (0.1, 0))])
    problem = Problem(None, world, (0.5, 0.5, 0.0), (9, 9, 0.0), 0.5, 0.5, 1.0, 1.0, True)
    old = Planner(problem, PlanOptions())
    old.step(40)
    Planner(problem, PlanOptions()).adopt(old, 0, 0.0)
    pose_at(0.0, 0.0, 0.0, np.zeros(5, np.int8), np.full(5, 0.2), np.zeros((5, 2)), 0.1)
    _warm = True
