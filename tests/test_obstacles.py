"""`planner.obstacles`: the one description of obstacle shapes and motion that the planner's
compiled world, the simulator's sensing and the studio's drawing all read."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import planner
from planner.obstacles import box_corners, motion_table, outline, reference_points, table_offsets
from planner.problem import resolve_track
from planner.scenario import parse_scenario
from planner.sim.sensing import mover_index, true_offsets

MOVING = [n for n in planner.scenario_names() if planner.load_scenario(n).has_motion]


def _placed(pose, local) -> np.ndarray:
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    return local @ np.array([[c, s], [-s, c]]) + [x, y]


@settings(max_examples=60, deadline=None)
@given(cx=st.floats(-50, 50), cy=st.floats(-50, 50), w=st.floats(0.01, 10),
       h=st.floats(0.01, 10), angle=st.floats(-720, 720))
def test_a_boxs_outline_placed_by_its_pose_is_its_corners(cx, cy, w, h, angle):
    box = parse_scenario({"name": "b", "bounds": [-100, -100, 100, 100], "start": [0, 0, 0],
                          "goal": [1, 1, 0], "obstacles": [{"type": "box", "center": [cx, cy],
                                                            "size": [w, h],
                                                            "angle_deg": angle}]}).obstacles[0]
    assert np.allclose(_placed(*outline(box)), box_corners((cx, cy), (w, h), angle), atol=1e-9)
    assert box.corners() == box_corners((cx, cy), (w, h), angle)


@settings(max_examples=60, deadline=None)
@given(dx=st.floats(-20, 20), dy=st.floats(-20, 20), turn=st.floats(-math.pi, math.pi),
       scale=st.floats(0.1, 5))
def test_a_polygons_pose_is_its_centroid_wherever_it_is(dx, dy, turn, scale):
    """An L-shaped polygon (centroid not its mean vertex), moved and turned: the pose point
    moves with it, and the pose places the outline back on the points."""
    shape = scale * np.array([[0, 0], [3, 0], [3, 1], [1, 1], [1, 3], [0, 3]], dtype=float)
    c, s = math.cos(turn), math.sin(turn)
    pts = shape @ np.array([[c, s], [-s, c]]) + [dx, dy]
    ob = parse_scenario({"name": "p", "bounds": [-100, -100, 100, 100], "start": [0, 0, 0],
                         "goal": [1, 1, 0], "obstacles": [{"type": "polygon",
                                                           "points": pts.tolist()}]}).obstacles[0]
    pose, local = outline(ob)
    centroid = scale * np.array([1.1, 1.1]) @ np.array([[c, s], [-s, c]]) + [dx, dy]  # 1.1 = 11/10
    assert np.allclose(pose[:2], centroid, atol=1e-9) and pose[2] == 0.0
    assert np.allclose(_placed(pose, local), pts, atol=1e-9)


@pytest.mark.parametrize("name", MOVING)
def test_the_motion_tables_are_the_compiled_worlds_motion(name):
    """What the studio draws (a motion's table) is where the planner and the simulator put
    every mover (the compiled world), at any time of a run, also long after its motion."""
    scn = planner.load_scenario(name)
    problem = planner.compile_problem(scn)
    track = resolve_track(scn) if scn.track is not None else None
    movers = mover_index(scn)
    times = np.concatenate([[0.0], np.random.default_rng(0).uniform(0, 120, 50), [3600.0]])
    compiled = true_offsets(problem.world, movers, times)
    for i, ob in enumerate(scn.obstacles):
        drawn = table_offsets(motion_table(ob.motion, track), times)
        assert np.allclose(drawn, compiled[:, i], atol=1e-9), (name, i)
    assert len(reference_points(scn.obstacles)) == int((movers >= 0).sum())
