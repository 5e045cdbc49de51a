"""What viewers see of a tree: copies with named fields, never the planner's live arrays.

`TreeSnapshot` is the tree at one moment (`Planner.snapshot()`); `TreeEvents` is what a batch of
iterations did (`Planner.add_listener`), one entry per iteration in the words of RRT*'s EXTEND:
the sample x_rand, x_nearest, x_new and its parent, the near set and radius, the rewires.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from planner._kernel import chain
from planner._paths import path_length, sample_path

__all__ = ["Rewire", "TreeEvents", "TreeSnapshot", "edge_points", "path_points"]


def edge_points(pose, parent, kinds, lens, curv, node: int, count: int) -> np.ndarray:
    """(count + 1, 2) positions along the local path from ``node``'s parent to it (the root:
    its position repeated), for drawing curved edges."""
    up = int(parent[node])
    if up < 0:
        return np.repeat(pose[node:node + 1, :2], count + 1, axis=0)
    return path_points(pose[up], kinds[node], lens[node], curv[node], count)


def path_points(start, kinds, lens, curv, count: int) -> np.ndarray:
    """(count + 1, 2) positions, evenly spread, along a local path from pose ``start``."""
    total = path_length(kinds, lens)
    dense = sample_path(*start, kinds, lens, curv, max(total / (4 * count), 1e-6))
    pick = np.linspace(0, len(dense) - 1, count + 1).round().astype(int)
    return dense[pick, :2]


@dataclass(frozen=True)
class TreeSnapshot:
    """A copy of the tree: node i has ``pose[i]`` (x, y, θ), ``parent[i]`` (-1: the root),
    ``cost[i]`` (driven length from the root) and reaches it by the local path (``kinds[i]``,
    ``lens[i]``, ``curv[i]``) in the segment form of `planner._paths`."""

    pose: np.ndarray
    parent: np.ndarray
    cost: np.ndarray
    kinds: np.ndarray
    lens: np.ndarray
    curv: np.ndarray
    best_node: int  # -1 before a solution

    @property
    def nodes(self) -> int:
        return len(self.pose)

    @property
    def best_path(self) -> np.ndarray:
        """The best path's nodes, root first (none before a solution)."""
        return chain(self.parent, self.best_node)

    def edge_points(self, node: int, count: int = 4) -> np.ndarray:
        """(count + 1, 2) positions along the edge into ``node`` (see `edge_points`)."""
        return edge_points(self.pose, self.parent, self.kinds, self.lens, self.curv, node, count)


class Rewire(NamedTuple):
    """RRT*'s Rewire: in ``iteration``, ``node`` changed parent from ``old_parent`` to
    ``new_parent`` (that iteration's x_new)."""

    iteration: int
    node: int
    old_parent: int
    new_parent: int


@dataclass(frozen=True)
class TreeEvents:
    """A batch of iterations, entry i for the batch's i-th iteration; -1 where a step did not
    happen (no x_nearest: the sample fell inside an obstacle; no x_new: the way was blocked)."""

    iteration: np.ndarray  # (n,) int: the planner's iteration number
    sample: np.ndarray  # (n, 3): x_rand
    nearest: np.ndarray  # (n,) int: x_nearest
    new: np.ndarray  # (n,) int: x_new, the node added
    parent: np.ndarray  # (n,) int: x_new's parent (x_min for RRT*)
    radius: np.ndarray  # (n,): the near radius r(n) (0 for RRT, inf for k-nearest)
    steered: np.ndarray  # (n, 3): where Steer ended, x_new added or blocked (NaN: no Steer)
    # (n,): how far a blocked Steer was free (NaN: not blocked); where half of it is ρ or more,
    # x_new is the pose there (`planner._kernel.KEEP_SHARE`)
    free: np.ndarray
    best_cost: np.ndarray  # (n,): the best cost after the iteration (inf: none yet)
    rewires: list[Rewire]
    polished: np.ndarray  # nodes added as the polished best path (`planner._polish`), in order
    _near: np.ndarray = field(repr=False)  # the near sets, concatenated
    _near_span: np.ndarray = field(repr=False)  # (n, 2): each iteration's slice of _near

    def __len__(self) -> int:
        return len(self.iteration)

    def near_of(self, i: int) -> np.ndarray:
        """X_near of the batch's i-th iteration (empty when no node was added)."""
        start, end = self._near_span[i]
        return self._near[max(start, 0):max(end, 0)]
