"""Drawing a scenario on the ground plane (z = 0, x right, y up): track, obstacles, poses.

Everything is flat geometry seen from above, so meshes are triangulated polygons and lines are
line segments; heights only order the layers (surface below centreline below tree below path).
"""

from __future__ import annotations

import math

import numpy as np
import shapely

import planner

__all__ = ["Z", "curvature_colors", "draw_obstacles", "draw_poses", "draw_track", "fit_camera",
           "obstacle_rings", "polyline_segments"]

Z = {"surface": -0.02, "centre": 0.002, "obstacle": 0.004, "tree": 0.006, "flash": 0.008,
     "path": 0.01, "step": 0.012, "pose": 0.014}


def polyline_segments(pts: np.ndarray, z: float, closed: bool = False) -> np.ndarray:
    """(n, 2) points → (n-1, 2, 3) line segments at height z (closing the ring if asked)."""
    pts = np.asarray(pts, dtype=np.float32)
    if closed:
        pts = np.vstack([pts, pts[:1]])
    seg = np.zeros((len(pts) - 1, 2, 3), np.float32)
    seg[:, 0, :2], seg[:, 1, :2] = pts[:-1], pts[1:]
    seg[:, :, 2] = z
    return seg


def curvature_colors(kappa: np.ndarray, kappa_max: float) -> np.ndarray:
    """Blue (straight) → yellow → red (at the car's limit 1/ρ and beyond), one RGB per value."""
    u = np.clip(np.abs(kappa) / kappa_max, 0.0, 1.0)[:, None]
    blue, yellow, red = np.array([60, 130, 255]), np.array([250, 210, 60]), np.array([235, 50, 40])
    lo = blue + (yellow - blue) * np.clip(2 * u, 0, 1)
    return np.where(u < 0.5, lo, yellow + (red - yellow) * np.clip(2 * u - 1, 0, 1)).astype(
        np.uint8)


def _fill(scene, name: str, rings: list[np.ndarray], z: float, color, opacity=None):
    """Triangulate a polygon (outer ring + holes) and add it as a flat mesh."""
    poly = shapely.Polygon(rings[0], rings[1:]) if len(rings) > 1 else shapely.Polygon(rings[0])
    tris = shapely.get_parts(shapely.constrained_delaunay_triangles(poly))
    if len(tris) == 0:
        return None
    coords = np.array([np.asarray(t.exterior.coords)[:3] for t in tris])  # (m, 3, 2)
    verts = np.zeros((len(coords) * 3, 3), np.float32)
    verts[:, :2] = coords.reshape(-1, 2)
    verts[:, 2] = z
    faces = np.arange(len(verts), dtype=np.uint32).reshape(-1, 3)
    # Counter-clockwise from above, so the face looks up at the camera.
    a, b, c = coords[:, 0], coords[:, 1], coords[:, 2]
    cw = ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])) < 0
    faces[cw] = faces[cw][:, ::-1]
    return scene.add_mesh_simple(name, verts, faces, color=color, opacity=opacity, side="double",
                          material="toon3", cast_shadow=False, receive_shadow=False)


def draw_track(scene, track, kappa_max: float) -> None:
    """Drivable surface, both edges, and the centreline coloured by curvature."""
    rings = track.region_rings()
    if track.closed and len(rings) == 2:
        _fill(scene, "/track/surface", rings, Z["surface"], (72, 74, 82))
    else:
        for i, ring in enumerate(rings):
            _fill(scene, f"/track/surface{i}", [ring], Z["surface"], (72, 74, 82))
    for i, ring in enumerate(rings):
        scene.add_line_segments(f"/track/edge{i}", polyline_segments(ring, 0.0, closed=True),
                                (235, 235, 235), thickness=2.0, thickness_units="screen")
    prof = track.sample(spacing=0.05)
    seg = polyline_segments(np.column_stack([prof.x, prof.y]), Z["centre"])
    col = curvature_colors(prof.curvature, kappa_max)
    colors = np.stack([col[:-1], col[1:]], axis=1)
    scene.add_line_segments("/track/centre", seg, colors, thickness=3.0,
                            thickness_units="screen")


