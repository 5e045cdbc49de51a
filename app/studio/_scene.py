"""Drawing a scenario on the ground plane (z = 0, x right, y up): track, obstacles, poses.

Everything is flat geometry seen from above, so meshes are triangulated polygons and lines are
line segments; heights only order the layers (surface below centreline below tree below path).
"""

from __future__ import annotations

import math

import numpy as np
import shapely

import planner
from planner.obstacles import motion_table, outline, table_offsets

__all__ = ["CURVATURE_RGB", "CUSP_UNDER_RGB", "DRAFT_RGB", "GOAL_RGB", "MOVER_RGB", "OBSTACLE_RGB",
           "REVERSE_RGB", "START_RGB", "Z", "add_grid", "arc_length", "car_outline", "circle_points", "curvature_colors",
           "cusp_rows", "draw_car", "draw_obstacles", "draw_poses", "draw_track", "fit_camera",
           "ground_point", "marker_size", "metres_per_px", "move_obstacles", "obstacle_rings",
           "path_layers", "polyline_segments", "put_segments", "reversing",
           "wxyz_yaw", "yaw_wxyz"]

# Obstacles above the tree: edges pass where a moving obstacle is at other times.
# A mover lies just above the static obstacles: over one, at the same height, the two would
# take turns at each pixel (z-fighting: stripes).
Z = {"surface": -0.02, "centre": 0.002, "tree": 0.006, "flash": 0.008, "obstacle": 0.009,
     "mover": 0.0093, "pin": 0.0095, "path": 0.01, "step": 0.012, "pose": 0.014, "car": 0.016}
CAR_RGB, CAR_LINE_RGB = (250, 250, 250), (20, 20, 20)
DISCS_RGB, MARGIN_RGB = (120, 120, 120), (235, 235, 235)  # checked discs, margin's dashes
DRAFT_RGB = (255, 120, 0)  # what is being clicked: polygon corners, a drawn track
START_RGB, GOAL_RGB = (60, 200, 90), (250, 200, 40)
OBSTACLE_RGB, MOVER_RGB = (200, 60, 60), (230, 140, 40)  # static and moving obstacles
CURVATURE_RGB = ((60, 130, 255), (250, 210, 60), (235, 50, 40))  # straight, half, the limit
# Reversing: dashes of the path's own colour on white, so a pinned run's reverse stays its own;
# a cusp is a white diamond on a dark one (no other marker in the scene is a diamond).
REVERSE_RGB, CUSP_UNDER_RGB = (250, 250, 250), (25, 25, 25)


def polyline_segments(pts: np.ndarray, z: float, closed: bool = False) -> np.ndarray:
    """(n, 2) points → (n-1, 2, 3) line segments at height z (closing the ring if asked)."""
    pts = np.asarray(pts, dtype=np.float32)
    if closed:
        pts = np.vstack([pts, pts[:1]])
    seg = np.zeros((len(pts) - 1, 2, 3), np.float32)
    seg[:, 0, :2], seg[:, 1, :2] = pts[:-1], pts[1:]
    seg[:, :, 2] = z
    return seg


def arc_length(path: np.ndarray) -> np.ndarray:
    """The distance driven to each row of a path (x, y in its first columns)."""
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path[:, :2], axis=0).T))])


def reversing(path: np.ndarray) -> np.ndarray:
    """For each piece of a path (rows i to i + 1 of x, y, θ, κ, direction, …), whether the
    car drives it in reverse: a row's direction is that of the piece ending at it, as
    `planner` samples paths. A path without a direction column drives forward."""
    if len(path) < 2 or path.shape[1] < 5:
        return np.zeros(max(len(path) - 1, 0), bool)
    return path[1:, 4] < 0


def cusp_rows(path: np.ndarray) -> np.ndarray:
    """The rows where the car stops and changes direction: the piece before and the piece
    after the row are driven in opposite directions."""
    rev = reversing(path)
    return np.flatnonzero(rev[:-1] != rev[1:]) + 1


def _diamond(x: float, y: float, r: float, z: float) -> np.ndarray:
    return polyline_segments(np.array([[x + r, y], [x, y + r], [x - r, y], [x, y - r]]), z,
                             closed=True)


