"""SVG import and export: units, transforms, layers, clones, shapes, path commands, safety."""

import math
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tracks import Track, TrackError, arc_from_endpoints, inspect_svg, line, load_svg
from tracks._segments import Bezier

DATA = Path(__file__).parent / "data"
MM = 0.001


def svg(body: str, head: str = 'width="100mm" height="50mm" viewBox="0 0 100 50"') -> bytes:
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
        f'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" {head}>{body}</svg>'
    ).encode()


# Hand-built matrices, independent of the importer's parser.
def T(x, y):
    return np.array([[1, 0, x], [0, 1, y], [0, 0, 1.0]])


def S(sx, sy):
    return np.diag([sx, sy, 1.0])


def R(deg, cx=0.0, cy=0.0):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return T(cx, cy) @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]) @ T(-cx, -cy)


def world(matrix, pts, unit=MM):
    """User points through ``matrix`` into metres, y up."""
    pts = np.column_stack([pts, np.ones(len(pts))]) @ matrix.T
    return pts[:, :2] * [unit, -unit]


def ends(track):
    return track.points_at(np.array([0.0, track.length_m]))


# ---- the Inkscape-style test drawing -------------------------------------------------------


def test_nested_transformed_groups_and_arcs_land_where_the_matrices_say():
    track = load_svg(DATA / "nested_mm.svg", path_id="arcpath")
    m = T(10, 20) @ R(30, 50, 50) @ S(2, 2)
    # local: h 20, then a quarter circle about (20, 10) to (30, 10), then v 5.
    local_len = 20 + 5 * math.pi + 5
    assert track.length_m == pytest.approx(2 * local_len * MM, rel=1e-12)
    s = np.array([0, 20, 20 + 2.5 * math.pi, 20 + 5 * math.pi, local_len]) * 2 * MM
    local = np.array(
        [
            [0, 0],
            [20, 0],
            [20 + 10 * math.cos(-math.pi / 4), 10 + 10 * math.sin(-math.pi / 4)],
            [30, 10],
            [30, 15],
        ]
    )
    assert np.allclose(track.points_at(s), world(m, local), atol=1e-12)
    assert track.width_m == pytest.approx(4 * 2 * MM)  # inherited stroke width, scaled by 2
    assert not track.closed


def test_a_clone_through_a_reflection_keeps_its_arc_on_the_mirrored_side():
    """matrix(0,1,1,0) has det −1 but a·d = 0: the case svgpathtools 1.8.0 gets wrong."""
    track = load_svg(DATA / "nested_mm.svg", path_id="mirror")
    m = T(10, 20) @ np.array([[0, 1, 5], [1, 0, 5], [0, 0, 1.0]])
    mid = [20 + 10 * math.cos(-math.pi / 4), 10 + 10 * math.sin(-math.pi / 4)]
    local = np.array([[0, 0], [20, 0], mid, [30, 10], [30, 15]])
    s = np.array([0, 20, 20 + 2.5 * math.pi, 20 + 5 * math.pi, 25 + 5 * math.pi]) * MM
    assert np.allclose(track.points_at(s), world(m, local), atol=1e-12)
    # The original turns right as drawn (sweep 1 on a y-down page), so κ < 0 in the world;
    # the mirrored clone turns left.
    original = load_svg(DATA / "nested_mm.svg", path_id="arcpath").sample(spacing=0.001).curvature
    mirrored = track.sample(spacing=0.001).curvature
    assert np.allclose(original[abs(original) > 1], -1 / (20 * MM), rtol=1e-9)
    assert np.allclose(mirrored[abs(mirrored) > 1], 1 / (10 * MM), rtol=1e-9)


def test_svgpathtools_transform_flips_the_sweep_by_the_wrong_test():
    """Documents why the importer transforms arcs itself; fails once svgpathtools is fixed."""
    from svgpathtools import parse_path
    from svgpathtools.path import transform

    arc = parse_path("M 20,0 A 10,10 0 0 1 30,10")[0]
    swap = np.array([[0, 1, 0], [1, 0, 0], [0, 0, 1.0]])
    theirs = transform(arc, swap).point(0.5)
    p = arc.point(0.5)
    assert abs(theirs - complex(p.imag, p.real)) > 1  # their arc bulges the other way
    ours = arc_from_endpoints([20, 0], [30, 10], (10, 10), 0, False, True).transformed(
        swap[:2, :2], np.zeros(2)
    )
    assert np.allclose(ours.point(np.array([0.5])), [[p.imag, p.real]], atol=1e-12)


