"""An independent validity checker for planned paths, written from docs/scenario-format.md alone.

Plain numpy, no planner code: it joins consecutive path points by the arc the two poses define (or
by the straight chord, as a consumer of the rows does), densifies, and tests every pose against the
scenario's obstacles where they are at that instant, and against a track's drivable region when the
scene gives its rings (``region``, even-odd). The car is the format's disc of ``vehicle.radius`` or,
in the rich schema (docs/planner.md), the rectangle ``vehicle.footprint`` at its exact outline (not
the discs the planner covers it with): the pose is the rear axle, the rectangle runs
``rear_overhang`` behind it and ``length - rear_overhang`` ahead along the heading, ``width / 2`` to
either side.
"""

from __future__ import annotations

import math

import numpy as np


def obstacle_offset(ob: dict, t: float) -> tuple[float, float]:
    dx, dy = _offsets(ob, np.array([t]))
    return float(dx[0]), float(dy[0])


def _outline(ob: dict) -> np.ndarray:
    """A polygon's points, or a box's corners (rich schema: centre, size, angle_deg)."""
    if ob["type"] == "polygon":
        return np.asarray(ob["points"], dtype=float)
    (cx, cy), (length, width) = ob["center"], ob["size"]
    a = math.radians(ob.get("angle_deg", 0.0))
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [length / 2, width / 2]
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return corners @ rot.T + [cx, cy]


def footprint(vehicle: dict) -> tuple[float, float, float] | None:
    """A rectangle footprint as (length, width, rear_overhang), or None for a disc car. Without
    ``rear_overhang`` the wheelbase sits in the middle of the length (docs/planner.md)."""
    fp = vehicle.get("footprint")
    if fp is None:
        return None
    length, width = fp["length"], fp["width"]
    overhang = fp.get("rear_overhang")
    if overhang is None:
        overhang = max(length - vehicle.get("wheelbase", 0.44), 0.0) / 2
    return length, width, overhang


def car_corners(x: float, y: float, theta: float, rect: tuple[float, float, float]) -> np.ndarray:
    """The (4, 2) corners of the footprint rectangle at the rear-axle pose (x, y, theta)."""
    length, width, overhang = rect
    c, s = math.cos(theta), math.sin(theta)
    u = np.array([-overhang, length - overhang, length - overhang, -overhang])
    v = np.array([-width / 2, -width / 2, width / 2, width / 2])
    return np.column_stack([x + c * u - s * v, y + s * u + c * v])


def _rect_distance(x, y, theta, rect, px, py):
    """Distance from the points (px, py) to the solid rectangle (0 inside or on it)."""
    length, width, overhang = rect
    c, s = math.cos(theta), math.sin(theta)
    dx, dy = np.subtract(px, x), np.subtract(py, y)
    u, v = c * dx + s * dy, -s * dx + c * dy
    du = np.maximum(np.maximum(-overhang - u, u - (length - overhang)), 0.0)
    dv = np.maximum(np.abs(v) - width / 2, 0.0)
    return np.hypot(du, dv)


def _point_segment(px, py, seg):
    """Distance from points to segments (broadcast; seg[..., :4] = x1, y1, x2, y2)."""
    ax, ay, bx, by = seg[..., 0], seg[..., 1], seg[..., 2], seg[..., 3]
    ex, ey = bx - ax, by - ay
    u = np.clip(((px - ax) * ex + (py - ay) * ey) / np.maximum(ex * ex + ey * ey, 1e-300), 0, 1)
    return np.hypot(ax + u * ex - px, ay + u * ey - py)


def _segment_distance(p: np.ndarray, q: np.ndarray) -> float:
    """The smallest distance between any segment of p (m, 4) and any of q (n, 4): 0 where two
    cross; otherwise the closest pair has an endpoint of one of them."""
    a, b = p[:, None, :], q[None, :, :]

    def orient(ox, oy, ux, uy, wx, wy):
        return (ux - ox) * (wy - oy) - (uy - oy) * (wx - ox)

    o1 = orient(a[..., 0], a[..., 1], a[..., 2], a[..., 3], b[..., 0], b[..., 1])
    o2 = orient(a[..., 0], a[..., 1], a[..., 2], a[..., 3], b[..., 2], b[..., 3])
    o3 = orient(b[..., 0], b[..., 1], b[..., 2], b[..., 3], a[..., 0], a[..., 1])
    o4 = orient(b[..., 0], b[..., 1], b[..., 2], b[..., 3], a[..., 2], a[..., 3])
    if ((o1 * o2 < 0) & (o3 * o4 < 0)).any():
        return 0.0
    return float(min(_point_segment(a[..., 0], a[..., 1], b).min(),
                     _point_segment(a[..., 2], a[..., 3], b).min(),
                     _point_segment(b[..., 0], b[..., 1], a).min(),
                     _point_segment(b[..., 2], b[..., 3], a).min()))


