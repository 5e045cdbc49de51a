"""The world as flat arrays for compiled kernels: bounds, obstacles, motions, drivable region.

Collision semantics are the scenario format's (docs/scenario-format.md): a pose at time t is valid
iff the car's footprint discs (one disc of radius r, or the discs covering a rectangle) are inside
the bounds, strictly clear of every obstacle where that obstacle is at time t, and (for a track)
inside the drivable region. `clearance` returns the signed distance from the discs to the nearest
forbidden point, so "valid" is ``clearance > 0``.

Motion checks are exact, not sampled ("sphere tracing"): at a pose with clearance d nothing can
be hit before the car has driven d / (1 + v_obs/v) further, since the car's position moves at
most as far as it drives and an obstacle at most v_obs per second. A motion is declared in
collision once the clearance drops below ``CONTACT`` (0.1 mm) — conservative, never letting a
collision through between samples, unlike a fixed 0.02 m sampling that can clip a corner.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from planner._jit import njit
from planner._paths import TURN, advance, peak_curvature

CONTACT = 1e-4
# Distance evaluations that filling the clearance grid may take (~1 s): a crowded scene gets
# coarser cells instead of a compile without end (10 000 circles took 46 s at full size).
GRID_WORK = 1e8
FAR_CELLS = 6  # cells farther out in the open hold a lower bound of their clearance
# Indices into World.geo.
XMIN, YMIN, XMAX, YMAX, RADIUS, VMAX_OBS, HAS_REGION, REACH = range(8)
STATIC, VELOCITY, WAYPOINTS = 0, 1, 2


class World(NamedTuple):
    """Everything a validity check reads, as arrays (a numba-friendly record)."""

    geo: np.ndarray  # float64[8], see the index constants (RADIUS: the smallest disc's)
    discs: np.ndarray  # (k, 2) the car's footprint as discs: offset along the heading, radius
    circ: np.ndarray  # (nc, 3) cx, cy, radius
    circ_motion: np.ndarray  # (nc,) index into the motion table, -1 when static
    poly_edges: np.ndarray  # (ne, 4) x1, y1, x2, y2 of all polygon edges
    poly_start: np.ndarray  # (np + 1,) polygon p owns edges poly_start[p]:poly_start[p + 1]
    poly_bbox: np.ndarray  # (np, 4) xmin, ymin, xmax, ymax
    poly_motion: np.ndarray  # (np,)
    ring_edges: np.ndarray  # (nr, 4) edges of the drivable region (even-odd), empty without one
    m_kind: np.ndarray  # (nm,) VELOCITY or WAYPOINTS
    m_vel: np.ndarray  # (nm, 2)
    m_wp_start: np.ndarray  # (nm + 1,)
    m_wp: np.ndarray  # (nw, 3) t, dx, dy
    m_grow: np.ndarray  # (nm, 5) a prediction's uncertainty: see `growth`; zeros for true motions
    sdf: np.ndarray  # (nx, ny) static clearance at cell centres (a lower-bound lookup table)
    sdf_geo: np.ndarray  # float64[3]: x0, y0, cell size
    lane: np.ndarray  # (nx, ny) driving direction of the nearest centreline point, NaN
    #                   where unknown; (0, 0) without a track. A sampling hint, not a rule.


def _edges(points: np.ndarray) -> np.ndarray:
    return np.hstack([points, np.roll(points, -1, axis=0)])


def build_world(bounds, radius, circles, polygons, motions, rings=(), centreline=None,
                discs=None) -> World:
    """Pack plain geometry into a `World`.

    ``circles``: list of (cx, cy, r, motion_index); ``polygons``: list of ((n, 2) points,
    motion_index); ``motions``: list of ("velocity", (vx, vy)) or ("waypoints", (m, 3) array);
    ``rings``: polygon rings of the drivable region (empty: the bounds alone);
    ``centreline``: (n, 3) x, y, heading of a track, for the lane-direction sampling hint;
    ``discs``: the footprint as (offset along the heading, radius) rows; default one disc of
    ``radius`` at the reference point.
    """
    discs = np.array([[0.0, radius]] if discs is None else discs, dtype=float).reshape(-1, 2)
    circ = np.array([c[:3] for c in circles], dtype=float).reshape(-1, 3)
    circ_motion = np.array([c[3] for c in circles], dtype=np.int64)
    pts = [np.asarray(p, dtype=float) for p, _ in polygons]
    poly_edges = np.vstack([_edges(p) for p in pts]) if pts else np.zeros((0, 4))
    poly_start = np.concatenate([[0], np.cumsum([len(p) for p in pts])]).astype(np.int64)
    poly_bbox = np.array([[*p.min(axis=0), *p.max(axis=0)] for p in pts]).reshape(-1, 4)
    poly_motion = np.array([m for _, m in polygons], dtype=np.int64)
    ring_edges = (np.vstack([_edges(np.asarray(r, dtype=float)) for r in rings])
                  if len(rings) else np.zeros((0, 4)))
    m_kind = np.zeros(len(motions), dtype=np.int64)
    m_vel = np.zeros((len(motions), 2))
    wps = []
    vmax = 0.0
    for i, (kind, data) in enumerate(motions):
        if kind == "velocity":
            m_kind[i] = VELOCITY
            m_vel[i] = data
            vmax = max(vmax, math.hypot(*data))
            wps.append(np.zeros((0, 3)))
        else:
            wp = np.asarray(data, dtype=float).reshape(-1, 3)
            m_kind[i] = WAYPOINTS
            wps.append(wp)
            if len(wp) > 1:
                step = np.hypot(*np.diff(wp[:, 1:], axis=0).T) / np.diff(wp[:, 0])
                vmax = max(vmax, float(step.max()))
    m_wp_start = np.concatenate([[0], np.cumsum([len(w) for w in wps])]).astype(np.int64)
    m_wp = np.vstack(wps) if wps else np.zeros((0, 3))
    geo = np.array([*bounds, discs[:, 1].min(), vmax, 1.0 if len(ring_edges) else 0.0,
                    np.abs(discs[:, 0]).max()], dtype=float)
    xmin, ymin, xmax, ymax = bounds
    per_cell = (1 + (circ_motion < 0).sum() + ring_edges.shape[0]
                + sum(len(p) for p, (_, m) in zip(pts, polygons) if m < 0))
    h = max(math.hypot(xmax - xmin, ymax - ymin) / 500.0, 0.01,
            math.sqrt((xmax - xmin) * (ymax - ymin) * per_cell / GRID_WORK))
    nx, ny = math.ceil((xmax - xmin) / h), math.ceil((ymax - ymin) / h)
    world = World(geo, discs, circ, circ_motion, poly_edges, poly_start, poly_bbox, poly_motion,
                  ring_edges, m_kind, m_vel, m_wp_start, m_wp, np.zeros((len(motions), 5)),
                  np.zeros((nx, ny)),
                  np.array([xmin, ymin, h]),
                  np.full((nx, ny) if centreline is not None else (0, 0), np.nan))
    _fill_sdf(world)
    if centreline is not None:
        _fill_lane(world, np.asarray(centreline, dtype=float))
    return world


def inflated(world: World, margin: float) -> World:
    """The same world for a footprint ``margin`` larger: every clearance drops by exactly
    ``margin``.

    Every check measures point clearances (the distance grid ``sdf`` holds them too) from each
    footprint disc's centre and subtracts that disc's radius, so growing every disc's radius —
    the one disc of a disc car, each covering disc of a rectangle — is the whole change;
    ``geo[RADIUS]``, the smallest disc's radius that sampling reads, grows with them.
    """
    if margin == 0.0:
        return world
    geo = world.geo.copy()
    geo[RADIUS] += margin
    discs = world.discs.copy()
    discs[:, 1] += margin
    return world._replace(geo=geo, discs=discs)


def without_movers(world: World) -> World:
    """The same world with its moving obstacles left out: where a path may go at all, for a
    planner that then chooses when to drive it (`planner.timing`)."""
    geo = world.geo.copy()
    geo[VMAX_OBS] = 0.0
    return _keep_shapes(world, world.circ_motion < 0, world.poly_motion < 0)._replace(
        geo=geo, m_kind=np.zeros(0, np.int64), m_vel=np.zeros((0, 2)),
        m_wp_start=np.zeros(1, np.int64), m_wp=np.zeros((0, 3)), m_grow=np.zeros((0, 5)))


def only_movers(world: World, which: np.ndarray) -> World:
    """The same world with only the shapes of the movers where the boolean ``which`` (per
    motion) is true: a check against some of them alone (the motion table is kept as it is)."""
    which = np.asarray(which, bool)

    def moved_by(motion: np.ndarray) -> np.ndarray:
        return (motion >= 0) & which[np.maximum(motion, 0)] if len(which) else motion < -1

    return _keep_shapes(world, moved_by(world.circ_motion), moved_by(world.poly_motion))


def _keep_shapes(world: World, keep_c: np.ndarray, keep_p: np.ndarray) -> World:
    """``world`` with only the circles and polygons where ``keep_c`` / ``keep_p`` is true."""
    keep_p = np.flatnonzero(keep_p)
    counts = np.diff(world.poly_start)[keep_p]
    edges = [world.poly_edges[world.poly_start[p]:world.poly_start[p + 1]] for p in keep_p]
    return world._replace(
        circ=world.circ[keep_c], circ_motion=world.circ_motion[keep_c],
        poly_edges=np.vstack(edges) if edges else np.zeros((0, 4)),
        poly_start=np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
        poly_bbox=world.poly_bbox[keep_p], poly_motion=world.poly_motion[keep_p])


@njit(cache=True)
def offset(w: World, m: int, t: float):
    """Translation (dx, dy) of motion ``m`` at time t (docs/scenario-format.md v1.1 semantics)."""
    if w.m_kind[m] == VELOCITY:
        return w.m_vel[m, 0] * t, w.m_vel[m, 1] * t
    a = w.m_wp_start[m]
    b = w.m_wp_start[m + 1] - 1
    if t <= w.m_wp[a, 0]:
        return w.m_wp[a, 1], w.m_wp[a, 2]
    if t >= w.m_wp[b, 0]:
        return w.m_wp[b, 1], w.m_wp[b, 2]
    while b - a > 1:  # bisect for the waypoint interval holding t
        mid = (a + b) // 2
        if w.m_wp[mid, 0] <= t:
            a = mid
        else:
            b = mid
    f = (t - w.m_wp[a, 0]) / (w.m_wp[b, 0] - w.m_wp[a, 0])
    return (w.m_wp[a, 1] + f * (w.m_wp[b, 1] - w.m_wp[a, 1]),
            w.m_wp[a, 2] + f * (w.m_wp[b, 2] - w.m_wp[a, 2]))


@njit(cache=True, inline="always")
def growth(w: World, m: int, t: float) -> float:
    """How far motion ``m`` may be from where it is predicted at time t: a predicted mover is
    its shape grown by e + e_v·τ + ½·a·τ², τ its look-ahead time from the sensing (age + t)
    held at the horizon T (``m_grow[m]`` = e, e_v, a, age, T; all zero for a true motion).
    ``geo[VMAX_OBS]`` must include its fastest growth, e_v + a·T."""
    g = w.m_grow[m]
    tau = min(max(t + g[3], 0.0), g[4])
    return g[0] + tau * (g[1] + 0.5 * g[2] * tau)


@njit(cache=True, inline="always")
def _segment_distance2(px, py, x1, y1, x2, y2):
    """Squared distance from a point to a segment."""
    dx = x2 - x1
    dy = y2 - y1
    den = dx * dx + dy * dy
    u = 0.0 if den == 0.0 else ((px - x1) * dx + (py - y1) * dy) / den
    u = min(1.0, max(0.0, u))
    ex, ey = px - x1 - u * dx, py - y1 - u * dy
    return ex * ex + ey * ey


@njit(cache=True)
def _edges_distance(edges, a, b, px, py):
    """(distance to the nearest edge, point inside by the even-odd rule) over edges[a:b].

    An edge whose bounding box is no nearer than the best edge so far is only counted for
    the even-odd rule: on the many-sided rings of a track most edges end there."""
    best = math.inf  # squared
    inside = False
    for e in range(a, b):
        x1, y1, x2, y2 = edges[e, 0], edges[e, 1], edges[e, 2], edges[e, 3]
        if (y1 > py) != (y2 > py):
            if px < x1 + (py - y1) * (x2 - x1) / (y2 - y1):
                inside = not inside
        bx = max(min(x1, x2) - px, px - max(x1, x2), 0.0)
        by = max(min(y1, y2) - py, py - max(y1, y2), 0.0)
        if bx * bx + by * by < best:
            best = min(best, _segment_distance2(px, py, x1, y1, x2, y2))
    return math.sqrt(best), inside


@njit(cache=True, inline="always")
def _point_obstacles(w: World, x: float, y: float, t: float, moving: bool, c: float) -> float:
    """min(c, distance from the point (x, y) to the moving (or the static) obstacles at t),
    negative inside one."""
    for i in range(w.circ.shape[0]):
        m = w.circ_motion[i]
        if (m >= 0) != moving:
            continue
        cx, cy, r = w.circ[i, 0], w.circ[i, 1], w.circ[i, 2]
        if moving:
            ox, oy = offset(w, m, t)
            cx += ox
            cy += oy
            r += growth(w, m, t)
        if max(abs(x - cx), abs(y - cy)) - r >= c:
            continue  # this circle cannot be nearer than what we have
        d = math.hypot(x - cx, y - cy) - r
        if d < c:
            c = d
    for p in range(w.poly_bbox.shape[0]):
        m = w.poly_motion[p]
        if (m >= 0) != moving:
            continue
        px, py, grown = x, y, 0.0
        if moving:
            ox, oy = offset(w, m, t)
            px -= ox
            py -= oy
            grown = growth(w, m, t)
        bx = max(w.poly_bbox[p, 0] - px, 0.0, px - w.poly_bbox[p, 2])
        by = max(w.poly_bbox[p, 1] - py, 0.0, py - w.poly_bbox[p, 3])
        if math.hypot(bx, by) - grown >= c:
            continue  # this polygon cannot be nearer than what we have
        d, inside = _edges_distance(w.poly_edges, w.poly_start[p], w.poly_start[p + 1], px, py)
        d = (-d if inside else d) - grown
        if d < c:
            c = d
    return c


@njit(cache=True, inline="always")
def _point_static(w: World, x: float, y: float) -> float:
    """Signed distance from a point to the bounds, the drivable region's edge and the static
    obstacles (the car's size is subtracted per footprint disc by the callers)."""
    c = min(x - w.geo[XMIN], w.geo[XMAX] - x, y - w.geo[YMIN], w.geo[YMAX] - y)
    if w.geo[HAS_REGION] > 0.0:
        d, inside = _edges_distance(w.ring_edges, 0, w.ring_edges.shape[0], x, y)
        d = d if inside else -d
        if d < c:
            c = d
    return _point_obstacles(w, x, y, 0.0, False, c)


@njit(cache=True)
def _fill_sdf(w: World) -> None:
    """The clearance grid, exact where it decides anything, a lower bound elsewhere.

    Point clearance is 1-Lipschitz, so the clearance d at a block's centre bounds every cell
    of the block from below by d − (its distance from the centre). An 8 × 8 block wholly
    inside an obstacle gets only that (all a sample test or a motion check needs there is a
    negative value); so does a 2 × 2 block at least `FAR_CELLS` cells out in the open (within
    1.5 cells of the truth). Only cells near an edge are measured one by one: the stadium
    lap's grid took 39 ms exactly and takes a fraction now.
    """
    h = w.sdf_geo[2]
    nx, ny = w.sdf.shape
    for bi in range(0, nx, 8):
        for bj in range(0, ny, 8):
            ie, je = min(bi + 8, nx), min(bj + 8, ny)
            hi = _bound_block(w, bi, ie, bj, je)[1]
            if hi < -h:
                continue
            for i in range(bi, ie, 2):
                for j in range(bj, je, 2):
                    i1, j1 = min(i + 2, ie), min(j + 2, je)
                    if hi > FAR_CELLS * h:  # else every cell of the block is near an edge
                        low, high = _bound_block(w, i, i1, j, j1)
                        if high < -h or low > FAR_CELLS * h:
                            continue
                    for a in range(i, i1):
                        for b in range(j, j1):
                            x, y = _cell_centre(w, a, b)
                            w.sdf[a, b] = _point_static(w, x, y)


@njit(cache=True, inline="always")
def _cell_centre(w: World, i: float, j: float):
    """The centre of cell (i, j); between cells for fractional indices."""
    h = w.sdf_geo[2]
    return w.sdf_geo[0] + (i + 0.5) * h, w.sdf_geo[1] + (j + 0.5) * h


@njit(cache=True, inline="always")
def _bound_block(w: World, i0: int, i1: int, j0: int, j1: int):
    """Write into cells [i0, i1) × [j0, j1) the lower bound from the clearance at their
    centre; returns the least and the most clearance any of them can have."""
    h = w.sdf_geo[2]
    cx, cy = _cell_centre(w, 0.5 * (i0 + i1 - 1), 0.5 * (j0 + j1 - 1))
    d = _point_static(w, cx, cy)
    for i in range(i0, i1):
        for j in range(j0, j1):
            x, y = _cell_centre(w, i, j)
            w.sdf[i, j] = d - math.hypot(x - cx, y - cy)
    r = 0.5 * h * math.hypot(i1 - i0 - 1, j1 - j0 - 1)
    return d - r, d + r


@njit(cache=True)
def _fill_lane(w: World, centreline: np.ndarray) -> None:
    """Heading of the nearest centreline point, for every free cell (brute force, once)."""
    x0, y0, h = w.sdf_geo[0], w.sdf_geo[1], w.sdf_geo[2]
    for i in range(w.sdf.shape[0]):
        for j in range(w.sdf.shape[1]):
            if w.sdf[i, j] <= -h:
                continue
            x, y = x0 + (i + 0.5) * h, y0 + (j + 0.5) * h
            best = math.inf
            for k in range(centreline.shape[0]):
                d = (centreline[k, 0] - x) ** 2 + (centreline[k, 1] - y) ** 2
                if d < best:
                    best = d
                    w.lane[i, j] = centreline[k, 2]


@njit(cache=True)
def pose_clearance(w: World, x: float, y: float, th: float, t: float) -> float:
    """Signed clearance of the car's footprint at pose (x, y, th) at time t; > 0 means valid.

    ``t`` NaN means "static obstacles only" (docs/scenario-format.md: the goal has no time
    condition).
    """
    c = math.inf
    for k in range(w.discs.shape[0]):
        a, r = w.discs[k, 0], w.discs[k, 1]
        cx, cy = x + a * math.cos(th), y + a * math.sin(th)
        d = _point_static(w, cx, cy)
        if t == t:
            d = _point_obstacles(w, cx, cy, t, True, d)
        c = min(c, d - r)
    return c


@njit(cache=True)
def moving_clearance(w: World, x: float, y: float, th: float, t: float) -> float:
    """Clearance of the car's footprint at pose (x, y, th) from the moving obstacles alone,
    where they are at time t (+inf without any)."""
    c = math.inf
    for k in range(w.discs.shape[0]):
        a, r = w.discs[k, 0], w.discs[k, 1]
        d = _point_obstacles(w, x + a * math.cos(th), y + a * math.sin(th), t, True, math.inf)
        c = min(c, d - r)
    return c


@njit(cache=True)
def clearance(w: World, x: float, y: float, t: float) -> float:
    """Clearance of a car heading along +x at (x, y): exact for disc footprints
    (docs/scenario-format.md), where the heading does not matter."""
    return pose_clearance(w, x, y, 0.0, t)


@njit(cache=True, inline="always")
def static_clearance_estimate(w: World, x: float, y: float) -> float:
    """Static clearance of the smallest footprint disc centred at (x, y), from the nearest grid
    cell centre (within h/√2 of the truth): for sampling."""
    i = min(max(int((x - w.sdf_geo[0]) / w.sdf_geo[2]), 0), w.sdf.shape[0] - 1)
    j = min(max(int((y - w.sdf_geo[1]) / w.sdf_geo[2]), 0), w.sdf.shape[1] - 1)
    return w.sdf[i, j] - w.geo[RADIUS]


@njit(cache=True, inline="always")
def _disc_grid_bound(sdf, sdf_geo, cx, cy, r) -> float:
    """The grid's lower bound of the clearance of a footprint disc of radius r centred at
    (cx, cy), or −inf off the grid. Point clearance is 1-Lipschitz, so the value stored at the
    nearest cell centre minus the distance to it (≤ h/√2) bounds it from below."""
    x0, y0, h = sdf_geo[0], sdf_geo[1], sdf_geo[2]
    i = int((cx - x0) / h)
    j = int((cy - y0) / h)
    if not (0 <= i < sdf.shape[0] and 0 <= j < sdf.shape[1] and cx >= x0 and cy >= y0):
        return -math.inf
    return sdf[i, j] - 0.7072 * h - r


@njit(cache=True, inline="always")
def _grid_bound(sdf, sdf_geo, discs, x, y, c, s) -> float:
    """`_disc_grid_bound` of the whole footprint at the pose (x, y) with heading cos and sin
    c, s, or −inf where it is not good enough: a disc off the grid or within 2 cells of an
    obstacle. Takes arrays, not the World, so a loop calling it pays no reference counting."""
    low = math.inf
    for k in range(discs.shape[0]):
        a, r = discs[k, 0], discs[k, 1]
        d = _disc_grid_bound(sdf, sdf_geo, x + a * c, y + a * s, r)
        if d < 2.0 * sdf_geo[2]:
            return -math.inf
        low = min(low, d)
    return low


@njit(cache=True)
def clearance_bound(w: World, x: float, y: float, c: float, s: float, t: float) -> float:
    """A lower bound of `pose_clearance` at the pose (x, y) with heading cos and sin c, s:
    the grid's (`_disc_grid_bound`) in open space, exact within 2 cells of an obstacle."""
    low = math.inf
    for k in range(w.discs.shape[0]):
        a, r = w.discs[k, 0], w.discs[k, 1]
        cx, cy = x + a * c, y + a * s
        d = _disc_grid_bound(w.sdf, w.sdf_geo, cx, cy, r)
        if d < 2.0 * w.sdf_geo[2]:
            d = _point_static(w, cx, cy) - r
        if w.m_kind.shape[0] > 0:
            d = _point_obstacles(w, cx, cy, t, True, d + r) - r
        low = min(low, d)
    return low


@njit(cache=True)
def motion_free(w: World, x, y, th, t0, kinds, lens, curv, speed, counter) -> bool:
    """Exact check of a whole segment path (`planner._paths`) driven from time t0 at
    ``speed``.

    ``counter`` (int64[1]) accumulates clearance evaluations, for the metrics.
    """
    return free_length(w, x, y, th, t0, kinds, lens, curv, speed, counter) == math.inf


@njit(cache=True)
def free_length(w: World, x, y, th, t0, kinds, lens, curv, speed, counter) -> float:
    """How far a segment path driven from time t0 at ``speed`` is certified free: +inf for
    all of it, else a driven length short of the first contact (every step before it is free).

    Poses along an arc come from its start's cos and sin: two trigonometric calls per step, none
    on a straight; along a clothoid from `advance`.
    """
    # A footprint disc at offset a moves at most (1 + a·|κ|) times as far as the car drives.
    kmax = 0.0
    for i in range(kinds.shape[0]):
        kmax = max(kmax, peak_curvature(kinds[i], lens[i], curv[i, 0], curv[i, 1]))
    slow = 1.0 + w.geo[VMAX_OBS] / speed + w.geo[REACH] * kmax
    sdf, sdf_geo, discs = w.sdf, w.sdf_geo, w.discs
    moving = w.m_kind.shape[0] > 0
    driven = 0.0
    for i in range(kinds.shape[0]):
        seg = lens[i]
        if seg == 0.0:
            continue
        if kinds[i] == TURN:  # on the spot: a disc robot's cover does not change
            th += seg
            continue
        length = abs(seg)
        direction = 1.0 if seg > 0.0 else -1.0
        turn, sigma = curv[i, 0], curv[i, 1]
        c0, s0 = math.cos(th), math.sin(th)
        s = 0.0
        while True:
            if sigma != 0.0:
                px, py, pth = advance(x, y, th, kinds[i], direction * s, turn, sigma)
                c, sn = math.cos(pth), math.sin(pth)
            elif turn == 0.0:
                c, sn = c0, s0
                px, py = x + direction * s * c0, y + direction * s * s0
            else:
                c, sn = math.cos(th + turn * direction * s), math.sin(th + turn * direction * s)
                px, py = x + (sn - s0) / turn, y - (c - c0) / turn
            counter[0] += 1
            d = -math.inf if moving else _grid_bound(sdf, sdf_geo, discs, px, py, c, sn)
            if d == -math.inf:
                d = clearance_bound(w, px, py, c, sn, t0 + (driven + s) / speed)
            if d <= CONTACT:
                return driven + s
            if s >= length:
                break
            s = min(length, s + d / slow)
        x, y, th = advance(x, y, th, kinds[i], seg, turn, sigma)
        driven += length
    return math.inf


@njit(cache=True)
def path_moving_clearances(w: World, samples: np.ndarray) -> np.ndarray:
    """`moving_clearance` at each row (x, y, theta, …, t in column 5) of ``samples``."""
    out = np.empty(samples.shape[0])
    for k in range(samples.shape[0]):
        out[k] = moving_clearance(w, samples[k, 0], samples[k, 1], samples[k, 2], samples[k, 5])
    return out


@njit(cache=True)
def least_clearance(w: World, samples: np.ndarray, timed: bool) -> float:
    """The least of `path_clearances`, exactly, without measuring every row: clearance is
    1-Lipschitz in where the footprint's discs are, and they move at most |Δ(x, y)| + reach·|Δθ|
    between rows, so the rows after one of clearance c, up to c − (least so far) on, cannot be
    less (a 140 m path through 10 000 circles took 0.4 s measuring every row). With moving
    obstacles, which move between rows too, every row is measured."""
    best = math.inf
    if w.m_kind.shape[0] > 0:
        for c in path_clearances(w, samples, timed):  # not .min(): numba's array math
            best = min(best, c)
        return best
    slack = 0.0  # how far the footprint may still move before a row could beat the least
    for k in range(samples.shape[0]):
        if k > 0:
            slack -= (math.hypot(samples[k, 0] - samples[k - 1, 0],
                                 samples[k, 1] - samples[k - 1, 1])
                      + w.geo[REACH] * abs(samples[k, 2] - samples[k - 1, 2]))
        if slack > 0.0:
            continue
        c = pose_clearance(w, samples[k, 0], samples[k, 1], samples[k, 2], 0.0)
        best = min(best, c)
        slack = c - best
    return best


@njit(cache=True)
def path_clearances(w: World, samples: np.ndarray, timed: bool) -> np.ndarray:
    """Clearance at each row (x, y, theta, …, t in column 5 when ``timed``) of ``samples``."""
    out = np.empty(samples.shape[0])
    for k in range(samples.shape[0]):
        t = samples[k, 5] if timed else 0.0
        out[k] = pose_clearance(w, samples[k, 0], samples[k, 1], samples[k, 2], t)
    return out
