"""Reeds-Shepp reversing made visible and each edge's word on a click (issue 20), without a
browser: a real viser server (no client connected), a Reeds-Shepp run on the parking scenario
that reverses into the slot, and what the studio draws of it — scene, profiles, labels."""

from __future__ import annotations

import math
import re
import time
from types import SimpleNamespace

import numpy as np
import pytest
import viser

import planner
from app.raceline import raceline_limits
from app.studio._compare import Pins, Run
from app.studio._live_view import BURST_TICKS, PATH_RGB, LiveView
from app.studio._plots import SHADE, Profiles
from app.studio._scene import REVERSE_RGB, Z, arc_length, marker_size
from app.studio._tree import SEG
from app.studio._worker import PlannerWorker


@pytest.fixture(scope="module")
def parked():
    """(problem, the worker's record) of RRT* with Reeds-Shepp on parking, 300 iterations."""
    problem = planner.compile_problem(planner.load_scenario("parking"))
    worker = PlannerWorker(problem, planner.PlanOptions(steering="reeds-shepp", seed=0),
                           budget=300)
    try:
        worker.run()
        deadline = time.monotonic() + 20
        while worker.live.state != "done" and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(0.05)
    finally:
        worker.stop()
    path = worker.live.best_path
    assert path is not None and (path[:, 4] < 0).any() and (path[:, 4] > 0).any()
    return problem, worker.live


@pytest.fixture
def server():
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    yield server
    server.stop()


def _cusps(path: np.ndarray) -> np.ndarray:
    """Rows where the direction of the piece before (ending at the row) and after differ."""
    return np.flatnonzero(np.diff(path[1:, 4]) != 0) + 1


def test_reverse_pieces_are_drawn_white_and_dashed_and_each_cusp_gets_a_diamond(parked, server):
    problem, live = parked
    path = live.best_path
    view = LiveView(server.scene, live, problem.bounds)
    view.tick()
    h = view._handles
    back = path[1:, 4] < 0  # the piece from row i to i + 1 is reversed
    pieces = np.stack([path[:-1, :2], path[1:, :2]], axis=1)
    assert np.allclose(h["best"].points[:, :, :2], pieces[~back], atol=1e-5)
    assert np.allclose(h["best_reverse"].points[:, :, :2], pieces[back], atol=1e-5)
    assert tuple(np.ravel(h["best"].colors)[:3]) == PATH_RGB  # forward: today's pink
    assert tuple(np.ravel(h["best_reverse"].colors)[:3]) == REVERSE_RGB
    assert tuple(np.ravel(h["best_reverse_dashes"].colors)[:3]) == PATH_RGB
    assert 0 < len(h["best_reverse_dashes"].points) < back.sum()  # dashes: some pieces
    corners = h["best_cusps"].points[:, 0, :2].reshape(-1, 4, 2)  # four per diamond
    assert np.allclose(corners.mean(axis=1), path[_cusps(path), :2], atol=1e-5)
    assert (h["best_cusps"].points[:, :, 2] > Z["path"]).all()  # above the path

    live.best_path = path.copy()
    live.best_path[:, 4] = 1.0  # a later best path that drives forward only
    live.best_version += 1
    for _ in range(BURST_TICKS):  # the path goes out with the next burst of the tree
        view.tick()
    assert not h["best_reverse"].visible and not h["best_cusps"].visible
    assert h["best"].visible and len(h["best"].points) == len(path) - 1
    live.best_path, live.best_version = path, live.best_version + 1


def test_a_pinned_path_shows_its_reverse_in_its_own_colour_dashed_on_white(parked):
    problem, live = parked
    drawn = {}
    scene = SimpleNamespace(remove_by_name=lambda name: drawn.clear(),
                            add_frame=lambda *a, **k: None,
                            add_line_segments=lambda name, seg, rgb, **k: drawn.update(
                                {name: (seg, rgb)}))
    pins = Pins(scene)
    pins.add(Run(planner.PlanOptions(steering="reeds-shepp"), {}, live.best_path, [],
                 problem.scenario.vehicle))
    pins.draw(marker_size(problem.bounds))
    colour = tuple(int(pins.runs[0].colour[i:i + 2], 16) for i in (1, 3, 5))
    assert drawn["/pins/0"][1] == colour and drawn["/pins/0_reverse_dashes"][1] == colour
    assert drawn["/pins/0_reverse"][1] == REVERSE_RGB
    assert len(drawn["/pins/0_reverse"][0]) == (live.best_path[1:, 4] < 0).sum()
    assert len(drawn["/pins/0_cusps"][0]) == 4 * len(_cusps(live.best_path))
    assert (drawn["/pins/0_cusps"][0][:, :, 2] < Z["path"]).all()  # below the current path


