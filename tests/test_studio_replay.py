"""The replay slider (issue 20), without a browser: the tree rebuilt at a past iteration from the
events alone is the tree a planner of the same seed had then, and in a real studio (viser
server, a websocket client as a tab) the slider draws fewer nodes at an earlier iteration and
the whole tree again at its end."""

from __future__ import annotations

import time

import numpy as np
import pytest

import planner
from app.studio._replay import TreeRecord
from app.studio._replay_slider import NO_REPLAY
from app.studio._tree import CHUNK, FULL_CHUNKS, OLD_SEG, SEG
from tests._studio_tab import open_tab, wait

OPTIONS = planner.PlanOptions(planner="rrtstar", seed=3)
BATCH = 5  # iterations per step: several per batch, as the studio's worker steps


@pytest.fixture(scope="module")
def slalom():
    """(problem, planner after 1500 iterations in batches, its record, the iterations whose
    batch polished the best path)."""
    problem = planner.compile_problem(planner.load_scenario("slalom"))
    run = planner.Planner(problem, OPTIONS)
    record = TreeRecord(run.root)
    polished = []

    def listen(ev: planner.TreeEvents) -> None:  # as the worker's listener records
        cost = run.best_cost
        record.add(ev, run.poses, run.nodes, run.rewires)
        if len(ev.polished):
            polished.append(int(ev.iteration[0]))
        if cost is not None and cost != listen.cost:
            listen.cost = cost
            record.add_path(run.dense_path(0.05))

    listen.cost = None
    run.add_listener(listen)
    for _ in range(1500 // BATCH):
        run.step(BATCH)
    return problem, run, record, polished


def test_the_tree_rebuilt_at_the_last_iteration_is_the_live_tree(slalom):
    _, run, record, polished = slalom
    assert record.note is None and polished  # the run polished its best path: nodes to place
    frame = record.frame(record.iterations)
    assert record.iterations == run.iterations == 1500
    assert np.array_equal(frame.parent, run.snapshot().parent)
    assert frame.cost == run.best_cost
    assert np.array_equal(frame.path, run.dense_path(0.05))


def test_the_tree_rebuilt_at_an_earlier_iteration_is_a_same_seed_run_stopped_there(slalom):
    """At iterations around a polish (its nodes hang from the root, added in that iteration)
    and in a batch's middle: the same parents, best cost and best path as a planner of the same
    seed stepped exactly that far, which had fewer nodes and other parents (rewires undone)."""
    problem, run, record, polished = slalom
    final = run.snapshot().parent
    for n in (polished[-1] - 1, polished[-1], 777, 48):
        again = planner.Planner(problem, OPTIONS)
        again.step(n)
        frame, tree = record.frame(n), again.snapshot()
        assert frame.iteration == n and frame.nodes == tree.nodes < len(final)
        assert np.array_equal(frame.parent, tree.parent), n
        assert frame.cost == again.best_cost
        if again.solved:
            assert frame.path_iteration == frame.cost_iteration  # batches of 5: each seen
            assert np.array_equal(frame.path, again.dense_path(0.05))
        else:
            assert frame.path is None
    frame = record.frame(777)
    assert np.any(frame.parent != final[:frame.nodes])  # rewires after 777 were undone


def test_recording_stops_with_a_note_past_its_limit():
    problem = planner.compile_problem(planner.load_scenario("slalom"))
    run = planner.Planner(problem, OPTIONS)
    record = TreeRecord(run.root, limit=60)
    run.add_listener(lambda ev: record.add(ev, run.poses, run.nodes, run.rewires))
    while run.nodes <= 60:
        run.step(BATCH)
    recorded = record.iterations
    run.step(50)
    assert record.iterations == recorded < run.iterations
    assert record.nodes <= 60 and "at most 60 nodes" in record.note
    assert record.frame(run.iterations).iteration == recorded


def test_a_lecture_run_is_recorded_whole():
    """Issue 33, item 3: the lecturer's run — the thesis track, RRT* Dubins, the old default
    budget of 30 000 iterations at full pace in the worker's batches — is recorded to its last
    iteration (it stopped at 10 019 once, "a later batch's events were incomplete"), and the
    tree rebuilt there is the live one."""
    from app.studio._scenario import default_scenario
    from app.studio._worker import PlannerWorker

    problem = planner.compile_problem(planner.parse_scenario(default_scenario("thesis")))
    budget = 30_000
    worker = PlannerWorker(problem, planner.PlanOptions(seed=0), budget=budget)
    try:
        worker.run()
        deadline = time.monotonic() + 60
        while worker.live.state != "done" and time.monotonic() < deadline:
            time.sleep(0.02)
        lane = worker.lanes[0]
        assert worker.live.state == "done" and lane.tree.iterations == budget
        record = lane.record
        assert record.note is None and record.iterations == budget
        assert np.array_equal(record.frame(budget).parent,
                              lane.tree.snapshot().parent)
    finally:
        worker.stop()


def _pieces(view, c: int) -> int:
    """Pieces per edge in chunk c: SEG in the newest FULL_CHUNKS shown, OLD_SEG in the older
    ones (a tree this small draws every edge)."""
    last = max(c for c, h in view._chunks.items() if h.visible)
    return SEG if c >= last + 1 - FULL_CHUNKS else OLD_SEG


def _drawn_nodes(view) -> int:
    """Tree edges in the scene: the visible chunks' pieces over their pieces per edge."""
    return sum(len(h.points) // _pieces(view, c) for c, h in view._chunks.items() if h.visible)


def test_the_slider_is_left_alone_while_the_run_goes_on():
    """GUI updates every tick, queued behind the tree's scene updates, kept the browser
    rendering: while the run goes on, the slider and its line stay as they are."""
    with open_tab() as session:
        ui, run = session.ui, session.planning
        ui.rate.value = "200 it/s"
        ui.budget.value = 400
        run.resume("run")
        assert wait(lambda: ui.replay_note.content == NO_REPLAY and ui.replay.disabled)
        before, iterations = ui.replay.max, run.worker.record.iterations
        time.sleep(0.3)  # ticks go by while the run goes on
        assert run.worker.live.state == "running"
        assert run.worker.record.iterations > iterations
        assert ui.replay.max == before and ui.replay_note.content == NO_REPLAY
        run.resume("pause")
        assert wait(lambda: not ui.replay.disabled and ui.replay.max == ui.replay.value
                    == run.worker.record.iterations > before
                    and "(the run)" in ui.replay_note.content)


def test_the_slider_redraws_the_tree_of_an_earlier_iteration_and_goes_back_to_the_run():
    with open_tab() as session:
        ui, run = session.ui, session.planning
        assert ui.replay.disabled  # nothing to replay yet
        ui.budget.value = 800  # a fresh run of 800 iterations
        run.resume("run")
        assert wait(lambda: run.worker.live.state == "done")
        assert wait(lambda: ui.replay.max == 800 and not ui.replay.disabled)
        view = run._view
        assert wait(lambda: _drawn_nodes(view) == run.worker.live.chunks.count)
        live_nodes = _drawn_nodes(view)
        assert ui.replay.value == 800 and "iteration 800 of 800" in ui.replay_note.content

        ui.replay.value = 200  # as a drag does: the slider's callback
        frame = run.worker.record.frame(200)
        assert view.replaying and 1 < frame.nodes < live_nodes
        assert _drawn_nodes(view) == frame.nodes
        # A node rewired since is drawn from the parent it had then, and gets to itself.
        final = run.worker.record.frame(800).parent
        node = int(np.flatnonzero(frame.parent != final[:frame.nodes])[0])
        poses = run.worker.record.poses(frame.nodes)
        per = _pieces(view, node // CHUNK)
        drawn = view._chunks[node // CHUNK].points[(node % CHUNK) * per:][:per]
        assert drawn[0, 0, :2] == pytest.approx(poses[frame.parent[node], :2], abs=1e-4)
        assert drawn[-1, 1, :2] == pytest.approx(poses[node, :2], abs=1e-4)
        assert f"iteration 200 of 800 · {frame.nodes:,} nodes" in ui.replay_note.content
        time.sleep(0.2)  # ticks do not draw the run over the replay
        assert _drawn_nodes(view) == frame.nodes

        ui.replay.value = 800
        assert not view.replaying and _drawn_nodes(view) == live_nodes
        assert "(the run)" in ui.replay_note.content

