"""RRT and RRT* for a car: a `Planner` with step() and solve(), over the compiled kernel.

The planner object owns the tree arrays and the random state, so a run is reproducible from its
seed, can be advanced one iteration at a time (the studio's step mode) or for a time budget, and
can be observed through listeners that receive the kernel's event records.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from planner import _kernel as K
from planner._paths import TURN, advance, path_buffers, pose_at, rest_points, sample_path
from planner._reroot import reroot
from planner._rng import seed_state
from planner._rows import SPACING_M, chord_sag, chord_sharpness, heading_sag, polyline_clearance
from planner._steer import steer_path
from planner._world import REACH, World, inflated
from planner.options import METRICS, PlanOptions
from planner.problem import Problem, check_room
from planner.steering import DEFAULT_STEERING, STEERINGS
from planner.tree import Rewire, TreeEvents, TreeSnapshot, edge_points, path_points

__all__ = ["Planner", "Result", "checked_world", "warm_up"]

NO_CAP = 2**62  # a polish's evaluations outside a time budget: only polishing's share bounds them
POLISH_TIME_SHARE = 0.2  # of a time budget's planning, polishing takes at most about this


@dataclass
class Result:
    """The outcome of a run: the best path as dense samples, and the metrics."""

    solved: bool
    cost: float | None
    time_to_first_solution_s: float | None
    iterations: int
    nodes: int
    collision_checks: int
    clearance_evaluations: int
    rewires: int
    refused_rewires: int
    planning_time_s: float
    polish_s: float  # of the planning time, spent polishing the best path
    min_clearance_m: float | None
    max_abs_curvature: float | None
    cost_over_time: list[tuple[float, float, int]]  # (t_s, best cost, iteration) per improvement
    path: np.ndarray  # (n, 6): x, y, theta, curvature, direction, t
    timed: bool  # the path's t column is the schedule (movers, or timing optimal)
    options: PlanOptions  # as resolved for the problem
    objective: str = "length"  # what ``cost`` measures: "length" (m) or "time" (s, arrival)
    length_m: float | None = None  # the path's driven length
    waited_s: float = 0.0  # time standing still on the path

    @property
    def arrival_time_s(self) -> float | None:
        return float(self.path[-1, 5]) if self.solved else None

    def cost_at(self, t: float) -> float | None:
        """Best cost found within the first ``t`` seconds, or None."""
        best = None
        for when, cost, _ in self.cost_over_time:
            if when <= t:
                best = cost
        return best


@dataclass
class _Clock:
    started: float = field(default_factory=time.perf_counter)
    first_solution_s: float | None = None
    cost_over_time: list[tuple[float, float, int]] = field(default_factory=list)

    def elapsed(self) -> float:
        return time.perf_counter() - self.started


class Planner:
    """An RRT / RRT* run on one problem. Not thread-safe: drive it from one thread."""

    def __init__(self, problem: Problem, options: PlanOptions | None = None,
                 capacity: int = 4096) -> None:
        self.problem = problem
        self.options = (options or PlanOptions()).resolved(problem)
        s = self.options
        if s.safety_margin > problem.margin:
            check_room(problem, s.safety_margin)
        self._world = checked_world(problem.world, problem, s)
        steering = STEERINGS[s.steering]
        xmin, ymin, xmax, ymax = problem.bounds
        diag = math.hypot(xmax - xmin, ymax - ymin)
        cell = min(max(s.eps / 10.0, diag / 400.0), diag / 8.0)
        nx, ny = math.ceil((xmax - xmin) / cell), math.ceil((ymax - ymin) / cell)
        grid = np.array([xmin, ymin, cell, nx, ny], dtype=float)
        self._tree = K.new_tree(capacity, grid, seed_state(s.seed), steering.segments)
        self._tree.cnt[K.BEST] = -1
        P = np.zeros(K.NPARAMS)
        P[K.EPS], P[K.GAMMA], P[K.GOAL_BIAS] = s.eps, s.gamma, s.goal_bias
        P[K.RHO], P[K.SPEED] = problem.rho, s.speed
        P[K.SIGMA] = chord_sharpness(problem.sharpness(s.speed), problem.rho)
        P[K.GX], P[K.GY], P[K.GTH] = problem.goal
        P[K.GPOS] = problem.goal_position_tol
        P[K.GHEAD] = math.pi if steering.heading_free else problem.goal_heading_tol
        P[K.INFORMED] = float(s.informed)
        P[K.STAR] = float(s.planner == "rrtstar")
        P[K.STEERING] = steering.code
        P[K.SX], P[K.SY] = problem.start[:2]
        P[K.K_RRT] = s.k_rrt or 0.0
        P[K.DIMS] = s.dimensions
        P[K.METRIC] = METRICS.index(s.metric)
        P[K.POLISH] = float(s.polish)
        self._P = P
        K.add_node(self._tree, P, *problem.start, 0.0, -1, *path_buffers(steering.segments))
        self._no_events = _event_buffers(0, 0, 0, 0)
        self._events = self._no_events  # the listeners' buffers, grown as needed, reused
        self._listeners: list[Callable[[TreeEvents], None]] = []
        self._clock = _Clock()
        self._compute_time = 0.0
        self._polish_time = 0.0  # of it, polishing the best path
        self._polish_cap = NO_CAP  # clearance evaluations a polish may spend before a deadline

    # -- observation -------------------------------------------------------------------------
    def add_listener(self, listener: Callable[[TreeEvents], None]) -> None:
        """Receive a `TreeEvents` after every batch of iterations (costs nothing when absent)."""
        self._listeners.append(listener)

    @property
    def iterations(self) -> int:
        return int(self._tree.cnt[K.ITER])

    @property
    def nodes(self) -> int:
        return int(self._tree.cnt[K.N])

    @property
    def solved(self) -> bool:
        return bool(self._tree.cnt[K.BEST] >= 0)

    @property
    def best_cost(self) -> float | None:
        best = self._tree.cnt[K.BEST]
        return float(self._tree.cost[best]) if best >= 0 else None

    @property
    def rewires(self) -> int:
        return int(self._tree.cnt[K.REWIRES])

    @property
    def time_to_first_solution_s(self) -> float | None:
        return self._clock.first_solution_s

    @property
    def cost_over_time(self) -> list[tuple[float, float, int]]:
        """(planning seconds, best cost, iteration) at each improvement so far."""
        return list(self._clock.cost_over_time)

    @property
    def planning_time_s(self) -> float:
        """Seconds spent planning so far: the clock of `cost_over_time`."""
        return self._compute_time

    @property
    def poses(self) -> np.ndarray:
        """A read-only *live* view of the nodes' poses: read it on the planner's thread (in a
        listener); `snapshot()` gives a copy for anywhere else."""
        view = self._tree.pose[: self.nodes]
        view.flags.writeable = False
        return view

    @property
    def costs(self) -> np.ndarray:
        """A read-only *live* view of the nodes' costs from the root, like `poses`."""
        view = self._tree.cost[: self.nodes]
        view.flags.writeable = False
        return view

    def edge_points(self, node: int, count: int = 4) -> np.ndarray:
        """(count + 1, 2) positions along the local path from ``node``'s parent to it (the root:
        its position repeated), for drawing curved edges; live, like `poses`."""
        t = self._tree
        return edge_points(t.pose, t.parent, t.kinds, t.lens, t.curv, node, count)

    def edge_segments(self, node: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The local path from ``node``'s parent to it in segment form: kinds, signed lengths
        and curvatures (`planner.path_word` names it, `planner.path_length` measures it);
        copies, of the live tree, so read on the planner's thread like `poses`."""
        t = self._tree
        return t.kinds[node].copy(), t.lens[node].copy(), t.curv[node].copy()

    def steer_points(self, a, b, count: int = 4) -> np.ndarray:
        """(count + 1, 2) positions along this planner's steering from pose a to pose b: a
        motion the tree does not hold, such as a Steer that an obstacle blocked."""
        steering = STEERINGS[self.options.steering]
        path = path_buffers(steering.segments)
        steer_path(steering.code, *a, *b, K.turning(self._P), *path)
        return path_points(a, *path, count)

    @property
    def finished(self) -> bool:
        """RRT is done at its first solution; RRT* goes on improving."""
        return self.options.planner == "rrt" and self.solved

    def snapshot(self) -> TreeSnapshot:
        """A copy of the tree, for reading anywhere."""
        n, t = self.nodes, self._tree
        return TreeSnapshot(t.pose[:n].copy(), t.parent[:n].copy(), t.cost[:n].copy(),
                            t.kinds[:n].copy(), t.lens[:n].copy(), t.curv[:n].copy(),
                            int(t.cnt[K.BEST]))

    # -- running -----------------------------------------------------------------------------
    def step(self, iterations: int = 1) -> None:
        """Advance by ``iterations`` samples (grows the tree arrays as needed)."""
        events = self._recording(iterations) if self._listeners else self._no_events
        done_before = self.iterations
        target = done_before + iterations
        t0 = time.perf_counter()
        while self.iterations < target and not self.finished:
            status = K.iterate(self._tree, self._world, self._P, target - self.iterations,
                               events)
            if status == K.FULL:
                self._tree = K.grown(self._tree, 2 * self._tree.pose.shape[0])
            elif status == K.POLISH_DUE:
                # Polishing adds at most as many nodes as the tree has room for.
                events = self._events = _room(events, polished=self._tree.pose.shape[0])
                started = time.perf_counter()
                K.polish(self._tree, self._world, self._P, events, self._polish_cap)
                self._polish_time += time.perf_counter() - started
            elif status == K.EVENTS_FULL:
                events = self._events = _room(events, near=2 * self.nodes)
        took = time.perf_counter() - t0
        self._compute_time += took
        self._note_progress(done_before, took)
        if self._listeners:
            batch = _named(events)
            for listener in self._listeners:
                listener(batch)

    def _recording(self, iterations: int) -> K.Events:
        """The event buffers, emptied, with a row for each of ``iterations``."""
        ev = self._events = _room(self._events, rows=iterations, near=64 * iterations)
        ev.cnt[:] = 0
        return ev

    def _note_progress(self, iterations_before: int, batch_s: float) -> None:
        """Time-stamp the batch's improvements, which the kernel records by iteration: inside
        the batch, in proportion to its iterations."""
        t, clock = self._tree, self._clock
        done = max(self.iterations - iterations_before, 1)
        for iteration, cost in t.improved[len(clock.cost_over_time):t.cnt[K.IMPROVED]]:
            share = min(max((iteration - iterations_before) / done, 0.0), 1.0)
            when = self._compute_time - batch_s * (1.0 - share)
            clock.cost_over_time.append((when, float(cost), int(iteration)))
            if clock.first_solution_s is None:
                clock.first_solution_s = when

    def solve(self, time_limit: float | None = 1.0, iterations: int | None = None,
              stop: Callable[[], bool] | None = None) -> Result:
        """Run until the time or iteration budget is spent (RRT: until the first solution) or
        ``stop()`` is true (asked between batches of about 2 ms); the result."""
        self.advance(time_limit, iterations, stop)
        return self.result()

    def advance(self, time_limit: float | None = 1.0, iterations: int | None = None,
                stop: Callable[[], bool] | None = None) -> None:
        """`solve` without building the result (which measures the best path's clearance)."""
        if time_limit is None and iterations is None:
            raise ValueError("give a time limit, an iteration budget, or both")
        warm_up()
        batch = 1  # then sized from the first: a slow scene passes its deadline by one at most
        limit = math.inf if time_limit is None else time_limit
        max_iter = math.inf if iterations is None else self.iterations + iterations
        start = self._compute_time
        while self._compute_time - start < limit and self.iterations < max_iter:
            if stop is not None and stop():
                break
            n = int(min(batch, max_iter - self.iterations))
            # A polish is counted, not timed (a seed's run is the same on any machine), so in a
            # time budget it gets the evaluations its pace fits into what is left, and, where
            # the time is the budget (no iteration count makes the run), into polishing's share
            # of the time.
            left = limit - (self._compute_time - start)
            if math.isfinite(left) and self._compute_time > 0.0:
                self._polish_cap = self._polish_evals_within(left, timed=iterations is None)
            t0 = time.perf_counter()
            try:
                self.step(n)
            finally:
                self._polish_cap = NO_CAP
            took = time.perf_counter() - t0
            if self.finished:
                break
            # Aim at ~2 ms batches: fine-grained budgets and cost-over-time samples.
            batch = max(1, min(4096, int(batch * (0.002 / took if took > 0 else 2.0))))

    def _polish_evals_within(self, left: float, timed: bool) -> int:
        """The clearance evaluations a polish may spend in ``left`` seconds and, if ``timed``,
        in what is left of polishing's share of the time (`POLISH_TIME_SHARE`), at polishing's
        pace so far (the run's, before the first polish)."""
        t, polished = self._tree, self._polish_time
        done = t.cnt[K.POLISH_EVALS] if polished > 0.0 else t.cnt[K.EVALS]
        pace = int(done) / (polished if polished > 0.0 else self._compute_time)
        if timed:
            share = POLISH_TIME_SHARE / (1.0 - POLISH_TIME_SHARE) * (self._compute_time
                                                                     - polished)
            left = min(left, share - polished)
        return int(min(pace * max(left, 0.0), NO_CAP))

    # -- results -----------------------------------------------------------------------------
    def best_path_nodes(self) -> list[int]:
        """The best path's nodes, root first (none before a solution)."""
        return K.chain(self._tree.parent, int(self._tree.cnt[K.BEST])).tolist()

    def dense_path(self, spacing: float = SPACING_M) -> np.ndarray:
        """The best path sampled every ≤ spacing m: columns x, y, θ, κ, direction, t."""
        t = self._tree
        chain = self.best_path_nodes()
        if not chain:
            return np.zeros((0, 6))
        parts = [np.array([[*t.pose[chain[0]], 0.0, 1.0, 0.0]])]
        driven = 0.0
        for node in chain[1:]:
            par = t.parent[node]
            seg = sample_path(*t.pose[par], t.kinds[node], t.lens[node], t.curv[node], spacing)
            seg[:, 5] += driven
            driven = seg[-1, 5]
            parts.append(seg[1:])
        pts = np.vstack(parts)
        pts[:, 5] /= self.options.speed
        return pts

    def best_path_segments(self) -> tuple[np.ndarray, ...]:
        """The best path as its driven segments: start poses (m, 3), kinds, signed lengths,
        curvatures (m, 2) (`planner._paths`) and the driven length where each starts (a turn on
        the spot is folded into the pose that follows it)."""
        t = self._tree
        poses, kinds, lens, curv, starts = [], [], [], [], []
        driven = 0.0
        for node in self.best_path_nodes()[1:]:
            x, y, th = t.pose[t.parent[node]]
            for kind, seg, (k0, sigma) in zip(t.kinds[node], t.lens[node], t.curv[node]):
                if seg != 0.0 and kind != TURN:
                    poses.append((x, y, th))
                    kinds.append(kind)
                    lens.append(seg)
                    curv.append((k0, sigma))
                    starts.append(driven)
                    driven += abs(seg)
                if seg != 0.0:
                    x, y, th = advance(x, y, th, kind, seg, k0, sigma)
        if not poses:  # the start is in the goal region
            poses, kinds, lens, curv, starts = [self.root], [0], [0.0], [(0.0, 0.0)], [0.0]
        return (np.array(poses, dtype=float), np.array(kinds, dtype=np.int64),
                np.array(lens, dtype=float), np.array(curv, dtype=float),
                np.array(starts, dtype=float))

    @property
    def root(self) -> tuple[float, float, float]:
        """The root's pose (x, y, θ)."""
        return self._pose(0)

    def best_path_at(self, s: float) -> tuple[tuple[float, float, float], int, float]:
        """Where the best path is ``s`` metres (driven) from the root: (pose, anchor, skip),
        the anchor being the node whose incoming edge holds the pose and skip how far along
        that edge it lies (0: the pose is the anchor's own). Past the end: the last node."""
        t = self._tree
        chain = self.best_path_nodes()
        i = int(np.searchsorted(t.cost[chain], s, side="right"))
        if i >= len(chain):
            return self._pose(chain[-1]), chain[-1], 0.0
        node, parent = chain[i], chain[i - 1]
        skip = s - t.cost[parent]
        if skip <= 1e-12:
            return self._pose(parent), parent, 0.0
        x, y, th, _, _ = pose_at(*t.pose[parent], t.kinds[node], t.lens[node], t.curv[node],
                                 skip)
        return (x, y, th), node, float(skip)

    def rest_from(self, s: float) -> float:
        """The least driven length ≥ ``s`` along the best path where its curvature is 0 (its
        end, if there is none): where a continuous-curvature plan may hand over to a new one,
        whose edges all start at κ = 0."""
        _, kinds, lens, curv, _ = self.best_path_segments()
        before, after = rest_points(kinds.astype(np.int8), lens, curv, s)
        return s if before == s else min(after, float(np.abs(lens).sum()))

    def _pose(self, node: int) -> tuple[float, float, float]:
        return tuple(float(v) for v in self._tree.pose[node])

    def adopt(self, old: Planner, anchor: int, skip: float, bound: float = math.inf) -> int:
        """Take over the still-valid part of ``old``'s tree (replanning: keep the tree).

        This planner holds only its root, which is the state ``skip`` metres along ``old``'s
        edge into ``anchor`` (skip 0: ``anchor`` itself). The subtree ahead of it is copied
        with its edges unchanged and its costs shifted; each edge is re-checked in this
        planner's world at its new arrival time and dropped, with what hangs below it, if it
        collides; nodes whose cost plus distance to the goal exceeds ``bound`` are pruned.
        Returns the number of nodes copied."""
        if self.nodes != 1:
            raise ValueError("adopt() needs a planner that holds only its root")
        if self._tree.pose.shape[0] < old.nodes + 1:
            self._tree = K.grown(self._tree, 2 * (old.nodes + 1))
        copied = reroot(old._tree, self._tree, self._world, self._P, anchor, skip, bound)
        K._update_best(self._tree)
        return int(copied)

    def best_path_clearance(self) -> float | None:
        """The least clearance of the best path as returned, its rows joined by chords, in
        space-time: the one definition of the path metric (None before a solution)."""
        if not self.solved:
            return None
        return polyline_clearance(self.problem.world, self.dense_path(), self.problem.timed)

    def result(self) -> Result:
        t = self._tree
        path = self.dense_path()
        solved = self.solved
        min_clear = self.best_path_clearance()
        return Result(
            solved=solved, cost=self.best_cost,
            time_to_first_solution_s=self._clock.first_solution_s,
            iterations=self.iterations, nodes=self.nodes,
            collision_checks=int(t.cnt[K.CHECKS]), clearance_evaluations=int(t.cnt[K.EVALS]),
            rewires=int(t.cnt[K.REWIRES]), refused_rewires=int(t.cnt[K.REFUSED]),
            planning_time_s=self._compute_time, polish_s=self._polish_time,
            min_clearance_m=min_clear,
            max_abs_curvature=float(np.abs(path[:, 3]).max()) if solved else None,
            cost_over_time=list(self._clock.cost_over_time), path=path,
            timed=self.problem.timed, options=self.options, length_m=self.best_cost)


def _event_buffers(rows: int, near: int, rewires: int, polished: int) -> K.Events:
    return K.Events(np.zeros((rows, K.EV_COLS)), np.zeros(near, np.int64),
                    np.zeros((rewires, 4), np.int64), np.zeros(polished, np.int64),
                    np.zeros(4, np.int64))


def _room(ev: K.Events, rows: int = 0, near: int = 0, polished: int = 0) -> K.Events:
    """``ev`` (its contents kept) with room for ``rows`` rows, and ``near`` more near-set
    entries and as many rewires, and ``polished`` more polished nodes than it holds."""
    used = ev.cnt
    want = (rows, used[1] + near, used[2] + near, used[3] + polished)
    have = (len(ev.rows), len(ev.near), len(ev.rewires), len(ev.polished))
    if all(h >= w for h, w in zip(have, want)):
        return ev
    grown = _event_buffers(*(h if h >= w else max(w, 2 * h) for h, w in zip(have, want)))
    for old, new in zip(ev, grown):
        new[:len(old)] = old
    return grown


def _named(ev: K.Events) -> TreeEvents:
    """The kernel's event columns as `TreeEvents` fields."""
    n_rows, n_near, n_rw, n_polished = ev.cnt
    rows = ev.rows[:n_rows]

    def ints(col):
        return rows[:, col].astype(np.int64)

    return TreeEvents(
        iteration=ints(K.EV_ITER), sample=rows[:, [K.EV_XR, K.EV_YR, K.EV_THR]],
        nearest=ints(K.EV_NEAREST), new=ints(K.EV_NEW), parent=ints(K.EV_PARENT),
        radius=rows[:, K.EV_RADIUS].copy(), best_cost=rows[:, K.EV_BEST].copy(),
        steered=np.where(rows[:, [K.EV_NEAREST]] >= 0, rows[:, [K.EV_XN, K.EV_YN, K.EV_THN]],
                         np.nan),
        free=np.where(rows[:, K.EV_FREE] >= 0.0, rows[:, K.EV_FREE], np.nan),
        rewires=[Rewire(*map(int, r)) for r in ev.rewires[:n_rw]],
        polished=ev.polished[:n_polished].copy(),
        _near=ev.near[:n_near].copy(), _near_span=ints([K.EV_NEAR_START, K.EV_NEAR_END]))


def checked_world(world: World, problem: Problem, options: PlanOptions) -> World:
    """``world`` (``problem``'s, or the part of it checked) as a planner with (resolved)
    ``options`` checks it: the footprint grown by the safety margin and, for a steering that
    drives arcs, by the sag of the returned rows' chords, and for one that drives clothoids
    also by the sag of their linearly interpolated headings (`planner._rows`), so that a path
    is valid as written."""
    steering = STEERINGS[options.steering]
    grow = options.safety_margin + (chord_sag(problem.rho) if steering.curved else 0.0)
    if steering.continuous:
        grow += heading_sag(problem.sharpness(options.speed), float(world.geo[REACH]))
    return inflated(world, grow)


_warm = False


def warm_up() -> None:
    """Compile (or load from numba's cache) the kernels once, outside any timed budget."""
    global _warm
    if _warm:
        return
    from planner._world import build_world

    # A metre square: its distance grid has the fewest cells (a tenth of a bundled scene's).
    # One kernel serves every planner and steering (they are parameters, not types); a world
    # in space-time and a static one, solved (after 60 iterations) and their results taken, so
    # that the kernels of rows, re-rooting and polishing (static plans only) compile here as
    # well: after an install, not inside the first plan's time budget, which they took 20 s
    # of. Loading them from numba's cache costs a process 0.02 s.
    triangle = [(0.1, 0.1), (0.2, 0.1), (0.2, 0.2)]
    for movers in ([("velocity", (0.01, 0))], []):
        world = build_world((0, 0, 1, 1), 0.01, [(0.5, 0.5, 0.1, -1)],
                            [(triangle, 0 if movers else -1)], movers)
        problem = Problem(None, world, (0.05, 0.05, 0.0), (0.9, 0.9, 0.0), 0.05, 0.5, 0.1, 0.1,
                          bool(movers))
        p = Planner(problem, PlanOptions(planner="rrtstar", steering=DEFAULT_STEERING))
        p.step(200)
        p.result()
    _warm = True