def path_layers(path: np.ndarray, rgb, marker: float, z: float) -> list[tuple]:
    """A path drawn with its reversing shown, as line layers (suffix, segments, colour, px at
    scale 1), lowest first: the forward pieces in ``rgb``; the reverse pieces white with
    dashes of ``rgb`` (each 2 ``marker`` long) over them; a diamond at each cusp. Every layer
    is returned, empty when the path has none of it, so that a drawing updated in place hides
    what the new path lacks."""
    seg = polyline_segments(path[:, :2], z) if len(path) > 1 else np.zeros((0, 2, 3), np.float32)
    rev = reversing(path)
    dash = np.floor(arc_length(path)[:-1] / (2 * marker)) % 2 == 0
    cusps = [_diamond(*path[i, :2], 1.3 * marker, z + 2e-4) for i in cusp_rows(path)]
    diamonds = np.concatenate(cusps) if cusps else np.zeros((0, 2, 3), np.float32)
    above = diamonds.copy()
    above[:, :, 2] += 1e-4
    return [("", seg[~rev], rgb, 4.0), ("_reverse", seg[rev], REVERSE_RGB, 4.0),
            ("_reverse_dashes", seg[rev & dash] + np.float32([0, 0, 1e-4]), rgb, 4.0),
            ("_cusps_under", diamonds, CUSP_UNDER_RGB, 6.0), ("_cusps", above, REVERSE_RGB, 2.5)]


def curvature_colors(kappa: np.ndarray, kappa_max: float) -> np.ndarray:
    """Blue (straight) → yellow → red (at the car's limit 1/ρ and beyond), one RGB per value."""
    u = np.clip(np.abs(kappa) / kappa_max, 0.0, 1.0)[:, None]
    blue, yellow, red = (np.array(rgb) for rgb in CURVATURE_RGB)
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


def draw_track(scene, track, kappa_max: float, root: str = "") -> None:
    """Drivable surface, both edges, and the centreline coloured by curvature, under
    ``root``/track (a frame that places a copy, as the split's second half)."""
    rings = track.region_rings()
    if track.closed and len(rings) == 2:
        _fill(scene, f"{root}/track/surface", rings, Z["surface"], (72, 74, 82))
    else:
        for i, ring in enumerate(rings):
            _fill(scene, f"{root}/track/surface{i}", [ring], Z["surface"], (72, 74, 82))
    for i, ring in enumerate(rings):
        scene.add_line_segments(f"{root}/track/edge{i}", polyline_segments(ring, 0.0, closed=True),
                                (235, 235, 235), thickness=2.0, thickness_units="screen")
    prof = track.sample(track.detail_spacing())
    seg = polyline_segments(np.column_stack([prof.x, prof.y]), Z["centre"])
    col = curvature_colors(prof.curvature, kappa_max)
    colors = np.stack([col[:-1], col[1:]], axis=1)
    scene.add_line_segments(f"{root}/track/centre", seg, colors, thickness=3.0,
                            thickness_units="screen")


def yaw_wxyz(yaw: float) -> tuple[float, float, float, float]:
    """The quaternion of a rotation by ``yaw`` about +z (the ground's normal)."""
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def wxyz_yaw(wxyz) -> float:
    """The rotation about +z of a quaternion that only turns about z (a ground-plane gizmo)."""
    w, _, _, z = wxyz
    return 2.0 * math.atan2(z, w)


def obstacle_rings(scenario: planner.Scenario, t: float = 0.0, track=None) -> list[np.ndarray]:
    """Each obstacle's outline in world coordinates at time t (``track``: for obstacles that
    follow it)."""
    out = []
    for ob in scenario.obstacles:
        (x, y, yaw), local = outline(ob)
        c, s = math.cos(yaw), math.sin(yaw)
        out.append(local @ np.array([[c, s], [-s, c]]) + [x, y]
                   + table_offsets(motion_table(ob.motion, track), t)[0])
    return out


def draw_obstacles(scene, scenario: planner.Scenario, track, root: str = "") -> list[tuple]:
    """Static obstacles red, moving ones orange, each a frame ``root/obstacles/o{i}`` at its
    pose holding its outline; returns (frame, pose, motion table) per obstacle for
    `move_obstacles`."""
    out = []
    for i, ob in enumerate(scenario.obstacles):
        pose, local = outline(ob)
        frame = scene.add_frame(f"{root}/obstacles/o{i}", show_axes=False, position=(*pose[:2], 0.0),
                                wxyz=yaw_wxyz(pose[2]))
        moves = ob.motion is not None
        _fill(scene, f"{root}/obstacles/o{i}/shape", [local], Z["mover" if moves else "obstacle"],
              MOVER_RGB if moves else OBSTACLE_RGB)
        out.append((frame, pose, motion_table(ob.motion, track)))
    return out


