"""The replay slider's record (issue 20): what rebuilding the tree at any past iteration needs.

The planner's `TreeEvents` name every node added (x_new with its parent, and the nodes that
polishing the best path added) and every rewire (node, old and new parent), each with its
iteration, and the best cost after each iteration. `TreeRecord` keeps, from them, per node the
iteration that added it and its first parent, per rewire its iteration, node, old and new
parent, and the best cost where it changed; `parents_at` rebuilds the parent array as of any
iteration N from that alone (nodes are numbered in the order they are added, and rewires come
in order, so "as of N" is a prefix of each). The best path is kept as the worker drew it, with
the iteration its cost was reached: between two improvements inside one batch of the running
planner the record has the cost but not the path (`Frame.path_iteration` says which is shown).

Recording stops, with a note, past `MAX_NODES` nodes, or if a batch's events ever missed
something (they should not: the kernel ends a batch early and its buffers grow rather than drop
an event): the slider then covers the iterations recorded before.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

import planner

__all__ = ["MAX_NODES", "Frame", "TreeRecord", "parents_at"]

MAX_NODES = 200_000  # nodes recorded at most: about 10 MB with the rewires


def _grown(a: np.ndarray, size: int) -> np.ndarray:
    if size <= len(a):
        return a
    out = np.zeros((max(size, 2 * len(a)), *a.shape[1:]), a.dtype)
    out[:len(a)] = a
    return out


def parents_at(node_iteration: np.ndarray, first_parent: np.ndarray, rewires: np.ndarray,
               n: int) -> np.ndarray:
    """The parent of each node as it stood after iteration ``n``: the nodes added by then (a
    prefix: node numbers grow with iterations) with their first parent, then for each node
    rewired by then the new parent of its last rewire. ``rewires``: (m, 4) rows (iteration,
    node, old parent, new parent) in the order they happened."""
    count = int(np.searchsorted(node_iteration, n, side="right"))
    parent = first_parent[:count].copy()
    done = rewires[:int(np.searchsorted(rewires[:, 0], n, side="right"))]
    # The last rewire of each node wins: the first of each in reversed order.
    nodes, at = np.unique(done[::-1, 1], return_index=True)
    parent[nodes] = done[::-1, 3][at]
    return parent


@dataclass(frozen=True)
class Frame:
    """The tree after ``iteration``: ``parent`` per node (its length is the node count), the
    best cost then (None: no solution yet), reached at ``cost_iteration``, and the best path
    drawn for it (rows as `Live.best_path`; None: none), the one drawn at ``path_iteration``
    (the same iteration unless the cost fell again inside one of the planner's batches)."""

    iteration: int
    parent: np.ndarray
    cost: float | None
    cost_iteration: int | None
    path: np.ndarray | None
    path_iteration: int | None

    @property
    def nodes(self) -> int:
        return len(self.parent)


class TreeRecord:
    """The iterations of one tree, as its listener saw them (see the module's docstring).

    `add` runs on the planner's thread after each batch; the UI's thread reads `frame`,
    `poses` and `iterations`. Every method takes the lock."""

    def __init__(self, root_pose, limit: int = MAX_NODES) -> None:
        self.limit = limit
        self.note: str | None = None  # why recording stopped (None: it goes on)
        self.iterations = 0  # recorded through this iteration
        self._iter = np.zeros(4096, np.int64)  # per node: the iteration that added it
        self._first = np.full(4096, -1, np.int64)  # per node: its first parent
        self._pose = np.zeros((4096, 3))
        self._pose[0] = root_pose
        self._n = 1
        self._rw = np.zeros((4096, 4), np.int64)  # iteration, node, old, new parent
        self._m = 0
        self._costs: list[tuple[int, float]] = []  # (iteration, best cost) where it changed
        self._paths: list[tuple[int, np.ndarray]] = []  # (iteration, best path) as drawn
        self._lock = threading.Lock()

    @property
    def nodes(self) -> int:
        return self._n

    def add(self, ev: planner.TreeEvents, poses: np.ndarray, nodes: int, rewires: int) -> None:
        """A batch's events; ``poses`` (the tree's, read on its thread), ``nodes`` and
        ``rewires`` (its counts after the batch) check that the events named everything.

        Polished nodes are the polished best path from the root, in order: the first of a
        chain hangs from the root, the others from the node before, all added in the
        iteration of the node numbered just before them (polishing follows an iteration's
        x_new)."""
        if self.note is not None or not len(ev):
            return
        fresh = ev.new >= 0
        added = np.concatenate([ev.new[fresh], ev.polished])
        order = np.argsort(added, kind="stable")
        added = added[order]
        polished = np.isin(ev.polished - 1, ev.polished)
        first = np.concatenate([ev.parent[fresh], np.where(polished, ev.polished - 1, 0)])[order]
        when = np.concatenate([ev.iteration[fresh], np.full(len(ev.polished), -1)])[order]
        with self._lock:
            n, m = self._n, self._m
            if nodes > self.limit:
                self.note = (f"Replay records the first {self.iterations:,} iterations "
                             f"(at most {self.limit:,} nodes)")
                return
            if (not np.array_equal(added, np.arange(n, n + len(added))) or n + len(added)
                    != nodes or m + len(ev.rewires) != rewires):
                self.note = (f"Replay records the first {self.iterations:,} iterations (a "
                             "later batch's events did not name every node and rewire, as "
                             "the planner's always should: please report this run)")
                return
            when = np.maximum.accumulate(np.concatenate([[self._iter[n - 1]], when]))[1:]
            self._iter, self._first = _grown(self._iter, nodes), _grown(self._first, nodes)
            self._pose = _grown(self._pose, nodes)
            self._iter[n:nodes], self._first[n:nodes] = when, first
            self._pose[n:nodes] = poses[n:nodes]
            self._n = nodes
            if ev.rewires:
                self._rw = _grown(self._rw, rewires)
                self._rw[m:rewires] = np.array(ev.rewires, np.int64)
                self._m = rewires
            # An iteration that stopped early (no x_new) leaves its best cost unset (-1): the
            # cost can only change in one that went on to the end.
            ended = ev.best_cost >= 0
            last = self._costs[-1][1] if self._costs else np.inf
            costs = np.concatenate([[last], ev.best_cost[ended]])
            for i in np.flatnonzero(costs[1:] != costs[:-1]):
                self._costs.append((int(ev.iteration[ended][i]), float(costs[i + 1])))
            self.iterations = int(ev.iteration[-1])

    def add_path(self, path: np.ndarray) -> None:
        """The best path the worker drew after the batch just added: the one of the batch's
        last cost change."""
        with self._lock:
            if self.note is None and self._costs:
                self._paths.append((self._costs[-1][0], path))

    def poses(self, count: int) -> np.ndarray:
        with self._lock:
            return self._pose[:count].copy()

    def frame(self, n: int) -> Frame:
        """The tree after iteration ``n`` (clipped to those recorded)."""
        with self._lock:
            n = min(max(int(n), 0), self.iterations)
            parent = parents_at(self._iter[:self._n], self._first[:self._n],
                                self._rw[:self._m], n)
            cost_at = next(((i, c) for i, c in reversed(self._costs) if i <= n), (None, None))
            path_at = next(((i, p) for i, p in reversed(self._paths) if i <= n), (None, None))
        if cost_at[1] is None or not np.isfinite(cost_at[1]):
            cost_at = (None, None)
        return Frame(n, parent, cost_at[1], cost_at[0], path_at[1], path_at[0])
