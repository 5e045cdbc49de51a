"""Dubins paths: known lengths, exact endpoints, lower bounds and invariances."""

import math

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from _arcs import arcs
from planner._dubins import (dubins_length, dubins_lower_bound_cs, dubins_path,
                             dubins_word_bound, turning_centres)
from planner._paths import path_end, path_length, sample_path

RHO = 0.44 / math.tan(math.radians(26))
coord = st.floats(-6, 6, allow_nan=False)
angle = st.floats(-math.pi, math.pi, allow_nan=False)
pose = st.tuples(coord, coord, angle)


def shortest(q0, q1, rho=RHO):
    kinds, lens = np.zeros(5, np.int8), np.zeros(5)
    length = dubins_path(*q0, *q1, rho, kinds, lens)
    return length, kinds, lens


def test_minimum_turning_radius_of_the_thesis_car():
    assert RHO == pytest.approx(0.9021, abs=1e-4)  # 90.2 cm, not the seed's 101.5 cm


@pytest.mark.parametrize("q1, expected", [
    ((3.0, 0.0, 0.0), 3.0),  # straight ahead
    ((RHO, RHO, math.pi / 2), RHO * math.pi / 2),  # quarter circle left
    ((RHO, -RHO, -math.pi / 2), RHO * math.pi / 2),  # quarter circle right
    ((0.0, 4 * RHO, math.pi), RHO * math.pi + 2 * RHO),  # symmetric U-turn: L S L
    ((2 * RHO, 0.0, math.pi), RHO * math.pi),  # half circle right... to the left of start
])
def test_known_lengths(q1, expected):
    if q1 == (2 * RHO, 0.0, math.pi):
        q1 = (0.0, 2 * RHO, math.pi)  # a half circle left ends 2ρ to the left, heading back
    length, _, _ = shortest((0.0, 0.0, 0.0), q1)
    assert length == pytest.approx(expected, abs=1e-9)