def _obstacles_at(scn: dict, t: float | None):
    """(obstacle, dx, dy): each obstacle there at time t and its offset (None: static ones)."""
    for ob in scn["obstacles"]:
        if t is None and ob.get("motion"):
            continue
        yield (ob, *obstacle_offset(ob, t or 0.0))


def _rectangle_valid(scn: dict, rect, x: float, y: float, theta: float,
                     t: float | None) -> bool:
    """The rectangle inside the bounds (touching them is fine, as for the disc) and apart from
    every obstacle (touching counts as collision)."""
    corners = car_corners(x, y, theta, rect)
    xmin, ymin, xmax, ymax = scn["bounds"]
    if not ((corners[:, 0] >= xmin).all() and (corners[:, 0] <= xmax).all()
            and (corners[:, 1] >= ymin).all() and (corners[:, 1] <= ymax).all()):
        return False
    edges = np.hstack([corners, np.roll(corners, -1, axis=0)])
    for ob, dx, dy in _obstacles_at(scn, t):
        if ob["type"] == "circle":
            cx, cy = ob["center"]
            if _rect_distance(x, y, theta, rect, cx + dx, cy + dy) <= ob["radius"]:
                return False
            continue
        pts = _outline(ob) + [dx, dy]
        # Apart iff the outlines neither cross nor touch and neither shape holds the other
        # (then one point of each decides: the car's corner, the obstacle's first vertex).
        if (_inside(_closed(pts), corners[:1, 0], corners[:1, 1])[0]
                or _rect_distance(x, y, theta, rect, pts[0, 0], pts[0, 1]) <= 0.0
                or _segment_distance(edges, np.hstack([pts, np.roll(pts, -1, axis=0)])) <= 0.0):
            return False
    return True


def pose_valid(scn: dict, x: float, y: float, t: float | None,
               theta: float | None = None) -> bool:
    """Validity (docs/scenario-format.md) at time t (None: static obstacles only). A rectangle
    footprint (rich schema) needs the heading ``theta``; a disc car ignores it."""
    if theta is None and footprint(scn.get("vehicle", {})) is not None:
        raise ValueError("a rectangle footprint is checked at a heading: give theta")
    pose = np.array([[x, y, 0.0 if theta is None else theta]])
    return bool(poses_valid(scn, pose, None if t is None else np.array([t]))[0])


def poses_valid(scn: dict, poses: np.ndarray, times: np.ndarray | None) -> np.ndarray:
    """`pose_valid` for many poses (x, y, theta rows) at once, at ``times`` (None: static
    obstacles only). A rectangle is tested exactly only where its circumscribed disc is not
    clear: where that disc is, the rectangle inside it is too."""
    vehicle = scn.get("vehicle", {})
    rect = footprint(vehicle)
    if rect is None:
        return _discs_valid(scn, poses, times, vehicle.get("radius", 0.0))
    length, width, overhang = rect
    reach = math.hypot(max(overhang, length - overhang), width / 2)
    valid = _discs_valid(scn, poses, times, reach)
    for k in np.flatnonzero(~valid):
        valid[k] = _rectangle_valid(scn, rect, *poses[k], None if times is None else times[k])
    return valid


def _discs_valid(scn: dict, poses: np.ndarray, times: np.ndarray | None,
                 r: float) -> np.ndarray:
    """docs/scenario-format.md's test of a disc car of radius r, per pose."""
    x, y = poses[:, 0], poses[:, 1]
    xmin, ymin, xmax, ymax = scn["bounds"]
    valid = (xmin + r <= x) & (x <= xmax - r) & (ymin + r <= y) & (y <= ymax - r)
    for ob in scn["obstacles"]:
        if times is None and ob.get("motion"):
            continue
        dx, dy = _offsets(ob, times)
        if ob["type"] == "circle":
            cx, cy = ob["center"]
            valid &= np.hypot(x - cx - dx, y - cy - dy) > ob["radius"] + r
            continue
        px, py = x - dx, y - dy  # the obstacle at rest, the car moved by the opposite offset
        edges = _closed(_outline(ob))
        valid &= ~_inside(edges, px, py)
        if r > 0:
            valid &= _edges_distance(edges, px, py) > r
    region = scn.get("region")  # a track's drivable region: rings, even-odd
    if region:
        edges = np.vstack([_closed(np.asarray(ring, dtype=float)) for ring in region])
        valid &= _inside(edges, x, y) & (_edges_distance(edges, x, y) > r)
    return valid


