"""Lap mode of the simulated car (issue 9): laps counted on a closed track, lap times, collisions.

Independent checks: laps are recounted from the log as the angle the car sweeps around the
thesis track's centre (a convex loop), and collisions with tests/checker.py plus shapely for the
track region, with track-following movers placed from the track's own centreline — never with
the simulator's progress or clearance code.
"""

from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path

import numpy as np
import pytest
import shapely
from checker import pose_valid
from conftest import scenario_dict

import tracks
from planner.sim.laps import LapCounter

THESIS = tracks.load_library_track("thesis")
CENTRE = (2.366, -2.297)  # inside the thesis loop: the middle of its bounding box


def _cli(*args, timeout=900):  # generous: a loaded 2-core runner, cold kernel caches
    return subprocess.run(["trackstar", "simulate", *map(str, args)], check=False,
                          capture_output=True, text=True, timeout=timeout)


def _plain(tmp_path) -> Path:
    path = tmp_path / "thesis_plain.json"
    path.write_text(json.dumps({
        "name": "thesis-plain", "track": {"name": "thesis"},
        "vehicle": {"wheelbase": 0.44, "max_steer_deg": 26, "radius": 0.1, "speed": 1.0},
        "start": [2.373, -0.264, 3.14], "goal": [2.353, -4.33, 0.0]}))
    return path


def _sweeps(log: np.ndarray) -> np.ndarray:
    """Turns the car has swept around the loop's centre at each log row (unwrapped, signed)."""
    ang = np.unwrap(np.arctan2(log[:, 2] - CENTRE[1], log[:, 1] - CENTRE[0]))
    return (ang - ang[0]) / (2.0 * math.pi)


def _read_log(path: Path) -> tuple[list[str], np.ndarray]:
    header = path.read_text().splitlines()[0].split(",")
    return header, np.loadtxt(path, delimiter=",", skiprows=1)


