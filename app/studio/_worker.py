"""One session's planner run(s) on one thread, and what they leave for the UI to draw.

The planners are stepped in short batches (~5 ms) so the UI thread gets the GIL between them;
each planner's listener (on this thread, where reading its tree is safe) turns kernel events
into edges, rewire flashes, the best path and metrics in its `Live` record the UI polls.

A worker drives one `Lane` (a planner and its record) or two (the studio's two-up split): the
same batch of iterations goes to each in turn and the metrics are published after the batch,
so the runs share one clock — at every published moment both have done the same number of
iterations, until one is done (RRT at its first solution) and stands still.

With ``timing: optimal`` the run is a `planner.TimeOptimalPlanner`: its route tree is the one
drawn, its detour tree grows alongside, and the best path shown is the run's result — the
chosen schedule, waits included — so that Drive car and the profiles show what it would drive.
"""

from __future__ import annotations

import queue
import threading
import time
from collections import deque
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

import planner
from app.studio._extend import StepInfo
from app.studio._replay import TreeRecord
from app.studio._tree import SEG, EdgeChunks

__all__ = ["Lane", "Live", "PlannerWorker", "Rewired", "Step"]

BATCH_S = 0.005
FLASH_S = 0.6
METRICS_S = 0.5  # metrics are published at most this often while running
STEP_CAP = 10_000  # iterations one "step until" takes at most


class Rewired(NamedTuple):
    """A node a step rewired: its edge before and after ((SEG + 1, 2) points), and its cost."""

    old: np.ndarray
    new: np.ndarray
    was: float
    now: float


@dataclass(frozen=True)
class Step:
    """One single iteration as the step overlay and the EXTEND panel show it; made on the
    planner's thread, read on the UI's."""

    info: StepInfo
    star: bool  # RRT*: the EXTEND lines on the near set and rewiring apply
    options: planner.PlanOptions
    x_rand: np.ndarray  # the sample (x, y, θ)
    nearest: np.ndarray | None  # x_nearest's pose
    new: np.ndarray | None  # x_new's pose, when a node was added
    blocked: tuple[np.ndarray, np.ndarray] | None  # where a blocked Steer ended, its motion
    parent_edge: np.ndarray | None  # x_new's edge from x_min
    near: np.ndarray  # the near set's poses
    radius: float
    rewired: tuple[Rewired, ...]
    until: tuple = ()  # how the "step until" search ended (`_extend.until_note`'s arguments)


@dataclass
class Live:
    """The planner's state as the UI sees it; each part carries a version the UI compares."""

    chunks: EdgeChunks = field(default_factory=EdgeChunks)
    flashes: deque = field(default_factory=lambda: deque(maxlen=96))  # (time, old, new)
    best_path: np.ndarray | None = None
    best_nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, int))  # its tree nodes
    best_version: int = 0
    metrics: dict = field(default_factory=dict)
    metrics_version: int = 0
    cost_over_time: list = field(default_factory=list)  # the planner's (s, cost, iteration)
    step: Step | None = None
    step_version: int = 0
    state: str = "ready"
    error: str | None = None