def _closed(pts: np.ndarray) -> np.ndarray:
    """A polygon's edges (x1, y1, x2, y2), the last point joined to the first."""
    return np.hstack([pts, np.roll(pts, -1, axis=0)])


def _inside(edges: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """Even-odd rule: whether each point is inside the edges' polygon(s)."""
    inside = np.zeros(len(px), bool)
    for x1, y1, x2, y2 in edges:
        crosses = (y1 > py) != (y2 > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            inside ^= crosses & (px < x1 + (py - y1) * (x2 - x1) / (y2 - y1))
    return inside


def _edges_distance(edges: np.ndarray, px: np.ndarray, py: np.ndarray,
                    chunk: int = 4096) -> np.ndarray:
    """Each point's distance to the nearest edge (in chunks of points: bounded memory)."""
    return np.concatenate([
        _point_segment(px[i:i + chunk, None], py[i:i + chunk, None], edges[None]).min(axis=1)
        for i in range(0, len(px), chunk)]) if len(px) else np.zeros(0)


def _offsets(ob: dict, times: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The obstacle's offsets at ``times`` (zero for a static one or without times)."""
    motion = ob.get("motion")
    if not motion or times is None:
        return np.zeros(1), np.zeros(1)
    if "velocity" in motion:
        vx, vy = motion["velocity"]
        return vx * times, vy * times
    wp = np.asarray(motion["waypoints"], dtype=float)
    return np.interp(times, wp[:, 0], wp[:, 1]), np.interp(times, wp[:, 0], wp[:, 2])


def densify(path: np.ndarray, step: float = 0.005, time_step: float = 0.005) -> np.ndarray:
    """Rows x, y, theta[, t] every ≤ step and ≤ time_step, each gap filled by the arc its end
    poses define (a wait, where both poses are the same, by instants)."""
    out = [path[:1]]
    for p, q in zip(path[:-1], path[1:]):
        chord = math.hypot(q[0] - p[0], q[1] - p[1])
        n = max(1, math.ceil(chord / step))
        if path.shape[1] > 3:
            n = max(n, math.ceil((q[3] - p[3]) / time_step))
        f = np.arange(1, n + 1) / n
        dth = (q[2] - p[2] + math.pi) % (2 * math.pi) - math.pi
        th = p[2] + f * dth
        if abs(dth) < 1e-9:
            x = p[0] + f * (q[0] - p[0])
            y = p[1] + f * (q[1] - p[1])
        else:
            s0, s1 = math.sin(p[2]), math.sin(p[2] + dth)
            c0, c1 = math.cos(p[2]), math.cos(p[2] + dth)
            radius = ((q[0] - p[0]) / (s1 - s0) if abs(s1 - s0) > abs(c1 - c0)
                      else -(q[1] - p[1]) / (c1 - c0))
            x = p[0] + radius * (np.sin(th) - s0)
            y = p[1] - radius * (np.cos(th) - c0)
        rows = [x, y, th]
        if path.shape[1] > 3:
            rows.append(p[3] + f * (q[3] - p[3]))
        out.append(np.column_stack(rows))
    return np.vstack(out)


def chords(path: np.ndarray, step: float = 0.001, time_step: float = 0.001) -> np.ndarray:
    """Rows x, y, theta[, t] every ≤ step and ≤ time_step along the straight chords between
    the path's rows, as a consumer joins them: every column linear, the heading the short way
    round (a turn on the spot, where both positions are the same, by angle steps of ``step``
    rad)."""
    path = np.asarray(path, dtype=float)
    out = [path[:1]]
    for p, q in zip(path[:-1], path[1:]):
        dth = (q[2] - p[2] + math.pi) % (2 * math.pi) - math.pi
        n = max(1, math.ceil(math.hypot(q[0] - p[0], q[1] - p[1]) / step),
                math.ceil(abs(dth) / step))
        if path.shape[1] > 3:
            n = max(n, math.ceil((q[3] - p[3]) / time_step))
        f = (np.arange(1, n + 1) / n)[:, None]
        gap = q - p
        gap[2] = dth
        out.append(p + f * gap)
    return np.vstack(out)


def first_collision(scn: dict, path, step: float = 0.005, along: str = "arcs") -> float | None:
    """Arc length of the first invalid pose on the path (timed if it has a t column), or None;
    the path's rows joined by the car's arcs (``along="arcs"``) or by straight chords
    (``"chords"``)."""
    path = np.asarray(path, dtype=float)
    dense = densify(path, step) if along == "arcs" else chords(path, step)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(dense[:, :2], axis=0).T))])
    valid = poses_valid(scn, dense[:, :3], dense[:, 3] if dense.shape[1] > 3 else None)
    return None if valid.all() else float(s[np.argmin(valid)])