def test_document_order_layers_hidden_elements_clones_and_shapes():
    report = inspect_svg(DATA / "nested_mm.svg")
    assert report["unit_m"] == pytest.approx(MM)
    ids = [p["id"] for p in report["paths"]]
    assert ids == ["arcpath", "mirror", "rounded", "ring", "skewed", "stamp"]  # hiddenpath skipped
    by_id = {p["id"]: p for p in report["paths"]}
    assert by_id["mirror"]["label"] == "centre"
    rect = 2 * (60 - 20) + 2 * (40 - 20) + 2 * math.pi * 10
    assert by_id["rounded"]["length_m"] == pytest.approx(rect * MM, rel=1e-12)
    assert by_id["rounded"]["closed"] and by_id["ring"]["closed"]
    assert by_id["ring"]["length_m"] == pytest.approx(2 * math.pi * 20 * MM, rel=1e-12)
    assert by_id["ring"]["bbox_m"] == pytest.approx([0.14, -0.11, 0.18, -0.07])
    assert by_id["rounded"]["width_m"] == pytest.approx(5 * MM)
    assert by_id["stamp"]["bbox_m"] == pytest.approx([0.005, -0.005, 0.009, -0.005])
    assert by_id["arcpath"]["length_user"] == pytest.approx(by_id["arcpath"]["length_m"] / MM)


def test_skewed_clone_with_x_y_offset_maps_its_end_points():
    track = load_svg(DATA / "nested_mm.svg", path_id="skewed")
    skew = np.array([[1, math.tan(math.radians(15)), 0], [0, 1, 0], [0, 0, 1.0]])
    assert np.allclose(
        ends(track), world(skew @ T(30, 40), np.array([[0, 0], [20, 20]])), atol=1e-12
    )


# ---- units ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("head", "unit", "metres_per_unit"),
    [
        ('width="100mm" height="50mm" viewBox="0 0 100 50"', None, 0.001),
        ('width="10cm" height="5cm" viewBox="0 0 1000 500"', None, 0.0001),
        ('width="4in" height="2in" viewBox="0 0 4 2"', None, 0.0254),
        ('width="72pt" height="72pt" viewBox="0 0 1 1"', None, 0.0254),
        ('width="6pc" height="6pc" viewBox="0 0 2 2"', None, 0.0127),
        ('width="400" height="200"', None, 0.0254 / 96),
        ('width="100mm" height="50mm"', None, 0.0254 / 96),
        ('width="100mm" height="80mm" viewBox="0 0 100 50"', None, 0.001),  # meet: the smaller
        ('width="100mm" height="50mm" viewBox="0 0 100 50"', "cm", 0.01),
        ('width="100mm" height="50mm" viewBox="0 0 100 50"', "px", 0.0254 / 96),
    ],
)
def test_document_units_set_metres_per_user_unit(head, unit, metres_per_unit):
    doc = svg('<path d="M 1,2 L 4,6" style="stroke-width:0.5"/>', head)
    track = load_svg(doc, unit=unit)
    assert track.length_m == pytest.approx(5 * metres_per_unit, rel=1e-12)
    assert track.width_m == pytest.approx(0.5 * metres_per_unit, rel=1e-12)
    assert np.allclose(ends(track), np.array([[1, -2], [4, -6]]) * metres_per_unit, atol=1e-15)
    assert inspect_svg(doc, unit=unit)["unit_m"] == pytest.approx(metres_per_unit, rel=1e-12)


def test_unknown_unit_and_unequal_axis_scales_are_refused():
    with pytest.raises(TrackError, match="unknown unit"):
        load_svg(svg('<path d="M 0 0 L 1 1"/>'), unit="furlong")
    squashed = 'width="100mm" height="100mm" viewBox="0 0 100 50" preserveAspectRatio="none"'
    with pytest.raises(TrackError, match="differently"):
        load_svg(svg('<path d="M 0 0 L 1 1"/>', squashed))


# ---- path data ------------------------------------------------------------------------------


def test_every_path_command_absolute_and_relative_with_implicit_repeats():
    absolute = "M 0,0 L 10,0 H 20 V 10 C 20,20 30,20 30,10 S 40,0 40,10 Q 50,20 60,10 T 80,10 A 5,5 0 0 1 90,10 Z"
    relative = "m 0,0 l 10,0 h 10 v 10 c 0,10 10,10 10,0 s 10,-10 10,0 q 10,10 20,0 t 20,0 a 5,5 0 0 1 10,0 z"
    repeats = "M 0,0 10,0 H 20 V 10 C 20,20 30,20 30,10 S 40,0 40,10 Q 50,20 60,10 T 80,10 A 5,5 0 0 1 90,10 z"
    tracks = [load_svg(svg(f'<path d="{d}"/>')) for d in (absolute, relative, repeats)]
    for track in tracks[1:]:
        assert track.length_m == pytest.approx(tracks[0].length_m, rel=1e-12)
        prof, ref = track.sample(0.001), tracks[0].sample(0.001)
        assert np.allclose([prof.x, prof.y], [ref.x, ref.y], atol=1e-12)
    assert all(t.closed for t in tracks)
    kinds = [type(seg).__name__ for seg in tracks[0].segments]
    assert kinds.count("EllipticArc") == 1 and len(tracks[0].segments) == 9


