"""Moving obstacles (docs/scenario-format.md v1.1): offsets, space-time planning, timed paths."""

import math

import numpy as np
import pytest
from checker import first_collision, obstacle_offset
from conftest import scenario_dict
from hypothesis import given, settings
from hypothesis import strategies as st

import planner
from planner._world import build_world, offset


def straight_line(scn, speed, step=0.01):
    (x0, y0, _), (x1, y1, _) = scn["start"], scn["goal"]
    n = int(math.hypot(x1 - x0, y1 - y0) / step)
    s = np.linspace(0, 1, n + 1)
    length = math.hypot(x1 - x0, y1 - y0)
    return np.column_stack([x0 + s * (x1 - x0), y0 + s * (y1 - y0), np.zeros_like(s),
                            s * length / speed])


def plan(scn, iterations=3000, seed=0, steering="dubins"):
    return planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=iterations,
                         seed=seed, steering=steering)


def test_crossing_straight_line_first_touches_the_disc_at_8_s():
    scn = scenario_dict("crossing")
    s = first_collision(scn, straight_line(scn, 1.0), step=0.001)
    assert s == pytest.approx(8.0, abs=0.05)  # at 1 m/s, metres driven = seconds


def test_crossing_is_planned_around_the_disc_in_space_time():
    scn = scenario_dict("crossing")
    result = plan(scn)
    assert result.solved
    path = result.path[:, [0, 1, 2, 5]]
    assert first_collision(scn, path) is None
    # Times are the driven length over the speed (docs/scenario-format.md: within 1 % + 0.02 s).
    driven = np.concatenate([[0], np.cumsum(np.hypot(*np.diff(path[:, :2], axis=0).T))])
    assert np.all(np.abs(path[:, 3] - driven) <= 0.01 * driven + 0.02)
    assert path[-1, 3] == pytest.approx(result.cost, rel=1e-3)


def test_a_plan_with_obstacles_frozen_at_t0_is_caught():
    scn = scenario_dict("crossing")
    frozen = {**scn, "obstacles": [{k: v for k, v in ob.items() if k != "motion"}
                                   for ob in scn["obstacles"]]}
    result = plan(frozen)
    assert result.solved
    timed = np.column_stack([result.path[:, :3], result.path[:, 5]])
    assert first_collision(scn, timed) is not None


def test_at_2_m_per_s_the_straight_line_is_free_and_the_plan_uses_it():
    fast = scenario_dict("crossing")
    fast["vehicle"]["speed"] = 2.0
    assert first_collision(fast, straight_line(fast, 2.0), step=0.001) is None
    slow_cost = plan(scenario_dict("crossing"), seed=1).cost
    result = plan(fast, seed=1)
    assert result.solved
    assert first_collision(fast, result.path[:, [0, 1, 2, 5]]) is None
    assert result.path[-1, 5] == pytest.approx(result.cost / 2.0, rel=1e-3)
    assert result.cost < slow_cost  # free to drive (nearly) straight


waypoint_lists = st.lists(
    st.tuples(st.floats(0.01, 5), st.floats(-5, 5), st.floats(-5, 5)), min_size=1, max_size=6,
).map(lambda rows: np.column_stack([np.cumsum([r[0] for r in rows]) - 1.0,
                                    [r[1] for r in rows], [r[2] for r in rows]]))


@settings(max_examples=150, deadline=None)
@given(waypoint_lists, st.floats(-10, 40))
def test_waypoint_offset_matches_linear_interpolation_with_clamping(wp, t):
    world = build_world((0, 0, 1, 1), 0.0, [(0.5, 0.5, 0.1, 0)], [], [("waypoints", wp)])
    ob = {"motion": {"waypoints": wp.tolist()}}
    assert offset(world, 0, t) == pytest.approx(obstacle_offset(ob, t), abs=1e-9)
    if t <= wp[0, 0]:
        assert offset(world, 0, t) == pytest.approx(tuple(wp[0, 1:]), abs=1e-12)
    if t >= wp[-1, 0]:
        assert offset(world, 0, t) == pytest.approx(tuple(wp[-1, 1:]), abs=1e-12)


@settings(max_examples=50, deadline=None)
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(-100, 100))
def test_velocity_offset_is_linear_in_time(vx, vy, t):
    world = build_world((0, 0, 1, 1), 0.0, [(0.5, 0.5, 0.1, 0)], [], [("velocity", (vx, vy))])
    assert offset(world, 0, t) == pytest.approx((vx * t, vy * t), abs=1e-9)


def test_obstacles_starting_outside_the_bounds_are_valid_input():
    scn = scenario_dict("crossing")
    # A triangle enters from the right, crosses the lane downwards and leaves the bounds.
    scn["obstacles"].append({"type": "polygon", "points": [[30, 8], [31, 8], [31, 9]],
                             "motion": {"waypoints": [[0, 0, 0], [6, -20, 0], [10, -20, -20]]}})
    result = plan(scn, iterations=2000)
    assert result.solved
    assert first_collision(scn, result.path[:, [0, 1, 2, 5]]) is None


movers = st.lists(st.tuples(st.floats(3, 17), st.floats(1, 9), st.floats(0.3, 1.2),
                            st.floats(-1, 1), st.floats(-1, 1)), min_size=1, max_size=4)


@settings(max_examples=12, deadline=None)
@given(movers, st.integers(0, 1000), st.sampled_from(["dubins", "cc-dubins", "cc-reeds-shepp"]))
def test_random_moving_scenarios_give_paths_valid_in_space_time(obs, seed, steering):
    scn = {"name": "random", "bounds": [0, 0, 20, 10],
           "vehicle": {"wheelbase": 0.44, "max_steer_deg": 26, "radius": 0.2, "speed": 1.5},
           "start": [1, 5, 0], "goal": [19, 5, 0], "obstacles": []}
    for cx, cy, r, vx, vy in obs:
        if math.hypot(cx - 1, cy - 5) < r + 0.5:
            continue
        scn["obstacles"].append({"type": "circle", "center": [cx, cy], "radius": r,
                                 "motion": {"velocity": [vx, vy]}})
    result = plan(scn, iterations=1500, seed=seed, steering=steering)
    if result.solved:
        assert first_collision(scn, result.path[:, [0, 1, 2, 5]]) is None
