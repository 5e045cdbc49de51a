"""The compiled RRT / RRT* iteration (LaValle 1998; Karaman & Frazzoli 2011) for a car.

Data live in flat arrays (`Tree`), positions in a uniform grid that grows with the tree. The
Euclidean distance between positions, and for Dubins the turning circles' bound, are lower
bounds of every car path length, so nearest and near queries scan grid cells outward and compute
exact steering lengths only for the few nodes whose bound can still beat the best so far (OMPL
instead computes a Dubins length to every node, every iteration).

Rewiring keeps the rewired child's full SE(2) state: with exact steering the new edge ends at
exactly the old pose, so the subtree stays kinematically valid and only its costs (and, with
moving obstacles, its arrival times) change. The seed thesis duplicated nodes instead, because
its edges did not fix the heading; see docs/planner.md. With moving obstacles a rewire is taken
only if every edge of the rewired subtree is still free at its new, earlier times.

The sampling and ring-walk helpers are inlined (``inline="always"``): a compiled call that takes
the Tree or the World counts references to each of their ~20 arrays up and down, atomically
(perf: NRT_incref / NRT_decref; see docs/planner.md).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from planner._cc_dubins import cc_constants
from planner._dubins import turning_centres
from planner._goal import in_goal
from planner._jit import njit
from planner._paths import path_buffers, path_end, truncate, wrap_angle
from planner._polish import PASSES, polish_path
from planner._rng import uniform
from planner._steer import (
    arrival_heading,
    state,
    steer_bound,
    steer_cut,
    steer_length,
    steer_path,
    steer_tight_bound,
)
from planner._world import World, free_length, motion_free, static_clearance_estimate

# Parameter vector indices.
(EPS, GAMMA, GOAL_BIAS, RHO, SIGMA, SPEED, GX, GY, GTH, GPOS, GHEAD, INFORMED, STAR, STEERING,
 SX, SY, K_RRT, DIMS, METRIC, POLISH, NPARAMS) = range(21)
STEERING_METRIC, SE2_METRIC = range(2)  # planner.options.METRICS
LANE_SHARE, LANE_SIGMA = 0.9, 0.25  # track scenarios: headings sampled along the lane
NEAREST_BUCKETS = 256  # nearest's queue: half-cell buckets, the last one takes the rest
# Polishes from this iteration on also shift blocks of poses: they cost twice as much, and the
# late polishes, a doubling apart, are few (earlier ones would slow the first 0.1 s).
BLOCKS_FROM = 8192
# Counter indices; POLISH_AT: the iteration at which the best path is next polished;
# POLISHED: the best cost the last polish left, in micrometres; POLISHED_AT: its iteration;
# POLISH_EVALS: the clearance evaluations polishing has spent (of EVALS, all of them).
(N, NGOAL, ITER, CHECKS, BEST, REWIRES, EVALS, IMPROVED, REFUSED, POLISH_AT, POLISHED,
 POLISHED_AT, POLISH_EVALS, NCOUNTERS) = range(14)
# Polishing may spend at most this share of a run's clearance evaluations, counted (not
# timed), so that a seed's run is the same on any machine; its share of the time stays under
# a quarter (`planner.rrt.Result.polish_s` measures it).
POLISH_SHARE = 0.2
# ... beyond a first few thousand evaluations, which the first polishes of a short run may spend
# whatever the search has spent so far (at the first solution that can be a few dozen).
POLISH_FREE = 5000
# A Steer blocked after a free part f (static scenes): x_new moves back to f·KEEP_SHARE, if
# that is KEEP_MIN·ρ or more (with the steering metric: the SE(2) nearest's path may loop, and
# its cut nodes left slalom unsolved). The tree reaches along narrow lanes instead of dropping
# every sample it cannot reach whole (benchmarks/results/scenes.md: first solutions 1.6–2.5×
# sooner on the stadium lap, the maze and the corridors); nearer the obstacle (0.75) it was
# slower.
KEEP_SHARE, KEEP_MIN = 0.5, 1.0
# What `iterate` returns: the batch ran; the tree is full (grow it and call again); a polish
# is due (call `polish`, then `iterate` for the rest of the batch); the event buffers might not
# hold the next iteration's near set and rewires (grow them and call again).
RAN, FULL, POLISH_DUE, EVENTS_FULL = range(4)
# Event row columns (only written when the event buffers are non-empty); EV_XN..EV_THN: where
# Steer ended, whether the motion to it was free or not; EV_FREE: how far a blocked one was free
# (static scenes; -1: not blocked).
EV_ITER, EV_XR, EV_YR, EV_THR, EV_NEAREST, EV_NEW, EV_PARENT, EV_NEAR_START, EV_NEAR_END, \
    EV_RADIUS, EV_BEST, EV_XN, EV_YN, EV_THN, EV_FREE, EV_COLS = range(16)


class Tree(NamedTuple):
    pose: np.ndarray  # (cap, 3)
    trig: np.ndarray  # (cap, 6): cos θ, sin θ and the turning circles' centres (left x, y,
    # right x, y): Dubins lengths and bounds then need no trigonometry
    cost: np.ndarray  # (cap,) driven length from the root
    parent: np.ndarray  # (cap,) int64, -1 for the root
    kinds: np.ndarray  # (cap, S) int8: the edge from the parent (`planner._paths`), S the
    lens: np.ndarray  # (cap, S)        steering's segments
    curv: np.ndarray  # (cap, S, 2)
    first_child: np.ndarray  # (cap,) int64
    next_sibling: np.ndarray  # (cap,) int64
    cell_head: np.ndarray  # (nx * ny,) int64
    cell_next: np.ndarray  # (cap,) int64
    grid: np.ndarray  # float64[5]: x0, y0, cell size, nx, ny
    goal_nodes: np.ndarray  # (cap,) int64
    improved: np.ndarray  # (cap, 2): iteration and best cost at each improvement (cnt[IMPROVED])
    cnt: np.ndarray  # int64[NCOUNTERS], see the counter indices
    rng: np.ndarray  # uint64[4]
    near: np.ndarray  # scratch (cap,) int64
    near_len: np.ndarray  # scratch (cap,)
    near_key: np.ndarray  # scratch (cap,)
    stack: np.ndarray  # scratch (cap,) int64


class Events(NamedTuple):
    """Per-iteration records for a visualiser; zero-length arrays switch recording off."""

    rows: np.ndarray  # (cap, EV_COLS)
    near: np.ndarray  # (cap,) int64, slices given by EV_NEAR_START:EV_NEAR_END
    rewires: np.ndarray  # (cap, 4) int64: iteration, node, old parent, new parent
    polished: np.ndarray  # (cap,) int64: nodes added by polishing the best path
    cnt: np.ndarray  # int64[4]: rows, near entries, rewires, polished nodes used


def new_tree(capacity: int, grid: np.ndarray, rng: np.ndarray, segments: int) -> Tree:
    """An empty tree whose edges have up to ``segments`` segments (the steering's)."""
    nx, ny = int(grid[3]), int(grid[4])
    return Tree(
        pose=np.zeros((capacity, 3)), trig=np.zeros((capacity, 6)), cost=np.zeros(capacity),
        parent=np.full(capacity, -1, np.int64), kinds=np.zeros((capacity, segments), np.int8),
        lens=np.zeros((capacity, segments)), curv=np.zeros((capacity, segments, 2)),
        first_child=np.full(capacity, -1, np.int64),
        next_sibling=np.full(capacity, -1, np.int64), cell_head=np.full(nx * ny, -1, np.int64),
        cell_next=np.full(capacity, -1, np.int64), grid=grid,
        goal_nodes=np.zeros(capacity, np.int64), improved=np.zeros((capacity, 2)),
        cnt=np.zeros(NCOUNTERS, np.int64), rng=rng,
        near=np.zeros(capacity, np.int64), near_len=np.zeros(capacity),
        near_key=np.zeros(capacity), stack=np.zeros(capacity, np.int64))


def grown(tree: Tree, capacity: int) -> Tree:
    """A copy of ``tree`` with room for ``capacity`` nodes (the grid is kept)."""
    def pad(a, fill):
        out = np.full((capacity,) + a.shape[1:], fill, dtype=a.dtype)
        out[: a.shape[0]] = a
        return out

    return tree._replace(
        pose=pad(tree.pose, 0.0), trig=pad(tree.trig, 0.0), cost=pad(tree.cost, 0.0), parent=pad(tree.parent, -1),
        kinds=pad(tree.kinds, 0), lens=pad(tree.lens, 0.0), curv=pad(tree.curv, 0.0),
        first_child=pad(tree.first_child, -1), next_sibling=pad(tree.next_sibling, -1),
        cell_next=pad(tree.cell_next, -1), goal_nodes=pad(tree.goal_nodes, 0),
        improved=pad(tree.improved, 0.0),
        near=np.zeros(capacity, np.int64), near_len=np.zeros(capacity),
        near_key=np.zeros(capacity), stack=np.zeros(capacity, np.int64))


@njit(cache=True, inline="always")
def _cell(tree: Tree, x: float, y: float):
    g = tree.grid
    i = min(max(int((x - g[0]) / g[2]), 0), int(g[3]) - 1)
    j = min(max(int((y - g[1]) / g[2]), 0), int(g[4]) - 1)
    return i, j


@njit(cache=True)
def add_node(tree: Tree, P: np.ndarray, x, y, th, cost, parent, kinds, lens, curv) -> int:
    """Append a node (the caller has checked capacity); returns its index."""
    k = tree.cnt[N]
    tree.pose[k, 0] = x
    tree.pose[k, 1] = y
    tree.pose[k, 2] = th
    c, s = math.cos(th), math.sin(th)
    tree.trig[k, 0] = c
    tree.trig[k, 1] = s
    tree.trig[k, 2:6] = turning_centres(x, y, c, s, P[RHO])
    tree.cost[k] = cost
    tree.parent[k] = parent
    tree.kinds[k, :] = kinds
    tree.lens[k, :] = lens
    tree.curv[k, :, :] = curv
    tree.first_child[k] = -1
    if parent >= 0:
        tree.next_sibling[k] = tree.first_child[parent]
        tree.first_child[parent] = k
    i, j = _cell(tree, x, y)
    c = i * int(tree.grid[4]) + j
    tree.cell_next[k] = tree.cell_head[c]
    tree.cell_head[c] = k
    tree.cnt[N] = k + 1
    if in_goal(x, y, th, P[GX:GHEAD + 1]):
        tree.goal_nodes[tree.cnt[NGOAL]] = k
        tree.cnt[NGOAL] += 1
    return k


@njit(cache=True, inline="always")
def _sample(tree: Tree, w: World, P: np.ndarray):
    """Goal-biased uniform sample; inside the informed ellipse once a solution exists."""
    xmin, ymin, xmax, ymax = w.geo[0], w.geo[1], w.geo[2], w.geo[3]
    th = (uniform(tree.rng) * 2.0 - 1.0) * math.pi
    if uniform(tree.rng) < P[GOAL_BIAS]:
        return P[GX], P[GY], P[GTH]
    best = tree.cnt[BEST]
    if P[INFORMED] > 0.0 and best >= 0:
        # Any state on a cheaper path lies in the ellipse |x - s| + |x - g| <= c_best + tol.
        diam = tree.cost[best] + P[GPOS]
        fx, fy = P[GX] - P[SX], P[GY] - P[SY]
        cmin = math.hypot(fx, fy)
        a = 0.5 * diam
        b = 0.5 * math.sqrt(max(diam * diam - cmin * cmin, 0.0))
        if math.pi * a * b < (xmax - xmin) * (ymax - ymin):
            c, s = (fx / cmin, fy / cmin) if cmin > 0.0 else (1.0, 0.0)
            mx, my = 0.5 * (P[SX] + P[GX]), 0.5 * (P[SY] + P[GY])
            for _ in range(100):
                rad = math.sqrt(uniform(tree.rng))
                phi = 2.0 * math.pi * uniform(tree.rng)
                u, v = a * rad * math.cos(phi), b * rad * math.sin(phi)
                x, y = mx + c * u - s * v, my + s * u + c * v
                if xmin <= x <= xmax and ymin <= y <= ymax:
                    return x, y, _lane_heading(tree, w, x, y, th)
    x = xmin + (xmax - xmin) * uniform(tree.rng)
    y = ymin + (ymax - ymin) * uniform(tree.rng)
    return x, y, _lane_heading(tree, w, x, y, th)


@njit(cache=True, inline="always")
def _lane_heading(tree: Tree, w: World, x, y, th) -> float:
    """On a track, most samples head along the lane (± a Gaussian 0.25 rad): a car on a race
    track drives along it, and uniform headings in a narrow lane are almost all unreachable."""
    if w.lane.shape[0] == 0 or uniform(tree.rng) >= LANE_SHARE:
        return th
    i = min(max(int((x - w.sdf_geo[0]) / w.sdf_geo[2]), 0), w.lane.shape[0] - 1)
    j = min(max(int((y - w.sdf_geo[1]) / w.sdf_geo[2]), 0), w.lane.shape[1] - 1)
    lane = w.lane[i, j]
    if lane != lane:
        return th
    u1 = max(uniform(tree.rng), 1e-300)
    gauss = math.sqrt(-2.0 * math.log(u1)) * math.cos(2.0 * math.pi * uniform(tree.rng))
    return wrap_angle(lane + LANE_SIGMA * gauss)


@njit(cache=True, inline="always")
def _node(tree: Tree, j):
    """Node j as a steering `state` (its cos, sin and turning circles are kept in tree.trig)."""
    p, f = tree.pose, tree.trig
    return p[j, 0], p[j, 1], p[j, 2], f[j, 0], f[j, 1], f[j, 2], f[j, 3], f[j, 4], f[j, 5]


@njit(cache=True, inline="always")
def _heap_push(keys, vals, size, key, val) -> int:
    i = size
    keys[i] = key
    vals[i] = val
    while i > 0:
        up = (i - 1) >> 1
        if keys[up] <= keys[i]:
            break
        keys[up], keys[i] = keys[i], keys[up]
        vals[up], vals[i] = vals[i], vals[up]
        i = up
    return size + 1


@njit(cache=True, inline="always")
def _heap_pop(keys, vals, size) -> int:
    """Remove the smallest entry (the caller has read keys[0], vals[0]); returns the new size."""
    size -= 1
    keys[0] = keys[size]
    vals[0] = vals[size]
    i = 0
    while True:
        c = 2 * i + 1
        if c >= size:
            break
        if c + 1 < size and keys[c + 1] < keys[c]:
            c += 1
        if keys[i] <= keys[c]:
            break
        keys[c], keys[i] = keys[i], keys[c]
        vals[c], vals[i] = vals[i], vals[c]
        i = c
    return size


@njit(cache=True, inline="always")
def turning(P: np.ndarray):
    """The car's turning constants as the steering functions read them (`cc_constants`)."""
    return cc_constants(P[RHO], P[SIGMA])


@njit(cache=True, inline="always")
def _se2(a, b, rho) -> float:
    """√(Δx² + Δy² + (ρ·Δθ)²): the cheap metric of many car planners."""
    dth = rho * wrap_angle(b[2] - a[2])
    return math.sqrt((b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2 + dth * dth)


@njit(cache=True, inline="always")
def _metric_bound(metric, code, a, b, g) -> float:
    """A lower bound of the nearest-neighbour metric (the chord, for se2)."""
    if metric == SE2_METRIC:
        return math.hypot(b[0] - a[0], b[1] - a[1])
    return steer_bound(code, a, b, g)


@njit(cache=True, inline="always")
def _metric_tight_bound(metric, code, a, b, g) -> float:
    if metric == SE2_METRIC:
        return 0.0
    return steer_tight_bound(code, a, b, g)


@njit(cache=True, inline="always")
def _metric(metric, code, a, b, g, bound) -> float:
    if metric == SE2_METRIC:
        return _se2(a, b, g[0])
    return steer_length(code, a, b, g, bound)


@njit(cache=True)
def nearest(tree: Tree, P: np.ndarray, g, qx, qy, qth):
    """(node, distance) of the tree node nearest to the query pose by the metric: the
    shortest car path (steering length) or se2; ``g``: the car's turning constants
    (`turning`, computed once per `iterate`).

    Best first: grid rings are opened outward and their nodes filed by a lower bound of their
    path length into buckets half a cell wide; exact lengths are computed bucket by bucket,
    lowest first, for buckets that no unopened ring can undercut (a node in ring k is at
    least (k − 1) cells away), so the first ones are usually near-optimal and the search
    stops when neither a bucket nor the next ring can beat the best length found. Filing
    costs a store where a heap cost a sift. A node taken from its bucket first gets the
    tighter `steer_tight_bound` and is filed again (key −1 − bound) if that moves it up: poses
    facing back at the tree pass the turning circles' bound by the hundred on a small track.
    """
    code, metric = int(P[STEERING]), int(P[METRIC])
    to = state(qx, qy, qth, math.cos(qth), math.sin(qth), g[0])
    nx, ny, cell = int(tree.grid[3]), int(tree.grid[4]), tree.grid[2]
    ci, cj = _cell(tree, qx, qy)
    cells = np.empty(8 * (max(nx, ny) + 1), np.int64)
    width = 0.5 * cell
    head = np.full(NEAREST_BUCKETS, -1, np.int64)
    link, key = tree.stack, tree.near_key  # per node; scratch until choose-parent
    cur, top = 0, -1  # the lowest bucket that may be non-empty, the highest filed into
    best, besti = math.inf, -1
    k = 0
    last_ring = max(nx, ny)
    while True:
        ring_bound = max(0.0, (k - 1) * cell) if k <= last_ring else math.inf
        while cur <= top and head[cur] < 0:
            cur += 1
        if cur <= top and cur * width <= ring_bound and cur * width < best:
            node = head[cur]
            head[cur] = link[node]
            lb = key[node]
            if lb >= 0.0:  # filed by its cheap bound: refine it first
                if lb >= best:
                    continue
                lb = max(lb, _metric_tight_bound(metric, code, _node(tree, node), to, g))
                b = min(int(lb / width), NEAREST_BUCKETS - 1)
                if lb < best and b > cur:  # no longer among the lowest: file it again
                    key[node] = -1.0 - lb
                    link[node] = head[b]
                    head[b] = node
                    top = max(top, b)
                    continue
            else:
                lb = -1.0 - lb  # refined before
            if lb < best:
                d = _metric(metric, code, _node(tree, node), to, g, best)
                if d < best:
                    best, besti = d, node
        elif ring_bound >= best:
            break  # every remaining candidate, filed or not, is at least this far
        else:
            for q in range(_ring_cells(tree, ci, cj, k, cells)):
                node = tree.cell_head[cells[q]]
                while node >= 0:
                    lb = _metric_bound(metric, code, _node(tree, node), to, g)
                    if lb < best:
                        b = min(int(lb / width), NEAREST_BUCKETS - 1)
                        key[node] = lb
                        link[node] = head[b]
                        head[b] = node
                        cur, top = min(cur, b), max(top, b)
                    node = tree.cell_next[node]
            k += 1
    return besti, best


@njit(cache=True, inline="always")
def _ring_cells(tree: Tree, ci, cj, k, out) -> int:
    """Write the grid cells at Chebyshev distance k from (ci, cj) into ``out``; their count."""
    nx, ny = int(tree.grid[3]), int(tree.grid[4])
    n = 0
    for i in range(ci - k, ci + k + 1):
        if i < 0 or i >= nx:
            continue
        step = 2 * k if 0 < k and i != ci - k and i != ci + k else 1
        j = cj - k
        while j <= cj + k:
            if 0 <= j < ny:
                out[n] = i * ny + j
                n += 1
            j += step
    return n


@njit(cache=True)
def _collect_ring(tree: Tree, x, y, ci, cj, k, m, cells) -> int:
    """Append the nodes of grid ring k around cell (ci, cj) to tree.near; returns the count."""
    for q in range(_ring_cells(tree, ci, cj, k, cells)):
        node = tree.cell_head[cells[q]]
        while node >= 0:
            tree.near[m] = node
            tree.near_len[m] = math.hypot(tree.pose[node, 0] - x, tree.pose[node, 1] - y)
            m += 1
            node = tree.cell_next[node]
    return m


@njit(cache=True)
def _select_smallest(tree: Tree, m: int, k: int) -> None:
    """Move the k smallest of near_len[:m] (with their nodes) to the front, in order."""
    for a in range(k):
        low = a
        for b in range(a + 1, m):
            if tree.near_len[b] < tree.near_len[low]:
                low = b
        tree.near_len[a], tree.near_len[low] = tree.near_len[low], tree.near_len[a]
        tree.near[a], tree.near[low] = tree.near[low], tree.near[a]


@njit(cache=True)
def _near(tree: Tree, x, y, radius, k_nearest) -> int:
    """Fill tree.near / near_len with the near candidates of (x, y), with Euclidean distances.

    Radius form: every node within ``radius``. Car path lengths are never shorter than the
    Euclidean distance, so this ball holds every node within steering length ``radius`` in
    either direction; exact lengths come later, and only for candidates whose bound can still
    pay off. k form (``k_nearest`` > 0): the k Euclidean-nearest nodes.
    """
    nx, ny, cell = int(tree.grid[3]), int(tree.grid[4]), tree.grid[2]
    ci, cj = _cell(tree, x, y)
    m = 0
    if k_nearest > 0:
        cells = np.empty(8 * (max(nx, ny) + 1), np.int64)
        for k in range(max(nx, ny) + 1):
            if m >= k_nearest:
                _select_smallest(tree, m, k_nearest)
                if (k - 1) * cell > tree.near_len[k_nearest - 1]:
                    break
            m = _collect_ring(tree, x, y, ci, cj, k, m, cells)
        if m > k_nearest:
            _select_smallest(tree, m, k_nearest)
            m = k_nearest
        return m
    kr = int(math.ceil(radius / cell))
    x0, y0, r2 = tree.grid[0], tree.grid[1], radius * radius
    for i in range(max(ci - kr, 0), min(ci + kr, nx - 1) + 1):
        gx = max(x0 + i * cell - x, 0.0, x - x0 - (i + 1) * cell)  # to the cell's column
        for j in range(max(cj - kr, 0), min(cj + kr, ny - 1) + 1):
            gy = max(y0 + j * cell - y, 0.0, y - y0 - (j + 1) * cell)
            if gx * gx + gy * gy > r2:
                continue  # the whole cell lies outside the ball
            node = tree.cell_head[i * ny + j]
            while node >= 0:
                dx, dy = tree.pose[node, 0] - x, tree.pose[node, 1] - y
                d2 = dx * dx + dy * dy
                if d2 <= r2:
                    tree.near[m] = node
                    tree.near_len[m] = math.sqrt(d2)
                    m += 1
                node = tree.cell_next[node]
    return m


@njit(cache=True)
def _unlink_child(tree: Tree, parent: int, child: int) -> None:
    prev = -1
    c = tree.first_child[parent]
    while c >= 0 and c != child:
        prev = c
        c = tree.next_sibling[c]
    if prev < 0:
        tree.first_child[parent] = tree.next_sibling[child]
    else:
        tree.next_sibling[prev] = tree.next_sibling[child]


@njit(cache=True)
def _collect_subtree(tree: Tree, root: int) -> int:
    """Write ``root`` and all its descendants into tree.stack (breadth first); their count."""
    tree.stack[0] = root
    n = 1
    i = 0
    while i < n:
        c = tree.first_child[tree.stack[i]]
        while c >= 0:
            tree.stack[n] = c
            n += 1
            c = tree.next_sibling[c]
        i += 1
    return n


@njit(cache=True)
def _subtree_free_at(tree: Tree, w: World, P: np.ndarray, n: int, delta: float,
                     counter) -> bool:
    """Are the edges into the collected subtree's nodes (all but its root, tree.stack[0]) free
    when every arrival time moves earlier by delta / v?"""
    for k in range(1, n):
        node = tree.stack[k]
        par = tree.parent[node]
        t0 = (tree.cost[par] - delta) / P[SPEED]
        tree.cnt[CHECKS] += 1
        if not motion_free(w, tree.pose[par, 0], tree.pose[par, 1], tree.pose[par, 2], t0,
                           tree.kinds[node], tree.lens[node], tree.curv[node], P[SPEED],
                           counter):
            return False
    return True


@njit(cache=True)
def chain(parent: np.ndarray, node: int) -> np.ndarray:
    """The nodes of the tree path from the root to ``node``, root first (none for -1): the one
    walk up the parents, for the kernel, the planner's results and a snapshot alike."""
    n = 0
    k = node
    while k >= 0:
        n += 1
        k = parent[k]
    out = np.empty(n, np.int64)
    k = node
    for i in range(n - 1, -1, -1):
        out[i] = k
        k = parent[k]
    return out


@njit(cache=True)
def polish(tree: Tree, w: World, P: np.ndarray, ev, cap: int) -> None:
    """The polish `iterate` stopped for (POLISH_DUE), within what is left of polishing's share
    of the run's clearance evaluations and within ``cap`` of them (what a time budget has left
    room for); the next one is due at twice the iterations."""
    kinds, lens, curv = path_buffers(tree.lens.shape[1])
    counter = np.zeros(1, np.int64)
    tree.cnt[POLISH_AT] = 2 * tree.cnt[ITER]
    if _polish_best(tree, w, P, kinds, lens, curv, counter, ev,
                    min(_polish_allowance(tree), cap)):
        _update_best(tree)
    tree.cnt[POLISHED] = int(tree.cost[tree.cnt[BEST]] * 1e6)
    tree.cnt[POLISHED_AT] = tree.cnt[ITER]
    tree.cnt[EVALS] += counter[0]
    tree.cnt[POLISH_EVALS] += counter[0]
    if ev.rows.shape[0] > 0 and ev.cnt[0] > 0:  # the iteration it followed ends at its cost
        ev.rows[ev.cnt[0] - 1, EV_BEST] = tree.cost[tree.cnt[BEST]]


@njit(cache=True, inline="always")
def _polish_allowance(tree: Tree) -> int:
    """The clearance evaluations a polish may spend now and keep within POLISH_SHARE (and
    POLISH_FREE)."""
    search = tree.cnt[EVALS] - tree.cnt[POLISH_EVALS]
    return (int(POLISH_SHARE / (1.0 - POLISH_SHARE) * search) + POLISH_FREE
            - tree.cnt[POLISH_EVALS])


@njit(cache=True)
def _polish_best(tree: Tree, w: World, P: np.ndarray, kinds, lens, curv, counter, ev,
                 limit: int) -> bool:
    """Polish the best path (`planner._polish`, at most ``limit`` clearance evaluations) and,
    if that shortens it, add the polished poses to the tree as a chain from the root: the tree
    stays exact and RRT* goes on from it. Returns whether it added them."""
    nodes = chain(tree.parent, tree.cnt[BEST])
    n = nodes.shape[0]
    # Each pass at most doubles the edges: the chain must fit whatever polishing makes of it.
    if n < 2 or tree.cnt[N] + (n - 1) * 2 ** PASSES > tree.pose.shape[0]:
        return False
    poses = tree.pose[nodes]
    root = nodes[0]
    code = int(P[STEERING])
    goal = np.array([P[GX], P[GY], P[GTH], P[GPOS], P[GHEAD]])
    g = turning(P)
    poses, length = polish_path(w, code, g, P[SPEED], poses, goal, (kinds, lens, curv),
                                counter, tree.cnt[ITER] >= BLOCKS_FROM, limit)
    if length >= tree.cost[tree.cnt[BEST]] - 1e-9:
        return False
    parent = root
    for i in range(1, poses.shape[0]):
        a, b = poses[i - 1], poses[i]
        edge = steer_path(code, a[0], a[1], a[2], b[0], b[1], b[2], g, kinds, lens, curv)
        parent = add_node(tree, P, b[0], b[1], b[2], tree.cost[parent] + edge, parent, kinds,
                          lens, curv)
        if ev.rows.shape[0] > 0 and ev.cnt[3] < ev.polished.shape[0]:
            ev.polished[ev.cnt[3]] = parent
            ev.cnt[3] += 1
    return True


@njit(cache=True, inline="always")
def _polish_due(tree: Tree) -> bool:
    """At the first solution, then at twice as many iterations each time; and sooner (after a
    quarter more iterations) when the tree's best path is 0.1 % shorter than the polished one:
    a tree path beating a polished one is most often another route, which polishing shortens
    most. Never while polishing has spent its share of the run's clearance evaluations."""
    if tree.cnt[BEST] < 0 or _polish_allowance(tree) <= 0:
        return False
    if tree.cnt[ITER] >= tree.cnt[POLISH_AT]:
        return True
    return (tree.cost[tree.cnt[BEST]] * 1e6 < 0.999 * tree.cnt[POLISHED]
            and 4 * tree.cnt[ITER] >= 5 * tree.cnt[POLISHED_AT])


@njit(cache=True)
def _update_best(tree: Tree) -> None:
    best = tree.cnt[BEST]
    for g in range(tree.cnt[NGOAL]):
        node = tree.goal_nodes[g]
        if best < 0 or tree.cost[node] < tree.cost[best]:
            best = node
    tree.cnt[BEST] = best
    k = tree.cnt[IMPROVED]
    # An improvement follows an added node, so there are never more than nodes (capacity).
    if best >= 0 and (k == 0 or tree.cost[best] < tree.improved[k - 1, 1]) and k < len(
            tree.improved):
        tree.improved[k, 0] = tree.cnt[ITER]
        tree.improved[k, 1] = tree.cost[best]
        tree.cnt[IMPROVED] = k + 1


@njit(cache=True)
def _choose_parent(tree: Tree, w: World, P, g, m, x, y, th, radius, c_new, parent, kinds,
                   lens, curv, pk, pl, pc, counter):
    """Cheapest collision-free parent among the near candidates, best first.

    Candidates enter a min-heap keyed by cost(j) + a lower bound of their path to x_new; a
    popped bound is replaced by the exact length (re-queued as ``-1 - j``), a popped exact key
    is the cheapest remaining candidate and gets its motion check. So exact lengths are
    computed only for candidates whose bound beats the answer. Returns (cost, parent) and
    leaves the winning edge in kinds/lens/curv (pk/pl/pc: scratch).
    """
    keys, vals = tree.near_key, tree.stack
    code = int(P[STEERING])
    to = state(x, y, th, math.cos(th), math.sin(th), g[0])
    size = 0
    for q in range(m):
        j = tree.near[q]
        if j == parent:
            continue
        if tree.near_len[q] >= radius or tree.cost[j] + tree.near_len[q] >= c_new - 1e-12:
            continue
        lb = steer_bound(code, _node(tree, j), to, g)
        if lb < radius and tree.cost[j] + lb < c_new - 1e-12:
            size = _heap_push(keys, vals, size, tree.cost[j] + lb, j)
    while size > 0 and keys[0] < c_new - 1e-12:
        key, v = keys[0], vals[0]
        size = _heap_pop(keys, vals, size)
        j = v if v >= 0 else -1 - v
        px, py, pth = tree.pose[j, 0], tree.pose[j, 1], tree.pose[j, 2]
        if v >= 0:
            bound = min(radius, c_new - tree.cost[j])
            d = steer_length(code, _node(tree, j), to, g, bound)
            if d < bound:
                size = _heap_push(keys, vals, size, tree.cost[j] + d, -1 - j)
            continue
        steer_path(code, px, py, pth, x, y, th, g, pk, pl, pc)
        tree.cnt[CHECKS] += 1
        if motion_free(w, px, py, pth, tree.cost[j] / P[SPEED], pk, pl, pc, P[SPEED], counter):
            kinds[:] = pk
            lens[:] = pl
            curv[:, :] = pc
            return key, j
    return c_new, parent


@njit(cache=True)
def iterate(tree: Tree, w: World, P: np.ndarray, n_iter: int, ev: Events) -> int:
    """Run up to ``n_iter`` iterations; returns RAN, FULL (grow the tree and call again),
    POLISH_DUE (call `polish`: apart, so that its time can be measured) or EVENTS_FULL (grow
    the event buffers and call again: a batch's events are always complete).

    Every iteration draws one sample, whether or not it adds a node (as OMPL counts them).
    """
    record = ev.rows.shape[0] > 0
    kinds, lens, curv = path_buffers(tree.lens.shape[1])
    scratch_k, scratch_l, scratch_c = path_buffers(tree.lens.shape[1])
    cut = np.zeros(tree.lens.shape[1])
    counter = np.zeros(1, np.int64)
    timed = w.m_kind.shape[0] > 0
    code, g = int(P[STEERING]), turning(P)
    status = RAN
    for _ in range(n_iter):
        if tree.cnt[N] >= tree.pose.shape[0]:
            status = FULL
            break
        # An iteration's near set, and so its rewires, name at most every node.
        if record and min(ev.near.shape[0] - ev.cnt[1],
                          ev.rewires.shape[0] - ev.cnt[2]) < tree.cnt[N]:
            status = EVENTS_FULL
            break
        if P[STAR] == 0.0 and tree.cnt[BEST] >= 0:
            break  # RRT ends at its first solution, whatever the batch size
        tree.cnt[ITER] += 1
        xr, yr, thr = _sample(tree, w, P)
        row = -1
        if record:
            row = ev.cnt[0]
            ev.cnt[0] += 1
            ev.rows[row, :] = -1.0
            ev.rows[row, EV_ITER] = tree.cnt[ITER]
            ev.rows[row, EV_XR] = xr
            ev.rows[row, EV_YR] = yr
            ev.rows[row, EV_THR] = thr
        if static_clearance_estimate(w, xr, yr) <= 0.0:
            # SampleFree: a sample inside a static obstacle is rejected at once (it still
            # counts as an iteration: OMPL's RRT* spends a nearest search and a failed
            # motion check on it).
            continue
        near_i, dist = nearest(tree, P, g, xr, yr, thr)
        nx0, ny0, nth0 = tree.pose[near_i, 0], tree.pose[near_i, 1], tree.pose[near_i, 2]
        thr = arrival_heading(code, nx0, ny0, nth0, xr, yr, thr)
        length = steer_path(code, nx0, ny0, nth0, xr, yr, thr, g, kinds, lens, curv)
        if P[METRIC] == SE2_METRIC:
            dist = length  # the metric chose the node; the edge is driven by the steering
        if dist > P[EPS]:
            dist = min(steer_cut(code, kinds, lens, curv, P[EPS], True), length)
            truncate(kinds, lens, dist, cut)
            lens[:] = cut
        x, y, th = path_end(nx0, ny0, nth0, kinds, lens, curv)
        th = wrap_angle(th)
        if record:
            ev.rows[row, EV_NEAREST] = near_i
            ev.rows[row, EV_XN] = x
            ev.rows[row, EV_YN] = y
            ev.rows[row, EV_THN] = th
        if dist <= 0.0:
            continue
        tree.cnt[CHECKS] += 1
        parent = near_i
        c_new = tree.cost[near_i] + dist
        free = free_length(w, nx0, ny0, nth0, tree.cost[near_i] / P[SPEED], kinds, lens,
                           curv, P[SPEED], counter)
        if free != math.inf and not timed:
            if record:
                ev.rows[row, EV_FREE] = free
            dist = steer_cut(code, kinds, lens, curv, free * KEEP_SHARE, False)
            if P[METRIC] == SE2_METRIC or dist < KEEP_MIN * P[RHO]:
                continue  # the SE(2) nearest's path may loop: its first half is no advance
            truncate(kinds, lens, dist, cut)
            lens[:] = cut
            c_new = tree.cost[near_i] + dist
            x, y, th = path_end(nx0, ny0, nth0, kinds, lens, curv)
            th = wrap_angle(th)
        elif free != math.inf:
            if P[STAR] == 0.0:
                continue  # as in Karaman & Frazzoli's EXTEND and OMPL: x_new is dropped
            # With moving obstacles another near node may still reach x_new: one that arrives
            # later, when the way is clear.
            parent = -1
            c_new = math.inf
        m = 0
        radius = 0.0
        if P[STAR] > 0.0:
            n = tree.cnt[N] + 1.0
            if P[K_RRT] > 0.0:
                radius = math.inf
                m = _near(tree, x, y, radius, int(math.ceil(P[K_RRT] * math.log(n))))
            else:
                radius = min(P[GAMMA] * (math.log(n) / n) ** (1.0 / P[DIMS]), P[EPS])
                m = _near(tree, x, y, radius, 0)
            c_new, parent = _choose_parent(tree, w, P, g, m, x, y, th, radius, c_new, parent,
                                           kinds, lens, curv, scratch_k, scratch_l, scratch_c,
                                           counter)
            if parent < 0:
                continue
        new = add_node(tree, P, x, y, th, c_new, parent, kinds, lens, curv)
        changed = tree.cnt[NGOAL] > 0 and tree.goal_nodes[tree.cnt[NGOAL] - 1] == new
        if record:
            ev.rows[row, EV_NEW] = new
            ev.rows[row, EV_PARENT] = parent
            ev.rows[row, EV_RADIUS] = radius
            ev.rows[row, EV_NEAR_START] = ev.cnt[1]
            for q in range(m):
                if ev.cnt[1] < ev.near.shape[0]:
                    ev.near[ev.cnt[1]] = tree.near[q]
                    ev.cnt[1] += 1
            ev.rows[row, EV_NEAR_END] = ev.cnt[1]
        # Rewire: near nodes that are cheaper to reach through the new node.
        frm = _node(tree, new)
        for q in range(m):
            j = tree.near[q]
            if j == parent:
                continue
            budget = min(tree.cost[j] - c_new, radius)
            if tree.near_len[q] >= budget - 1e-9 or steer_bound(
                    code, frm, _node(tree, j), g) >= budget - 1e-9:
                continue  # not even the lower bound could make j cheaper
            l = steer_length(code, frm, _node(tree, j), g, budget)
            if l >= budget - 1e-9:
                continue
            steer_path(code, x, y, th, tree.pose[j, 0], tree.pose[j, 1],
                       tree.pose[j, 2], g, kinds, lens, curv)
            tree.cnt[CHECKS] += 1
            if not motion_free(w, x, y, th, c_new / P[SPEED], kinds, lens, curv, P[SPEED],
                               counter):
                continue
            delta = tree.cost[j] - (c_new + l)
            n_sub = _collect_subtree(tree, j)
            if timed and not _subtree_free_at(tree, w, P, n_sub, delta, counter):
                tree.cnt[REFUSED] += 1
                continue
            old = tree.parent[j]
            _unlink_child(tree, old, j)
            tree.parent[j] = new
            tree.next_sibling[j] = tree.first_child[new]
            tree.first_child[new] = j
            tree.kinds[j, :] = kinds
            tree.lens[j, :] = lens
            tree.curv[j, :, :] = curv
            for k in range(n_sub):  # the whole subtree arrives earlier by the same Δ
                tree.cost[tree.stack[k]] -= delta
            tree.cnt[REWIRES] += 1
            changed = True
            if record and ev.cnt[2] < ev.rewires.shape[0]:
                r = ev.cnt[2]
                ev.rewires[r, 0] = tree.cnt[ITER]
                ev.rewires[r, 1] = j
                ev.rewires[r, 2] = old
                ev.rewires[r, 3] = new
                ev.cnt[2] += 1
        if changed:
            _update_best(tree)
        if record:
            ev.rows[row, EV_BEST] = tree.cost[tree.cnt[BEST]] if tree.cnt[BEST] >= 0 else math.inf
        if P[POLISH] > 0.0 and P[STAR] > 0.0 and not timed:
            tree.cnt[EVALS] += counter[0]  # the allowance reads them
            counter[0] = 0
            if _polish_due(tree):
                status = POLISH_DUE
                break
    tree.cnt[EVALS] += counter[0]
    return status
