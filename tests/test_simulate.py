"""The simulated car (issue 9): kinematics, limits, tracking, replanning among movers, the CLI.

Independent checks: the log is replayed with the exact-arc formula written out here, limits are
re-derived from the log, and collisions are recounted with tests/checker.py (plain numpy from
docs/scenario-format.md), never with the simulator's own clearance code.
"""

from __future__ import annotations

import csv
import io
import itertools
import json
import math
import subprocess
from pathlib import Path

import numpy as np
import pytest
from checker import obstacle_offset, pose_valid
from conftest import scenario_dict
from hypothesis import given, settings
from hypothesis import strategies as st

import planner
from planner.sim import SimSettings, simulate
from planner.sim.control import CONTROLLERS, Reference, Tracking, steer_command
from planner.sim.metrics import collision_runs
from planner.sim.vehicle import Limits, arc_step, limit_commands

FIXED = {"fixed_latency_ms": 20.0}


def _run(source: str | Path, **kw):
    """A simulated run of a scenario file or bundled name, with the scenario's JSON object."""
    scn = planner.load_scenario(source)
    raw = json.loads(Path(source).read_text()) if Path(source).is_file() else scenario_dict(source)
    return raw, simulate(scn, SimSettings(**{**FIXED, **kw}))


def _replay_error(log: np.ndarray, wheelbase: float, dt: float) -> float:
    """Largest position/heading mismatch of each row against the exact arc from the row before."""
    x, y, th, v, d = (log[:-1, i] for i in range(1, 6))
    dth = v * dt * np.tan(d) / wheelbase
    th2 = th + dth
    # The formula; for tiny |δ| it cancels badly, and below 1e-6 the straight step is
    # within v²·dt²·tan δ / 2L < 1e-10 m of the arc.
    curved = np.abs(d) > 1e-6
    with np.errstate(divide="ignore", invalid="ignore"):
        r = wheelbase / np.tan(d)
        x2 = np.where(curved, x + r * (np.sin(th2) - np.sin(th)), x + v * dt * np.cos(th))
        y2 = np.where(curved, y - r * (np.cos(th2) - np.cos(th)), y + v * dt * np.sin(th))
    return float(np.max(np.abs(np.column_stack([x2, y2, th2]) - log[1:, 1:4]), initial=0.0))


def _as_polygons(scn: dict) -> dict:
    """Boxes written out as their corner polygons (docs/scenario-format.md: centre, size,
    angle_deg)."""
    out = []
    for ob in scn["obstacles"]:
        if ob["type"] == "box":
            (cx, cy), (w, h) = ob["center"], ob["size"]
            a = math.radians(ob.get("angle_deg", 0.0))
            pts = [(cx + math.cos(a) * u - math.sin(a) * v, cy + math.sin(a) * u + math.cos(a) * v)
                   for u, v in ((-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2))]
            ob = {**ob, "type": "polygon", "points": pts}
        out.append(ob)
    return {**scn, "obstacles": out}


def _independent_collisions(scn: dict, log: np.ndarray) -> int:
    scn = _as_polygons(scn)
    hit = np.array([not pose_valid(scn, row[1], row[2], row[0]) for row in log])
    return int(np.count_nonzero(hit[1:] & ~hit[:-1]) + hit[0])


# -- kinematics ----------------------------------------------------------------------------
@settings(max_examples=200, deadline=None)
@given(th=st.floats(-math.pi, math.pi), v=st.floats(-3, 3), d=st.floats(-0.6, 0.6),
       dt=st.floats(0.001, 0.1))
def test_two_half_steps_are_one_step(th, v, d, dt):
    """Holding (v, δ) is one circle: two steps of dt/2 land where one step of dt does."""
    one = arc_step(0.3, -0.2, th, v, d, 0.44, dt)
    half = arc_step(0.3, -0.2, th, v, d, 0.44, dt / 2)
    two = arc_step(*half, v, d, 0.44, dt / 2)
    assert np.allclose(one, two, atol=1e-9)
    assert math.hypot(one[0] - 0.3, one[1] + 0.2) <= abs(v) * dt + 1e-12  # chord ≤ arc


