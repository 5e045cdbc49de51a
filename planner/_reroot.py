"""Re-rooting an RRT* tree at a committed state (compiled; `Planner.adopt` is its public face).

The committed state lies on an edge of the old tree (or on a node). The new tree's root is that
state; the part of the old edge still ahead becomes the root's first edge, and the whole subtree
below it is copied with its edges unchanged and its costs shifted, each edge re-checked against
the new (predicted) world at its new arrival time. An edge that fails is dropped with its whole
subtree: this is the "keep the still-valid subtree, prune what became invalid" of RRTX-style
replanning. Nodes behind the car (other branches) are not kept.
"""

from __future__ import annotations

import numpy as np

from planner import _kernel as K
from planner._jit import njit
from planner._paths import TURN, curvature_at, path_buffers
from planner._world import World, motion_free


@njit(cache=True)
def _tail(kinds, lens, curv, skip, out_lens, out_curv):
    """Into ``out_lens``/``out_curv`` the segments left after driving ``skip`` metres along
    (kinds, lens, curv): a segment entered part way starts at the curvature reached there."""
    remaining = skip
    for i in range(lens.shape[0]):
        seg = lens[i]
        out_curv[i, 0], out_curv[i, 1] = curv[i, 0], curv[i, 1]
        if kinds[i] == TURN:  # taken once the car has gone on past it (see `_paths`)
            out_lens[i] = 0.0 if remaining > 0.0 else seg
            continue
        take = min(abs(seg), max(remaining, 0.0))
        left = abs(seg) - take
        out_lens[i] = left if seg >= 0.0 else -left
        out_curv[i, 0] = curvature_at(kinds[i], curv[i, 0], curv[i, 1], take)
        remaining -= take


@njit(cache=True)
def reroot(old: K.Tree, new: K.Tree, w: World, P: np.ndarray, anchor: int, skip: float,
           bound: float) -> int:
    """Copy into ``new`` (holding only its root) the still-valid subtree ahead of the root.

    The new root is at ``skip`` metres along the edge into ``anchor`` (skip = 0: at ``anchor``
    itself, whose children are then copied). Nodes whose cost plus straight-line distance to
    the goal exceeds ``bound`` are dropped with their subtrees (that sum only grows down a
    branch), as informed RRT* prunes: it keeps the tree, and each iteration, small. Returns the
    number of nodes copied; the caller has made room for all of them. Goal nodes are registered
    by `add_node`; the caller updates the best node.
    """
    speed = P[K.SPEED]
    stack = np.empty(old.cnt[K.N] + 1, np.int64)  # old node
    mapped = np.empty(old.cnt[K.N] + 1, np.int64)  # its new parent
    top = 0
    if skip > 0.0:
        stack[0] = anchor
        mapped[0] = 0
        top = 1
        base = old.cost[old.parent[anchor]] + skip
    else:
        base = old.cost[anchor]
        c = old.first_child[anchor]
        while c >= 0:
            stack[top] = c
            mapped[top] = 0
            top += 1
            c = old.next_sibling[c]
    _, lens, curv = path_buffers(old.lens.shape[1])
    counter = np.zeros(1, np.int64)
    copied = 0
    while top > 0:
        top -= 1
        node = stack[top]
        par_new = mapped[top]
        if skip > 0.0 and node == anchor:
            _tail(old.kinds[node], old.lens[node], old.curv[node], skip, lens, curv)
        else:
            lens[:] = old.lens[node]
            curv[:, :] = old.curv[node]
        cost = old.cost[node] - base
        if cost + np.hypot(old.pose[node, 0] - P[K.GX], old.pose[node, 1] - P[K.GY]) > bound:
            continue
        px, py, pth = new.pose[par_new, 0], new.pose[par_new, 1], new.pose[par_new, 2]
        if not motion_free(w, px, py, pth, new.cost[par_new] / speed, old.kinds[node], lens,
                           curv, speed, counter):
            continue  # this edge became invalid: prune it and everything below
        x, y, th = old.pose[node, 0], old.pose[node, 1], old.pose[node, 2]
        k = K.add_node(new, P, x, y, th, cost, par_new, old.kinds[node], lens, curv)
        copied += 1
        c = old.first_child[node]
        while c >= 0:
            stack[top] = c
            mapped[top] = k
            top += 1
            c = old.next_sibling[c]
    return copied