@settings(max_examples=300, deadline=None)
@given(pose, pose)
def test_exact_endpoint_and_length(q0, q1):
    # Within a micrometre (but not equal), poses sit on Dubins' discontinuity: rounding decides
    # between "already there" and a full loop.
    assume(q0 == q1 or math.hypot(q1[0] - q0[0], q1[1] - q0[1]) > 1e-6
           or abs(math.remainder(q1[2] - q0[2], 2 * math.pi)) > 1e-6)
    length, kinds, lens = shortest(q0, q1)
    end = path_end(*q0, kinds, lens, arcs(kinds, RHO))
    assert end[:2] == pytest.approx(q1[:2], abs=1e-9)
    assert math.remainder(end[2] - q1[2], 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
    assert path_length(kinds, lens) == pytest.approx(length, abs=1e-12)
    assert np.all(lens >= 0)  # forward only
    assert length >= math.hypot(q1[0] - q0[0], q1[1] - q0[1]) * (1 - 1e-9) - 1e-12


@settings(max_examples=200, deadline=None)
@given(pose, pose, st.floats(-5, 5), st.floats(-5, 5), angle)
def test_invariant_under_rigid_motion(q0, q1, tx, ty, rot):
    # Near-identical poses sit on a discontinuity (a hair behind needs a full loop), where
    # rounding in the moved copy may pick the other side.
    assume(math.hypot(q1[0] - q0[0], q1[1] - q0[1]) > 1e-6)
    c, s = math.cos(rot), math.sin(rot)

    def move(q):
        return (c * q[0] - s * q[1] + tx, s * q[0] + c * q[1] + ty, q[2] + rot)

    assert shortest(move(q0), move(q1))[0] == pytest.approx(shortest(q0, q1)[0], abs=1e-7)


@settings(max_examples=300, deadline=None)
@given(pose, pose, st.floats(0.1, 40))
def test_bounded_length_never_underestimates(q0, q1, bound):
    exact = dubins_length(*q0, *q1, RHO, math.inf)
    bounded = dubins_length(*q0, *q1, RHO, bound)
    if exact < bound:
        assert bounded == pytest.approx(exact, abs=1e-12)
    else:
        assert bounded >= bound - 1e-12


near_pose = st.tuples(st.floats(-4 * RHO, 4 * RHO), st.floats(-4 * RHO, 4 * RHO), angle)


@settings(max_examples=500, deadline=None)
@given(near_pose)
def test_a_bound_a_hair_above_the_length_still_finds_it(q1):
    """Every early exit (a word's cheap lower bound) really is below that word's length: with
    the bound barely above the shortest length nothing may be cut. Nearby poses are where the
    CCC words and their outer-arc bound matter."""
    q0 = (0.0, 0.0, 0.0)
    exact = dubins_length(*q0, *q1, RHO, math.inf)
    assert dubins_length(*q0, *q1, RHO, exact * (1 + 1e-9) + 1e-12) == pytest.approx(
        exact, abs=1e-9)


def turn_of(a, b):
    return (b[2] - a[2] + math.pi) % (2 * math.pi) - math.pi


def lower_bound(a, b):
    return dubins_lower_bound_cs(a[0], a[1], math.cos(a[2]), math.sin(a[2]), b[0], b[1],
                                 math.cos(b[2]), math.sin(b[2]), turn_of(a, b), RHO)


def word_bound(a, b):
    (c0, s0), (c1, s1) = (math.cos(a[2]), math.sin(a[2])), (math.cos(b[2]), math.sin(b[2]))
    return dubins_word_bound(*turning_centres(a[0], a[1], c0, s0, RHO), c0, s0,
                             *turning_centres(b[0], b[1], c1, s1, RHO), c1, s1, turn_of(a, b),
                             RHO)


@settings(max_examples=500, deadline=None)
@given(pose, pose, st.floats(-1e-3, 1e-3), st.floats(-1e-3, 1e-3),
       st.sampled_from([None, 0.0, 1e-14, -1e-14, math.pi]))
@example((0.0, 0.0, 1e-6), (1e-6, 0.0, 0.0), 0.0, 0.0, 0.0)  # 1e-12 beside the straight ahead
def test_lower_bounds_never_exceed_the_length(q0, q1, jx, jy, same_turn):
    # jx, jy: also nearby pairs (offsets under a millimetre), where the bounds are tightest;
    # same_turn: headings equal or opposite up to rounding, where the words' loops flip.
    if same_turn is not None:
        q1 = (q1[0], q1[1], q0[2] + same_turn)
    for a, b in ((q0, q1), (q0, (q0[0] + jx, q0[1] + jy, q1[2]))):
        exact = dubins_length(*a, *b, RHO, math.inf)
        assert lower_bound(a, b) <= exact + 1e-9
        assert lower_bound(a, b) >= math.hypot(b[0] - a[0], b[1] - a[1]) - 1e-9
        assert word_bound(a, b) <= exact + 1e-9


@pytest.mark.parametrize("q1, expected", [
    ((2.0, 0.0, 0.0), 2.0),  # straight behind: the chord
    ((0.0, 2 * RHO, math.pi), math.pi * RHO),  # a half circle to the left: exact
    ((0.0, 0.0, math.pi), (2 + math.pi) * RHO),  # facing back on the spot: a loop
    ((0.3, 0.0, math.pi), None),  # facing back just ahead
])
def test_cheap_lower_bound_is_tight_on_arcs_and_large_facing_back(q1, expected):
    """The chord and |Δθ| give at most ρπ where the car has to turn round on the spot; the
    turning circles' bound sees the loop (the length there is about 7.3 ρ)."""
    bound = lower_bound((0.0, 0.0, 0.0), q1)
    exact = dubins_length(0.0, 0.0, 0.0, *q1, RHO, math.inf)
    assert bound <= exact + 1e-12
    if expected is not None:
        assert bound == pytest.approx(expected)
    else:
        assert bound > 1.5 * math.pi * RHO


@pytest.mark.parametrize("q1", [(0.3, 0.0, math.pi), (0.0, 0.0, math.pi), (-0.5, 0.2, 1.0),
                                (0.5, 0.5, -2.5), (2.0, 0.0, 0.0)])
def test_word_bound_sees_the_loops_the_turning_circles_miss(q1):
    """Poses facing back at, or beside and behind, a node: the turning circles give 2.4-5.2 ρ
    for paths of 6-7.3 ρ; the words' bound stays within 5 %."""
    q0 = (0.0, 0.0, 0.0)
    exact = dubins_length(*q0, *q1, RHO, math.inf)
    assert 0.95 * exact <= word_bound(q0, q1) <= exact
    if q1 != (2.0, 0.0, 0.0):
        assert lower_bound(q0, q1) < 0.8 * exact


@settings(max_examples=100, deadline=None)
@given(pose, pose)
def test_samples_have_curvature_zero_or_one_over_rho(q0, q1):
    _, kinds, lens = shortest(q0, q1)
    pts = sample_path(*q0, kinds, lens, arcs(kinds, RHO), 0.02)
    assert set(np.round(np.abs(pts[:, 3]) * RHO, 12)) <= {0.0, 1.0}
    assert np.all(np.hypot(*np.diff(pts[:, :2], axis=0).T) <= 0.02 + 1e-9)
