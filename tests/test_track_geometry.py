"""Geometry of the tracks layer: de Casteljau, arc length, curvature, resampling, degenerate input."""

import math

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from tracks import Bezier, Track, arc_from_endpoints, de_casteljau, length_bounds, line, split

coord = st.floats(-5, 5, allow_nan=False)
point = st.tuples(coord, coord).map(np.array)
cubic = st.lists(point, min_size=4, max_size=4).map(np.array)
fast = settings(max_examples=40, deadline=None)


def bernstein(ctrl, t):
    """The expanded Bernstein form: an independent evaluation to check de Casteljau against."""
    n = len(ctrl) - 1
    basis = np.array([math.comb(n, i) * t**i * (1 - t) ** (n - i) for i in range(n + 1)])
    return basis.T @ ctrl


def max_curvature(ctrl, samples=200_001):
    """|κ| of a cubic at dense parameters, from its hodographs: independent of the track's sampling,
    which can step over a hook far shorter than its spacing."""
    ts = np.linspace(0, 1, samples)
    d1 = bernstein(3 * np.diff(ctrl, axis=0), ts)
    d2 = bernstein(6 * np.diff(ctrl, n=2, axis=0), ts)
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.hypot(*d1.T) ** 3
    return np.nan_to_num(kappa, nan=np.inf).max()


def track_of(*segments, closed=False):
    return Track(name="t", closed=closed, width_m=0.5, segments=tuple(segments))


@fast
@given(cubic, st.floats(0, 1))
def test_de_casteljau_matches_bernstein_form_and_split_halves_trace_the_curve(ctrl, t):
    ts = np.linspace(0, 1, 7)
    assert np.allclose(de_casteljau(ctrl, ts), bernstein(ctrl, ts), atol=1e-12)
    left, right = split(ctrl, t)
    assert np.allclose(de_casteljau(left, ts), de_casteljau(ctrl, ts * t), atol=1e-12)
    assert np.allclose(de_casteljau(right, ts), de_casteljau(ctrl, t + ts * (1 - t)), atol=1e-12)


@fast
@given(cubic)
def test_bezier_length_by_quadrature_agrees_with_dense_chords(ctrl):
    length = track_of(Bezier(ctrl)).length_m if np.ptp(ctrl, axis=0).max() > 1e-3 else None
    if length is None:
        return
    pts = bernstein(ctrl, np.linspace(0, 1, 200_001))
    chords = np.hypot(*np.diff(pts, axis=0).T).sum()
    lower, upper = length_bounds(ctrl, depth=10)
    assert chords <= length * (1 + 1e-12)
    assert length - chords <= 1e-7 * max(length, 1) + 1e-9
    assert lower - 1e-12 <= length <= upper + 1e-12


@fast
@given(point, st.floats(0.2, 20), st.floats(-180, 180), st.floats(0.1, 6.2), st.booleans())
def test_circle_arc_curvature_is_plus_or_minus_one_over_r(centre, r, start_deg, sweep, left):
    a0 = math.radians(start_deg)
    a1 = a0 + (sweep if left else -sweep)
    p0 = centre + r * np.array([math.cos(a0), math.sin(a0)])
    p1 = centre + r * np.array([math.cos(a1), math.sin(a1)])
    arc = arc_from_endpoints(p0, p1, (r, r), 0.0, sweep > math.pi, left)
    track = track_of(arc)
    prof = track.sample(spacing=r / 50)
    assert track.length_m == pytest.approx(r * sweep, rel=1e-9)
    assert np.allclose(prof.curvature, (1 if left else -1) / r, rtol=1e-9)
    assert np.allclose(np.hypot(prof.x - centre[0], prof.y - centre[1]), r, rtol=1e-9)


@fast
@given(point, point)
def test_straight_lines_have_zero_curvature_and_constant_heading(p0, p1):
    if np.hypot(*(p1 - p0)) < 1e-3:
        return
    prof = track_of(line(p0, p1)).sample(spacing=0.05)
    assert np.all(prof.curvature == 0.0)
    turn = np.remainder(prof.heading - math.atan2(*(p1 - p0)[::-1]) + math.pi, 2 * math.pi)
    assert np.allclose(turn - math.pi, 0.0, atol=1e-12)  # equal headings modulo 2π (±π)
    assert np.all(prof.steering_deg == 0.0) and prof.feasible.all()