@settings(max_examples=100, deadline=None)
@given(th=st.floats(-math.pi, math.pi), v=st.floats(0.1, 3), d=st.floats(1e-7, 1e-5))
def test_arc_tends_to_the_straight_line(th, v, d):
    bent = arc_step(0.0, 0.0, th, v, d, 0.44, 0.05)
    straight = arc_step(0.0, 0.0, th, v, 0.0, 0.44, 0.05)
    assert np.allclose(bent, straight, atol=1e-5)


@settings(max_examples=200, deadline=None)
@given(vp=st.floats(-2, 2), sp=st.floats(-0.4, 0.4), vw=st.floats(-9, 9), sw=st.floats(-3, 3))
def test_limits_clamp_every_command(vp, sp, vw, sw):
    lim = Limits(0.44, 0.45, 1.0, 2.0, 1.5)
    v, s = limit_commands(vp, sp, vw, sw, lim, 0.01)
    assert abs(s) <= 0.45 and abs(s - sp) <= 0.01 + 1e-12
    assert abs(v) <= 2.0 and abs(v - vp) <= 0.015 + 1e-12
    if abs(vw) <= 2.0 and abs(vw - vp) <= 0.015 and abs(sw) <= 0.45 and abs(sw - sp) <= 0.01:
        assert (v, s) == (vw, sw)  # feasible commands pass unchanged


def test_collision_runs_counts_contacts():
    assert collision_runs(np.array([1, 0, -1, 1, 1, 0.0, 2, -3])) == 3
    assert collision_runs(np.array([-1, 1, 0])) == 2
    assert collision_runs(np.array([1.0, 2.0])) == 0


# -- tracking ------------------------------------------------------------------------------
def _round_a_circle(name: str, gear: float) -> Reference:
    """Two laps of a 2 m circle (the steering left), forward (gear 1) or reversing (-1, so the
    car turns right), from 0.3 m off it, within the limits: the error settles."""
    radius, L, dt = 2.0, 0.44, 0.01
    a = np.linspace(0, 4 * math.pi, 4000)
    rows = np.column_stack([gear * radius * np.sin(a), radius * (1 - np.cos(a)), gear * a,
                            np.full_like(a, 1 / radius), np.full_like(a, gear)])
    ref = Reference(rows)
    assert ref.direction == gear and len(ref.signs) == 1
    lim = Limits(L, math.radians(30), math.radians(180), 1.0, 1.0)
    x, y, th, v, s, e_old, errs = 0.0, -0.3, 0.0, 0.0, 0.0, math.nan, []
    for _ in range(2000):
        i, e = ref.project(x, y)
        want = steer_command(name, ref, i, e, e_old, (x, y, th), v, L, dt, Tracking())
        v, s = limit_commands(v, s, gear, want, lim, dt)
        x, y, th = arc_step(x, y, th, v, s, L, dt)
        e_old = e
        errs.append(math.hypot(x, y - radius) - radius)
    errs = np.abs(errs)
    assert errs[:100].max() > 0.2  # it did start off the path
    assert errs[1000:].max() < 0.05, errs[1000:].max()
    return ref


@pytest.mark.parametrize("name", CONTROLLERS)
def test_controllers_follow_a_circle(name):
    _round_a_circle(name, 1.0)


@pytest.mark.parametrize("name", CONTROLLERS)
def test_controllers_back_along_a_circle(name):
    """Reversing, each controller steers the mirror car, and the error settles as forward."""
    ref = _round_a_circle(name, -1.0)
    assert ref.s[ref.cursor] > 9.0  # it went round, backwards