def test_the_longest_subpath_of_an_element_is_its_track():
    track = load_svg(svg('<path d="M 0,0 h 10 M 0,20 h 30 v 5 M 50,0 h 3 z"/>'))
    assert track.length_m == pytest.approx(35 * MM)
    assert np.allclose(ends(track), [[0, -0.02], [0.03, -0.025]])


def test_choice_by_id_then_label_else_the_longest_path():
    doc = svg(
        '<path id="a" inkscape:label="Short" d="M 0,0 h 10"/>'
        '<path id="b" inkscape:label="Long" d="M 0,0 h 40"/>'
        '<path id="Short" d="M 0,0 h 20"/>'
    )
    assert load_svg(doc).length_m == pytest.approx(0.04)
    assert load_svg(doc, path_id="a").length_m == pytest.approx(0.01)
    assert load_svg(doc, path_id="Long").length_m == pytest.approx(0.04)
    assert load_svg(doc, path_id="Short").length_m == pytest.approx(0.02)  # an id wins over a label
    assert load_svg(doc, path_id="a", width_m=0.7).width_m == 0.7
    with pytest.raises(TrackError, match="no path with id or label 'zz'; available: a, b, Short"):
        load_svg(doc, path_id="zz")


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"", "malformed XML"),
        (b"<svg xmlns='http://www.w3.org/2000/svg'><path d='M 0 0 L 1 1'></svg>", "malformed XML"),
        (b"<html><body/></html>", "not an SVG"),
        (
            b'<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;">]>'
            b'<svg xmlns="http://www.w3.org/2000/svg"><text>&lol2;</text></svg>',
            "unsafe XML",
        ),
        (
            b'<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY xxe SYSTEM "file:///etc/passwd">]>'
            b'<svg xmlns="http://www.w3.org/2000/svg"><text>&xxe;</text></svg>',
            "unsafe XML",
        ),
        (svg('<path d="M 0 0 L"/>'), "bad path data"),
        (svg('<path d="M 0 0 L 1 1" transform="rotate(1,2)"/>'), "bad transform"),
        (svg('<use id="u" href="#g"/><g id="g"><use href="#u"/></g>'), "refers to itself"),
        (svg('<circle r="0"/>'), "no path of positive length"),
    ],
)
def test_bad_documents_raise_one_clear_track_error_quickly(data, message):
    started = time.perf_counter()
    with pytest.raises(TrackError, match=message):
        load_svg(data)
    assert time.perf_counter() - started < 1.0


def _fan_out(levels: int, leaf: str) -> bytes:
    """Clones of clones: each level's group shows the one below twice (2**levels leaves)."""
    groups = [f'<g id="l0">{leaf}</g>'] + [
        f'<g id="l{i}"><use href="#l{i - 1}"/><use href="#l{i - 1}"/></g>'
        for i in range(1, levels + 1)]
    return svg(f"<defs>{''.join(groups[:-1])}</defs>{groups[-1]}")


@pytest.mark.parametrize(("data", "message"), [
    (_fan_out(22, "<g/>"), "shows more than 50000 elements"),  # 1.2 KB, 4 million walks
    (_fan_out(12, f'<path d="M 0 0 {"L 1 1 " * 2000}"/>'), "more than 40000 numbers"),
    (svg("<g/>" * 1_300_000), "more than 50000 elements"),  # 5 MB of empty groups
], ids=["empty clones", "clones of a long path", "empty groups"])
def test_the_work_of_a_document_is_bounded_not_only_its_size(data, message):
    """Issue 32: 2**18 clones took 55 s and no signal stopped them; now the walk counts."""
    started = time.perf_counter()
    with pytest.raises(TrackError, match=message):
        load_svg(data)
    assert time.perf_counter() - started < 5.0


def test_a_missing_file_is_a_track_error():
    with pytest.raises(TrackError, match="cannot read"):
        load_svg(DATA / "no-such-file.svg")


# ---- transforms (property) and the export round trip ---------------------------------------

items = st.one_of(
    st.tuples(st.just("translate"), st.tuples(st.floats(-50, 50), st.floats(-50, 50))),
    st.tuples(
        st.just("scale"),
        st.tuples(st.sampled_from([-2, -1, -0.5, 0.5, 1, 3]), st.sampled_from([-1, 0.25, 1, 2])),
    ),
    st.tuples(
        st.just("rotate"), st.tuples(st.floats(-180, 180), st.floats(-20, 20), st.floats(-20, 20))
    ),
    st.tuples(st.just("skewX"), st.tuples(st.floats(-40, 40))),
    st.tuples(st.just("skewY"), st.tuples(st.floats(-40, 40))),
    st.tuples(
        st.just("matrix"),
        st.tuples(
            *[st.floats(-2, 2)] * 2, *[st.floats(-2, 2)] * 2, st.floats(-9, 9), st.floats(-9, 9)
        ),
    ),
)


