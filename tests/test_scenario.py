"""Scenario parsing: both formats, strict keys with suggestions, one-line errors."""

import copy
import json

import pytest
from conftest import scenario_dict

import planner


@pytest.mark.parametrize("name", planner.scenario_names())
def test_every_bundled_scenario_reads_unchanged_under_its_name(name):
    scn = planner.load_scenario(name)
    raw = scenario_dict(name)
    assert scn.name == raw["name"] == name and len(scn.obstacles) == len(raw["obstacles"])
    assert scn.description, "a bundled scenario says what it is about"
    assert scn.has_motion == any("motion" in ob for ob in raw["obstacles"])


def test_turning_radius_from_wheelbase_and_steering_or_given():
    scn = scenario_dict("slalom")
    assert planner.parse_scenario(scn).vehicle.turning_radius == pytest.approx(0.90214, abs=1e-5)
    scn["vehicle"]["min_turning_radius"] = 2.0
    assert planner.parse_scenario(scn).vehicle.turning_radius == 2.0


def crossing_with(mutate):
    scn = copy.deepcopy(scenario_dict("crossing"))
    mutate(scn)
    return scn


def set_motion(motion):
    return lambda s: s["obstacles"][0].update(motion=motion)


@pytest.mark.parametrize("mutate, expected", [
    (lambda s: s.update(goal_tolerence={}), "unknown key 'goal_tolerence' (did you mean "
                                            "'goal_tolerance'?)"),
    (set_motion({"velocty": [0, 1]}), "did you mean 'velocity'?"),
    (set_motion({"velocity": [0, 1], "waypoints": [[0, 0, 0]]}), "exactly one of"),
    (set_motion({}), "exactly one of"),
    (set_motion({"waypoints": []}), "at least one"),
    (set_motion({"waypoints": [[0, 0, 0], [0, 1, 1]]}), "strictly increasing"),
    (set_motion({"waypoints": [[0, 0]]}), "[t, dx, dy]"),
    (lambda s: s["vehicle"].update(speed=0), "vehicle.speed"),
    (lambda s: s["vehicle"].update(speed=-1), "vehicle.speed"),
    (lambda s: s["vehicle"].update(max_speed=0.5), "max_speed"),
    (lambda s: s["obstacles"][0].update(radius=-1), "obstacles[0].radius"),
    (lambda s: s["obstacles"][0].update(type="circel"), "did you mean 'circle'?"),
    (lambda s: s.update(bounds=[0, 0, -1, 1]), "bounds"),
    (lambda s: s.update(start=[1, 2]), "start"),
])
def test_bad_scenarios_fail_with_one_clear_line(mutate, expected):
    with pytest.raises(planner.ScenarioError) as err:
        planner.parse_scenario(crossing_with(mutate))
    message = str(err.value)
    assert expected in message and "\n" not in message


def test_nan_is_rejected_in_files(tmp_path):
    path = tmp_path / "nan.json"
    path.write_text(json.dumps(scenario_dict("slalom")).replace('"radius": 0.3', '"radius": NaN', 1))
    with pytest.raises(planner.ScenarioError, match="NaN"):
        planner.load_scenario(path)


def test_rich_schema_boxes_and_waypoints_compile():
    scn = scenario_dict("open_field")
    scn["obstacles"] = [{"type": "box", "center": [10, 10], "size": [4, 1], "angle_deg": 45,
                         "motion": {"waypoints": [[0, 0, 0], [10, 2, 0]]}}]
    problem = planner.compile_problem(planner.parse_scenario(scn))
    assert problem.timed
    # The box's corner along its 45° axis is inside at t = 0, and 2 m further at t = 10.
    assert problem.clearance(10 + 1.9 * 0.7071, 10 + 1.9 * 0.7071, 0.0) < 0
    assert problem.clearance(12 + 1.9 * 0.7071, 10 + 1.9 * 0.7071, 10.0) < 0
    assert problem.clearance(10 + 1.9 * 0.7071, 10 + 1.9 * 0.7071, 10.0) > 0


def test_schema_is_json_schema_with_all_obstacle_types():
    schema = planner.scenario_schema()
    assert {"Circle", "Polygon", "Box", "Motion", "Vehicle"} <= set(schema["$defs"])


def test_the_independent_checker_knows_boxes():
    from checker import pose_valid

    scn = {"bounds": [0, 0, 10, 10], "vehicle": {"radius": 0.1},
           "obstacles": [{"type": "box", "center": [5, 5], "size": [4, 1], "angle_deg": 90}]}
    assert not pose_valid(scn, 5.0, 6.9, None)  # inside: the box stands upright
    assert pose_valid(scn, 6.9, 5.0, None)  # beside it, not along it
    problem = planner.compile_problem(planner.parse_scenario(
        {**scn, "name": "box", "start": [1, 1, 0], "goal": [9, 9, 0]}))
    for x, y in [(5.0, 6.9), (6.9, 5.0), (5.55, 5.0), (5.65, 5.0)]:
        assert pose_valid(scn, x, y, None) == (problem.clearance(x, y) > 0), (x, y)