@pytest.mark.parametrize("name", CONTROLLERS)
def test_the_guards_rollout_is_the_car_the_simulator_drives(name):
    """The guard foresees the car by rolling the compiled controller out (`Tracker.rollout`):
    tick for tick it is the simulator's own loop (projection, steering law, actuator limits,
    exact arc), from 0.3 m off a circle with the steering at the other lock."""
    from planner.sim.control import Tracker

    radius, L, dt, sub = 2.0, 0.44, 0.01, 2
    a = np.linspace(0, 2 * math.pi, 2000)
    rows = np.column_stack([radius * np.sin(a), radius * (1 - np.cos(a)), a,
                            np.full_like(a, 1 / radius), np.ones_like(a)])
    lim = Limits(L, math.radians(30), math.radians(180), 1.0, 1.0)
    vs = np.minimum(np.arange(150) * lim.max_accel * dt * sub, 1.0)
    state = (0.0, -0.3, 0.0, 0.0, -lim.max_steer)
    poses = Tracker(name).rollout(Reference(rows), state, vs, np.zeros(len(vs), np.int64), lim,
                                  dt * sub)
    ref = Reference(rows)
    x, y, th, _, s = state
    e_old, mine = math.nan, [(x, y, th)]
    for k in range(len(vs) - 1):
        for j in range(sub):
            v_was, v_now = (vs[k] + (vs[k + 1] - vs[k]) * f / sub for f in (j, j + 1))
            i, e = ref.project(x, y)
            want = steer_command(name, ref, i, e, e_old, (x, y, th), v_was, L, dt, Tracking())
            v, s = limit_commands(v_was, s, v_now, want, lim, dt)
            assert v == pytest.approx(v_now, abs=1e-12)  # the speeds are the car's
            x, y, th = arc_step(x, y, th, v_now, s, L, dt)
            e_old = e
        mine.append((x, y, th))
    assert np.allclose(poses, mine, rtol=0.0, atol=1e-9)
    assert abs(math.hypot(x, y - radius) - radius) < 0.05  # and it did get onto the circle


def test_a_cusp_is_passed_at_rest_only():
    """Forward 1 m, then back 1 m along a line: the projection keeps to the stretch the car is
    on (the rows of both lie on top of each other) and goes on to the next only at rest."""
    x = np.concatenate([np.linspace(0, 1, 21), np.linspace(1, 0, 21)[1:]])
    dirs = np.concatenate([np.ones(21), -np.ones(20)])
    ref = Reference(np.column_stack([x, np.zeros((len(x), 3)), dirs]))
    assert ref.signs.tolist() == [1.0, -1.0] and ref.stretch_end == pytest.approx(1.0)
    i, _ = ref.project(0.3, 0.0)
    assert (i, ref.direction) == (6, 1.0)
    ref.project(0.8, 0.0)
    assert not ref.advance(0.0)  # standing 0.2 m before the cusp
    ref.project(1.0, 0.0)
    assert not ref.advance(0.2) and ref.direction == 1.0  # still rolling forward
    assert ref.advance(0.0) and ref.direction == -1.0 and ref.stretch_end == pytest.approx(2.0)
    i, _ = ref.project(0.7, 0.0)  # on the way back: the row of the second stretch
    assert i == 26 and ref.s[i] == pytest.approx(1.3)
    ref.project(0.0, 0.0)  # the end of the last stretch
    assert not ref.advance(0.0) and ref.direction == -1.0


def test_a_reversing_car_parks_backing_into_the_slot():
    """Reeds-Shepp plans are driven as planned: forward and reverse stretches, at rest at each
    cusp, tracked to a few centimetres, without a contact (recounted independently)."""
    scn, run = _run("parking", duration=30.0, seed=0, steering="reeds-shepp")
    s, v = run.summary, run.log[:, 4]
    assert s["reached_goal"] and s["collisions"] == 0 and _independent_collisions(scn, run.log) == 0
    assert (v < -0.5).sum() > 100 and (v > 0.5).sum() > 100  # it drove both ways
    assert s["cross_track_error_m"]["max"] < 0.06
    assert _replay_error(run.log, 0.44, 0.01) < 1e-8


# -- whole runs ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def crossing_run():
    return _run("crossing", duration=25.0, seed=1)


def test_crossing_obstacle_is_avoided(crossing_run):
    scn, run = crossing_run
    s = run.summary
    assert s["reached_goal"] and s["collisions"] == 0 and s["min_clearance_m"] > 0
    assert _independent_collisions(scn, run.log) == 0
    gx, gy, gth = scn["goal"]
    x, y, th = run.log[-1, 1:4]
    assert math.hypot(x - gx, y - gy) <= 0.25 and s["time_to_goal_s"] == run.log[-1, 0]
    assert abs(math.remainder(th - gth, 2 * math.pi)) <= math.radians(20)


