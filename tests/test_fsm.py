"""Behaviour state machines driving the simulated car (issue 9): sensors, states, transitions.

Each transition is checked against the log with the geometry of its small scene written out
here (where a wall or a post is, how far the car drove), not with the runtime's own numbers;
collisions of the bundled hallway example are recounted with tests/checker.py.
"""

from __future__ import annotations

import csv
import json
import math
import subprocess
from pathlib import Path

import numpy as np
import pytest
from checker import pose_valid
from conftest import scenario_dict

import planner
from planner._world import build_world
from planner.sim import SimSettings, simulate
from planner.sim.fsm import parse_fsm
from planner.sim.rangefinder import (
    cast,
    lane_ahead,
    scene_at,
    scene_of,
    ultrasonic,
    wall_estimate,
    wall_range,
)

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "fsm" / "hallway.json"
DT = 0.01
CONTRACT_COLUMNS = ["t", "x", "y", "theta", "v", "steer"]


def _scene(obstacles=(), start=(1.0, 3.0, 0.0), bounds=(0, 0, 30, 6), radius=0.1) -> dict:
    return {"name": "fsm-test", "bounds": list(bounds),
            "vehicle": {"wheelbase": 0.44, "max_steer_deg": 26.0, "radius": radius},
            "start": list(start), "goal": [bounds[2] - 1.0, start[1], 0.0],
            "obstacles": list(obstacles)}


def _drive(scn: dict, states: list, initial: str | None = None, duration: float = 30.0):
    machine = parse_fsm({"initial": initial or states[0]["id"], "states": states})
    return simulate(planner.parse_scenario(scn),
                    SimSettings(duration=duration, fixed_latency_ms=20.0), behaviour=machine)


def _states(run) -> list[str]:
    names = run.summary["behaviour"]["states"]
    return [names[int(i)] for i in run.log[:, run.columns.index("state")]]


def _first(run, name: str) -> int:
    """Row of the first tick driven by state ``name``."""
    return _states(run).index(name)


def _col(run, name: str) -> np.ndarray:
    return run.log[:, run.columns.index(name)]


def _driven(run) -> np.ndarray:
    """Metres driven up to each row's t: Σ|v|·Δt of the commands held before it."""
    return np.concatenate([[0.0], np.cumsum(np.abs(_col(run, "v")[:-1])) * DT])


def _state(sid, kind, params=None, transitions=()):
    return {"id": sid, "type": kind, "params": params or {}, "transitions": list(transitions)}


def _to(sid, kind, **params):
    return {"type": kind, "params": params, "to": sid}


STOP = _state("stop", "Stop")
AHEAD = {"point": [29.0, 3.0], "speed": 1.0, "tolerance_m": 0.2}  # straight down the scene


# -- sensors ---------------------------------------------------------------------------------
def test_rays_see_bounds_region_edges_obstacles_and_movers_where_they_are():
    world = build_world((0, 0, 20, 10), 0.1, [(6.0, 4.5, 0.5, 0)],
                        [(np.array([[2.0, 7.0], [4.0, 7.0], [4.0, 8.0], [2.0, 8.0]]), -1)],
                        [("velocity", (0.5, 0.0))],
                        rings=[np.array([[1.0, 1.0], [19.0, 1.0], [19.0, 9.0], [1.0, 9.0]])])
    scene, pose = scene_of(world), (3.0, 4.5, 0.0)
    segs, circ = scene_at(scene, world, 0.0)
    assert wall_range(segs, circ, pose, "left") == pytest.approx(2.5)  # the box's lower edge
    assert wall_range(segs, circ, pose, "right") == pytest.approx(3.5)  # the region's edge
    assert cast(segs, circ, 3.0, 4.5, [0.0])[0] == pytest.approx(2.5)  # the mover at t = 0
    segs2, circ2 = scene_at(scene, world, 2.0)
    assert cast(segs2, circ2, 3.0, 4.5, [0.0])[0] == pytest.approx(3.5)  # ... 1 m on at t = 2
    segs3, circ3 = scene_at(scene, world, 4.0)
    assert cast(segs3, circ3, 3.0, 4.5, [0.0])[0] == math.inf  # beyond the 4 m range
    assert cast(segs, circ, 3.0, 4.5, [math.pi], max_range=10.0)[0] == pytest.approx(2.0)
    assert wall_estimate(segs, circ, (3.0, 2.0, 0.3), "right") == pytest.approx((1.0, -0.3))
    assert wall_estimate(segs, circ, (3.0, 4.5, 0.3), "left") == pytest.approx((2.5, 0.3))
    bounds_only = build_world((0, 0, 20, 10), 0.1, [], [], [])
    segs, circ = scene_at(scene_of(bounds_only), bounds_only, 0.0)
    assert cast(segs, circ, 3.0, 4.5, [math.pi])[0] == pytest.approx(3.0)  # the bounds