def obstacle_rings(scenario: planner.Scenario, t: float = 0.0) -> list[np.ndarray]:
    """Each obstacle's outline at time t (circles as 48-gons), motions applied."""
    out = []
    for ob in scenario.obstacles:
        if ob.type == "circle":
            a = np.linspace(0, 2 * math.pi, 48, endpoint=False)
            ring = np.column_stack([ob.center[0] + ob.radius * np.cos(a),
                                    ob.center[1] + ob.radius * np.sin(a)])
        elif ob.type == "box":
            ring = np.array(ob.corners())
        else:
            ring = np.array(ob.points, dtype=float)
        out.append(ring + _offset(ob.motion, t))
    return out


def _offset(motion, t: float) -> np.ndarray:
    if motion is None:
        return np.zeros(2)
    if motion.velocity is not None:
        return np.array(motion.velocity) * t
    if motion.waypoints is not None:
        w = np.array(motion.waypoints)
        return np.array([np.interp(t, w[:, 0], w[:, 1]), np.interp(t, w[:, 0], w[:, 2])])
    return np.zeros(2)  # follow_track: drawn where it starts


def draw_obstacles(scene, scenario: planner.Scenario, t: float = 0.0) -> list:
    """Static obstacles red, moving ones orange (where they are at time t); returns handles."""
    handles = []
    for i, ring in enumerate(obstacle_rings(scenario, t)):
        moving = scenario.obstacles[i].motion is not None
        handles.append(_fill(scene, f"/obstacles/o{i}", [ring], Z["obstacle"],
                             (230, 140, 40) if moving else (200, 60, 60)))
    return handles


def _car_outline(pose, length: float, width: float) -> np.ndarray:
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    local = np.array([[-0.3, -0.5], [0.7, -0.5], [1.0, 0.0], [0.7, 0.5], [-0.3, 0.5]])
    local = local * [length, width]
    return np.column_stack([x + c * local[:, 0] - s * local[:, 1],
                            y + s * local[:, 0] + c * local[:, 1]])


def draw_poses(scene, scenario: planner.Scenario, size: float) -> None:
    """Start (green) and goal (gold) as arrow-nosed car footprints; the goal's tolerance disc."""
    _fill(scene, "/poses/start", [_car_outline(scenario.start, size, 0.5 * size)], Z["pose"],
          (60, 200, 90))
    _fill(scene, "/poses/goal", [_car_outline(scenario.goal, size, 0.5 * size)], Z["pose"],
          (250, 200, 40))
    a = np.linspace(0, 2 * math.pi, 48, endpoint=False)
    r = scenario.goal_tolerance.position
    ring = np.column_stack([scenario.goal[0] + r * np.cos(a), scenario.goal[1] + r * np.sin(a)])
    scene.add_line_segments("/poses/goal_tol", polyline_segments(ring, Z["pose"], closed=True),
                            (250, 200, 40), thickness=1.5, thickness_units="screen")


def fit_camera(client, bounds, fov_deg: float = 20.0, usable: float = 0.72) -> None:
    """Look straight down on ``bounds`` with a narrow field of view (nearly orthographic),
    slightly off the pole so the orbit controls keep +y up on screen. The GUI panel covers the
    right of the canvas, so the scene is centred in the left ``usable`` fraction."""
    xmin, ymin, xmax, ymax = bounds
    cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
    tanf = math.tan(math.radians(fov_deg) / 2)
    aspect = client.camera.aspect if client.camera.aspect > 0 else 1.5
    h = max(0.55 * (ymax - ymin) / tanf, 0.55 * (xmax - xmin) / usable / (tanf * aspect))
    cx += (1 - usable) * tanf * aspect * h  # the scene's centre at usable / 2 across
    with client.atomic():
        client.camera.fov = math.radians(fov_deg)
        client.camera.up_direction = (0.0, 0.0, 1.0)
        # Small tracks (an SVG in millimetres) need the camera closer than viser's default
        # closest orbit distance.
        client.camera.min_orbit_distance = min(0.05 * h, client.camera.max_orbit_distance)
        client.camera.near = 0.01 * h
        client.camera.position = (cx, cy - 0.01 * h, h)
        client.camera.look_at = (cx, cy, 0.0)
        client.camera.far = 10 * h