def test_log_replays_and_respects_the_limits(crossing_run):
    scn, run = crossing_run
    log, cols = run.log, run.columns
    assert cols[:6] == ["t", "x", "y", "theta", "v", "steer"] and cols[6:8] == ["obs0_dx", "obs0_dy"]
    dt = 0.01
    assert np.allclose(log[:, 0], np.arange(len(log)) * dt)
    assert _replay_error(log, 0.44, dt) < 1e-8
    lim = Limits.of(planner.load_scenario("crossing").vehicle)
    v = np.concatenate([[0.0], log[:, 4]])
    d = np.concatenate([[0.0], log[:, 5]])
    assert np.abs(d).max() <= lim.max_steer + 1e-12
    assert np.abs(np.diff(d)).max() <= lim.max_steer_rate * dt + 1e-12
    assert np.abs(v).max() <= lim.max_speed + 1e-12
    assert np.abs(np.diff(v)).max() <= lim.max_accel * dt + 1e-12
    ob = scn["obstacles"][0]
    expect = np.array([obstacle_offset(ob, t) for t in log[:, 0]])
    assert np.allclose(log[:, 6:8], expect, atol=1e-12)


@pytest.mark.parametrize("scene", ["stop_in_lane", "back_up"])
def test_replanning_passes_movers_a_blind_plan_hits(scene):
    """A mover stops (or backs up) in the lane: the replanning car passes it, the car that
    follows its t = 0 plan collides — recounted independently from the log."""
    scn, run = _run(scene, duration=30.0, seed=2)
    assert run.summary["reached_goal"] and run.summary["collisions"] == 0
    assert _independent_collisions(scn, run.log) == 0
    _, blind = _run(scene, duration=22.0, seed=2, replan=False)
    assert blind.summary["collisions"] >= 1
    assert _independent_collisions(scn, blind.log) == blind.summary["collisions"]
    assert blind.summary["min_clearance_m"] < 0


def test_with_timing_optimal_the_car_waits_for_the_train():
    """At the level crossing the car stops beside the rails until the train has passed (a
    planned wait, no emergency stop), instead of looping as the constant-timing car must."""
    scn, run = _run("train", duration=30.0, seed=1, timing="optimal")
    s = run.summary
    assert s["reached_goal"] and s["collisions"] == 0 and _independent_collisions(scn, run.log) == 0
    assert s["planned_waits"] >= 1 and s["emergency_stops"] == 0
    assert s["distance_m"] < 18.5  # straight on: no loop


def test_the_guards_check_comes_off_the_planning_budget():
    """A cycle's guard check and its planning share one budget: the replanner plans for what
    the check left of it, at most half of it taken (a car in danger still gets a plan). Before,
    a 15 ms check in danger came on top of the 10 ms planning at 30 Hz."""
    from planner.options import PlanOptions
    from planner.problem import compile_problem
    from planner.sim.replan import Replanner
    from planner.sim.sensing import mover_index, sense

    scn = planner.load_scenario("crowd_square")
    problem = compile_problem(scn)
    sensing = sense(problem.world, mover_index(scn), 0.0, 10.0, 0.0, np.random.default_rng(0))

    def wall(spent_s):
        replanner = Replanner(problem, PlanOptions(polish=False), seed=0, budget_s=0.2,
                              iterations=None, margin=0.05)
        return replanner.cycle(0.0, sensing, problem.start, 0.0, 0.0, 0.1, spent_s).wall_s

    assert wall(0.0) >= 0.2
    assert 0.1 <= wall(0.5) < 0.15  # half the budget taken, not all of it


# -- the command line ----------------------------------------------------------------------
def _cli(*args, timeout=120):
    return subprocess.run(["trackstar", "simulate", *map(str, args)], check=False,
                          capture_output=True, text=True, timeout=timeout)