def move_obstacles(drawn: list[tuple], t: float) -> None:
    """Put each moving obstacle where it is at scene time t (a position update, no mesh)."""
    for frame, pose, table in drawn:
        if table is not None:
            frame.position = (*(np.array(pose[:2]) + table_offsets(table, t)[0]), 0.0)


def car_outline(length: float, width: float) -> np.ndarray:
    """An arrow-nosed car footprint in its own frame (rear axle at the origin, heading +x)."""
    return np.array([[-0.3, -0.5], [0.7, -0.5], [1.0, 0.0], [0.7, 0.5], [-0.3, 0.5]]) * [
        length, width]


def circle_points(x: float, y: float, r: float, n: int = 40) -> np.ndarray:
    """(n, 2) points round the circle of radius r about (x, y), counter-clockwise from +x."""
    a = np.linspace(0, 2 * math.pi, n, endpoint=False)
    return np.column_stack([x + r * np.cos(a), y + r * np.sin(a)])


def put_segments(scene, handles: dict, name: str, path: str, seg: np.ndarray, rgb,
                 px: float) -> None:
    """Show ``seg`` as the line-segments node ``path`` kept in ``handles[name]``: created
    ``px`` screen pixels wide on first use, updated in place after, hidden while empty."""
    h = handles.get(name)
    if len(seg) == 0:
        if h is not None:
            h.visible = False
    elif h is None:
        handles[name] = scene.add_line_segments(path, seg, rgb, thickness=px,
                                                thickness_units="screen")
    else:
        h.points, h.visible = seg, True


def _car_ring(vehicle, marker: float) -> np.ndarray:
    """The car's outline about its rear axle, heading +x: see `draw_car`."""
    fp = vehicle.footprint
    if fp is None:
        return circle_points(0.0, 0.0, vehicle.radius or 2 * marker, 32)
    back = -fp.overhang(vehicle.wheelbase)
    w = fp.width / 2
    return np.array([[back, -w], [back + fp.length, -w], [back + fp.length, w], [back, w]])


def _discs_ring(vehicle, grow: float) -> np.ndarray:
    """The outline of the discs the planner checks, each grown by ``grow`` (> 0 for a point)."""
    discs = [shapely.Point(dx, 0.0).buffer(r + grow, quad_segs=16) for dx, r in vehicle.discs()]
    return np.asarray(shapely.union_all(discs).exterior.coords)[:-1]


def draw_car(scene, name: str, vehicle, marker: float, pose):
    """The car as the planner plans it, in a frame ``name`` at ``pose`` (x, y, heading) that
    the caller moves: its footprint rectangle (the rear axle ``rear_overhang`` in front of the
    rear bumper) with the discs that cover it, which are what the planner checks, else the disc
    of ``vehicle.radius``; the safety margin around them dashed. A point car (radius 0) gets a
    disc of two ``marker`` (the start's and goal's size) only so that it stays visible. White
    with a dark outline and a line from the rear axle to the front, so the heading shows on a
    disc too; the Drive car and the simulated car are this one drawing."""
    ring = _car_ring(vehicle, marker)
    frame = scene.add_frame(name, show_axes=False, position=(*pose[:2], 0.0),
                            wxyz=yaw_wxyz(pose[2]))
    _fill(scene, f"{name}/body", [ring], Z["car"], CAR_RGB)
    nose = np.array([[0.0, 0.0], [ring[:, 0].max(), 0.0]])
    scene.add_line_segments(
        f"{name}/outline", np.concatenate([polyline_segments(ring, Z["car"], True),
                                           polyline_segments(nose, Z["car"])]),
        CAR_LINE_RGB, thickness=2.5, thickness_units="screen")
    if vehicle.footprint is not None:
        scene.add_line_segments(f"{name}/discs",
                                polyline_segments(_discs_ring(vehicle, 0.0), Z["car"], True),
                                DISCS_RGB, thickness=1.5, thickness_units="screen")
    if vehicle.safety_margin > 0:
        dashes = polyline_segments(_discs_ring(vehicle, vehicle.safety_margin), Z["car"], True)
        scene.add_line_segments(f"{name}/margin", dashes[::2], MARGIN_RGB, thickness=1.5,
                                thickness_units="screen")
    return frame


def marker_size(bounds) -> float:
    """The size of the scene's markers (start, goal, step overlay): 0.6 % of the larger side of
    ``bounds``, so they look the same on a 30 cm track and a 100 m one."""
    xmin, ymin, xmax, ymax = bounds
    return 0.006 * max(xmax - xmin, ymax - ymin)