def arc_mismatch(path) -> float:
    """Largest error of reconstructing each gap as one arc: consecutive points must be joined
    by the car's own motion (a single arc or straight piece, since samples include the joints).
    A gap whose end pose is not reachable by one arc shows as a position mismatch."""
    path = np.asarray(path, dtype=float)
    worst = 0.0
    for p, q in zip(path[:-1], path[1:]):
        chord_dir = math.atan2(q[1] - p[1], q[0] - p[0])
        dth = (q[2] - p[2] + math.pi) % (2 * math.pi) - math.pi
        if math.hypot(q[0] - p[0], q[1] - p[1]) < 1e-12:
            continue
        # For a circular arc, the chord bisects the headings (forward or reversing).
        mid = p[2] + dth / 2
        err = abs((chord_dir - mid + math.pi / 2) % math.pi - math.pi / 2)
        worst = max(worst, err)
    return worst


def clothoid_mismatch(path) -> float:
    """Largest position error (m) of reconstructing each gap of a continuous-curvature path as
    one clothoid: κ linear from the row before's κ to the next row's, driven in the next row's
    direction (columns x, y, θ, κ, direction), its length from the heading change (the chord
    where κ is 0 at both ends), integrated by Simpson's rule."""
    path = np.asarray(path, dtype=float)
    u = np.linspace(0.0, 1.0, 33)
    weights = np.ones(33)
    weights[1:-1:2], weights[2:-1:2] = 4.0, 2.0
    worst = 0.0
    for p, q in zip(path[:-1], path[1:]):
        chord = math.hypot(q[0] - p[0], q[1] - p[1])
        if chord < 1e-12:
            continue
        d, k0, k1 = q[4], p[3], q[3]
        dth = (q[2] - p[2] + math.pi) % (2 * math.pi) - math.pi
        length = chord if abs(k0 + k1) < 1e-9 else 2.0 * d * dth / (k0 + k1)
        th = p[2] + d * length * (k0 * u + 0.5 * (k1 - k0) * u * u)
        x = p[0] + d * length * np.dot(weights, np.cos(th)) / 96.0
        y = p[1] + d * length * np.dot(weights, np.sin(th)) / 96.0
        worst = max(worst, math.hypot(x - q[0], y - q[1]))
    return worst


def schedule_errors(path, max_speed: float, rounding: float = 0.0) -> list[str]:
    """docs/scenario-format.md v1.3's rules for a timed path of ``timing: optimal``: t from 0 and
    non-decreasing, at most ``max_speed`` between entries (1 % tolerance, and ``rounding`` m
    for rows rounded to that many metres and seconds), entries at most 0.05 m and 0.1 s apart
    (up to the rounding too).
    Returns one message per kind of breach."""
    path = np.asarray(path, dtype=float)
    step = np.hypot(*np.diff(path[:, :2], axis=0).T)
    dt = np.diff(path[:, 3])
    errors = []
    if path[0, 3] != 0.0:
        errors.append(f"the first entry is at t = {path[0, 3]}, not 0")
    if (dt < 0).any():
        errors.append(f"t decreases after entry {int(np.argmax(dt < 0))}")
    moving = step > 1e-9
    fast = moving & (step > 1.01 * max_speed * np.maximum(dt, 0.0) + 2 * rounding)
    if fast.any():
        k = int(np.argmax(fast))
        errors.append(f"entry {k} to {k + 1}: {step[k]:.4f} m in {dt[k]:.4f} s is above "
                      f"{max_speed} m/s")
    if (step > 0.05 + 1e-9 + 2 * rounding).any():
        errors.append(f"entries up to {step.max():.4f} m apart")
    if (dt > 0.1 + 1e-9 + 2 * rounding).any():
        errors.append(f"entries up to {dt.max():.4f} s apart")
    return errors