def test_cli_json_and_log_are_reproducible(tmp_path):
    path = "crossing"
    outs = []
    for k in range(2):
        r = _cli(path, "--duration", 3, "--seed", 5, "--fixed-latency", 20, "--json",
                 "--log", tmp_path / f"{k}.csv", "--controller", "stanley",
                 "--raceline", tmp_path / f"{k}_raceline.csv")
        assert r.returncode == 0, r.stderr
        outs.append(json.loads(r.stdout))
    a, b = ((tmp_path / f"{k}.csv").read_bytes() for k in range(2))
    assert a == b
    s = outs[0]
    for key in ("reached_goal", "time_to_goal_s", "duration_s", "collisions", "min_clearance_m",
                "cycles", "replans", "cycle_ms", "share_30hz", "share_4hz", "emergency_stops",
                "cross_track_error_m", "distance_m", "parameters"):
        assert key in s
    assert s["parameters"]["controller"] == "stanley" and s["duration_s"] == 3.0
    rows = list(csv.reader(a.decode().splitlines()))
    assert len(rows) == 302 and rows[0][:8] == ["t", "x", "y", "theta", "v", "steer",
                                                "obs0_dx", "obs0_dy"]
    # The driven path in the TUM raceline layout: its poses are the log's, its speed the
    # fastest within the car's limits (crossing: max speed unset, so its speed).
    text = (tmp_path / "0_raceline.csv").read_text()
    assert text.startswith("# s_m; x_m; y_m; psi_rad; kappa_radpm; vx_mps; ax_mps2\n")
    line = np.loadtxt(io.StringIO(text), delimiter=";")
    log = np.loadtxt(io.StringIO(a.decode()), delimiter=",", skiprows=1)
    assert np.allclose(line[[0, -1], 1:3], log[[0, -1], 1:3], atol=1e-6)
    assert np.all(np.diff(line[:, 0]) > 0) and line[-1, 0] == pytest.approx(s["distance_m"], 0.01)
    speed = scenario_dict(path)["vehicle"]["speed"]
    assert np.all(np.abs(line[:, 5]) <= speed + 1e-9) and np.all(np.abs(line[:, 6]) <= 2 + 1e-9)


def _with(tmp_path, name="crossing", **changes):
    scn = scenario_dict(name)
    for key, value in changes.items():
        if key.startswith("vehicle."):
            scn["vehicle"][key.split(".")[1]] = value
        else:
            scn[key] = value
    path = tmp_path / "s.json"
    path.write_text(json.dumps(scn))
    return path


