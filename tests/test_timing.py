"""Time-optimal planning (``timing: optimal``): waits for movers, docs/scenario-format.md v1.3
rows checked by the independent checker, never later than the constant-speed plan of the same
trees."""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest
from checker import arc_mismatch, first_collision, schedule_errors
from conftest import scenario_dict
from hypothesis import given, settings
from hypothesis import strategies as st

import planner


def assert_valid_v13(scn: dict, path, rounded: bool = False) -> None:
    """Speed, spacing and validity in space-time, sampled every 5 mm and every 5 ms; each gap
    one arc (not checked on JSON's rounded rows: a wait 0.1 mm from a row turns 1e-6 of
    rounding into a heading error; their speeds get the rounding's 1e-6 m each way)."""
    path = np.asarray(path, dtype=float)
    vehicle = scn["vehicle"]
    vmax = vehicle.get("max_speed", vehicle.get("speed", 1.0))
    assert schedule_errors(path, vmax, rounding=1e-6 if rounded else 0.0) == []
    assert first_collision(scn, path) is None
    assert rounded or arc_mismatch(path) < 1e-6


def test_the_train_is_waited_for_from_the_command_line():
    """The level crossing: the car cannot cross before the train nor go round it. The best
    possible arrival is 21.08 s: the train clears the gap for a 0.2 m car (y ≥ 3.4) at
    t = 15.6 s, and from the train's side (x = 7.8) to the goal region is 10.95 m at 2 m/s."""
    out = subprocess.run(["trackstar", "plan", "train", "--timing", "optimal", "--time", "3",
                          "--json"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout)
    assert report["solved"] and report["objective"] == "time"
    assert 21.08 <= report["cost"] == report["arrival_time_s"] <= 1.15 * 21.08
    assert report["waited_s"] > 10.0 and report["length_m"] < 19.0
    assert report["parameters"]["timing"] == "optimal"
    assert_valid_v13(scenario_dict("train"), report["path"], rounded=True)
    path = np.asarray(report["path"])
    assert np.interp(15.0, path[:, 3], path[:, 0]) < 7.8  # waiting beside the rails


def test_waiting_beats_the_constant_plan_of_the_same_seed():
    """The gate opens at t = 10–11 s; the constant plan must lose time in a loop. The best
    possible arrival is above 14.86 s: the gap lets a 0.2 m car through (y ≥ 4.4) once the
    door has risen 0.5 m, at t = 10.23 s, when the car is at x ≤ 9.5, 9.25 m from the goal
    at 2 m/s."""
    for name, best_possible in (("gate", 14.86), ("train", 21.08)):
        constant = planner.solve(name, time_limit=None, iterations=3000, seed=3)
        optimal = planner.solve(name, time_limit=None, iterations=3000, seed=3,
                                timing="optimal")
        assert optimal.solved and optimal.objective == "time" and constant.objective == "length"
        assert best_possible <= optimal.cost <= 1.15 * best_possible
        assert not constant.solved or optimal.cost < constant.arrival_time_s, name
        assert optimal.min_clearance_m > 0
        assert_valid_v13(scenario_dict(name), optimal.path[:, [0, 1, 2, 5]])


def test_without_movers_it_is_the_shortest_path_at_top_speed():
    scn = scenario_dict("slalom")
    scn["vehicle"]["max_speed"] = 2.0
    result = planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=1500,
                           timing="optimal")
    assert result.waited_s == 0.0 and result.timed
    assert math.isclose(result.cost, result.length_m / 2.0, rel_tol=1e-9)
    assert_valid_v13(scn, result.path[:, [0, 1, 2, 5]])


MOVER = st.tuples(st.floats(3, 13), st.floats(0.3, 1.2), st.floats(-1.0, 1.0), st.floats(0.1, 3))


@settings(max_examples=8, deadline=None)
@given(movers=st.lists(MOVER, min_size=1, max_size=3), seed=st.integers(0, 2**16))
def test_optimal_plans_are_valid_and_never_later_than_constant(movers, seed):
    """Random discs crossing a 16 x 8 m lane. With an iteration budget both runs grow the same
    trees, so 'planning noise' is zero: the optimal plan never arrives later."""
    scn = {"name": "random-crossings", "bounds": [0, 0, 16, 8],
           "vehicle": {"radius": 0.2, "speed": 1.0, "max_speed": 1.5},
           "start": [1, 4, 0], "goal": [15, 4, 0],
           "obstacles": [{"type": "circle", "center": [x, -r if v > 0 else 8 + r], "radius": r,
                          "motion": {"velocity": [0.2 * v, math.copysign(speed, v)]}}
                         for x, r, v, speed in movers]}
    constant = planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=800,
                             seed=seed)
    optimal = planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=800,
                            seed=seed, timing="optimal")
    if constant.solved:
        assert optimal.solved and optimal.cost <= constant.arrival_time_s + 1e-9
    if optimal.solved:
        assert_valid_v13(scn, optimal.path[:, [0, 1, 2, 5]])


def test_a_crawl_that_needs_too_many_entries_is_refused_naming_max_speed():
    scn = scenario_dict("slalom")
    scn["vehicle"].update(speed=0.001, max_speed=0.001)  # 0.1 mm apart over 23 m
    with pytest.raises(planner.ScenarioError, match="vehicle.max_speed: 0.001 m/s"):
        planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=1000,
                      timing="optimal")