def test_the_profiles_shade_the_reverse_stretches_and_mark_the_cusps(parked, server):
    problem, live = parked
    path, vehicle = live.best_path, problem.scenario.vehicle
    profiles = Profiles(server.gui, np.linspace(0, 20, 50), np.zeros(50), 10.0,
                        vehicle.wheelbase, vehicle.max_steer_deg, vehicle.max_steer_rate_deg_s,
                        raceline_limits(vehicle=vehicle))
    assert "bang-bang" in profiles.caption.content  # Dubins until told otherwise
    profiles.set_steering("dubins", "cc-dubins", 7.0)  # the split: both, named
    assert "**A, Dubins:**" in profiles.caption.content
    assert "**B, CC-Dubins:**" in profiles.caption.content and "ramp" in profiles.caption.content
    kmax = math.tan(math.radians(vehicle.max_steer_deg)) / vehicle.wheelbase
    assert f"σmax = 7 1/m²: from straight to full lock takes {kmax / 7:.2g} m" \
        in profiles.caption.content
    profiles.set_steering("reeds-shepp", sigma=7.0)
    assert "reverse" in profiles.caption.content and "cusp" in profiles.caption.content
    profiles.show_path(path)
    slope = [np.array(v, dtype=float) for v in profiles.slope.data]
    assert np.all(slope[2] == 7.0) and np.all(slope[3] == -7.0)  # ±σmax
    assert np.nanmax(np.abs(slope[1])) > 3 * 7.0  # a bang-bang step: κmax within one row
    s = arc_length(path)
    cusp_s = s[_cusps(path)]
    for chart in (profiles.curvature, profiles.steering):
        grid, shade, marks = chart.data[0], chart.data[5], chart.data[6]
        assert [sr["label"] for sr in chart.series[5:7]] == ["reverse (shaded)", "cusp ◆"]
        at = np.searchsorted(grid, cusp_s)
        assert np.allclose(grid[at], cusp_s)  # each cusp is a point of the s grid
        assert list(chart.series[6]["points"]["filter"]) == list(at) and (marks[at] == 0).all()
        # The piece from row i to i + 1 spans s[i]..s[i + 1], in the direction of row i + 1.
        on = (s[:-1, None] <= grid) & (grid <= s[1:, None])  # (piece, grid point)
        back, ahead = (on & (path[1:, 4:5] < 0)).any(0), (on & (path[1:, 4:5] > 0)).any(0)
        top = chart.data[3][0] * SHADE  # +κmax, +δmax
        assert back.any() and np.allclose(shade[back], top)  # filled down to −top
        assert np.allclose(shade[ahead & ~back], -top)  # a fill of no height


def test_a_click_on_an_edge_names_its_word_and_length(parked, server):
    """Clicked at its middle, each best-path edge says its word and length; their lengths add
    up to the path's, and the edges that reverse say so with −. A tree edge away from the
    path says it is one; a click beside every edge takes the label away."""
    problem, live = parked
    view = LiveView(server.scene, live, problem.bounds)
    view.tick()
    nodes = list(live.best_nodes)
    labels = [view.pick(*live.chunks.get(n)[SEG // 2]) for n in nodes[1:]]
    form = re.compile(r"^([LSRT][+−]?)+ · (\d+\.\d\d) m · best path, edge (\d+) of (\d+)$")
    found = [form.match(text) for text in labels]
    assert all(found), labels
    assert [int(m[3]) for m in found] == list(range(1, len(nodes)))
    total = sum(float(m[2]) for m in found)
    assert total == pytest.approx(arc_length(live.best_path)[-1], abs=0.01 * len(nodes))
    assert any("−" in text for text in labels) and any("−" not in text for text in labels)
    assert view._handles["pick_l"].text == labels[-1] and view._handles["pick"].visible

    away = [n for n in range(1, live.chunks.count) if n not in nodes and np.min(np.hypot(
        *(live.best_path[:, None, :2] - live.chunks.get(n)[SEG // 2]).T)) > 1.0]
    assert "· tree edge into node " in view.pick(*live.chunks.get(away[0])[SEG // 2])
    *_, xmax, ymax = problem.bounds
    assert view.pick(xmax + 5.0, ymax + 5.0) is None
    assert not view._handles["pick"].visible and not view._handles["pick_l"].visible
