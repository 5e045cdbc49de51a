"""Centreline CSVs in (TUM / F1TENTH layout), centreline CSVs and TUM racelines out (issue 18)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tracks
from tracks import Limits, TrackError, centerline_csv, load_track, raceline_rows
from tracks._spline import _cyclic, spline_beziers


def csv_bytes(points, right=0.3, left=0.3, header="# x_m,y_m,w_tr_right_m,w_tr_left_m") -> bytes:
    rows = [f"{float(x)!r},{float(y)!r},{right!r},{left!r}" for x, y in points]
    return ("\n".join([header, *rows]) + "\n").encode()


def circle(r, n=200, clockwise=False):
    th = np.linspace(0, 2 * np.pi, n, endpoint=False) * (-1 if clockwise else 1)
    return np.column_stack([r * np.cos(th), r * np.sin(th)])


def ellipse_length(a, b):
    th = np.linspace(0, 2 * np.pi, 20_000, endpoint=False)  # spectrally exact on a period
    return float(np.mean(np.hypot(a * np.sin(th), b * np.cos(th))) * 2 * np.pi)


@pytest.mark.parametrize("clockwise", [False, True])
def test_a_circle_has_its_length_and_curvature_signed_by_orientation(clockwise):
    r = 2.5
    track = load_track(csv_bytes(circle(r, clockwise=clockwise)))
    assert track.closed and track.length_m == pytest.approx(2 * math.pi * r, rel=1e-4)
    kappa = track.sample(0.02).curvature
    assert kappa == pytest.approx(np.full_like(kappa, (-1 if clockwise else 1) / r), rel=5e-3)


def test_an_ellipse_has_its_length_and_extreme_curvatures():
    a, b = 3.0, 1.0
    th = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    track = load_track(csv_bytes(np.column_stack([a * np.cos(th), b * np.sin(th)])))
    assert track.length_m == pytest.approx(ellipse_length(a, b), rel=1e-4)
    kappa = track.sample(0.005).curvature
    assert kappa.max() == pytest.approx(a / b**2, rel=5e-3)
    assert kappa.min() == pytest.approx(b / a**2, rel=5e-3)


def test_a_straight_road_read_open_is_straight():
    x = np.linspace(0.0, 10.0, 9)
    track = load_track(csv_bytes(np.column_stack([x, 0.5 * x - 1])), closed=False)
    assert not track.closed and track.length_m == pytest.approx(math.hypot(10, 5), rel=1e-12)
    assert np.abs(track.sample(0.05).curvature).max() < 1e-9


def test_widths_are_to_the_right_and_left_of_the_driving_direction():
    r = 5.0  # counter-clockwise: the left edge is the inner one
    track = load_track(csv_bytes(circle(r), right=1.0, left=2.0))
    left, right = track.boundaries(0.05)
    assert np.hypot(*left.T) == pytest.approx(np.full(len(left), r - 2.0), rel=1e-3)
    assert np.hypot(*right.T) == pytest.approx(np.full(len(right), r + 1.0), rel=1e-3)
    assert track.width_m == 3.0
    outer, inner = sorted(track.region_rings(), key=lambda ring: -np.hypot(*ring.T).max())
    assert np.hypot(*outer.T).max() == pytest.approx(r + 1.0, rel=1e-3)
    assert np.hypot(*inner.T).min() == pytest.approx(r - 2.0, rel=1e-3)


def test_widths_are_linear_between_points_and_inspect_reports_the_narrowest():
    pts = [(0, 0), (1, 0), (2, 0), (3, 0)]
    rows = "\n".join(f"{x},{y},{w},{w / 2}" for (x, y), w in zip(pts, [1.0, 2.0, 4.0, 4.0]))
    track = load_track(rows.encode(), closed=False)
    right, left = track.widths_at(np.array([0.5, 1.5]))
    assert right == pytest.approx([1.5, 3.0]) and left == pytest.approx([0.75, 1.5])
    assert tracks.inspect_track(rows.encode(), closed=False)["paths"][0]["width_m"] == 1.5


def test_a_repeated_last_point_is_dropped_and_comments_semicolons_and_spaces_pass():
    pts = circle(1.0, 40)
    text = "# a comment\n\n" + "\n".join(f"{x} ; {y};0.2, 0.2" for x, y in [*pts, pts[0]])
    track = load_track(text.encode())
    assert len(track.segments) == 40


@pytest.mark.parametrize(("text", "words"), [
    ("", "no points"),
    ("# x_m,y_m,w_tr_right_m,w_tr_left_m\n", "no points"),
    ("0,0,1,1\n1,0,1,1\n2,1,1,1\n", "at least 4 points, got 3"),
    ("0,0,1,1\n1,0,1\n2,1,1,1\n3,3,1,1\n", "line 2: expected 4 numbers"),
    ("0,0,1,1\n1,0,1,1\n2,x,1,1\n3,3,1,1\n", "line 3: not a number"),
    ("0,0,1,1\n1,0,1,1\n2,nan,1,1\n3,3,1,1\n", "line 3: NaN or infinite"),
    ("#\n0,0,1,1\n1,0,1,inf\n2,1,1,1\n3,3,1,1\n", "line 3: NaN or infinite"),
    ("0,0,1,1\n1,0,1,1\n2,1,-1,1\n3,3,1,1\n", "line 3: negative width"),
    ("0,0,1,1\n1,0,1,1\n1,0,1,1\n3,3,1,1\n", "line 3: repeats the point of line 2"),
    ("0,0,1,1\n1,0,0,0\n2,1,1,1\n3,3,1,1\n", "line 2: the track has no width"),
    ("1,2,1,1\n" * 200_000, "line 10001: more than 10000 rows"),  # counted while reading
    ("".join(f"{i},0,1,1\n" for i in range(180_000)), "line 10001: more than 10000 rows"),
])
def test_bad_csvs_raise_one_line_naming_the_line(text, words):
    with pytest.raises(TrackError, match=words) as err:
        load_track(text.encode(), closed=False)
    assert "\n" not in str(err.value)


def test_svg_only_options_and_a_wrong_closed_are_refused():
    data = csv_bytes(circle(1.0, 20))
    with pytest.raises(TrackError, match="'unit' is for SVG"):
        load_track(data, unit="mm")
    with pytest.raises(TrackError, match="'path' is for SVG"):
        load_track(data, path_id="outer")
    with pytest.raises(TrackError, match="is a loop in the SVG"):
        load_track(tracks.library_path("thesis"), closed=False)


def test_the_thesis_track_exported_as_csv_reads_back_to_its_length_and_width():
    thesis = tracks.load_library_track("thesis")
    text = centerline_csv(thesis, spacing=0.05)
    assert text.startswith("# x_m,y_m,w_tr_right_m,w_tr_left_m\n")
    first = np.array(text.splitlines()[1].split(","), float)
    assert first == pytest.approx([*thesis.points_at(np.array([0.0]))[0], 0.25, 0.25])
    back = load_track(text.encode())
    assert back.length_m == pytest.approx(thesis.length_m, rel=1e-4)
    assert back.width_m == pytest.approx(thesis.width_m) and back.closed


@settings(max_examples=30, deadline=None)
@given(st.integers(4, 12), st.booleans(), st.randoms(use_true_random=False))
def test_the_spline_interpolates_and_is_c2_at_every_point(n, closed, rnd):
    angles = np.sort([rnd.uniform(0, 2 * np.pi) for _ in range(n)])
    angles = angles[np.diff(np.append(angles, angles[0] + 2 * np.pi)) > 0.05]
    radius = np.array([rnd.uniform(1.0, 2.0) for _ in angles])
    pts = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
    if len(pts) < 3:
        return
    segs = spline_beziers(pts, closed)
    ctrl = np.array([s.ctrl for s in segs])
    h = np.linalg.norm(np.diff(np.vstack([pts, pts[:1]]) if closed else pts, axis=0), axis=1)
    assert np.allclose(ctrl[:, 0], pts[: len(segs)], atol=1e-12)
    d1_end = 3 * (ctrl[:, 3] - ctrl[:, 2]) / h[:, None]
    d1_start = 3 * (ctrl[:, 1] - ctrl[:, 0]) / h[:, None]
    d2_end = 6 * (ctrl[:, 3] - 2 * ctrl[:, 2] + ctrl[:, 1]) / h[:, None] ** 2
    d2_start = 6 * (ctrl[:, 0] - 2 * ctrl[:, 1] + ctrl[:, 2]) / h[:, None] ** 2
    following = np.roll(np.arange(len(segs)), -1) if closed else np.arange(1, len(segs))
    ends = np.arange(len(segs)) if closed else np.arange(len(segs) - 1)
    assert np.allclose(d1_end[ends], d1_start[following], atol=1e-9)
    assert np.allclose(d2_end[ends], d2_start[following], atol=1e-7)
    if not closed:  # natural ends
        assert np.allclose([d2_start[0], d2_end[-1]], 0, atol=1e-7)


@settings(max_examples=30, deadline=None)
@given(st.integers(3, 9), st.randoms(use_true_random=False))
def test_the_cyclic_solver_agrees_with_a_dense_solve(n, rnd):
    sub, sup = np.array([rnd.uniform(0.1, 1) for _ in range(2 * n)]).reshape(2, n)
    diag = 2 * (sub + sup) + np.array([rnd.uniform(0, 1) for _ in range(n)])  # the spline's
    rhs = np.array([rnd.uniform(-1, 1) for _ in range(2 * n)]).reshape(n, 2)
    dense = np.diag(diag) + np.diag(sub[1:], -1) + np.diag(sup[:-1], 1)
    dense[0, -1], dense[-1, 0] = sub[0], sup[-1]
    assert np.allclose(_cyclic(sub, diag, sup, rhs), np.linalg.solve(dense, rhs), atol=1e-10)


# ---- racelines ------------------------------------------------------------------------------


def test_the_raceline_of_a_circle_runs_at_the_lateral_limit_with_tum_psi():
    r, a_lat = 2.0, 4.0
    track = load_track(csv_bytes(circle(r)))  # counter-clockwise from (r, 0): heading +y
    rows = raceline_rows(track.sample(0.05), Limits(v_max=10.0, a_lat=a_lat))
    s, x, y, psi, kappa, vx, ax = rows.T
    assert kappa == pytest.approx(np.full_like(kappa, 1 / r), rel=5e-3)
    assert vx == pytest.approx(np.full_like(vx, math.sqrt(a_lat * r)), rel=5e-3)
    assert psi[0] == pytest.approx(0.0, abs=1e-6)  # heading along +y is psi = 0
    assert psi[np.argmin(np.hypot(x, y - r))] == pytest.approx(math.pi / 2, abs=0.02)  # to −x
    assert np.all((-math.pi <= psi) & (psi < math.pi)) and np.abs(ax).max() < 0.05
    assert s[-1] < track.length_m  # a loop's closing point is not repeated


def test_the_raceline_of_an_ellipse_keeps_every_limit_and_reaches_v_max():
    a, b = 6.0, 1.5
    th = np.linspace(0, 2 * np.pi, 300, endpoint=False)
    track = load_track(csv_bytes(np.column_stack([a * np.cos(th), b * np.sin(th)])))
    limits = Limits(v_max=4.0, a_lat=4.0, a_long=2.0)
    rows = raceline_rows(track.sample(0.05), limits)
    s, kappa, vx, ax = rows[:, 0], rows[:, 4], rows[:, 5], rows[:, 6]
    assert vx.max() == pytest.approx(limits.v_max) and vx.min() > 0
    assert np.all(vx <= limits.v_max + 1e-12)
    assert np.all(vx**2 * np.abs(kappa) <= limits.a_lat * (1 + 1e-9))
    assert np.abs(ax).max() <= limits.a_long * (1 + 1e-9)
    ds = np.diff(np.append(s, track.length_m))
    assert ax == pytest.approx((np.roll(vx, -1) ** 2 - vx**2) / (2 * ds))  # ax matches vx
    assert vx.min() == pytest.approx(math.sqrt(limits.a_lat / kappa.max()), rel=1e-9)


def test_a_road_raceline_starts_and_ends_at_rest():
    x = np.linspace(0.0, 20.0, 6)
    track = load_track(csv_bytes(np.column_stack([x, 0 * x])), closed=False)
    rows = raceline_rows(track.sample(0.05), Limits(v_max=3.0, a_long=1.0))
    vx, ax = rows[:, 5], rows[:, 6]
    assert vx[0] == 0 and vx[-1] == 0 and vx.max() == pytest.approx(3.0)
    assert rows[-1, 0] == pytest.approx(20.0) and ax[-1] == 0 and ax.max() == pytest.approx(1.0)


def test_a_planned_path_with_a_cusp_stops_there_and_reverses():
    forward = np.column_stack([np.linspace(0, 2, 41), np.zeros(41), np.zeros(41)])
    back = np.column_stack([np.linspace(2, 0, 41)[1:], np.zeros(40), np.zeros(40)])
    rows = tracks.path_rows(np.vstack([forward, back]), Limits(v_max=1.0))
    s, vx = rows[:, 0], rows[:, 5]
    assert s[-1] == pytest.approx(4.0) and vx[40] == 0 and vx[0] == 0 and vx[-1] == 0
    assert vx[20] > 0 and vx[60] < 0 and np.abs(rows[:, 4]).max() == 0


def test_limits_must_be_positive():
    with pytest.raises(TrackError, match="a_lat_max must be a positive number"):
        Limits(v_max=1.0, a_lat=0.0)