# -- the counter on its own ----------------------------------------------------------------
def test_counter_counts_centreline_progress_in_both_directions():
    prof = THESIS.sample(spacing=0.1)
    pts = np.column_stack([prof.x, prof.y])[:-1]  # one lap, without the closing repeat
    for direction in (1, -1):
        path = np.vstack([pts[::direction]] * 3)[: int(2.5 * len(pts))]
        th = math.atan2(*(path[1] - path[0])[::-1])
        counter = LapCounter(THESIS, (*path[0], th), ahead=3.0)
        for k, (x, y) in enumerate(path):
            counter.update(0.1 * k, x, y)
        assert counter.laps == 2
        # Each lap ends when the car is back at its start: after one lap's worth of samples.
        assert counter.finished_at == pytest.approx([0.1 * len(pts), 0.2 * len(pts)], abs=0.11)
        assert counter.lap_times == pytest.approx([0.1 * len(pts)] * 2, abs=0.21)
        # Backing up loses progress: half a lap back and forth again does not count twice.
        back = path[::-1][: len(pts) // 2]
        for k, (x, y) in enumerate([*back, *back[::-1]]):
            counter.update(100.0 + 0.1 * k, x, y)
            if k == len(back) - 1:
                assert counter.progress == pytest.approx(2.0 * counter.length, abs=0.2)
        assert counter.laps == 2
        assert counter.progress == pytest.approx(2.5 * counter.length, abs=0.2)


def test_goals_lie_ahead_on_the_track_heading_along_the_lane():
    counter = LapCounter(THESIS, (2.373, -0.264, 3.14), ahead=3.0)
    outer, *holes = THESIS.region_rings()
    region = shapely.Polygon(outer, holes)
    goals = counter.goals()
    assert len(goals) == 15
    gx, gy, gth = goals[0]  # 3 m of arc ahead of the start: on the west side, heading south
    assert (gx, gy) == pytest.approx((0.334, -1.787), abs=0.03)
    assert math.cos(gth + math.pi / 2) > 0.99
    assert all(region.contains(shapely.Point(x, y)) for x, y, _ in goals)


# -- the command line ----------------------------------------------------------------------
def test_laps_are_counted_and_timed_on_the_thesis_track(tmp_path):
    """Two laps: the JSON's laps agree with the angle swept in the log, and each lap takes
    about the track's length over the cruise speed."""
    laps = 2
    log_path = tmp_path / "run.csv"
    r = _cli(_plain(tmp_path), "--laps", laps, "--seed", 3,
             "--fixed-latency", 100, "--json", "--log", log_path)
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["laps"] == laps and s["reached_goal"] and len(s["lap_times_s"]) == laps
    assert s["time_to_goal_s"] == pytest.approx(sum(s["lap_times_s"]), abs=1e-9)
    length = THESIS.length_m  # 14.0 m at 1 m/s; the car cuts corners a little, and starts at 0
    for lap in s["lap_times_s"]:
        assert 0.85 * length < lap < 1.25 * length
    assert s["parameters"]["laps"] == laps
    _, log = _read_log(log_path)
    sweeps = np.abs(_sweeps(log))
    assert sweeps[-1] == pytest.approx(laps, abs=0.02)  # ends as it comes round the last time
    first = round(s["lap_times_s"][0] * 100)
    assert sweeps[first] == pytest.approx(1.0, abs=0.02)
    assert s["collisions"] == 0


def _follow_offsets(ob: dict, track, times: np.ndarray) -> np.ndarray:
    """A follow_track motion as timed offsets, straight from the centreline (FORMAT-style)."""
    f = ob["motion"]["follow_track"]
    prof = track.sample(spacing=0.01)
    s = f.get("start_s", 0.0) + f["speed"] * np.minimum(times, f.get("horizon_s", 120.0))
    s = np.mod(s, prof.s[-1])
    s0 = np.mod(f.get("start_s", 0.0), prof.s[-1])
    return np.column_stack([times, np.interp(s, prof.s, prof.x) - np.interp(s0, prof.s, prof.x),
                            np.interp(s, prof.s, prof.y) - np.interp(s0, prof.s, prof.y)])


def _independent_collisions(scn: dict, log: np.ndarray) -> int:
    track = THESIS.with_width(scn["track"]["width_m"])
    outer, *holes = track.region_rings()
    region = shapely.Polygon(outer, holes)
    radius = scn["vehicle"]["radius"]
    times = log[:, 0]
    obstacles = []
    for ob in scn["obstacles"]:
        if ob["type"] == "box":
            (cx, cy), (w, h) = ob["center"], ob["size"]
            ob = {**ob, "type": "polygon",
                  "points": [(cx - w / 2, cy - h / 2), (cx + w / 2, cy - h / 2),
                             (cx + w / 2, cy + h / 2), (cx - w / 2, cy + h / 2)]}
        if ob.get("motion", {}).get("follow_track"):
            ob = {**ob, "motion": {"waypoints": _follow_offsets(ob, track, times).tolist()}}
        obstacles.append(ob)
    flat = {**scn, "bounds": [-1e3, -1e3, 1e3, 1e3], "obstacles": obstacles}
    hit = []
    for t, x, y in log[:, :3]:
        p = shapely.Point(x, y)
        on_track = region.contains(p) and region.boundary.distance(p) > radius
        hit.append(not (on_track and pose_valid(flat, x, y, t)))
    hit = np.array(hit)
    return int(np.count_nonzero(hit[1:] & ~hit[:-1]) + hit[0])


def test_lap_scene_collisions_recounted_independently(tmp_path):
    """The benchmark's lap scene (static boxes, movers ahead, oncoming and stopping): the car
    drives its lap untouched, and an independent check of the log agrees."""
    log_path = tmp_path / "run.csv"
    r = _cli("thesis_laps", "--laps", 1, "--seed", 1, "--fixed-latency", 20, "--json",
             "--log", log_path, "--duration", 40)
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    _, log = _read_log(log_path)
    scn = scenario_dict("thesis_laps")
    assert _independent_collisions(scn, log) == s["collisions"] == 0
    assert s["laps"] == 1


def test_laps_without_a_track_is_exit_2_with_one_line():
    r = _cli("crossing", "--laps", 2)
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0
    assert "--laps needs a scenario with a closed track" in r.stderr
    r = _cli("thesis_half_lap", "--laps", 0)
    assert r.returncode == 2 and "--laps: Input should be greater than or equal to 1" in r.stderr, r.stderr


def test_the_first_plan_is_not_a_replan():
    """Replanning off: one plan, which replaced nothing."""
    r = _cli("crossing", "--no-replan", "--duration", 5, "--fixed-latency", 20,
             "--json")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["cycles"] >= 1 and s["replans"] == 0


@pytest.mark.parametrize("bang_bang", ["dubins", "reeds-shepp"])
def test_a_continuous_curvature_lap_is_tracked_closer_than_a_bang_bang_one(tmp_path, bang_bang):
    """The thesis's PD feeds the plan's curvature forward as δ = atan(Lκ): a servo at
    max_steer_rate cannot follow a Dubins or Reeds-Shepp path's steps and the car drifts off
    (about 0.12 m, into a wall here for Dubins), while it follows a CC path's ramps (issue 36)."""
    cc = "cc-" + bang_bang
    worst = {}
    for steering in (bang_bang, cc):
        r = _cli(_plain(tmp_path), "--laps", 1, "--controller", "pd", "--seed", 0,
                 "--fixed-latency", 20, "--steering", steering, "--json")
        assert r.returncode == 0, r.stderr
        s = json.loads(r.stdout)
        assert s["parameters"]["steering"] == steering
        worst[steering] = s["cross_track_error_m"]["max"], s["collisions"], s["reached_goal"]
    assert worst[cc][0] < 0.5 * worst[bang_bang][0]
    assert worst[cc][1:] == (0, True)
