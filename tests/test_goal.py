"""The goal region (docs/scenario-format.md), tested in one place for the kernel, the polish,
the simulator and OMPL's goal distance alike."""

import math

import numpy as np
from conftest import scenario_dict
from hypothesis import given, settings
from hypothesis import strategies as st

import planner
from planner._goal import goal_offset, in_goal, in_goal_rows

coord = st.floats(-5, 5)
angle = st.floats(-10, 10)


@settings(max_examples=200, deadline=None)
@given(x=coord, y=coord, th=angle, gth=angle, pos=st.floats(0, 2), head=st.floats(0, math.pi))
def test_a_pose_is_in_the_goal_when_near_in_position_and_heading(x, y, th, gth, pos, head):
    goal = np.array([1.0, -1.0, gth, pos, head])
    turn = abs(math.remainder(th - gth, 2 * math.pi))  # the short way round
    inside = math.hypot(x - 1.0, y + 1.0) <= pos and turn <= head + 1e-12
    if abs(turn - head) > 1e-9:  # away from the heading's boundary, where rounding decides
        assert in_goal(x, y, th, goal) == inside
    assert in_goal(x, y, th, goal) == (goal_offset(x, y, th, goal) <= 0.0)
    assert in_goal_rows(np.array([[x, y, th, 0.0]]), goal)[0] == in_goal(x, y, th, goal)


def test_the_problem_builds_the_region_and_shrinks_it():
    problem = planner.compile_problem(planner.parse_scenario(scenario_dict("slalom")))
    region = problem.goal_region(0.5)
    assert region[:3].tolist() == list(problem.goal)
    assert region[3] == 0.5 * problem.goal_position_tol
    assert region[4] == 0.5 * problem.goal_heading_tol
    gx, gy, gth = problem.goal
    edge = gx + 0.75 * problem.goal_position_tol
    assert in_goal(edge, gy, gth, problem.goal_region())
    assert not in_goal(edge, gy, gth, region)