@fast
@given(cubic, st.floats(0.01, 0.1))
@example(np.array([[0, 0], [2**-14, 0], [0, 0], [0, 3]], dtype=float), 0.09375)  # a hook of 61 µm
def test_resampled_points_are_spacing_apart_from_start_to_end(ctrl, spacing):
    if np.ptp(ctrl, axis=0).max() < 1e-2:
        return
    track = track_of(Bezier(ctrl))
    prof = track.sample(spacing=spacing)
    assert prof.s[0] == 0 and prof.s[-1] == pytest.approx(track.length_m, abs=1e-12)
    assert np.allclose(np.diff(prof.s)[:-1], spacing, atol=1e-12)
    assert np.allclose([prof.x[0], prof.y[0]], ctrl[0], atol=1e-12)
    assert np.allclose([prof.x[-1], prof.y[-1]], ctrl[-1], atol=1e-12)
    # The chord between neighbours is shorter than the arc between them, by about κ²h³/24.
    assume(np.all(np.cos(np.diff(prof.heading)) > 0))  # no cusp: the curve never reverses
    chord = np.hypot(np.diff(prof.x), np.diff(prof.y))
    kappa_max = max_curvature(ctrl)
    deficit = 2 * kappa_max**2 * spacing**3 / 24 + 1e-9
    assert np.all(chord <= np.diff(prof.s) + 1e-9)
    assert np.all(chord[:-1] >= spacing - deficit)


def test_default_spacing_is_two_centimetres_to_a_micrometre_on_a_drivable_track():
    r = 0.9  # the tightest drivable radius, 0.44 / tan 26°
    arc = arc_from_endpoints([r, 0], [0, r], (r, r), 0, True, True)
    prof = track_of(arc).sample()
    chord = np.hypot(np.diff(prof.x), np.diff(prof.y))
    assert np.all(abs(chord[:-1] - 0.02) <= 1e-6)


@pytest.mark.parametrize(
    "segments",
    [
        [Bezier(np.array([[0, 0], [0, 0], [1, 1], [2, 0.0]]))],  # P0 = P1
        [Bezier(np.array([[0, 0], [1, 1], [2, 0], [2, 0.0]]))],  # P2 = P3
        [Bezier(np.array([[0, 0], [2, 1], [0, 1], [2, 0.0]]))],  # a cusp inside
        [Bezier(np.array([[0, 0], [1, 0], [2, 0], [3, 0.0]])), line([3, 0], [3, 0])],  # zero length
        [Bezier(np.array([[0, 0], [3, 0], [1, 0], [2, 0.0]]))],  # straight, reversing
        [
            line([0, 0], [1, 0]),
            Bezier(np.array([[1, 0], [1, 0], [1, 0], [1, 0.0]])),
            line([1, 0], [1, 1]),
        ],
    ],
)
def test_degenerate_segments_give_finite_profiles(segments):
    prof = track_of(*segments).sample(spacing=0.01)
    for name in prof.COLUMNS:
        assert np.all(np.isfinite(getattr(prof, name).astype(float))), name


def test_a_path_of_nothing_but_a_point_is_refused():
    with pytest.raises(ValueError, match="zero length"):
        track_of(line([1, 1], [1, 1]))


def test_points_at_arc_length_on_a_semicircle_are_where_the_angle_says():
    arc = arc_from_endpoints([1, 0], [-1, 0], (1, 1), 0, False, True)
    track = track_of(arc)
    s = np.array([0, math.pi / 4, math.pi / 2, math.pi])
    assert np.allclose(track.points_at(s), np.column_stack([np.cos(s), np.sin(s)]), atol=1e-12)


def test_steering_angle_is_atan_of_wheelbase_times_curvature_and_flags_tight_turns():
    r = 0.8  # tighter than 0.44 / tan 26° = 0.902 m
    arc = arc_from_endpoints([r, 0], [-r, 0], (r, r), 0, False, True)
    prof = track_of(arc).sample(wheelbase=0.44, max_steer_deg=26)
    assert np.allclose(prof.steering_deg, math.degrees(math.atan(0.44 / r)))
    assert not prof.feasible.any()
    assert track_of(arc).sample(max_steer_deg=30).feasible.all()


def test_an_arc_between_endpoints_too_close_to_tell_apart_is_omitted_like_a_closed_one():
    """SVG omits an arc whose endpoints coincide; 1e-170 apart, their distance squares to 0 and
    no centre can be computed (it was NaN, silently)."""
    assert arc_from_endpoints((0.0, 0.0), (0.0, 0.0), (1.0, 1.0), 0.0, False, True) is None
    assert arc_from_endpoints((0.0, 0.0), (1e-170, 0.0), (1.0, 1.0), 0.0, False, True) is None
    arc = arc_from_endpoints((0.0, 0.0), (1e-9, 0.0), (1.0, 1.0), 0.0, False, True)
    assert np.all(np.isfinite(arc.center))