def test_ultrasonic_cone_and_lane_see_off_axis_posts_a_single_ray_misses():
    bearing = math.radians(10.0)
    post = (3.0 + 2.0 * math.cos(bearing), 4.5 + 2.0 * math.sin(bearing), 0.05)
    world = build_world((0, 0, 20, 10), 0.1, [(*post, -1)], [], [])
    segs, circ = scene_at(scene_of(world), world, 0.0)
    pose = (3.0, 4.5, 0.0)
    assert cast(segs, circ, 3.0, 4.5, [0.0])[0] == math.inf
    assert ultrasonic(segs, circ, pose, "front") == pytest.approx(1.95)
    assert lane_ahead(segs, circ, pose, 0.2) == math.inf  # 0.35 m to the side: not in the lane
    assert lane_ahead(segs, circ, pose, 0.35) < 2.0


# -- transitions -----------------------------------------------------------------------------
def test_always_gives_a_state_exactly_one_tick():
    first = _state("a", "Idle", transitions=[_to("b", "Always"), _to("c", "Always")])
    run = _drive(_scene(), [first, _state("b", "Stop"), _state("c", "Stop")])
    assert _states(run) == ["a", "b"]  # the first listed transition wins; Stop at rest ends it
    assert run.summary["behaviour"]["transitions"] == [{"t": DT, "from": "a", "to": "b"}]
    assert run.summary["behaviour"]["final_state"] == "b"


def test_distance_fires_at_the_tick_the_state_has_driven_its_metres():
    run = _drive(_scene(), [
        _state("a", "ApproachPoint", AHEAD, [_to("stop", "Distance", meters=3.0)]), STOP])
    k, driven = _first(run, "stop"), _driven(run)
    assert driven[k] >= 3.0 > driven[k - 1]
    assert _col(run, "x")[k] - 1.0 == pytest.approx(driven[k], abs=1e-9)  # a straight line
    assert run.summary["behaviour"]["final_state"] == "stop" and _col(run, "v")[-1] == 0.0


def test_finished_fires_when_the_approached_point_is_within_tolerance():
    point = [6.0, 4.0]
    run = _drive(_scene(), [_state("a", "ApproachPoint", {"point": point, "speed": 0.8,
                                                          "tolerance_m": 0.3},
                                   [_to("stop", "Finished")]), STOP])
    k = _first(run, "stop")
    gap = np.hypot(_col(run, "x") - point[0], _col(run, "y") - point[1])
    assert gap[k] <= 0.3 < gap[k - 1] and gap[:k].min() > 0.3
    assert run.summary["collisions"] == 0


def test_sensor_level_below_fires_before_a_wall_ahead():
    wall = {"type": "polygon", "points": [[10, 0], [11, 0], [11, 6], [10, 6]]}
    run = _drive(_scene([wall]), [
        _state("a", "ApproachPoint", AHEAD,
               [_to("stop", "SensorLevel", sensor="front", below_m=2.5)]), STOP])
    k = _first(run, "stop")
    ahead = 10.0 - _col(run, "x")  # the wall face is perpendicular: the shortest echo
    assert ahead[k] < 2.5 <= ahead[k - 1]
    assert run.summary["collisions"] == 0 and _col(run, "v")[-1] == 0.0
    assert _col(run, "x")[-1] < 10.0 - 0.1


def test_sensor_level_above_sees_a_mover_where_it_is_at_t():
    """A post drives away from a waiting car at 0.5 m/s: front reads 1.5 + 0.5·t (m)."""
    post = {"type": "circle", "center": [3.0, 3.0], "radius": 0.5,
            "motion": {"velocity": [0.5, 0.0]}}
    run = _drive(_scene([post]), [
        _state("wait", "Idle", transitions=[_to("stop", "SensorLevel", sensor="front",
                                               above_m=2.0)]), STOP])
    k = _first(run, "stop")
    t = _col(run, "t")
    front = 3.0 + 0.5 * t - 0.5 - 1.0
    assert front[k] > 2.0 >= front[k - 1]
    assert t[k] == pytest.approx(1.0, abs=1.5 * DT)


