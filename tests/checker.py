"""An independent validity checker for planned paths, written from FORMAT.md alone.

Plain numpy, no planner code: it reconstructs the arc between consecutive path points from the
two poses, densifies to 5 mm and tests every pose against the scenario's obstacles where they
are at that instant.
"""

from __future__ import annotations

import math

import numpy as np


def obstacle_offset(ob: dict, t: float) -> tuple[float, float]:
    motion = ob.get("motion")
    if not motion:
        return 0.0, 0.0
    if "velocity" in motion:
        vx, vy = motion["velocity"]
        return vx * t, vy * t
    wp = np.asarray(motion["waypoints"], dtype=float)
    return float(np.interp(t, wp[:, 0], wp[:, 1])), float(np.interp(t, wp[:, 0], wp[:, 2]))


def _inside_even_odd(pts: np.ndarray, x: float, y: float) -> bool:
    inside = False
    n = len(pts)
    for i in range(n):
        (x1, y1), (x2, y2) = pts[i], pts[(i + 1) % n]
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


def _edge_distance(pts: np.ndarray, x: float, y: float) -> float:
    a = pts
    b = np.roll(pts, -1, axis=0)
    ab = b - a
    u = np.clip(((x - a[:, 0]) * ab[:, 0] + (y - a[:, 1]) * ab[:, 1])
                / np.maximum((ab ** 2).sum(axis=1), 1e-300), 0, 1)
    return float(np.hypot(a[:, 0] + u * ab[:, 0] - x, a[:, 1] + u * ab[:, 1] - y).min())


def _outline(ob: dict) -> np.ndarray:
    """A polygon's points, or a box's corners (rich schema: centre, size, angle_deg)."""
    if ob["type"] == "polygon":
        return np.asarray(ob["points"], dtype=float)
    (cx, cy), (length, width) = ob["center"], ob["size"]
    a = math.radians(ob.get("angle_deg", 0.0))
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [length / 2, width / 2]
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return corners @ rot.T + [cx, cy]


def pose_valid(scn: dict, x: float, y: float, t: float | None) -> bool:
    """FORMAT.md validity at time t (None: static obstacles only)."""
    r = scn["vehicle"].get("radius", 0.0)
    xmin, ymin, xmax, ymax = scn["bounds"]
    if not (xmin + r <= x <= xmax - r and ymin + r <= y <= ymax - r):
        return False
    for ob in scn["obstacles"]:
        if t is None and ob.get("motion"):
            continue
        dx, dy = obstacle_offset(ob, t or 0.0)
        if ob["type"] == "circle":
            cx, cy = ob["center"]
            if math.hypot(x - cx - dx, y - cy - dy) <= ob["radius"] + r:
                return False
        else:
            pts = _outline(ob) + [dx, dy]
            if _inside_even_odd(pts, x, y) or (r > 0 and _edge_distance(pts, x, y) <= r):
                return False
    return True


def densify(path: np.ndarray, step: float = 0.005) -> np.ndarray:
    """Rows x, y, theta[, t] every ≤ step, each gap filled by the arc its end poses define."""
    out = [path[:1]]
    for p, q in zip(path[:-1], path[1:]):
        chord = math.hypot(q[0] - p[0], q[1] - p[1])
        n = max(1, math.ceil(chord / step))
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


def first_collision(scn: dict, path, step: float = 0.005) -> float | None:
    """Arc length of the first invalid pose on the path (timed if it has a t column), or None."""
    dense = densify(np.asarray(path, dtype=float), step)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(dense[:, :2], axis=0).T))])
    timed = dense.shape[1] > 3
    for k, row in enumerate(dense):
        if not pose_valid(scn, row[0], row[1], row[3] if timed else None):
            return float(s[k])
    return None


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