class Lane:
    """One planner run (`planner.planner_for`) and its `Live` record; stepped by its worker's
    thread only."""

    def __init__(self, problem, options: planner.PlanOptions) -> None:
        self.live = Live()
        self.options = options  # as the panel gave them: what a compared run is labelled with
        self.run = planner.planner_for(problem, options)
        self._optimal = options.timing == "optimal"
        self.tree = self.run.route if self._optimal else self.run  # the tree drawn
        self.tree.add_listener(self._on_events)
        self.record = TreeRecord(self.tree.root)  # what the replay slider rebuilds from
        self.stepped = 0  # iterations asked of each tree
        self.wall = 0.0  # s of the worker's clock this run was going: planning, pace's sleeps
        self._result = self._timed_costs = None  # timing optimal: the result shown, and of what
        self._star = options.planner == "rrtstar"
        self._stepping = False
        self.last_step: Step | None = None  # the last single iteration, not yet shown
        self._costs_before = None  # the tree's costs before it: a rewired node's old cost
        self._best = None
        self._clearance = self._clearance_of = None  # the best path's, and of which cost
        self._on_events(None)  # the root

    def done(self, budget: int) -> bool:
        return self.run.finished or self.stepped >= budget or self.live.error is not None

    def advance(self, n: int, stepping: bool) -> None:
        """``n`` iterations; a planner's error ends this lane's run, not the session."""
        self._stepping = stepping
        if stepping:
            self._costs_before = self.tree.costs.copy()
        try:
            self.run.step(n)
            self.stepped += n
        except Exception as exc:  # noqa: BLE001  (a planner bug must not kill the session)
            self.live.error = f"{type(exc).__name__}: {exc}"

    def found(self, until: str) -> bool:
        """Whether the last single iteration did ``until`` ("node" or "rewire")."""
        info = self.last_step and self.last_step.info
        return bool(info and (info.new >= 0 if until == "node" else info.n_rewired > 0))

    def show_step(self, until: tuple) -> None:
        """Publish the last single iteration with how the "step until" search ended."""
        if self.last_step is not None:
            self.live.step = replace(self.last_step, until=until)
            self.live.step_version += 1

    def steer_points(self, a, b) -> np.ndarray:
        """(SEG + 1, 2) positions along the steering from pose a to pose b: an edge the tree
        held once (the replay draws a rewired node's old edge); any thread (no tree state)."""
        return self.tree.steer_points(a, b, SEG)

    # -- the listener (planner thread) ---------------------------------------------------------
    def _on_events(self, ev: planner.TreeEvents | None) -> None:
        live = self.live
        if ev is None:
            self._record(0)
            return
        for node in (*ev.new[ev.new >= 0], *ev.polished):
            self._record(int(node))
        now = time.monotonic()
        rewired = []
        for rewire in ev.rewires:
            node = rewire.node
            old = live.chunks.get(node)
            new = self._record(node)
            live.flashes.append((now, old, new))
            rewired.append((old, new, node))
        if self._stepping and len(ev):
            self._note_step(ev, rewired)
        self.record.add(ev, self.tree.poses, self.tree.nodes, self.tree.rewires)
        self._note_best()

    def _record(self, node: int) -> np.ndarray:
        """Node's edge as drawn and as a click names it (its segments); returns its points."""
        pts = self.tree.edge_points(node, SEG)
        kinds, lens, _ = self.tree.edge_segments(node)
        self.live.chunks.set(node, pts, kinds, lens)
        return pts

    def _note_step(self, ev: planner.TreeEvents, rewired: list) -> None:
        """The iteration as the step overlay and the EXTEND panel show it: a blocked Steer's
        motion, and each rewired node's edges with its cost before and after."""
        tree = self.tree
        pose, cost = tree.poses, tree.costs
        info = StepInfo.from_events(ev, -1, len(rewired))
        blocked = info.blocked
        self.last_step = Step(
            info, self._star, tree.options, ev.sample[-1].copy(),
            nearest=pose[info.nearest].copy() if info.nearest >= 0 else None,
            new=pose[info.new].copy() if info.new >= 0 else None,
            blocked=((ev.steered[-1].copy(),
                      tree.steer_points(pose[info.nearest], ev.steered[-1], SEG))
                     if blocked else None),
            parent_edge=self.live.chunks.get(info.new) if info.new >= 0 else None,
            near=pose[ev.near_of(-1)].copy(), radius=info.radius,
            rewired=tuple(Rewired(old, new, float(self._costs_before[node]), float(cost[node]))
                          for old, new, node in rewired))

    def _note_best(self) -> None:
        tree, live = self.tree, self.live
        cost = tree.best_cost
        if cost is not None and (self._best is None or cost < self._best - 1e-9):
            self._best = cost
            if not self._optimal:  # else the schedule, timed with the metrics
                live.best_nodes = np.array(tree.best_path_nodes())
                self._show_path(tree.dense_path(0.05))
                self.record.add_path(live.best_path)
            live.cost_over_time = tree.cost_over_time

    def _show_path(self, path: np.ndarray) -> None:
        self.live.best_path = path
        self.live.best_version += 1

    def _timed(self) -> planner.Result:
        """Timing optimal: the run's result, timed anew when a tree's best path has changed
        (tens of ms: with the metrics, at most twice a second); its path is the one shown."""
        costs = [p.best_cost for p in self.run.planners]
        if costs != self._timed_costs:
            self._timed_costs, self._result = costs, self.run.result()
            if self._result.solved:
                self._show_path(self._result.path)
        return self._result

    def metrics(self) -> dict:
        """The metrics as the UI shows them: iterations/s over ``wall``, the rate achieved
        (under the pace too, and beside the other run: both share one clock)."""
        tree, wall = self.tree, self.wall
        out = {"iterations": tree.iterations, "nodes": tree.nodes, "rewires": tree.rewires,
               "time_to_first_solution_s": tree.time_to_first_solution_s,
               "first_solution_iteration": next(
                   (it for _, _, it in tree.cost_over_time), None),
               "cost": tree.best_cost,
               "iterations_per_s": tree.iterations / wall if wall > 0 else 0.0,
               "planning_time_s": tree.planning_time_s}
        if self._optimal:
            result = self._timed()
            return out | {"min_clearance_m": result.min_clearance_m,
                          "arrival_s": result.cost, "waited_s": result.waited_s}
        if self._clearance_of != self._best:  # the exact check costs ms: at most twice a second
            self._clearance, self._clearance_of = tree.best_path_clearance(), self._best
        return out | {"min_clearance_m": self._clearance}