@pytest.mark.parametrize("lateral, fires", [(0.1, True), (0.3, False)])
def test_obstacle_ahead_fires_for_a_post_in_the_lane_only(lateral, fires):
    """Car radius 0.1 m: its lane is ±0.2 m. A post of 5 cm at 0.1 m stops it; one at 0.3 m
    is passed (though the front ultrasonic cone sees it), and Distance ends the run."""
    post = {"type": "circle", "center": [6.0, 3.0 + lateral], "radius": 0.05}
    run = _drive(_scene([post]), [
        _state("a", "ApproachPoint", AHEAD, [_to("stop", "ObstacleAhead", within_m=1.0),
                                             _to("stop", "Distance", meters=8.0)]), STOP])
    k = _first(run, "stop")
    x = _col(run, "x")
    if fires:
        free = 5.95 - x  # the lane ray at 0.1 m meets the post's face
        assert free[k] <= 1.0 < free[k - 1]
    else:
        assert _driven(run)[k] >= 8.0 > _driven(run)[k - 1] and x[k] > 6.0
        world = planner.compile_problem(planner.parse_scenario(_scene([post]))).world
        segs, circ = scene_at(scene_of(world), world, 0.0)
        near = min(ultrasonic(segs, circ, tuple(row), "front") for row in run.log[:k, 1:4])
        assert near < 1.0
    assert run.summary["collisions"] == 0


# -- states ----------------------------------------------------------------------------------
@pytest.mark.parametrize("side", ["left", "right"])
def test_follow_wall_holds_its_distance_on_a_straight_wall(side):
    """The scene's bounds are the walls (y = 0 on the right, y = 6 on the left); the car
    starts 0.3 m too far from the wall and must settle within 2 cm."""
    wall_y = 0.0 if side == "right" else 6.0
    start_y = 1.3 if side == "right" else 6.0 - 1.3
    run = _drive(_scene(start=(1.0, start_y, 0.0)), [
        _state("a", "FollowWall", {"side": side, "distance_m": 1.0, "speed": 1.0},
               [_to("stop", "Distance", meters=20.0)]), STOP])
    gap = np.abs(_col(run, "y") - wall_y)
    driven = _driven(run)
    assert gap[0] == pytest.approx(1.3)
    settled = (driven > 8.0) & (np.array(_states(run)) == "a")
    assert np.abs(gap[settled] - 1.0).max() < 0.02
    assert np.abs(_col(run, "theta")[settled]).max() < 0.05


def test_follow_wall_ramp_moves_its_clearance_linearly_then_finishes():
    ramp = {"side": "right", "from_m": 0.6, "to_m": 1.2, "over_m": 4.0, "speed": 0.8}
    run = _drive(_scene(start=(1.0, 0.6, 0.0)), [
        _state("ramp", "FollowWallRamp", ramp, [_to("hold", "Finished")]),
        _state("hold", "FollowWall", {"side": "right", "distance_m": 1.2, "speed": 0.8},
               [_to("stop", "Distance", meters=6.0)]), STOP])
    driven, y = _driven(run), _col(run, "y")
    k = _first(run, "hold")
    assert driven[k] >= 4.0 > driven[k - 1]  # Finished once the ramp's metres are driven
    mid = (driven > 1.5) & (driven < 4.0)
    want = 0.6 + 0.15 * driven[mid]
    assert np.abs(y[mid] - want).max() < 0.05
    slope = np.polyfit(driven[mid], y[mid], 1)[0]
    assert slope == pytest.approx(0.15, rel=0.15)
    end = driven > 8.0
    assert np.abs(y[end] - 1.2).max() < 0.02


def test_nested_machine_finishes_when_it_reaches_its_stop():
    inner = {"id": "inner", "type": "StateMachine", "initial": "go", "states": [
        _state("go", "ApproachPoint", AHEAD, [_to("done", "Distance", meters=3.0)]),
        _state("done", "Stop")], "transitions": [_to("after", "Finished")]}
    run = _drive(_scene(), [inner,
                            _state("after", "ApproachPoint", AHEAD,
                                   [_to("halt", "Distance", meters=2.0)]),
                            _state("halt", "Stop")])
    tr = run.summary["behaviour"]["transitions"]
    assert [(x["from"], x["to"]) for x in tr] == [("inner/go", "inner/done"),
                                                  ("inner", "after"), ("after", "halt")]
    assert tr[0]["t"] == tr[1]["t"]  # the outer machine sees its Stop on the same tick
    names = _states(run)
    assert "inner/done" not in names  # so the nested Stop never brakes the car
    k = names.index("after")
    assert _col(run, "v")[k] == pytest.approx(1.0)
    assert run.summary["behaviour"]["final_state"] == "halt" and _col(run, "v")[-1] == 0.0


