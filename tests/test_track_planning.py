"""Planning on a library track: the drivable region comes from the tracks layer."""

import numpy as np
import shapely
from checker import densify
from conftest import scenario_dict

import planner
import tracks


def test_half_lap_of_the_thesis_track_stays_on_the_track_and_off_the_box():
    data = scenario_dict("thesis_half_lap")
    result = planner.solve(planner.parse_scenario(data), time_limit=None, iterations=6000)
    assert result.solved
    # Independent check with shapely: the car's disc stays inside the drivable region.
    outer, *holes = tracks.load_library_track("thesis").region_rings()
    region = shapely.Polygon(outer, holes)
    radius = data["vehicle"]["radius"]
    dense = densify(result.path[:, [0, 1, 2, 5]], 0.005)
    discs = shapely.buffer(shapely.points(dense[:, :2]), radius)
    assert shapely.contains(region, discs).all()
    (cx, cy), (length, width) = data["obstacles"][0]["center"], data["obstacles"][0]["size"]
    box = shapely.box(cx - length / 2, cy - width / 2, cx + length / 2, cy + width / 2)
    assert not shapely.intersects(box, discs).any()
    # The goal is half a lap ahead: the path follows the track, it does not cut across.
    assert 6.0 < result.cost < 7.5
    assert np.abs(result.path[:, 3]).max() <= 1 / 0.9021 + 1e-9