class PlannerWorker:
    """Drives one run (`Lane`), or two on one clock (``other``: the second run's options, the
    two-up split), on its own thread; commanded (run, pause, step, stop) from the UI.
    ``budget`` is the iterations of each tree; Run after it is spent runs on for as many
    again (a lecture budget ends while the tree is readable, and the run can go on)."""

    def __init__(self, problem, options: planner.PlanOptions, budget: int,
                 rate: float | None = None, other: planner.PlanOptions | None = None) -> None:
        self.lanes = [Lane(problem, o) for o in (options, other) if o is not None]
        self.budget = self.run_on = budget
        self.rate = rate  # iterations per second, None: as fast as it goes
        self._cmds: queue.Queue[str] = queue.Queue()
        # Held while the runs' metrics are replaced and while the UI reads them: the numbers
        # it shows of A and B are of one moment of the clock.
        self.published = threading.Lock()
        self._last_metrics = 0.0
        self._thread = threading.Thread(target=self._loop, daemon=True, name="planner")
        self._thread.start()

    @property
    def live(self) -> Live:
        """The first run's record (the only one outside the split)."""
        return self.lanes[0].live

    @property
    def record(self) -> TreeRecord:
        return self.lanes[0].record

    @property
    def options(self) -> planner.PlanOptions:
        return self.lanes[0].options

    # -- commands (any thread) -----------------------------------------------------------------
    def run(self) -> None:
        self._cmds.put("run")

    def pause(self) -> None:
        self._cmds.put("pause")

    def step(self, until: str | None = None) -> None:
        """One iteration of each run; with ``until`` ("node" or "rewire") single iterations
        until one adds a node or rewires in either run (`STEP_CAP` at most). The last one is
        shown."""
        self._cmds.put(f"step {until}" if until else "step")

    def steer_points(self, a, b) -> np.ndarray:
        return self.lanes[0].steer_points(a, b)

    def stop(self) -> None:
        self._cmds.put("stop")
        self._thread.join(timeout=2.0)

    @property
    def started(self) -> bool:
        """Whether the run has iterated."""
        return self.lanes[0].stepped > 0

    @property
    def can_run_on(self) -> bool:
        """Whether the runs stopped at the budget alone, so that Run would go on (not RRT at
        its first solution, not a planner's error)."""
        return self._done() and any(not lane.run.finished and lane.live.error is None
                                    for lane in self.lanes)

    # -- the thread ------------------------------------------------------------------------------
    def _loop(self) -> None:
        running, batch = False, 16
        while True:
            try:
                cmd = self._cmds.get(timeout=0.0 if running else 0.2)
            except queue.Empty:
                cmd = None
            if cmd == "stop":
                return
            if cmd == "run":
                if self.can_run_on:
                    self.budget += self.run_on
                running = not self._done()
            elif cmd == "pause":
                running = False
                self._publish_metrics()
            elif cmd and cmd.startswith("step") and not self._done():
                running = False
                self._single_steps(cmd.partition(" ")[2] or None)
            self._set_state(running)
            if running:
                n = batch if self.rate is None else max(1, int(self.rate * BATCH_S))
                n = min(n, self.budget - min(lane.stepped for lane in self._active()))
                took = self._advance(n)
                if self.rate is None:
                    batch = max(1, min(20000, int(n * BATCH_S / max(took, 1e-6))))
                else:
                    self._throttle(n / self.rate - took)
                running = not self._done()
                self._publish_metrics(force=not running)  # a short run ends between updates
                time.sleep(0)  # let the UI thread take the GIL between batches

    def _active(self) -> list[Lane]:
        """The runs still going: they have all done the same number of iterations."""
        return [lane for lane in self.lanes if not lane.done(self.budget)]

    def _done(self) -> bool:
        return not self._active()

    def _set_state(self, running: bool) -> None:
        for lane in self.lanes:
            lane.live.state = ("done" if lane.done(self.budget)
                               else "running" if running else "paused")

    def _single_steps(self, until: str | None) -> None:
        """One iteration, or single iterations until one did ``until`` (see `step`); only the
        last is published, with how many it took and how the search ended."""
        for lane in self.lanes:
            lane.last_step = None
        found = False
        for count in range(1, (STEP_CAP if until else 1) + 1):
            self._advance(1, stepping=True)
            found = until is not None and any(lane.found(until) for lane in self.lanes)
            if until is None or found or self._done():
                break
        outcome = "found" if found else ("done" if self._done() else "cap")
        for lane in self.lanes:
            lane.show_step((until, count, outcome))
        self._publish_metrics()

    def _advance(self, n: int, stepping: bool = False) -> float:
        """``n`` iterations of each run still going, one after the other."""
        t0 = time.perf_counter()
        active = self._active()
        for lane in active:
            lane.advance(n, stepping)
        took = time.perf_counter() - t0
        for lane in active:
            lane.wall += took
        return took

    def _throttle(self, pause: float) -> None:
        """Sleep to hold the pace; the sleep counts as the run's time, so iterations/s shows
        the rate achieved, not the planner's raw one."""
        t0 = time.perf_counter()
        time.sleep(max(0.0, pause))
        slept = time.perf_counter() - t0
        for lane in self._active():
            lane.wall += slept

    def _publish_metrics(self, force: bool = True) -> None:
        """Every run's metrics at once, after a whole batch: the runs' numbers are of one
        moment of the clock."""
        now = time.monotonic()
        if force or now - self._last_metrics >= METRICS_S:
            self._last_metrics = now
            metrics = [lane.metrics() for lane in self.lanes]
            with self.published:
                for lane, m in zip(self.lanes, metrics):
                    lane.live.metrics = m
                    lane.live.metrics_version += 1