def test_follow_track_hands_over_to_the_replanner_which_reaches_the_goal():
    """Drive 1.5 m by hand, then FollowTrack: the replanner starts from where the car is,
    plans round a post and reaches the goal at no more than the state's speed."""
    post = {"type": "circle", "center": [6.0, 3.0], "radius": 0.5}
    scn = _scene([post], bounds=(0, 0, 12, 6))
    run = _drive(scn, [_state("manual", "ApproachPoint", AHEAD,
                              [_to("track", "Distance", meters=1.5)]),
                       _state("track", "FollowTrack", {"speed": 0.7})])
    s = run.summary
    assert s["reached_goal"] and s["collisions"] == 0 and s["cycles"] > 0
    k = _first(run, "track")
    assert min(c["t"] for c in run.cycles) >= _col(run, "t")[k]  # no planning before it
    v = _col(run, "v")
    assert v[k - 1] == pytest.approx(1.0)
    assert v[k + 31:].max() <= 0.7 + 1e-12  # after braking from 1 m/s at 1 m/s²
    assert s["min_clearance_m"] > 0


# -- the bundled example and the command line ------------------------------------------------
def test_hallway_example_reaches_the_goal_without_touching_anything():
    scn = scenario_dict("hallway")
    run = simulate(planner.load_scenario("hallway"),
                   SimSettings(duration=60.0, fixed_latency_ms=20.0),
                   behaviour=parse_fsm(json.loads(EXAMPLE.read_text())))
    s = run.summary
    assert s["reached_goal"] and s["collisions"] == 0
    hit = np.array([not pose_valid(scn, x, y, t) for t, x, y in run.log[:, :3]])
    assert not hit.any()
    gx, gy, _ = scn["goal"]
    assert math.hypot(run.log[-1, 1] - gx, run.log[-1, 2] - gy) <= 0.25
    visited = [tr["to"] for tr in s["behaviour"]["transitions"]]
    assert visited[-1] == "to_goal" and "past_the_column/ramp_out" in visited


def _cli(*args, timeout=120):
    return subprocess.run(["trackstar", "simulate", *map(str, args)], check=False,
                          capture_output=True, text=True, timeout=timeout)


def test_cli_drives_by_the_machine_and_logs_the_state(tmp_path):
    log = tmp_path / "run.csv"
    r = _cli("hallway", "--behaviour", EXAMPLE, "--fixed-latency", 20,
             "--json", "--log", log)
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    for key in ("reached_goal", "time_to_goal_s", "duration_s", "collisions", "min_clearance_m",
                "cycles", "replans", "cycle_ms", "share_30hz", "share_4hz", "emergency_stops",
                "cross_track_error_m", "distance_m", "parameters"):
        assert key in s
    assert s["reached_goal"] and s["collisions"] == 0
    b = s["behaviour"]
    assert b["final_state"] == "to_goal" and all({"t", "from", "to"} == set(x)
                                                 for x in b["transitions"])
    rows = list(csv.reader(log.read_text().splitlines()))
    assert rows[0][:6] == CONTRACT_COLUMNS and rows[0][-1] == "state"
    states = [b["states"][int(float(row[-1]))] for row in rows[1:]]
    assert states[0] == "corridor_1" and states[-1] == "to_goal"
    assert float(rows[-1][0]) == s["time_to_goal_s"]


@pytest.mark.parametrize("content, needle", [
    ("{not json", "not JSON"),
    (None, "No such file"),
    (('{"initial": "a", "states": [{"id": "a", "type": "FollowWall", '
      '"params": {"side": "up", "distance_m": 1, "speed": 1}}]}'), "states[0].params.side"),
])
def test_cli_rejects_a_bad_machine_in_one_line(tmp_path, content, needle):
    path = tmp_path / "fsm.json"
    if content is not None:
        path.write_text(content)
    r = _cli("hallway", "--behaviour", path, "--json", timeout=30)
    assert r.returncode == 2 and r.stdout == ""
    assert len(r.stderr.strip().splitlines()) == 1 and needle in r.stderr, r.stderr
