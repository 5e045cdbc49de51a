"""The independent checker's rectangle footprint: hand-made poses whose answer is known, an
oracle (shapely) on random poses, and a planned path of a rectangle car."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import shapely
import shapely.affinity
from checker import first_collision, pose_valid
from conftest import scenario_dict

import planner

GAP = 1e-6  # "just missing" / "just touching": either side of contact, clear of rounding

# A 1.0 m × 0.4 m car with its rear axle 0.2 m in front of the rear bumper: at the pose
# (0, 0, 0) it covers x ∈ [-0.2, 0.8], y ∈ [-0.2, 0.2]; at (0, 0, π/2) x ∈ [-0.2, 0.2],
# y ∈ [-0.2, 0.8].
CAR = {"wheelbase": 0.44, "max_steer_deg": 26,
       "footprint": {"type": "rectangle", "length": 1.0, "width": 0.4, "rear_overhang": 0.2}}


def scene(*obstacles, vehicle=CAR) -> dict:
    return {"name": "t", "bounds": [-10, -10, 10, 10], "vehicle": vehicle,
            "start": [0, 0, 0], "goal": [5, 5, 0], "obstacles": list(obstacles)}


def circle(x, y, r=0.5, **more):
    return {"type": "circle", "center": [x, y], "radius": r, **more}


def box(x, y, length=1.0, width=1.0, angle_deg=0.0):
    return {"type": "box", "center": [x, y], "size": [length, width], "angle_deg": angle_deg}


def polygon(*points):
    return {"type": "polygon", "points": [list(p) for p in points]}


R2 = math.sqrt(2) / 2  # half the diagonal of a unit square


@pytest.mark.parametrize("obstacle, theta, valid", [
    # A circle ahead of the nose (x = 0.8), behind the rear bumper (x = -0.2), beside (y = 0.2).
    (circle(1.3 + GAP, 0), 0.0, True),
    (circle(1.3 - GAP, 0), 0.0, False),
    (circle(-0.7 - GAP, 0), 0.0, True),
    (circle(-0.7 + GAP, 0), 0.0, False),
    (circle(0.3, 0.7 + GAP), 0.0, True),
    (circle(0.3, 0.7 - GAP), 0.0, False),
    # Off the front-left corner (0.8, 0.2) along (3, 4)/5: within 0.5 of the corner's axes,
    # so only the corner's true distance decides.
    (circle(1.1, 0.6, 0.5 - GAP), 0.0, True),
    (circle(1.1, 0.6, 0.5 + GAP), 0.0, False),
    # Turned 90° the nose points along +y: the circle ahead at θ = 0 is beside it, far away.
    (circle(1.3 - GAP, 0), math.pi / 2, True),
    (circle(0, 1.3 + GAP), math.pi / 2, True),
    (circle(0, 1.3 - GAP), math.pi / 2, False),
    (circle(0.7 - GAP, 0.3), math.pi / 2, False),
    (circle(0.7 + GAP, 0.3), math.pi / 2, True),
    # Boxes: side to side with the nose; a 45° box's corner at the nose or in the car's side.
    (box(1.3 + GAP, 0), 0.0, True),
    (box(1.3 - GAP, 0), 0.0, False),
    (box(0.8 + R2 + GAP, 0, angle_deg=45), 0.0, True),
    (box(0.8 + R2 - GAP, 0, angle_deg=45), 0.0, False),
    (box(0.3, 0.2 + R2 + GAP, angle_deg=45), 0.0, True),
    (box(0.3, 0.2 + R2 - GAP, angle_deg=45), 0.0, False),
    (box(0, 1.3 + GAP), math.pi / 2, True),
    (box(0, 1.3 - GAP), math.pi / 2, False),
    (box(0.45, 0, 0.2, 2.0), 0.0, False),  # a bar across the car, no corner inside
    (box(0.45, 0, 0.2, 2.0), math.pi / 2, True),
    # Polygons: a triangle's tip at the car's side; a bar across the car (no vertex of either
    # inside the other: only the crossing edges tell); a polygon holding the whole car, and
    # polygons the car holds.
    (polygon((0.3, 0.2 + GAP), (0, 1), (0.6, 1)), 0.0, True),
    (polygon((0.3, 0.2 - GAP), (0, 1), (0.6, 1)), 0.0, False),
    (polygon((0.3, -1), (0.4, -1), (0.4, 1), (0.3, 1)), 0.0, False),
    (polygon((0.3, -1), (0.4, -1), (0.4, 1), (0.3, 1)), math.pi, True),
    (polygon((-2, -2), (2, -2), (2, 2), (-2, 2)), 0.0, False),
    (polygon((0.1, -0.05), (0.3, -0.05), (0.2, 0.05)), 0.0, False),  # wholly under the car
    (box(0.3, 0, 0.1, 0.1, 30.0), 0.0, False),
    (polygon((-0.2 - GAP, 0), (-1, -1), (-1, 1)), 0.0, True),
    (polygon((-0.2 + GAP, 0), (-1, -1), (-1, 1)), 0.0, False),
    (polygon((0.2 + GAP, 0.3), (1, 0), (1, 1)), math.pi / 2, True),
    (polygon((0.2 - GAP, 0.3), (1, 0), (1, 1)), math.pi / 2, False),
])
def test_rectangle_against_obstacles(obstacle, theta, valid):
    assert pose_valid(scene(obstacle), 0.0, 0.0, None, theta) is valid


def test_rectangle_inside_the_bounds():
    scn = scene()
    assert pose_valid(scn, 9.2 - GAP, 0, None, 0.0)  # nose at x = 10 - GAP
    assert not pose_valid(scn, 9.2 + GAP, 0, None, 0.0)
    assert not pose_valid(scn, -9.8 - GAP, 0, None, 0.0)  # rear bumper past xmin
    assert pose_valid(scn, 9.8 - GAP, 0, None, math.pi / 2)  # turned: 0.2 m to the side
    assert not pose_valid(scn, 9.8 + GAP, 0, None, math.pi / 2)
    assert not pose_valid(scn, 0, 9.2 + GAP, None, math.pi / 2)


def test_rear_overhang_default_centres_the_wheelbase():
    vehicle = copy.deepcopy(CAR)
    del vehicle["footprint"]["rear_overhang"]  # (1.0 - 0.44) / 2 = 0.28: nose at 0.72
    assert pose_valid(scene(circle(1.22 + GAP, 0), vehicle=vehicle), 0, 0, None, 0.0)
    assert not pose_valid(scene(circle(1.22 - GAP, 0), vehicle=vehicle), 0, 0, None, 0.0)
    assert pose_valid(scene(circle(-0.78 - GAP, 0), vehicle=vehicle), 0, 0, None, 0.0)
    assert not pose_valid(scene(circle(-0.78 + GAP, 0), vehicle=vehicle), 0, 0, None, 0.0)


def test_moving_obstacles_meet_the_rectangle_where_they_are():
    scn = scene(circle(3.3, 0, motion={"velocity": [-1, 0]}))  # at (1.3, 0) at t = 2
    assert pose_valid(scn, 0, 0, 2 - 2 * GAP, 0.0)
    assert not pose_valid(scn, 0, 0, 2 + 2 * GAP, 0.0)
    assert pose_valid(scn, 0, 0, None, 0.0)  # the goal's check: static obstacles only


def test_a_rectangle_needs_the_heading():
    with pytest.raises(ValueError, match="theta"):
        pose_valid(scene(), 0, 0, None)
    disc = scene(vehicle={"wheelbase": 0.44, "max_steer_deg": 26, "radius": 0.5})
    assert pose_valid(disc, 0, 0, None) == pose_valid(disc, 0, 0, None, 1.0)


def outline(x, y, th, length, width, overhang) -> shapely.Polygon:
    """The car's rectangle, built here from the docs for the oracle (not the checker's)."""
    c, s = math.cos(th), math.sin(th)
    rear, front = -overhang, length - overhang
    return shapely.Polygon([(x + c * u - s * v, y + s * u + c * v)
                            for u, v in ((rear, -width / 2), (front, -width / 2),
                                         (front, width / 2), (rear, width / 2))])


def test_the_checker_agrees_with_shapely_on_random_poses():
    obstacles = [circle(-3, 2, 1.0), box(3, -2, 2.0, 1.0, 35.0),
                 polygon((0, 3), (4, 3), (4, 6), (2, 4), (0, 6)),  # concave
                 polygon((-6, -6), (-2, -6), (-6, -2))]
    disc = shapely.Point(-3, 2)
    solids = [shapely.affinity.rotate(shapely.box(2, -2.5, 4, -1.5), 35.0, origin=(3, -2)),
              shapely.Polygon(obstacles[2]["points"]), shapely.Polygon(obstacles[3]["points"])]
    bounds = shapely.box(-10, -10, 10, 10)

    def free(car: shapely.Polygon) -> bool:
        return (bounds.covers(car) and car.distance(disc) > 1.0
                and not any(car.intersects(solid) for solid in solids))

    rng = np.random.default_rng(7)
    answers = []
    for _ in range(1500):
        length, width = rng.uniform(0.3, 3.0), rng.uniform(0.2, 1.5)
        overhang = rng.uniform(0, length)
        vehicle = {"wheelbase": 0.44, "max_steer_deg": 26, "footprint": {
            "type": "rectangle", "length": length, "width": width, "rear_overhang": overhang}}
        x, y, th = rng.uniform(-9, 9), rng.uniform(-9, 9), rng.uniform(-math.pi, math.pi)
        car = outline(x, y, th, length, width, overhang)
        grown, shrunk = (car.buffer(d, join_style="mitre") for d in (1e-9, -1e-9))
        if free(grown) != free(shrunk):
            continue  # touching within rounding: either answer is right
        expected = free(car)
        answers.append(expected)
        assert pose_valid(scene(*obstacles, vehicle=vehicle), x, y, None, th) is expected, (
            length, width, overhang, x, y, th)
    assert sum(answers) > 300 and len(answers) - sum(answers) > 300


def test_a_planned_rectangle_path_passes_the_rectangle_check():
    data = scenario_dict("slalom")  # circles; a box and a polygon added near the goal
    data["vehicle"].pop("radius")
    data["vehicle"]["footprint"] = {"type": "rectangle", "length": 0.6, "width": 0.3,
                                    "rear_overhang": 0.08}
    data["obstacles"] += [box(22.5, 5.2, 1.2, 0.6, 30.0),
                          polygon((21.5, 0), (23.5, 0), (22.5, 1.6))]
    result = planner.solve(planner.parse_scenario(copy.deepcopy(data)), time_limit=None,
                           iterations=5000, steering="reeds-shepp", seed=0)
    assert result.solved
    assert first_collision(data, result.path[:, :3]) is None
    # The check is not vacuous: the same path with a car twice the size hits something.
    bigger = copy.deepcopy(data)
    bigger["vehicle"]["footprint"].update(length=1.2, width=0.6)
    assert first_collision(bigger, result.path[:, :3]) is not None
