"""The studio's simulation view without a browser: a real viser server (no client connected),
its scene clock, the crossing scenario; what `SimView.tick` draws is the frame it drew."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest
import viser
from conftest import scenario_dict

import planner
from app.studio._clock import SceneClock
from app.studio._scene import yaw_wxyz
from app.studio._sim_view import EDGE_PIECES, PREDICT_S, SimView
from planner.sim.predict import REACH_S
from planner.sim.sensing import mover_index, true_offsets


@pytest.fixture
def view():
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    clock = SceneClock(server.gui.add_slider("Scene time (s)", 0.0, 30.0, 0.1, 0.0),
                       server.gui.add_checkbox("Play scene time", False), max_step=0.16)
    sim = SimView(server.gui, server.scene, clock)
    yield sim
    sim.clear()
    server.stop()


def test_the_view_draws_the_frame_it_received(view):
    view.start(planner.compile_problem(planner.load_scenario("crossing")), view.settings("dubins"))
    run = view.run
    deadline = time.monotonic() + 60
    while (run.frame is None or run.frame.t < 1.5 or run.tree_version == 0) and (
            time.monotonic() < deadline):
        time.sleep(0.05)
    view.tick()
    f = view._shown["frame"]
    assert f is not None and f.t >= 1.5
    car = view._handles["car"]
    assert np.allclose(car.position, (*f.pose[:2], 0.0))
    assert np.allclose(car.wxyz, yaw_wxyz(f.pose[2]))
    assert view.clock.t == pytest.approx(f.t)  # the true mover, at the clock
    # The ghost: the last sensing, extrapolated at constant velocity to the frame's time.
    s = f.sensing
    believed = np.array([10.0, -1.3]) + s.offsets[0] + s.velocities[0] * (f.t - s.t)
    assert np.allclose(view._handles["ghost0"].position[:2], believed)
    assert np.allclose(believed, np.array([10.0, -1.3]) + f.offsets[0], atol=0.01)  # no noise
    assert view._handles["committed"].points.shape[0] == len(view._shown["reference"].rows) - 1
    assert len(view._handles["tree"].points) % EDGE_PIECES == 0
    assert len(view._handles["tree"].points) > 0
    t, soll, ist = view.ui.steering.data
    assert len(t) == len(soll) == len(ist) > 10
    assert "running" in view.ui.status.content and "| cycles |" in view.ui.metrics.content
    view.stop()
    deadline = time.monotonic() + 10
    while run.running and time.monotonic() < deadline:
        time.sleep(0.05)
    view.tick()
    assert "stopped" in view.ui.status.content and view.run is None


def test_a_collision_and_a_stall_are_marked_where_and_when_with_their_cause(view):
    """A blind run into the lane's stopped car collides; in the gate scene with the door's
    timetable unknown, the car, believing the door shut for good, finds no path and stands:
    each gets a disc and a label."""
    gate = scenario_dict("gate")
    gate["obstacles"][2]["motion"]["known"] = False
    for scenario, kind, cause in ((planner.load_scenario("stop_in_lane"), "collision",
                                   "clearance"),
                                  (planner.parse_scenario(gate), "stall", "no path found")):
        settings = dataclasses.replace(view.settings("dubins"), realtime=False, duration=12.0,
                                       replan=scenario.name != "stop_in_lane")
        view.start(planner.compile_problem(scenario), settings)
        run = view.run
        deadline = time.monotonic() + 60
        while run.running and time.monotonic() < deadline:
            time.sleep(0.05)
        view.tick()
        events = [e for e in run.events if e[3] == kind]
        assert events, run.events
        t, x, y, _, why = events[0]
        assert cause in why and 0.0 <= t <= 12.0
        k = run.events.index(events[0])
        assert np.allclose(view._handles[f"event{k}"].position[:2], (x, y))
        assert view._handles[f"event{k}/label"].text.startswith(f"{kind} at t = {t:.1f} s")
    # The door's belief is drawn while the car predicts it, not once it is told the timetable.
    assert "ghost2" in view._handles and "grown2_0" in view._handles
    view.start(planner.compile_problem(planner.load_scenario("gate")), settings)
    assert "ghost2" not in view._handles and "grown2_0" not in view._handles
    view.stop()


def test_movers_that_keep_to_the_track_are_drawn_predicted_along_it(view):
    """thesis_half_lap predicts its disc along the track (prediction.along_track): the drawn
    prediction bends with the track, onto where the disc will truly be."""
    problem = planner.compile_problem(planner.load_scenario("thesis_half_lap"))
    view.start(problem, dataclasses.replace(view.settings("dubins"), realtime=False, duration=3.0))
    run = view.run
    deadline = time.monotonic() + 60
    while run.running and time.monotonic() < deadline:
        time.sleep(0.05)
    view.tick()
    f = view._shown["frame"]
    line = view._handles["prediction"].points[:, :, :2]
    ahead = np.vstack([line[:, 0], line[-1:, 1]])  # the drawn points, from now on
    taus = np.linspace(0.0, PREDICT_S, len(ahead))
    movers = mover_index(problem.scenario)
    truth = (np.asarray(problem.scenario.obstacles[1].center)
             + true_offsets(problem.world, movers, f.t + taus)[:, 1])
    assert np.linalg.norm(ahead - truth, axis=1).max() < 0.05
    turned = np.diff(np.unwrap(np.arctan2(*np.diff(ahead, axis=0).T[::-1])))
    assert abs(turned.sum()) > 0.5  # it bends with the track (radians over the 2 s drawn)


def test_a_mover_seen_turning_at_once_gets_its_reachable_set_drawn(view):
    """The crossing's disc walks 0.8 m/s into the lane and turns back at once at t = 1 s: from
    then on its reachable set is drawn, an outline round where it was last sensed, its radius
    the disc's plus (fastest speed seen + e_v)·REACH_S."""
    crossing = scenario_dict("crossing")
    crossing["obstacles"][0]["motion"] = {"waypoints": [[-1, 0, -0.8], [1, 0, 0.8], [3, 0, -0.8]]}
    problem = planner.compile_problem(planner.parse_scenario(crossing))
    settings = dataclasses.replace(view.settings("dubins"), realtime=False, duration=0.8)
    view.start(problem, settings)
    while view.run.running:
        time.sleep(0.05)
    view.tick()
    assert not view._handles.get("reachable") or not view._handles["reachable"].visible
    view.start(problem, dataclasses.replace(settings, duration=2.0))
    while view.run.running:
        time.sleep(0.05)
    view.tick()
    f = view._shown["frame"]
    rate = f.reach[0]
    assert rate == pytest.approx(0.8 + settings.uncertainty(problem.scenario).speed_error)
    ring = view._handles["reachable"].points[:, 0, :2]
    sensed = np.array([10.0, -1.3]) + f.sensing.offsets[0]
    assert np.linalg.norm(ring - sensed, axis=1) == pytest.approx(
        np.full(len(ring), 1.0 + rate * REACH_S), abs=0.01)
