"""The steering contract: every registered steering function, through the same properties.

Exact endpoints, length = the sum of the driven segments, lower bounds ≤ length, the triangle
inequality (shortest paths always satisfy it), symmetry where the robot may reverse or turn on
the spot; continuous-curvature paths never shorter than their bang-bang kin and tending to them
as the sharpness grows — and the registry is what every edge lists.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from planner import STEERINGS, PlanOptions
from planner._cc_dubins import cc_constants
from planner._paths import path_buffers, path_end, path_length, pose_at, sample_path
from planner._steer import state, steer_bound, steer_length, steer_path, steer_tight_bound

RHO, SIGMA = 0.9, 3.0  # σ: a servo of 150°/s on a 0.4 m wheelbase at 1.25 m/s
G = cc_constants(RHO, SIGMA)
coord = st.floats(-5, 5, allow_nan=False)
angle = st.floats(-math.pi, math.pi, allow_nan=False)
pose = st.tuples(coord, coord, angle)
steerings = pytest.mark.parametrize("steering", list(STEERINGS.values()), ids=list(STEERINGS))


def shortest(code, q0, q1):
    """(length, kinds, lens, curv) of the shortest path from q0 to q1."""
    steering = next(s for s in STEERINGS.values() if s.code == code)
    path = path_buffers(steering.segments)
    length = steer_path(code, *q0, *q1, G, *path)
    return (length, *path)


def as_state(q):
    return state(*q, math.cos(q[2]), math.sin(q[2]), RHO)


def distinct(q0, q1):
    """Away from Dubins' discontinuity (a micrometre from the goal, rounding picks a loop)."""
    return (math.hypot(q1[0] - q0[0], q1[1] - q0[1]) > 1e-6
            or abs(math.remainder(q1[2] - q0[2], 2 * math.pi)) > 1e-6)


