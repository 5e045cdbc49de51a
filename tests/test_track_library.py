"""The shipped tracks: real Inkscape files with physical units, sensible widths, drivable regions."""

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import shapely

from tracks import (
    STEERING_COLUMNS,
    Track,
    TrackError,
    arc_from_endpoints,
    library_names,
    library_path,
    line,
    load_library_track,
)

NAMES = ["carolo", "hallway", "parking", "slalom", "thesis"]
INKSCAPE = "{http://www.inkscape.org/namespaces/inkscape}"
R_MIN = 0.44 / math.tan(math.radians(26))


def test_the_library_holds_the_five_designed_tracks():
    assert set(NAMES) <= set(library_names())
    with pytest.raises(TrackError, match="no library track 'nowhere'"):
        library_path("nowhere")


@pytest.mark.parametrize("name", NAMES)
def test_each_file_is_an_inkscape_document_with_physical_units_and_a_layer(name):
    root = ET.parse(library_path(name)).getroot()
    assert root.attrib["width"][-2:] in ("mm", "cm") and "viewBox" in root.attrib
    layers = [
        g
        for g in root.iter("{http://www.w3.org/2000/svg}g")
        if g.get(f"{INKSCAPE}groupmode") == "layer"
    ]
    assert layers and root.find(f".//*[@id='{name}']") is not None


@pytest.mark.parametrize("name", NAMES)
def test_each_track_has_a_sensible_width_and_is_drivable_but_for_designed_spots(name):
    track = load_library_track(name)
    assert track.name == name and 0.4 <= track.width_m <= 2.0
    prof = track.sample()
    infeasible = prof.s[~prof.feasible]
    if name == "hallway":  # the tight door corner, R 0.7 m, is the one designed infeasible spot
        assert 0 < np.ptp(infeasible) < 0.5 * math.pi * 0.7 + 0.05
        assert abs(prof.curvature).max() == pytest.approx(1 / 0.7, rel=1e-9)
    else:
        assert infeasible.size == 0 and abs(prof.curvature).max() <= 1 / R_MIN


def test_thesis_track_is_listing_5_1_at_one_centimetre_per_unit():
    track = load_library_track("thesis")
    assert track.closed and track.length_m == pytest.approx(14.003325889, abs=1e-9)
    assert track.points_at(np.array([0.0]))[0] == pytest.approx([2.3732491, -0.26388819])


@pytest.mark.parametrize("name", NAMES)
def test_region_rings_contain_the_centreline_and_exclude_points_beyond_the_edges(name):
    track = load_library_track(name)
    rings = track.region_rings()
    assert len(rings) == (2 if track.closed else 1)
    region = shapely.Polygon(rings[0], rings[1:])
    assert region.area == pytest.approx(track.length_m * track.width_m, rel=0.02)
    left, right = track.boundaries(spacing=0.1)
    prof = track.sample(spacing=0.1)
    centre = np.column_stack([prof.x, prof.y])
    for edge in (left, right):
        inside = shapely.contains_xy(region, *(centre + 0.95 * (edge - centre))[1:-1].T)
        assert inside.all()
    outside = shapely.contains_xy(region, *(centre + 1.05 * (left - centre))[1:-1].T)
    assert outside.mean() < 0.1  # only where the edge of another part of the track is near


def test_loop_rings_are_outer_then_inner():
    outer, inner = load_library_track("carolo").region_rings()
    assert shapely.Polygon(outer).contains(shapely.Polygon(inner))


def test_steering_commands_follow_the_track_from_a_pose():
    track = load_library_track("thesis")
    prof = track.sample()
    i = 300
    x, y, h = prof.x[i] + 0.003, prof.y[i] - 0.004, prof.heading[i] + 0.2
    cmds = track.steering_commands(x, y, h, n=10)
    assert cmds.shape == (10, len(STEERING_COLUMNS))
    assert np.allclose(cmds[:, 0], prof.s[i + 1 : i + 11])
    assert np.allclose(cmds[:, 4], prof.steering_deg[i + 1 : i + 11])


def test_steering_commands_wrap_on_a_loop_and_stop_at_a_road_end():
    loop = load_library_track("thesis")
    prof = loop.sample()
    cmds = loop.steering_commands(prof.x[-3], prof.y[-3], prof.heading[-3], n=5)
    assert np.allclose(cmds[:, 0], [prof.s[-2], 0, 0.02, 0.04, 0.06])
    road = load_library_track("parking")
    end = road.sample()
    cmds = road.steering_commands(end.x[-2], end.y[-2], end.heading[-2], n=4)
    assert np.allclose(cmds[:, 1:3], [[end.x[-1], end.y[-1]]] * 4)


def test_heading_picks_the_branch_the_car_drives_along_at_a_crossing():
    """An alpha-shaped road crosses itself at the origin, once heading east, once south."""
    arc = arc_from_endpoints([1, 0], [0, 1], (1, 1), 0, True, True)  # 270° left about (1, 1)
    segments = (line([-3, 0], [1, 0]), arc, line([0, 1], [0, -3]))
    track = Track(name="alpha", closed=False, width_m=0.5, segments=segments)
    east = track.steering_commands(0.0, 0.0, 0.0, n=1, spacing=0.01)
    south = track.steering_commands(0.0, 0.0, -math.pi / 2, n=1, spacing=0.01)
    assert east[0, 0] == pytest.approx(3.01)
    assert south[0, 0] == pytest.approx(4 + 1.5 * math.pi + 1.01, abs=0.01)
