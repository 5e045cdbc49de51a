"""Rectangular car footprints: covered exactly by discs, checked in the car's real outline."""

import json
import math

import numpy as np
import pytest
import shapely
from checker import densify
from conftest import scenario_dict
from hypothesis import given, settings
from hypothesis import strategies as st

import planner
from planner.scenario import Footprint


@settings(max_examples=100, deadline=None)
@given(st.floats(0.1, 3), st.floats(0.05, 2), st.floats(0, 1), st.floats(0.1, 1))
def test_discs_cover_the_rectangle(length, width, overhang, wheelbase):
    fp = Footprint(type="rectangle", length=length, width=width, rear_overhang=overhang)
    discs = np.array(fp.discs(wheelbase))
    u = np.linspace(-overhang, length - overhang, 41)
    v = np.linspace(-width / 2, width / 2, 21)
    pts = np.array([(a, b) for a in u for b in v])
    dist = np.hypot(pts[:, None, 0] - discs[None, :, 0], pts[:, None, 1])
    assert np.all((dist <= discs[None, :, 1] + 1e-12).any(axis=1))


def car_outline(x, y, th, length, width, overhang):
    c, s = math.cos(th), math.sin(th)
    corners = [(-overhang, -width / 2), (length - overhang, -width / 2),
               (length - overhang, width / 2), (-overhang, width / 2)]
    return shapely.Polygon([(x + c * u - s * v, y + s * u + c * v) for u, v in corners])


@pytest.mark.parametrize("steering", ["dubins", "reeds-shepp", "cc-dubins", "cc-reeds-shepp"])
def test_planned_rectangle_never_touches_an_obstacle(steering):
    data = scenario_dict("parking")
    data["vehicle"].pop("radius")
    data["vehicle"]["footprint"] = {"type": "rectangle", "length": 0.6, "width": 0.3,
                                    "rear_overhang": 0.08}
    result = planner.solve(planner.parse_scenario(data), time_limit=None, iterations=5000,
                           steering=steering)
    assert result.solved
    obstacles = shapely.union_all([shapely.Polygon(o["points"]) for o in data["obstacles"]])
    xmin, ymin, xmax, ymax = data["bounds"]
    inside = shapely.box(xmin, ymin, xmax, ymax)
    for x, y, th in densify(result.path[:, :3], 0.005):
        car = car_outline(x, y, th, 0.6, 0.3, 0.08)
        assert not car.intersects(obstacles) and inside.contains(car)


def test_start_heading_matters_for_a_long_car():
    data = scenario_dict("slalom")
    data["vehicle"]["footprint"] = {"type": "rectangle", "length": 1.2, "width": 0.3,
                                    "rear_overhang": 0.1}
    data["obstacles"].append({"type": "circle", "center": [2.0, 4.0], "radius": 0.3})
    data["start"] = [1.0, 4.0, 0.0]  # the car's nose reaches x = 2.1: into the circle
    with pytest.raises(planner.ScenarioError, match="start"):
        planner.compile_problem(planner.parse_scenario(data))
    data["start"] = [1.0, 4.0, math.pi / 2]  # turned away, it fits
    planner.compile_problem(planner.parse_scenario(data))


def test_radius_and_footprint_together_are_refused():
    data = scenario_dict("parking")  # has radius 0.15
    data["vehicle"]["footprint"] = {"type": "rectangle", "length": 0.6, "width": 0.3}
    with pytest.raises(planner.ScenarioError, match="either 'radius'"):
        planner.parse_scenario(json.loads(json.dumps(data)))