@pytest.mark.parametrize("args, needle", [
    (["--rate", "0"], "--rate"), (["--duration", "-1"], "--duration"),
    (["--control-rate", "nan"], "--control-rate"), (["--controller", "lqr"], "--controller"),
    (["--sense-rate", "0"], "--sense-rate"), (["--timing", "fastest"], "--timing"),
    (["--steering", "straight"], "--steering"), (["--steering", "cc-dubbins"], "--steering"),
])
def test_cli_rejects_bad_options(args, needle):
    r = _cli("crossing", *args, timeout=30)
    assert r.returncode == 2 and needle in r.stderr and len(r.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("change, needle", [
    ({"vehicle.max_speed": 0.5}, "max_speed"), ({"vehicle.max_accel": 0}, "max_accel"),
    ({"vehicle.max_steer_rate_deg_s": -3}, "max_steer_rate_deg_s"),
    ({"obstacles": [{"type": "circle", "center": [1.0, 4.0], "radius": 0.9,  # on the start
                     "motion": {"velocity": [0.0, -1.0]}}]}, "start"),  # at t = 0 only
])
def test_cli_rejects_bad_scenarios(tmp_path, change, needle):
    r = _cli(_with(tmp_path, **change), timeout=30)
    assert r.returncode == 2 and needle in r.stderr and len(r.stderr.strip().splitlines()) == 1


# -- behaviour state machines (format and checks) -----------------------------------------
EXAMPLE_FSM = Path(__file__).resolve().parents[1] / "examples" / "fsm" / "hallway.json"


def _fsm_check(path, timeout=30):
    return subprocess.run(["trackstar", "fsm", "check", str(path)], check=False,
                          capture_output=True, text=True, timeout=timeout)


def test_fsm_example_checks():
    r = _fsm_check(EXAMPLE_FSM)
    assert r.returncode == 0 and "ok" in r.stdout, r.stderr


@pytest.mark.parametrize("edit, message", [
    (lambda d: d["states"][2]["transitions"][0].update(type="SensorLvl"),
     "states[2].transitions[0]: unknown type 'SensorLvl' (did you mean 'SensorLevel'?)"),
    (lambda d: d["states"][0]["transitions"][0].update(to="nowhere"),
     "states[0].transitions[0].to: unknown state 'nowhere'"),
    (lambda d: d["states"][1]["params"].pop("tolerance_m"),
     "states[1].params: missing parameter 'tolerance_m' for ApproachPoint"),
    (lambda d: d["states"][4]["states"][0].update(type="FollowWallRmp"),
     "states[4].states[0]: unknown type 'FollowWallRmp' (did you mean 'FollowWallRamp'?)"),
    (lambda d: d.update(initial="start"), "initial: unknown state 'start'"),
    (lambda d: d["states"][0]["transitions"][0]["params"].update(above_m=2.0),
     "states[0].transitions[0].params: give exactly one of 'below_m' and 'above_m'"),
])
def test_fsm_errors_name_the_element(tmp_path, edit, message):
    data = json.loads(EXAMPLE_FSM.read_text())
    edit(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    r = _fsm_check(path)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert r.stderr.startswith(f"error: {message}"), r.stderr
    r = _cli("hallway", "--behaviour", path, timeout=30)
    assert r.returncode == 2 and message in r.stderr


def test_blocked_lane_ends_in_an_emergency_stop_not_a_collision(tmp_path):
    """A box lowers itself across the whole lane and stays: no plan exists, so the car must
    brake to a stop on its committed trajectory before the box (counted), and touch nothing."""
    scn = {"name": "blocked", "bounds": [0, 0, 20, 4],
           "vehicle": {"wheelbase": 0.44, "max_steer_deg": 26.0, "radius": 0.2, "speed": 1.0},
           "start": [1.0, 2.0, 0.0], "goal": [19.0, 2.0, 0.0],
           "obstacles": [{"type": "box", "center": [9.0, 7.0], "size": [1.0, 4.4],
                          "motion": {"waypoints": [[0, 0, 0], [5, 0, -5.0], [99, 0, -5.0]]}}]}
    path = tmp_path / "blocked.json"
    path.write_text(json.dumps(scn))
    _, run = _run(path, duration=14.0, seed=0)
    s = run.summary
    assert not s["reached_goal"] and s["emergency_stops"] >= 1
    assert s["collisions"] == 0 and _independent_collisions(scn, run.log) == 0
    assert abs(run.log[-1, 4]) < 1e-9 and run.log[-1, 1] < 8.3  # at rest, before the box


def test_a_new_plan_keeps_the_stretch_the_steering_cannot_change():
    """Each replacement keeps the trajectory ahead of the car for as far as it drives while its
    steering swings from lock to lock (2·δmax/δ̇: 0.29 s at 26° and 180°/s). A plan that bent
    right in front of the car would ask the steering for what it cannot do: on a tightest
    S-bend the car drifted 12 cm wide into `gate`'s wall."""
    scn = planner.load_scenario("crowd_square")
    seen, guards = [], set()

    def observe(f):
        guards.add(f.guard)
        if f.reference is not None and (not seen or f.reference is not seen[-1][1]):
            # Only plans on the plan: an evasion drops it, and the car plans afresh.
            seen.append((f.pose, f.reference, f.v if guards == {"follow"} else 0.0))
            guards.clear()

    simulate(scn, SimSettings(rate=30.0, fixed_latency_ms=20.0, duration=10.0, seed=0),
             observer=observe)
    swing = 2.0 * scn.vehicle.max_steer_deg / scn.vehicle.max_steer_rate_deg_s
    checked = 0
    for (_, old, _), (pose, new, v) in itertools.pairwise(seen):
        if v < 0.5:  # standing, or the guard has the car off the plan (it plans afresh)
            continue
        i, _ = Reference(old.rows).project(*pose[:2])
        ahead = old.rows[(old.s >= old.s[i]) & (old.s <= old.s[i] + 0.9 * v * swing), :2]
        gaps = np.linalg.norm(ahead[:, None] - new.rows[None, :, :2], axis=2).min(axis=1)
        assert gaps.max() < 1e-9, (pose, v, gaps.max())
        checked += 1
    assert checked >= 20