def draw_poses(scene, scenario: planner.Scenario, size: float, root: str = "") -> dict:
    """Start (green) and goal (gold) as car footprints in frames ``root/poses/start`` and
    ``root/poses/goal`` (dragging moves the frame); the goal's tolerance disc. Returns the
    frames."""
    frames = {}
    for name, pose, rgb in (("start", scenario.start, START_RGB),
                            ("goal", scenario.goal, GOAL_RGB)):
        frames[name] = scene.add_frame(f"{root}/poses/{name}", show_axes=False, position=(*pose[:2], 0.0),
                        wxyz=yaw_wxyz(pose[2]))
        _fill(scene, f"{root}/poses/{name}/shape", [car_outline(size, 0.5 * size)], Z["pose"], rgb)
    ring = circle_points(0.0, 0.0, scenario.goal_tolerance.position, 48)
    scene.add_line_segments(f"{root}/poses/goal/tol", polyline_segments(ring, Z["pose"], closed=True),
                            GOAL_RGB, thickness=1.5, thickness_units="screen")
    return frames


def add_grid(scene, bounds) -> None:
    """A ground grid scaled to the scene: cells of a power of ten near a tenth of its size, so
    a 30 cm track drawn in mm gets centimetre cells and a 100 m one ten-metre cells."""
    xmin, ymin, xmax, ymax = bounds
    extent = max(xmax - xmin, ymax - ymin)
    cell = 10.0 ** math.floor(math.log10(extent / 4))
    size = 20 * cell * math.ceil(extent / cell)
    scene.add_grid("/grid", size, size, plane="xy", cell_size=cell, section_size=5 * cell,
                   position=((xmin + xmax) / 2, (ymin + ymax) / 2, Z["surface"] - 0.01 * cell),
                   cell_color=(225, 225, 225), section_color=(190, 190, 190))


def ground_point(ev) -> tuple[float, float] | None:
    """Where a click's ray (``ev.ray_origin``, ``ev.ray_direction``) meets the ground z = 0;
    None when it points away from it."""
    (ox, oy, oz), (dx, dy, dz) = ev.ray_origin, ev.ray_direction
    if abs(dz) < 1e-12 or -oz / dz < 0:
        return None
    t = -oz / dz
    return ox + t * dx, oy + t * dy


def metres_per_px(camera) -> float | None:
    """The size of a screen pixel on the ground at the centre of the view (the camera looks
    down, as `fit_camera` puts it); None before the browser has reported its camera."""
    if camera.update_timestamp == 0.0:
        return None
    distance = float(np.linalg.norm(np.subtract(camera.position, camera.look_at)))
    return 2 * distance * math.tan(camera.fov / 2) / camera.image_height


def fit_camera(client, bounds, panel_px: float, fov_deg: float = 20.0,
               min_height: float = 20.0) -> None:
    """Look straight down on ``bounds`` with a narrow field of view (nearly orthographic),
    slightly off the pole so the orbit controls keep +y up on screen. The GUI panel floats
    over the right of the canvas, ``panel_px`` wide (15 px from the edge): the scene is centred
    in what is left of the canvas, so at any window width the panel covers none of it.

    The layers sit millimetres to centimetres apart in height (`Z`); seen from close above, a
    small track (30 cm drawn in mm) would show them shifted by parallax. So the camera never
    comes below ``min_height`` m: a small scene narrows the field of view instead."""
    xmin, ymin, xmax, ymax = bounds
    cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
    tanf = math.tan(math.radians(fov_deg) / 2)
    aspect = client.camera.aspect if client.camera.aspect > 0 else 1.5
    usable = min(max(1.0 - (panel_px + 15) / client.camera.image_width, 0.25), 1.0)
    h = max(0.55 * (ymax - ymin) / tanf, 0.55 * (xmax - xmin) / usable / (tanf * aspect))
    if h < min_height:
        tanf, h = tanf * h / min_height, min_height
    cx += (1 - usable) * tanf * aspect * h  # the scene's centre at usable / 2 across
    with client.atomic():
        client.camera.fov = 2 * math.atan(tanf)
        client.camera.up_direction = (0.0, 0.0, 1.0)
        # Zooming in 20× needs the camera closer than viser's default closest orbit distance.
        client.camera.min_orbit_distance = min(0.05 * h, client.camera.max_orbit_distance)
        client.camera.near = 0.01 * h
        client.camera.position = (cx, cy - 0.01 * h, h)
        client.camera.look_at = (cx, cy, 0.0)
        client.camera.far = 10 * h
