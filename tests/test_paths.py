"""The segment-path integrator: exact arcs, continuity, sampling spacing."""

import math

import numpy as np
import pytest
from _arcs import arcs
from hypothesis import given, settings
from hypothesis import strategies as st

from planner._paths import (
    MIN_SEGMENT,
    path_buffers,
    path_end,
    path_length,
    path_word,
    pose_at,
    sample_path,
    truncate,
)

lengths = st.floats(-5, 5, allow_nan=False)
kinds_st = st.lists(st.sampled_from([-1, 0, 1]), min_size=5, max_size=5)


def test_quarter_circle_left_ends_where_geometry_says():
    kinds = np.array([1, 0, 0, 0, 0], dtype=np.int8)
    lens = np.array([math.pi / 2, 0, 0, 0, 0])
    x, y, th = path_end(0.0, 0.0, 0.0, kinds, lens, arcs(kinds, 1.0))
    assert (x, y, th) == pytest.approx((1.0, 1.0, math.pi / 2), abs=1e-12)


@settings(max_examples=200, deadline=None)
@given(kinds_st, st.lists(lengths, min_size=5, max_size=5), st.floats(0.3, 3))
def test_samples_are_continuous_and_end_at_the_end(kinds, lens, rho):
    kinds = np.array(kinds, dtype=np.int8)
    lens = np.array(lens)
    curv = arcs(kinds, rho)
    pts = sample_path(0.5, -0.2, 0.3, kinds, lens, curv, 0.02)
    end = path_end(0.5, -0.2, 0.3, kinds, lens, curv)
    assert np.allclose(pts[-1, :3], end, atol=1e-9)
    # A segment under MIN_SEGMENT has no row: the step over it is that much longer.
    assert np.all(np.hypot(*np.diff(pts[:, :2], axis=0).T) <= 0.02 + 6 * MIN_SEGMENT)
    mid = pose_at(0.5, -0.2, 0.3, kinds, lens, curv, path_length(kinds, lens))
    assert np.allclose(mid[:3], end, atol=1e-9)


def _word(steering: str, goal, rho: float = 1.0) -> str:
    from planner._cc_dubins import cc_constants
    from planner._steer import steer_path
    from planner.steering import STEERINGS

    kinds, lens, curv = path_buffers(STEERINGS[steering].segments)
    steer_path(STEERINGS[steering].code, 0.0, 0.0, 0.0, *map(float, goal),
               cc_constants(rho, math.inf), kinds, lens, curv)
    return path_word(kinds, lens)


@pytest.mark.parametrize("goal, word", [
    ((5, 0, 0), "S"),  # LSL with both arcs 0: unused segments are left out
    ((5, 3, 0), "LSR"), ((5, -3, 0), "RSL"),  # a lane change to the left, to the right
    ((0, 5, math.pi), "LSL"), ((0, -5, math.pi), "RSR"),  # wide U-turns
    ((0.3, 0, math.pi), "LRL"),  # facing back close by: three arcs
])
def test_dubins_words_of_known_motions(goal, word):
    assert _word("dubins", goal) == word


@pytest.mark.parametrize("goal, word", [
    ((-3, 0, 0), "S−"),  # straight back
    ((5, 3, 0), "LSR"),  # no reversing: the Dubins word, unsigned
    ((0.3, 0, math.pi), "L+R−L+"),  # a three-point turn
    ((0, 0.5, 0), "R+L−R−L+"),  # parallel parking: a cusp on each side of the reverse
])
def test_reeds_shepp_words_mark_each_segments_direction_once_it_reverses(goal, word):
    assert _word("reeds-shepp", goal) == word


def test_a_turn_on_the_spot_is_t_without_a_direction():
    assert _word("straight", (5, 3, 0)) == "TST"
    assert path_word(np.array([2, 0, 0, 0, 0]), np.array([1.0, -2.0, 0, 0, 0])) == "TS−"
    assert path_word(np.zeros(5, np.int8), np.zeros(5)) == ""  # the root's edge


@settings(max_examples=100, deadline=None)
@given(kinds_st, st.lists(lengths, min_size=5, max_size=5))
def test_the_word_names_the_segments_a_path_samples(kinds, lens):
    """One letter per run of segments that move (MIN_SEGMENT at least, or a turn on the spot)
    with one letter and direction, and where a sign is written it is the driving direction
    `sample_path` gives that run's poses."""
    kinds, lens = np.array(kinds, dtype=np.int8), np.array(lens)
    word = path_word(kinds, lens)
    rows = sample_path(0.0, 0.0, 0.0, kinds, lens, arcs(kinds, 1.0), 10.0)[1:, 4]  # a row per segment
    moving = [("LSR"[1 - k], d) for (k, v), d in
              zip([(k, v) for k, v in zip(kinds, lens) if abs(v) > MIN_SEGMENT], rows)]
    runs = [m for i, m in enumerate(moving) if i == 0 or m != moving[i - 1]]
    assert [c for c in word if c in "LSR"] == [letter for letter, _ in runs]
    signs = [c for c in word if c in "+−"]
    assert signs == ([] if (rows > 0).all() else ["+" if d > 0 else "−" for _, d in runs])


def cc_turn(kappa: float, sigma: float, arc: float, direction: float = 1.0):
    """A continuous-curvature left turn in the segment form: a clothoid from κ = 0 up to
    ``kappa`` at sharpness σ, an arc of ``arc`` metres, a clothoid back down to 0."""
    ramp = kappa / sigma
    kinds = np.array([1, 1, 1, 0, 0], np.int8)
    lens = direction * np.array([ramp, arc, ramp, 0.0, 0.0])
    curv = np.array([[0.0, sigma], [kappa, 0.0], [kappa, -sigma], [0.0, 0.0], [0.0, 0.0]])
    return kinds, lens, curv


@settings(max_examples=100, deadline=None)
@given(st.floats(0.2, 2.5), st.floats(0.5, 20.0), st.floats(0.0, 3.0), st.sampled_from([1.0, -1.0]),
       st.floats(0.0, 1.0))
def test_a_clothoid_turn_samples_with_curvature_ramps_and_cuts_where_it_is_driven(
        kappa, sigma, arc, direction, share):
    """Rows of a CC turn change curvature by at most σ × their spacing, never jump; they are
    continuous and end at the path's end; the pose a share of the way along is the end of the
    path cut there, and it turns the heading by exactly the area under κ."""
    kinds, lens, curv = cc_turn(kappa, sigma, arc, direction)
    spacing = 0.02
    rows = sample_path(0.3, -0.1, 0.4, kinds, lens, curv, spacing)
    steps = np.hypot(*np.diff(rows[:, :2], axis=0).T)
    assert steps.max() <= spacing + 1e-9
    assert np.abs(np.diff(rows[:, 3])).max() <= sigma * spacing + 1e-9
    assert rows[0, 3] == 0.0 and rows[-1, 3] == pytest.approx(0.0, abs=1e-9)
    assert rows[:, 3].max() == pytest.approx(kappa)
    assert np.all(rows[:, 4] == direction)
    end = path_end(0.3, -0.1, 0.4, kinds, lens, curv)
    assert rows[-1, :3] == pytest.approx(end, abs=1e-9)
    total = path_length(kinds, lens)
    assert end[2] - 0.4 == pytest.approx(direction * kappa * (kappa / sigma + arc), abs=1e-9)
    cut = np.zeros(5)
    truncate(kinds, lens, share * total, cut)
    assert pose_at(0.3, -0.1, 0.4, kinds, lens, curv, share * total)[:3] == pytest.approx(
        path_end(0.3, -0.1, 0.4, kinds, cut, curv), abs=1e-9)
