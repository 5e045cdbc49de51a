"""The studio's logic without a browser: tree chunks, EXTEND explanations, default scenarios,
drawn tracks — each against a real planner run, not hand-made numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

import planner
from app.studio._custom import custom_scenario, track_from_points
from app.studio._extend import LINES, StepInfo, explain, render
from app.studio._scenario import default_scenario
from app.studio._tree import EdgeChunks


def _problem(name: str = "thesis"):
    return planner.compile_problem(planner.parse_scenario(default_scenario(name)))


@pytest.mark.parametrize("name", ["thesis", "carolo", "slalom"])
def test_default_scenario_starts_on_the_track_heading_along_it(name):
    import tracks

    problem = _problem(name)
    track = tracks.load_library_track(name)
    prof = track.sample(0.05)
    sx, sy, sth = problem.start
    i = int(np.argmin(np.hypot(prof.x - sx, prof.y - sy)))
    assert math.hypot(prof.x[i] - sx, prof.y[i] - sy) < 0.03
    assert abs(math.remainder(prof.heading[i] - sth, 2 * math.pi)) < 0.05
    assert problem.clearance(*problem.goal[:2], math.nan) > 0


def test_edge_points_run_from_parent_to_node_along_the_tree():
    run = planner.Planner(_problem(), planner.PlannerSettings(seed=3))
    run.step(300)
    snap = run.snapshot()
    for node in range(1, run.nodes):
        pts = run.edge_points(node, 4)
        assert pts.shape == (5, 2)
        assert np.allclose(pts[0], snap.pose[snap.parent[node], :2], atol=1e-6)
        assert np.allclose(pts[-1], snap.pose[node, :2], atol=1e-6)
        # Consecutive samples along a car path never jump further than the edge is long.
        edge = snap.cost[node] - snap.cost[snap.parent[node]]
        assert np.hypot(*np.diff(pts, axis=0).T).sum() <= edge + 1e-6


def test_chunks_send_the_tail_every_time_and_rewired_chunks_a_few_at_a_time():
    ch = EdgeChunks(seg=2, chunk=4)
    line = np.array([[0, 0], [1, 0], [2, 0]], float)
    for node in range(10):  # chunks 0, 1 full; chunk 2 the tail
        ch.set(node, line + node)
    sent = ch.take_tail()
    assert [c for c, _ in sent] == [0, 1, 2]
    assert [len(seg) for _, seg in sent] == [8, 8, 4]  # 2 pieces per edge
    assert ch.take_tail() == []  # nothing new
    ch.set(1, line * 2)  # a rewire in chunk 0
    ch.set(5, line * 3)  # and in chunk 1
    ch.set(10, line)  # a new node in the tail
    assert [c for c, _ in ch.take_tail()] == [2]
    assert ch.pending_rewired() == 2
    first = ch.take_rewired(1)
    assert [c for c, _ in first] == [0]  # oldest first, at most the limit
    assert np.allclose(first[0][1][2:4, :, :2], [[[0, 0], [2, 0]], [[2, 0], [4, 0]]])
    assert [c for c, _ in ch.take_rewired(5)] == [1]
    assert ch.take_rewired(5) == []


def test_chunk_messages_stay_the_same_size_however_big_the_tree():
    ch = EdgeChunks(seg=4, chunk=256)
    pts = np.zeros((5, 2))
    sizes = []
    for node in range(5000):
        ch.set(node, pts)
        if node % 256 == 255:
            sizes.append(sum(seg.nbytes for _, seg in ch.take_tail()))
    assert max(sizes) == min(sizes) == 256 * 4 * 2 * 3 * 4


def test_extend_explains_what_each_iteration_really_did():
    """Every iteration of a real RRT* run maps to the line its event record implies."""
    run = planner.Planner(_problem(), planner.PlannerSettings(seed=5))
    seen = set()
    events = []
    run.add_listener(events.append)
    for _ in range(400):
        run.step(1)
        ev = events[-1]
        info = StepInfo.from_row(ev.rows[-1], len(ev.rewires))
        line, note = explain(info, star=True)
        seen.add(line)
        if info.nearest < 0:
            assert line == 0 and "SampleFree" in note
        elif info.new < 0:
            assert line == 3 and run.nodes == len({*range(run.nodes)})
        else:
            assert line == (7 if len(ev.rewires) else 6)
            assert f"#{info.new}" in note and f"#{info.parent}" in note
            assert run._tree.parent[info.new] == info.parent or len(ev.rewires)
    assert {6, 7} <= seen  # nodes were added, with and without rewires
    html = render(7, "a <note>")
    assert html.count("<mark>") == 1 and LINES[7].split(":")[0] in html
    assert "&lt;note&gt;" in html


def test_rrt_without_star_ends_on_the_insert_line():
    info = StepInfo(iteration=1, nearest=0, new=1, parent=0, n_near=0, n_rewired=0, radius=0.0)
    assert explain(info, star=False)[0] == 6


def test_a_drawn_loop_becomes_a_plannable_scenario():
    track = track_from_points([(0, 0), (4, 0), (5, 3), (1, 4), (-1, 2)], 0.8, closed=True)
    scenario, region = custom_scenario(track, "drawn")
    problem = planner.compile_problem(planner.parse_scenario(
        dict(scenario, obstacles=region)))
    result = planner.solve(problem, time_limit=None, iterations=20000, seed=0)
    assert result.solved
    # The path stays on the drawn track: every sample within half a width of the centreline.
    prof = track.sample(0.02)
    centre = np.column_stack([prof.x, prof.y])
    d = np.min(np.hypot(*(result.path[:, None, :2] - centre[None]).transpose(2, 0, 1)), axis=1)
    assert d.max() <= track.width_m / 2 + 0.02


def test_too_few_drawn_points_are_refused():
    with pytest.raises(ValueError, match="at least 3"):
        track_from_points([(0, 0), (1, 0)], 0.5, closed=True)
