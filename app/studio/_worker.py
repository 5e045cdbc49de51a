"""One session's planner on its own thread, and what it leaves for the UI to draw.

The planner is stepped in short batches (~5 ms) so the UI thread gets the GIL between them;
its listener (on this thread, where reading the tree is safe) turns kernel events into edges,
rewire flashes, the best path and metrics in a `Live` record the UI polls.

With ``timing: optimal`` the run is a `planner.TimeOptimalPlanner`: its route tree is the one
drawn, its detour tree grows alongside, and the best path shown is the run's result — the
chosen schedule, waits included — so that Drive car and the profiles show what it would drive.
"""

from __future__ import annotations

import queue
import threading
import time
from collections import deque
from dataclasses import dataclass, field

import numpy as np

import planner
from app.studio._extend import StepInfo
from app.studio._replay import TreeRecord
from app.studio._tree import SEG, EdgeChunks

__all__ = ["Live", "PlannerWorker"]

BATCH_S = 0.005
FLASH_S = 0.6
STEP_CAP = 10_000  # iterations one "step until" takes at most


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
    step: dict | None = None
    step_version: int = 0
    state: str = "ready"
    error: str | None = None


class PlannerWorker:
    """Owns a planner run (`planner.planner_for`); driven by commands (run, pause, step, stop)
    from the UI. ``budget`` is the iterations of each tree."""

    def __init__(self, problem, options: planner.PlanOptions, budget: int,
                 rate: float | None = None) -> None:
        self.live = Live()
        self.options = options  # as the panel gave them: what a pinned run is labelled with
        self.budget = budget
        self.rate = rate  # iterations per second, None: as fast as it goes
        self._problem = problem
        self._run = planner.planner_for(problem, options)
        self._optimal = options.timing == "optimal"
        self._tree = self._run.route if self._optimal else self._run  # the tree drawn
        self._tree.add_listener(self._on_events)
        self.record = TreeRecord(self._tree.root)  # what the replay slider rebuilds from
        self._stepped = 0  # iterations asked of each tree
        self._result = self._timed_costs = None  # timing optimal: the result shown, and of what
        self._star = options.planner == "rrtstar"
        self._cmds: queue.Queue[str] = queue.Queue()
        self._stepping = False
        self._last_step: dict | None = None  # the last single iteration, not yet shown
        self._costs_before = None  # the tree's costs before it: a rewired node's old cost
        self._best = None
        self._clearance = self._clearance_of = None  # the best path's, and of which cost
        self._wall = 0.0  # s the run took: planning and the Speed throttle's sleeps
        self._last_metrics = 0.0
        self._thread = threading.Thread(target=self._loop, daemon=True, name="planner")
        self._on_events(None)  # the root
        self._thread.start()

    # -- commands (any thread) -----------------------------------------------------------------
    def run(self) -> None:
        self._cmds.put("run")

    def pause(self) -> None:
        self._cmds.put("pause")

    def step(self, until: str | None = None) -> None:
        """One iteration; with ``until`` ("node" or "rewire") single iterations until one adds
        a node or rewires (`STEP_CAP` at most). The last one is shown."""
        self._cmds.put(f"step {until}" if until else "step")

    def steer_points(self, a, b) -> np.ndarray:
        """(SEG + 1, 2) positions along the steering from pose a to pose b: an edge the tree
        held once (the replay draws a rewired node's old edge); any thread (no tree state)."""
        return self._tree.steer_points(a, b, SEG)

    def stop(self) -> None:
        self._cmds.put("stop")
        self._thread.join(timeout=2.0)

    @property
    def started(self) -> bool:
        """Whether the run has iterated."""
        return self._stepped > 0

    @property
    def iterations_per_s(self) -> float:
        return self._tree.iterations / self._wall if self._wall > 0 else 0.0

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
                running = not self._done()
            elif cmd == "pause":
                running = False
                self._publish_metrics()
            elif cmd and cmd.startswith("step") and not self._done():
                running = False
                self._single_steps(cmd.partition(" ")[2] or None)
            self.live.state = "done" if self._done() else ("running" if running else "paused")
            if running:
                n = batch if self.rate is None else max(1, int(self.rate * BATCH_S))
                n = min(n, self.budget - self._stepped)
                took = self._advance(n)
                if self.rate is None:
                    batch = max(1, min(20000, int(n * BATCH_S / max(took, 1e-6))))
                else:
                    self._throttle(n / self.rate - took)
                running = not self._done()
                if not running:  # a short run can end between two throttled updates
                    self._publish_metrics()
                time.sleep(0)  # let the UI thread take the GIL between batches

    def _done(self) -> bool:
        return self._run.finished or self._stepped >= self.budget

    def _single_steps(self, until: str | None) -> None:
        """One iteration, or single iterations until one did ``until`` (see `step`); only the
        last is published, with how many it took and how the search ended."""
        self._last_step = found = None
        for count in range(1, (STEP_CAP if until else 1) + 1):
            self._advance(1, stepping=True)
            info = self._last_step and self._last_step["info"]
            found = info and (info.new >= 0 if until == "node" else info.n_rewired > 0)
            if until is None or found or self._done():
                break
        if self._last_step is not None:
            outcome = "found" if found else ("done" if self._done() else "cap")
            self.live.step = dict(self._last_step, until=(until, count, outcome))
            self.live.step_version += 1

    def _advance(self, n: int, stepping: bool = False) -> float:
        t0 = time.perf_counter()
        self._stepping = stepping
        if stepping:
            self._costs_before = self._tree.costs.copy()
        try:
            self._run.step(n)
            self._stepped += n
        except Exception as exc:  # noqa: BLE001  (a planner bug must not kill the session)
            self.live.error = f"{type(exc).__name__}: {exc}"
            self.budget = self._stepped
        took = time.perf_counter() - t0
        self._wall += took
        return took

    def _throttle(self, pause: float) -> None:
        """Sleep to hold the Speed rate; the sleep counts as the run's time, so iterations/s
        shows the rate achieved, not the planner's raw one."""
        t0 = time.perf_counter()
        time.sleep(max(0.0, pause))
        self._wall += time.perf_counter() - t0

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
        self.record.add(ev, self._tree.poses, self._tree.nodes, self._tree.rewires)
        self._note_best(now)

    def _record(self, node: int) -> np.ndarray:
        """Node's edge as drawn and as a click names it (its segments); returns its points."""
        pts = self._tree.edge_points(node, SEG)
        self.live.chunks.set(node, pts, *self._tree.edge_segments(node))
        return pts

    def _note_step(self, ev: planner.TreeEvents, rewired: list) -> None:
        """The iteration as the step overlay and the EXTEND panel show it: a blocked Steer's
        motion, and each rewired node's edges with its cost before and after."""
        tree = self._tree
        pose, cost = tree.poses, tree.costs
        info = StepInfo.from_events(ev, -1, len(rewired))
        blocked = info.nearest >= 0 and info.new < 0
        self._last_step = {
            "info": info, "star": self._star, "options": tree.options,
            "x_rand": ev.sample[-1].copy(),
            "nearest": pose[info.nearest].copy() if info.nearest >= 0 else None,
            "new": pose[info.new].copy() if info.new >= 0 else None,
            "blocked": ((ev.steered[-1].copy(),
                         tree.steer_points(pose[info.nearest], ev.steered[-1], SEG))
                        if blocked else None),
            "parent_edge": (self.live.chunks.get(info.new) if info.new >= 0 else None),
            "near": pose[ev.near_of(-1)].copy(), "radius": info.radius,
            "rewired": [(old, new, float(self._costs_before[node]), float(cost[node]))
                        for old, new, node in rewired],
        }

    def _note_best(self, now: float) -> None:
        tree, live = self._tree, self.live
        cost = tree.best_cost
        if cost is not None and (self._best is None or cost < self._best - 1e-9):
            self._best = cost
            if not self._optimal:  # else the schedule, timed with the metrics
                live.best_nodes = np.array(tree.best_path_nodes())
                self._show_path(tree.dense_path(0.05))
                self.record.add_path(live.best_path)
            live.cost_over_time = tree.cost_over_time
        if now - self._last_metrics >= 0.5 or self._stepping:
            self._last_metrics = now
            self._publish_metrics()

    def _show_path(self, path: np.ndarray) -> None:
        self.live.best_path = path
        self.live.best_version += 1

    def _timed(self) -> planner.Result:
        """Timing optimal: the run's result, timed anew when a tree's best path has changed
        (tens of ms: with the metrics, at most twice a second); its path is the one shown."""
        costs = [p.best_cost for p in self._run.planners]
        if costs != self._timed_costs:
            self._timed_costs, self._result = costs, self._run.result()
            if self._result.solved:
                self._show_path(self._result.path)
        return self._result

    def _publish_metrics(self) -> None:
        self.live.metrics = self._metrics()
        self.live.metrics_version += 1

    def _metrics(self) -> dict:
        tree = self._tree
        out = {"iterations": tree.iterations, "nodes": tree.nodes, "rewires": tree.rewires,
               "time_to_first_solution_s": tree.time_to_first_solution_s,
               "cost": tree.best_cost, "iterations_per_s": self.iterations_per_s,
               "planning_time_s": tree.planning_time_s}
        if self._optimal:
            result = self._timed()
            return out | {"min_clearance_m": result.min_clearance_m,
                          "arrival_s": result.cost, "waited_s": result.waited_s}
        if self._clearance_of != self._best:  # the exact check costs ms: at most twice a second
            self._clearance, self._clearance_of = tree.best_path_clearance(), self._best
        return out | {"min_clearance_m": self._clearance}