@steerings
@settings(max_examples=150, deadline=None)
@given(q0=pose, q1=pose)
def test_paths_end_exactly_and_their_length_is_the_segments(steering, q0, q1):
    assume(distinct(q0, q1))
    length, kinds, lens, curv = shortest(steering.code, q0, q1)
    end = path_end(*q0, kinds, lens, curv)
    assert end[:2] == pytest.approx(q1[:2], abs=1e-9)
    assert math.remainder(end[2] - q1[2], 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
    assert path_length(kinds, lens) == pytest.approx(length, abs=1e-9)
    assert length >= math.hypot(q1[0] - q0[0], q1[1] - q0[1]) - 1e-9
    if not steering.reverses:
        assert np.all(lens[kinds != 2] >= 0.0)


@steerings
@settings(max_examples=150, deadline=None)
@given(q0=pose, q1=pose)
def test_bounds_never_exceed_the_length_and_pruned_lengths_stay_above_the_bound(steering, q0,
                                                                                q1):
    assume(distinct(q0, q1))
    a, b = as_state(q0), as_state(q1)
    exact = steer_length(steering.code, a, b, G, math.inf)
    assert exact == pytest.approx(shortest(steering.code, q0, q1)[0], abs=1e-9)
    assert steer_bound(steering.code, a, b, G) <= exact + 1e-9
    assert steer_tight_bound(steering.code, a, b, G) <= exact + 1e-9
    cut = 0.5 * exact
    assert steer_length(steering.code, a, b, G, cut) >= cut - 1e-9


@pytest.mark.parametrize("steering", [s for s in STEERINGS.values() if s.shortest],
                         ids=[s.name for s in STEERINGS.values() if s.shortest])
@settings(max_examples=150, deadline=None)
@given(q0=pose, q1=pose, q2=pose)
def test_triangle_inequality(steering, q0, q1, q2):
    """Where the paths are the shortest ones; CC paths are within a few % of that."""
    assume(distinct(q0, q1) and distinct(q1, q2) and distinct(q0, q2))
    d = [shortest(steering.code, p, q)[0] for p, q in ((q0, q2), (q0, q1), (q1, q2))]
    assert d[0] <= d[1] + d[2] + 1e-9


@steerings
@settings(max_examples=100, deadline=None)
@given(q0=pose, q1=pose)
def test_symmetric_where_the_robot_may_go_back_and_under_flipped_headings(steering, q0, q1):
    """q0 → q1 is as long as q1 → q0 where the robot may reverse or turn on the spot; for
    every steering, it is as long as the same curve driven the other way: from q1 to q0 with
    both headings turned round."""
    assume(distinct(q0, q1))
    there, back = shortest(steering.code, q0, q1)[0], shortest(steering.code, q1, q0)[0]
    if steering.reverses or steering.heading_free:
        assert there == pytest.approx(back, abs=1e-9)

    def turned(q):
        return (q[0], q[1], q[2] + math.pi)

    flipped = shortest(steering.code, turned(q1), turned(q0))[0]
    assert there == pytest.approx(flipped, abs=1e-9)


@settings(max_examples=100, deadline=None)
@given(q0=pose, q1=pose)
def test_straight_rows_carry_the_direction_of_travel_and_no_curvature(q0, q1):
    assume(math.hypot(q1[0] - q0[0], q1[1] - q0[1]) > 1e-3)
    _, kinds, lens, curv = shortest(STEERINGS["straight"].code, q0, q1)
    rows = sample_path(*q0, kinds, lens, curv, 0.05)
    travel = math.atan2(q1[1] - q0[1], q1[0] - q0[0])
    moving = np.hypot(*np.diff(rows[:, :2], axis=0).T) > 1e-9
    headings = rows[1:][moving, 2]
    assert np.allclose(np.cos(headings - travel), 1.0, atol=1e-9)
    assert np.all(rows[:, 3] == 0.0) and np.all(rows[:, 4] == 1.0)
    assert rows[-1, :2] == pytest.approx(q1[:2], abs=1e-9)
    # halfway along, the robot faces its way; at the start it has not turned yet
    half = pose_at(*q0, kinds, lens, curv, 0.5 * path_length(kinds, lens))
    assert math.cos(half[2] - travel) == pytest.approx(1.0)
    assert pose_at(*q0, kinds, lens, curv, 0.0)[2] == q0[2]


def test_the_registry_is_what_the_options_accept():
    schema = PlanOptions.model_json_schema()["properties"]["steering"]
    assert schema["enum"] == list(STEERINGS)
    assert {s.code for s in STEERINGS.values()} == set(range(len(STEERINGS)))


continuous = [s for s in STEERINGS.values() if s.continuous]


def bang_bang_kin(steering):
    """The steering of the same car without clothoids: Reeds-Shepp's if it reverses."""
    return STEERINGS["reeds-shepp" if steering.reverses else "dubins"]


@pytest.mark.parametrize("steering", continuous, ids=[s.name for s in continuous])
@settings(max_examples=150, deadline=None)
@given(q0=pose, q1=pose, sigma=st.floats(0.01, 50.0))
def test_cc_paths_are_never_shorter_than_bang_bang_ones_and_keep_the_limits_as_rows(
        steering, q0, q1, sigma):
    """Every row of a CC path keeps |κ| ≤ 1/ρ and changes κ by at most σmax × the chord to
    the row before (`chord_sharpness` plans just below σmax so that chords, not only arcs,
    keep it), and the path ends where it should at κ = 0."""
    from planner._rows import SPACING_M, chord_sharpness

    assume(distinct(q0, q1))
    g = cc_constants(RHO, chord_sharpness(sigma, RHO))
    kinds, lens, curv = path_buffers(steering.segments)
    length = steer_path(steering.code, *q0, *q1, g, kinds, lens, curv)
    kin = path_buffers(bang_bang_kin(steering).segments)
    assert length >= steer_path(bang_bang_kin(steering).code, *q0, *q1, G, *kin) - 1e-9
    rows = sample_path(*q0, kinds, lens, curv, SPACING_M)
    assert np.abs(rows[:, 3]).max() <= 1.0 / RHO + 1e-9
    chords = np.hypot(*np.diff(rows[:, :2], axis=0).T)
    assert np.all(np.abs(np.diff(rows[:, 3])) <= sigma * chords + 1e-9)
    assert rows[0, 3] == 0.0 and abs(rows[-1, 3]) < 1e-9
    assert rows[-1, :2] == pytest.approx(q1[:2], abs=1e-9)
    if not steering.reverses:  # a servo so slow that each clothoid spirals round, too
        assert np.all(lens >= 0.0)


@pytest.mark.parametrize("steering", continuous, ids=[s.name for s in continuous])
@settings(max_examples=100, deadline=None)
@given(q0=pose, q1=pose)
def test_cc_lengths_tend_to_bang_bang_ones_as_the_sharpness_grows(steering, q0, q1):
    assume(distinct(q0, q1))
    kin = bang_bang_kin(steering)
    target = shortest(kin.code, q0, q1)[0]
    gaps = []
    for sigma in (1.0, 1e2, 1e4, 1e6):
        path = path_buffers(steering.segments)
        gaps.append(steer_path(steering.code, *q0, *q1, cc_constants(RHO, sigma), *path)
                    - target)
    assert gaps[-1] == pytest.approx(0.0, abs=1e-4)
    assert all(g >= -1e-9 for g in gaps)