def hand_matrix(kind, v):
    if kind == "translate":
        return T(*v)
    if kind == "scale":
        return S(*v)
    if kind == "rotate":
        return R(*v)
    if kind == "skewX":
        return np.array([[1, math.tan(math.radians(v[0])), 0], [0, 1, 0], [0, 0, 1.0]])
    if kind == "skewY":
        return np.array([[1, 0, 0], [math.tan(math.radians(v[0])), 1, 0], [0, 0, 1.0]])
    a, b, c, d, e, f = v
    return np.array([[a, c, e], [b, d, f], [0, 0, 1.0]])


@settings(max_examples=40, deadline=None)
@given(st.lists(items, min_size=1, max_size=4))
def test_nested_transforms_compose_like_hand_built_matrices_reflections_included(chain):
    matrix = np.eye(3)
    for kind, values in chain:
        matrix = matrix @ hand_matrix(kind, values)
    if abs(np.linalg.det(matrix[:2, :2])) < 1e-3:
        return
    body = '<path d="M 2,1 L 12,1 A 5,5 0 0 1 17,6"/>'
    for kind, values in reversed(chain):
        body = f'<g transform="{kind}({",".join(map(repr, values))})">{body}</g>'
    track = load_svg(svg(body))
    local_mid = [12 + 5 * math.cos(-math.pi / 4), 6 + 5 * math.sin(-math.pi / 4)]
    expected = world(matrix, np.array([[2, 1], [12, 1], local_mid, [17, 6]]))
    got = np.vstack(
        [ends(track)[:1], track.segments[0].end, track.segments[1].point(np.array([0.5, 1.0]))]
    )
    assert np.allclose(got, expected, atol=1e-12)


def chained(pieces):
    """Segments translated end to end, so the path is continuous."""
    out, cursor = [], np.zeros(2)
    for seg in pieces:
        moved = seg.transformed(np.eye(2), cursor - seg.start)
        out.append(moved)
        cursor = moved.end
    return tuple(out)


pt = st.tuples(st.floats(-3, 3), st.floats(-3, 3)).map(np.array)
bezier = st.lists(pt, min_size=2, max_size=4).map(lambda ps: Bezier(np.array(ps)))
arc = st.builds(
    lambda p, r1, r2, rot, large, sweep: arc_from_endpoints(
        np.zeros(2), p, (r1, r2), rot, large, sweep
    ),
    pt,
    st.floats(0.3, 4),
    st.floats(0.3, 4),
    st.floats(-90, 90),
    st.booleans(),
    st.booleans(),
)


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.one_of(bezier, arc).filter(lambda s: s is not None), min_size=1, max_size=5),
    st.floats(0.05, 2),
)
def test_export_then_import_gives_the_same_geometry(pieces, width):
    segments = chained(pieces)
    try:
        track = Track(name="round trip", closed=False, width_m=width, segments=segments)
    except TrackError:
        return
    if track.length_m < 1e-6:
        return  # a point, not a track: open and closed cannot be told apart
    back = load_svg(track.to_svg().encode())
    assert back.width_m == pytest.approx(width, abs=1e-12)
    ends_meet = np.allclose(segments[0].start, segments[-1].end, atol=1e-9)
    assert back.closed == ends_meet  # closure is geometric: a road whose ends meet reads as a loop
    assert back.length_m == pytest.approx(track.length_m, abs=1e-9)
    s = np.linspace(0, track.length_m, 101)
    assert np.allclose(back.points_at(s), track.points_at(s), atol=1e-9, rtol=0)


def test_a_loop_exports_as_a_closed_inkscape_path():
    circle = chained(
        [
            arc_from_endpoints([0, 0], [2, 0], (1, 1), 0, False, True),
            arc_from_endpoints([2, 0], [0, 0], (1, 1), 0, False, True),
        ]
    )
    track = Track(name="ring", closed=True, width_m=0.4, segments=circle)
    text = track.to_svg()
    assert 'inkscape:groupmode="layer"' in text and 'id="ring"' in text and "Z" in text
    assert "stroke-width:400" in text.replace(".0", "")
    back = load_svg(text.encode())
    assert back.closed and back.length_m == pytest.approx(2 * math.pi, abs=1e-12)
    assert back.name == "ring"


def test_line_helper_and_zero_length_closing_segment_are_dropped():
    track = Track(
        name="x", closed=False, width_m=1, segments=(line([0, 0], [1, 0]), line([1, 0], [1, 0]))
    )
    assert len(track.segments) == 1
