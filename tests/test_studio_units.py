"""The studio's logic without a browser: tree chunks, EXTEND explanations, default scenarios,
drawn tracks — each against a real planner run, not hand-made numbers."""

from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest
import viser

import planner
from app.studio._custom import Draft, custom_scenario
from app.studio._edit import moved_obstacle, parse_waypoints
from app.studio._extend import RRT_LINES, STAR_LINES, StepInfo, explain, render
from app.studio._live_view import BURST_TICKS, HEAVY_BURST_TICKS, LiveView
from app.studio._panel import STEERINGS
from app.studio._scenario import default_scenario
from app.studio._tree import CHUNK, FULL_CHUNKS, OLD_PIECES, OLD_SEG, SEG, EdgeChunks
from app.studio._worker import Live
from planner.problem import resolve_track


def _problem(name: str = "thesis"):
    return planner.compile_problem(planner.parse_scenario(default_scenario(name)))


def _run_to_the_end(worker) -> None:
    """Run the worker until its budget is spent (10 s at most), and a moment longer. (Run on
    a run that has spent its budget would go on for as much again.)"""
    if worker.live.state not in ("running", "done"):
        worker.run()
    deadline = time.monotonic() + 10
    while worker.live.state != "done" and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.05)


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
    run = planner.Planner(_problem(), planner.PlanOptions(seed=3))
    run.step(300)
    snap = run.snapshot()
    for node in range(1, run.nodes):
        pts = run.edge_points(node, 4)
        assert pts.shape == (5, 2) and np.array_equal(pts, snap.edge_points(node, 4))
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


def test_chunks_drawn_with_more_pieces_are_re_sent_first():
    """A tree growing fast leaves chunks to re-level faster than they go out: a chunk still
    drawn in full goes before one a rewire touched that is already drawn in fewer pieces."""
    ch = EdgeChunks(seg=4, chunk=2, full_chunks=1, old_seg=2)
    line = np.column_stack([np.linspace(0, 4, 5), np.zeros(5)])
    for node in (0, 1):
        ch.set(node, line)
    assert [(c, len(seg)) for c, seg in ch.take_tail()] == [(0, 8)]  # in full: 4 pieces an edge
    for node in (2, 3):
        ch.set(node, line)
    ch.take_tail()
    assert [(c, len(seg)) for c, seg in ch.take_rewired(5)] == [(0, 4)]  # re-levelled: 2 pieces
    ch.set(0, line * 2)  # a rewire in chunk 0
    for node in (4, 5):  # chunk 1 falls behind the newest: to re-level
        ch.set(node, line)
    assert ch.new_chunks() == 1
    assert [c for c, _ in ch.take_tail()] == [2]
    assert ch.new_chunks() == 0 and ch.pending_rewired() == 2
    assert [(c, len(seg)) for c, seg in ch.take_rewired(1)] == [(1, 4)]  # not the older 0
    assert [c for c, _ in ch.take_rewired(1)] == [0]
    assert ch.pending_rewired() == 0


def test_a_coarse_tree_draws_its_newest_chunks_like_the_old_and_in_full_after():
    """While a tree grows faster than the eye can follow, its newest chunks too go out in
    OLD_SEG pieces an edge; back from coarse, they are re-sent in full."""
    ch = EdgeChunks(seg=4, chunk=2, full_chunks=2, old_seg=2)
    line = np.column_stack([np.linspace(0, 4, 5), np.zeros(5)])
    for node in range(4):
        ch.set(node, line)
    ch.coarse = True
    assert [(c, len(seg)) for c, seg in ch.take_tail()] == [(0, 4), (1, 4)]
    ch.coarse = False
    assert [(c, len(seg)) for c, seg in ch.take_rewired(5)] == [(0, 8), (1, 8)]


def test_a_slow_tree_goes_out_five_times_a_second_a_fast_one_coarse_and_less_often():
    """Each scene update keeps the browser rendering for a while: a tree growing by a few
    chunks a tick goes out every HEAVY_BURST_TICKS, its newest chunks coarse; a slow one, or
    one that stopped, every BURST_TICKS, in full."""
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    edge = np.column_stack([np.linspace(0, 1, SEG + 1), np.zeros(SEG + 1)])

    def grow(live, view, per_tick: int, ticks: int) -> list[int]:
        """The ticks (from 0) on which tree chunks went out."""
        out = []
        for t in range(ticks):
            for _ in range(per_tick):
                live.chunks.set(live.chunks.count, edge)
            sent = view.sent_chunks
            view.tick()
            if view.sent_chunks > sent:
                out.append(t)
        return out

    try:
        slow = Live(state="running")
        view = LiveView(server.scene, slow, (0.0, 0.0, 10.0, 10.0))
        assert grow(slow, view, 8, 31) == [0, 5, 10, 15, 20, 25, 30]
        assert len(view._chunks[slow.chunks.chunks - 1].points) == (8 * 31 % CHUNK) * SEG
        fast = Live(state="running")
        view = LiveView(server.scene, fast, (0.0, 0.0, 10.0, 10.0), root="/fast")
        assert grow(fast, view, CHUNK, 41) == [0, HEAVY_BURST_TICKS, 2 * HEAVY_BURST_TICKS]
        newest = fast.chunks.chunks - 1
        assert len(view._chunks[newest].points) == CHUNK * OLD_SEG  # coarse
        fast.state = "paused"
        grow(fast, view, 0, BURST_TICKS + 1)
        assert len(view._chunks[newest].points) == CHUNK * SEG  # in full again
    finally:
        server.stop()


def test_a_tree_growing_faster_than_the_tail_budget_is_sent_behind_and_catches_up():
    ch = EdgeChunks(seg=2, chunk=4)
    line = np.array([[0, 0], [1, 0], [2, 0]], float)
    for node in range(10):  # chunks 0, 1 full; chunk 2 the tail
        ch.set(node, line + node)
    assert [c for c, _ in ch.take_tail(8)] == [0]  # one chunk's pieces per call
    ch.set(10, line)
    assert [c for c, _ in ch.take_tail(8)] == [1]
    assert [(c, len(seg)) for c, seg in ch.take_tail(8)] == [(2, 6)]  # caught up: 3 nodes
    assert ch.take_tail(8) == []


def test_chunk_messages_stay_the_same_size_however_big_the_tree():
    ch = EdgeChunks(seg=4, chunk=256)
    pts = np.zeros((5, 2))
    sizes = []
    for node in range(5000):
        ch.set(node, pts)
        if node % 256 == 255:
            sizes.append(sum(seg.nbytes for _, seg in ch.take_tail()))
    assert max(sizes) == min(sizes) == 256 * 4 * 2 * 3 * 4


def test_the_drawn_tree_stays_bounded_however_big_it_grows():
    """What the browser holds, tick after tick, while a tree grows to 30 000 nodes: the newest
    chunks in full, older edges in OLD_SEG pieces, and past OLD_PIECES of those every k-th
    edge (k a power of two); always under the bound, and every node's chunk is drawn."""
    ch = EdgeChunks()
    curve = np.column_stack([np.linspace(0, 1, SEG + 1), np.linspace(0, 1, SEG + 1) ** 2])
    browser: dict[int, np.ndarray] = {}
    for node in range(30_000):
        ch.set(node, curve + node)
        if node % 50 == 0 or node == 29_999:  # a UI tick: the tail, then the re-levelled
            for c, seg in ch.take_tail() + ch.take_rewired(4):
                browser[c] = seg
    while ch.pending_rewired():
        browser.update(ch.take_rewired(4))
    drawn = sum(len(seg) for seg in browser.values())
    assert drawn <= FULL_CHUNKS * CHUNK * SEG + OLD_PIECES, drawn
    assert len(browser) == ch.chunks
    newest, oldest = browser[ch.chunks - 1], browser[0]
    assert len(newest) == (30_000 % CHUNK or CHUNK) * SEG  # the tail keeps its curves
    old_nodes = (ch.chunks - FULL_CHUNKS) * CHUNK
    stride = 1 << (math.ceil(old_nodes * OLD_SEG / OLD_PIECES) - 1).bit_length()
    assert stride > 1
    edges = np.arange(0, CHUNK, stride)
    assert len(oldest) == len(edges) * OLD_SEG
    knots = curve[np.linspace(0, SEG, OLD_SEG + 1).astype(int)]  # along the curve, not a chord
    assert np.allclose(oldest[:, 0, :2], (knots[:-1] + edges[:, None, None]).reshape(-1, 2))
    assert np.allclose(oldest[:, 1, :2], (knots[1:] + edges[:, None, None]).reshape(-1, 2))
    assert np.allclose(ch.get(0), curve)  # clicks and replay still see the full edge


def test_extend_explains_what_each_iteration_really_did():
    """Every iteration of real RRT* runs maps to the line its event record implies: on the
    thesis track and on slalom, whose longer steps move x_new back from blocked Steers."""
    seen = set()
    for name in ("thesis", "slalom"):
        run = planner.Planner(_problem(name) if name == "thesis" else planner.compile_problem(
            planner.load_scenario(name)), planner.PlanOptions(seed=5))
        events = []
        run.add_listener(events.append)
        for _ in range(400):
            before = run.nodes
            run.step(1)
            ev = events[-1]
            info = StepInfo.from_events(ev, -1, len(ev.rewires))
            line, note = explain(info, star=True)
            seen.add(line)
            if info.nearest < 0:
                assert line == 0 and "SampleFree" in note
            elif info.new < 0:
                assert line == 4 and run.nodes == before  # no node added
            else:
                assert line == (8 if len(ev.rewires) else 7)
                assert f"#{info.new}" in note and f"#{info.parent}" in note
                assert run.snapshot().parent[info.new] == info.parent
                if info.blocked:  # moved back to half the free part, on Steer's path
                    seen.add("cut")
                    assert f"{info.free / 2:.2f} m" in note
                    assert info.free / 2 >= run.problem.rho
                    assert not np.allclose(run.snapshot().pose[info.new], ev.steered[-1])
    assert {7, 8, "cut"} <= seen  # nodes were added, with and without rewires, moved back
    html = render(8, "a <note>")
    assert html.count("<mark>") == 1 and STAR_LINES[8].split(":")[0] in html
    assert "&lt;note&gt;" in html


def test_rrt_shows_its_own_pseudocode_and_ends_on_its_insert_line():
    """RRT never runs Near, argmin or Rewire: its panel does not show them."""
    info = StepInfo(iteration=1, nearest=0, new=1, parent=0, n_near=0, n_rewired=0, radius=0.0)
    line, _ = explain(info, star=False)
    assert RRT_LINES[line].strip() == "T.add(x_new, parent = x_nearest)"
    html = render(line, star=False)
    assert "Rewire" not in html and "Near(" not in html and "argmin" not in html
    assert "Rewire" in render(None) and "Near(" in render(None)


def _draft(points) -> Draft:
    d = Draft()
    for p in points:
        d.add(p)
    return d


def test_a_drawn_loop_embedded_in_its_scenario_is_plannable_and_loads_back():
    track = _draft([(0, 0), (4, 0), (5, 3), (1, 4), (-1, 2)]).track(0.8, closed=True)
    scenario = custom_scenario(track, "drawn")
    parsed = planner.parse_scenario(json.loads(json.dumps(scenario)))  # as saved
    again = resolve_track(parsed)
    assert again.length_m == pytest.approx(track.length_m, rel=1e-6)
    assert again.width_m == pytest.approx(0.8)
    result = planner.solve(planner.compile_problem(parsed), time_limit=None, iterations=20000,
                           seed=0)
    assert result.solved
    # The path stays on the drawn track: every sample within half a width of the centreline.
    prof = track.sample(0.02)
    centre = np.column_stack([prof.x, prof.y])
    d = np.min(np.hypot(*(result.path[:, None, :2] - centre[None]).transpose(2, 0, 1)), axis=1)
    assert d.max() <= track.width_m / 2 + 0.02


def test_drawn_points_get_catmull_rom_handles_until_one_is_dragged():
    d = _draft([(0, 0), (1, 0), (2, 1), (3, 1)])
    assert np.allclose(d.handle(1, closed=False), (np.array([2, 1]) - [0, 0]) / 6)
    first = d.beziers(closed=False)[0]
    assert np.allclose(first[[0, 3]], [[0, 0], [1, 0]])  # through the clicked points
    d.handles[1] = np.array([0.0, 0.5])  # dragged: the tangent at point 1 turns up
    a, b = d.beziers(closed=False)[:2]
    assert np.allclose(a[2], [1, -0.5]) and np.allclose(b[1], [1, 0.5])  # mirrored: smooth
    svg = d.track(0.5, closed=False).to_svg()
    assert svg.count(" C ") == 3  # real cubic Béziers in the download


def test_too_few_drawn_points_are_refused():
    with pytest.raises(ValueError, match="at least 3"):
        _draft([(0, 0), (1, 0)]).track(0.5, closed=True)


def test_a_dragged_obstacle_keeps_its_shape_and_turns_about_its_centre():
    poly = {"type": "polygon", "points": [[0, 0], [2, 0], [2, 1], [0, 1]]}
    parsed = planner.parse_scenario({"name": "p", "bounds": [-5, -5, 5, 5], "start": [0, 0, 0],
                                     "goal": [1, 1, 0], "obstacles": [poly]}).obstacles[0]
    moved = moved_obstacle(poly, parsed, 3.0, 2.0, math.pi / 2, None)
    pts = np.array(moved["points"])
    assert np.allclose(pts.mean(axis=0), [3, 2])
    assert np.allclose(np.ptp(pts, axis=0), [1, 2])  # turned a quarter
    box = {"type": "box", "center": [0, 0], "size": [1, 0.5]}
    assert moved_obstacle(box, None, 1, 2, math.radians(30), None) == {
        "type": "box", "center": [1, 2], "size": [1, 0.5], "angle_deg": 30.0}


def test_waypoints_text_is_rows_of_t_dx_dy():
    assert parse_waypoints("0 0 0; 3 0.5 0\n6, 1, 1") == [[0, 0, 0], [3, 0.5, 0], [6, 1, 1]]
    with pytest.raises(ValueError, match="t dx dy"):
        parse_waypoints("0 0; 1 1 1")


def test_a_run_that_ends_between_metric_updates_still_shows_its_last_numbers():
    """Metrics are throttled to two a second; a 300-iteration run ends well within one."""
    from app.studio._worker import PlannerWorker

    worker = PlannerWorker(_problem(), planner.PlanOptions(seed=0), budget=300)
    try:
        _run_to_the_end(worker)
        assert worker.live.state == "done"
        assert worker.live.metrics["iterations"] == 300
        assert worker.live.metrics["nodes"] == worker.lanes[0].run.nodes > 2
    finally:
        worker.stop()


def test_timing_optimal_shows_the_schedule_and_drive_car_stands_still_through_its_wait():
    """The level crossing: the path shown is the run's result, the car waiting for the train;
    Drive car holds the pose of the wait's start while the scene time runs on."""
    from app.studio._run_text import metrics_md, pose_at_time
    from app.studio._worker import PlannerWorker

    problem = planner.compile_problem(planner.load_scenario("train"))
    worker = PlannerWorker(problem, planner.PlanOptions(seed=3, timing="optimal"), budget=1500)
    try:
        _run_to_the_end(worker)
        path, m = worker.live.best_path, worker.live.metrics
    finally:
        worker.stop()
    assert worker.live.error is None and worker.lanes[0].run.detour.iterations == 1500
    assert m["waited_s"] > 10.0 and m["arrival_s"] == pytest.approx(path[-1, 5])
    assert f"| arrives after | {m['arrival_s']:.3g} s (waits {m['waited_s']:.3g} s) |" in (
        metrics_md(m))
    # When it came, in the planner's own terms (a paced run takes longer to watch).
    first = m["first_solution_iteration"]
    assert 0 < first <= 1500 and (f"| first solution | iteration {first:,} "
                                  f"({m['time_to_first_solution_s']:.3g} s of planning) |"
                                  ) in metrics_md(m)
    still = np.flatnonzero(np.all(np.diff(path[:, :3], axis=0) == 0.0, axis=1))  # i to i + 1
    assert np.diff(path[:, 5])[still].sum() == pytest.approx(m["waited_s"])
    for i in still:
        for t in np.linspace(path[i, 5], path[i + 1, 5], 3):
            assert pose_at_time(path, t) == tuple(path[i, :3])


def test_an_uploaded_csv_track_is_offered_shown_and_embedded_with_its_side_widths():
    from types import SimpleNamespace

    from app.studio._sources import Sources

    n, r = 60, 4.0
    rows = [f"{r * math.cos(2 * math.pi * k / n)},{r * math.sin(2 * math.pi * k / n)},0.5,1.0"
            for k in range(n)]
    ui = SimpleNamespace(svg_upload=SimpleNamespace(value=SimpleNamespace(
        name="ring.csv", content="\n".join(rows).encode())),
        svg_path=SimpleNamespace(options=(), visible=False, value="—"),
        track=SimpleNamespace(options=("thesis",), value="thesis"))
    shown = []
    sources = Sources(None, ui, None, "", lambda track, scenario: shown.append((track, scenario)),
                      lambda *message: pytest.fail(str(message)))
    sources.svg_uploaded()
    assert ui.svg_path.options == ("ring",) and not ui.svg_path.visible
    ui.svg_path.value = "ring"  # what the dropdown's update fires
    sources.svg_path_chosen()
    track, scenario = shown[-1]
    assert ui.track.value == "ring" and ui.track.options[-1] == "ring"  # named in the dropdown
    again = resolve_track(planner.parse_scenario(json.loads(json.dumps(scenario))))
    assert again.length_m == pytest.approx(track.length_m, rel=1e-6) and again.closed
    assert [w[0] for w in again.widths_at(np.array([1.0]))] == pytest.approx([0.5, 1.0])


def test_the_raceline_download_is_the_best_path_within_the_scenario_vehicle():
    from types import SimpleNamespace

    from app.studio._planner_run import PlannerRun

    run = PlannerRun(None, None, None, None, None, None)
    assert run.raceline() is None  # no run yet
    scenario = planner.parse_scenario(dict(default_scenario("thesis"),
                                           vehicle={"speed": 1.0, "max_speed": 1.5}))
    path = np.column_stack([np.linspace(0, 6, 121), np.zeros(121), np.zeros(121)])
    run.worker = SimpleNamespace(live=SimpleNamespace(best_path=path))
    run.stage = SimpleNamespace(parsed=scenario)
    lines = run.raceline().splitlines()
    vx = [float(line.split(";")[5]) for line in lines[1:]]
    assert lines[0].startswith("# s_m; x_m") and max(vx) == pytest.approx(1.5) and vx[-1] == 0


def test_the_vehicle_folder_reads_back_the_scenario_car_and_keeps_what_it_does_not_show():
    from app.studio._vehicle import fields_of, vehicle_from_fields

    base = {"wheelbase": 0.3, "max_steer_deg": 30.0, "speed": 1.5, "safety_margin": 0.02,
            "max_accel": 2.0, "min_turning_radius": 0.6,
            "footprint": {"type": "rectangle", "length": 0.5, "width": 0.25,
                          "rear_overhang": 0.05}}
    fields = fields_of(planner.scenario.Vehicle.model_validate(base))
    assert vehicle_from_fields(base, fields) == base
    disc = vehicle_from_fields(base, dict(fields, footprint="disc", radius=0.1, wheelbase=0.25))
    assert disc["radius"] == 0.1 and "footprint" not in disc and disc["max_accel"] == 2.0
    assert "min_turning_radius" not in disc  # it would overrule the new wheelbase
    servo = vehicle_from_fields(base, dict(fields, max_steer_rate_deg_s=60.0))
    assert servo == dict(base, max_steer_rate_deg_s=60.0)  # what CC-Dubins plans with


@pytest.mark.parametrize(("change", "message"), [
    ({"wheelbase": -0.1}, "wheelbase: Input should be greater than 0"),
    ({"radius": -0.05}, "radius: Input should be greater than or equal to 0"),
    ({"footprint": "rectangle", "length": 5.0, "width": 0.01}, "needs 500 discs"),
    ({"safety_margin": -1.0}, "safety_margin: Input should be greater than or equal to 0"),
    ({"max_steer_deg": 90.0}, "max_steer_deg: Input should be less than 90"),
    ({"max_steer_rate_deg_s": 0.0}, "max_steer_rate_deg_s: Input should be greater than 0"),
])
def test_the_vehicle_folder_refuses_what_the_scenario_model_refuses(change, message):
    from app.studio._vehicle import fields_of, vehicle_from_fields

    fields = dict(fields_of(planner.scenario.Vehicle()), length=0.4, width=0.2)
    with pytest.raises(ValueError, match=message):
        vehicle_from_fields({}, dict(fields, **change))


class _Scene:
    """Records what `draw_car` adds: node name → points."""

    def __init__(self) -> None:
        self.nodes = {}

    def add_frame(self, name, **_):
        return name

    def add_mesh_simple(self, name, verts, *_, **__):
        self.nodes[name] = verts

    def add_line_segments(self, name, seg, *_, **__):
        self.nodes[name] = seg


def test_the_drawn_car_is_the_planned_one_its_discs_and_its_safety_margin():
    from app.studio._scene import draw_car
    from app.studio._vehicle import fields_of, vehicle_from_fields

    fields = dict(fields_of(planner.scenario.Vehicle()), footprint="rectangle", length=0.4,
                  width=0.2, safety_margin=0.02)
    scenario = dict(default_scenario("thesis"), vehicle=vehicle_from_fields({}, fields))
    problem = planner.compile_problem(planner.parse_scenario(scenario))
    vehicle = problem.scenario.vehicle
    (d0, r), (d1, _) = vehicle.discs()
    assert np.allclose(problem.world.discs, vehicle.discs())  # what the planner checks
    scene = _Scene()
    draw_car(scene, "/car", vehicle, 0.01, (0.0, 0.0, 0.0))
    body = scene.nodes["/car/body"][:, :2]
    assert np.allclose(body.min(axis=0), [-0.0, -0.1]) and np.allclose(body.max(axis=0),
                                                                        [0.4, 0.1])
    for name, reach in (("/car/discs", r), ("/car/margin", r + 0.02)):
        pts = scene.nodes[name][:, 0, :2]
        gap = np.minimum(np.hypot(pts[:, 0] - d0, pts[:, 1]), np.hypot(pts[:, 0] - d1, pts[:, 1]))
        assert np.allclose(gap, reach, atol=2e-3), name


def test_an_svg_without_a_usable_path_says_why():
    from types import SimpleNamespace

    from app.studio._sources import Sources

    svg = b'<svg xmlns="http://www.w3.org/2000/svg"><text>no track</text></svg>'
    ui = SimpleNamespace(svg_upload=SimpleNamespace(value=SimpleNamespace(name="a.svg",
                                                                          content=svg)))
    said = []
    Sources(None, ui, None, "", lambda *_: pytest.fail("shown"),
            lambda *message: said.append(message)).svg_uploaded()
    assert said == [("No track in a.svg", "the document has no path of positive length")]


def test_iterations_per_second_is_the_rate_achieved_under_the_speed_throttle():

    from app.studio._worker import PlannerWorker

    worker = PlannerWorker(_problem(), planner.PlanOptions(seed=0), budget=100, rate=200.0)
    try:
        _run_to_the_end(worker)
        assert worker.live.metrics["iterations_per_s"] == pytest.approx(200, rel=0.25)
    finally:
        worker.stop()


def test_a_negative_budget_is_refused_with_the_models_message():
    from types import SimpleNamespace

    from app.studio._planner_run import PlannerRun

    ui = SimpleNamespace(planner_name=SimpleNamespace(value="RRT*"),
                         steering=SimpleNamespace(value=next(iter(STEERINGS))),
                         timing=SimpleNamespace(value="constant speed"),
                         eps=SimpleNamespace(value=0.0), gamma=SimpleNamespace(value=0.0),
                         k_rrt=SimpleNamespace(value=0.0), goal_bias=SimpleNamespace(value=0.05),
                         seed=SimpleNamespace(value=0), budget=SimpleNamespace(value=-5))
    run = PlannerRun(None, None, ui, None, None, None)
    with pytest.raises(ValueError, match="Budget: Input should be greater than or equal to 1"):
        run.options()


def test_step_labels_never_share_a_place():
    from app.studio._labels import step_labels
    from app.studio._worker import Rewired, Step

    bounds = (-10.0, -10.0, 10.0, 10.0)  # markers of 0.12
    rand, nearest = np.array([1.0, 1.0, 0.0]), np.array([0.0, 0.0, 0.0])

    def step(new, blocked=None, rand=rand, rewired=()):
        return Step(None, True, planner.PlanOptions(), rand, nearest, new, blocked, None,
                    np.zeros((0, 3)), 0.0, rewired)

    def labels(new, blocked=None, rand=rand):
        st = step(new, blocked, rand)
        return {text: (where, anchor) for _, text, where, anchor in step_labels(st, bounds)}

    assert list(labels(rand.copy())) == ["x_new = x_rand", "x_nearest"]
    short = labels(rand * 0.98)  # x_new just short of x_rand: their labels go opposite ways
    assert short["x_new"][1] != short["x_rand"][1] and short["x_nearest"][1] == "top-right"
    across = labels(np.array([0.3, 0.0, 0.0]), rand=np.array([2.0, 0.0, 0.0]))
    (x_new, _), (x_nearest, _) = across["x_new"], across["x_nearest"]
    assert x_nearest[0] < 0 < x_new[0]  # on a line: x_nearest's label left, x_new's right
    blocked = labels(None, (np.array([0.3, 0.1, 0.0]), None), rand=np.array([2.0, 0.0, 0.0]))
    assert set(blocked) == {"x_new (blocked)", "x_rand", "x_nearest"}
    # A big tree's iteration rewires many nodes: only the two that gained most are labelled.
    edge = np.array([[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]])
    rewired = tuple(Rewired(edge + k, edge - k, 9.0 + k, 8.9 + k - gain)
                    for k, gain in enumerate((0.1, 0.7, 0.3, 0.9, 0.2)))
    st = step(rand.copy(), rewired=rewired)
    texts = [text for _, text, _, _ in step_labels(st, bounds)]
    assert [t for t in texts if t.startswith(("old", "new"))] == [
        "old 12.00 m", "new 11.00 m", "old 10.00 m", "new 9.20 m"]


def test_step_until_a_rewire_stops_at_one_and_states_the_near_radius_it_used():
    """`Step until a rewire` runs single iterations to the first that rewired, shows each
    rewired node's cost before and after, and r(n)'s formula with its numbers gives the radius
    the kernel used (γ = 2: its term, not ε, bounds r)."""
    from app.studio._extend import near_note
    from app.studio._worker import PlannerWorker

    worker = PlannerWorker(_problem(), planner.PlanOptions(seed=0, gamma=2.0), budget=5000)
    try:
        worker.step("rewire")
        deadline = time.monotonic() + 10
        while worker.live.step is None and time.monotonic() < deadline:
            time.sleep(0.01)
        step, nodes = worker.live.step, worker.lanes[0].run.nodes
    finally:
        worker.stop()
    info = step.info
    assert step.until == ("rewire", info.iteration, "found") and info.n_rewired > 0
    assert info.new == nodes - 1 and all(r.now < r.was for r in step.rewired)
    note = near_note(info, step.options)
    term = 2.0 * (math.log(nodes) / nodes) ** (1 / 3)
    assert term < step.options.eps and info.radius == pytest.approx(term)
    assert note.endswith(f"= min({term:.2f}, {step.options.eps:.2f}) = {info.radius:.2f} m "
                         f"(n = {nodes} nodes, d = 3: x, y, θ).")


def test_pinned_runs_keep_their_colours_and_the_comparison_has_a_row_and_curves_for_each():
    """Pins: four at most, a fifth replaces the oldest and takes its colour. The CSV has one
    row per pinned run and the current one with that run's numbers; the plots get a series
    per pin that matches its data, none starting with NaN (uPlot would then draw nothing) and
    RRT's one solution held as a line; the PNG is the plots."""
    import csv
    import io
    from types import SimpleNamespace

    from PIL import Image

    from app.raceline import raceline_limits
    from app.studio._compare import (
        CURRENT,
        MAX_PINS,
        PALETTE,
        Pins,
        Run,
        comparison_csv,
        comparison_png,
    )
    from app.studio._plots import Profiles
    from app.studio._worker import PlannerWorker

    problem = planner.compile_problem(planner.load_scenario("slalom"))  # quick to compile
    workers = [PlannerWorker(problem, options, budget=600)
               for options in (planner.PlanOptions(planner="rrt", seed=0),
                               planner.PlanOptions(seed=0))]
    try:
        for worker in workers:  # side by side
            worker.run()
        for worker in workers:
            _run_to_the_end(worker)
    finally:
        for worker in workers:
            worker.stop()
    rrt, star = (Run(w.options, w.live.metrics, w.live.best_path, w.live.cost_over_time,
                     problem.scenario.vehicle)
                 for w in workers)
    assert rrt.label == "RRT, Dubins, seed 0" and len(rrt.path) and len(star.path)

    drawn = []
    pins = Pins(SimpleNamespace(remove_by_name=lambda name: drawn.clear(),
                                add_frame=lambda *a, **k: None,
                                add_line_segments=lambda name, seg, rgb, **k: drawn.append(rgb)))
    for run in (rrt, star, rrt, star, rrt):
        pins.add(run)
    pins.draw(0.1)
    assert [p.name for p in pins.runs] == ["pin 2", "pin 3", "pin 4", "pin 5"]
    assert len(drawn) == MAX_PINS and pins.runs[-1].colour == PALETTE[0]  # pin 1's
    assert {p.colour for p in pins.runs} == set(PALETTE)

    pins.clear()
    pins.add(rrt)
    pins.add(star)
    compared = [*pins.runs, star]
    rows = list(csv.DictReader(io.StringIO(comparison_csv(compared))))
    assert [r["run"] for r in rows] == ["pin 1", "pin 2", "this run"]
    assert [r["colour"] for r in rows] == [PALETTE[0], PALETTE[1], CURRENT]
    assert [r["planner"] for r in rows] == ["rrt", "rrtstar", "rrtstar"]
    for row, run in zip(rows, compared):
        assert int(row["iterations"]) == run.metrics["iterations"]
        assert float(row["cost"]) == pytest.approx(run.metrics["cost"], rel=1e-5)
        assert float(row["length_m"]) == pytest.approx(float(row["cost"]), rel=1e-3)
        assert 0 < float(row["time_to_first_solution_s"]) and float(row["min_clearance_m"]) >= 0
        assert float(row["max_abs_curvature_per_m"]) <= 1 / problem.rho + 1e-6
        assert row["timing"] == "constant" and row["waited_s"] == ""
    # Compare shows the difference: each row after the first against the first (pin 1).
    assert [r["compared_with"] for r in rows] == ["", "pin 1", "pin 1"]
    assert all(rows[0][f"{k}_diff{x}"] == "" for k in ("cost", "nodes", "time_to_first_solution")
               for x in ("", "_pct"))
    for row, run in zip(rows[1:], compared[1:]):
        for key, stem in (("cost", "cost"), ("nodes", "nodes"),
                          ("time_to_first_solution_s", "time_to_first_solution")):
            a, b = float(row[key]), float(rows[0][key])
            assert float(row[f"{stem}_diff"]) == pytest.approx(a - b, rel=1e-5, abs=1e-9)
            assert float(row[f"{stem}_diff_pct"]) == pytest.approx(100 * (a - b) / b, rel=1e-4)
    assert int(rows[0]["nodes"]) == rrt.metrics["nodes"] < int(rows[1]["nodes"])
    legend = pins.legend_html((star,))
    assert "<b>pin 1</b>: RRT, Dubins, seed 0 — cost" in legend
    gain = 100 * (star.metrics["cost"] - rrt.metrics["cost"]) / rrt.metrics["cost"]
    less = abs(star.metrics["cost"] - rrt.metrics["cost"])
    assert gain < 0 and f"vs pin 1: cost −{less:.3g} m (−{abs(gain):.2g} %)" in legend
    assert legend.count("vs pin 1:") == 2 and f"{star.metrics['nodes']} nodes" in legend

    charts = []
    gui = SimpleNamespace(add_uplot=lambda data, series, **k: charts.append(
        SimpleNamespace(data=data, series=series)) or charts[-1],
                          add_markdown=lambda content: SimpleNamespace(content=content))
    profiles = Profiles(gui, np.linspace(0, 14, 50), np.zeros(50), 10.0, 0.44, 26.0, 180.0,
                        raceline_limits(vehicle=problem.scenario.vehicle))
    profiles.show_path(star.path)
    profiles.show_cost(star)
    profiles.set_pins(pins.runs)
    curvature, steering, rate, slope, _, cost = charts
    for chart in (curvature, steering, rate, slope, cost):
        assert [s["label"] for s in chart.series[-2:]] in (
            [f"pin 1{x}", f"pin 2{x}"] for x in (" κ", " δ", " dδ/dt", " dκ/ds", ""))
        assert len(chart.series) == len(chart.data)
        assert len({len(d) for d in chart.data}) == 1
        assert not any(np.isnan(d[0]) for d in chart.data[1:])
    held = cost.data[2]  # pin 1, RRT: its one cost to the axis' end
    assert held[-1] == pytest.approx(rrt.metrics["cost"]) and np.isfinite(cost.data[1][-1])

    png = comparison_png(compared, "slalom: compared runs")
    assert Image.open(io.BytesIO(png)).size == (800, 900) and len(png) > 30_000


def test_run_on_a_finished_run_goes_on_for_another_budget():
    """A lecture budget ends while the tree is readable; Run then goes on for as many again,
    growing the same tree a longer run of that seed grows. RRT, done at its first solution,
    does not run on."""
    from app.studio._worker import PlannerWorker

    problem = _problem("slalom")
    options = planner.PlanOptions(seed=0)
    worker = PlannerWorker(problem, options, budget=300)
    try:
        _run_to_the_end(worker)
        lane = worker.lanes[0]
        assert lane.tree.iterations == 300 and worker.can_run_on
        worker.run()
        deadline = time.monotonic() + 10
        while lane.tree.iterations < 600 and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(0.1)
        assert lane.tree.iterations == 600 and worker.budget == 600
        same = planner.Planner(problem, options)
        same.step(600)
        assert np.array_equal(lane.tree.snapshot().parent, same.snapshot().parent)
    finally:
        worker.stop()
    rrt = PlannerWorker(problem, planner.PlanOptions(planner="rrt", seed=0), budget=5000)
    try:
        _run_to_the_end(rrt)
        assert rrt.lanes[0].run.finished and not rrt.can_run_on
    finally:
        rrt.stop()


def test_a_gizmo_drag_previews_under_the_session_lock():
    """The ticker moves the obstacles along the scene clock holding the session's lock; a
    gizmo's drag previews on viser's event loop. A preview waits for the lock, and a dragged
    moving obstacle then goes on along its motion from where it was dragged to."""
    import threading

    from planner.obstacles import table_offsets
    from tests._studio_tab import open_tab, wait

    with open_tab() as session:
        stage = session.stage
        session.sources.load_scenario(
            json.loads(planner.bundled_scenario_path("crossing").read_text()))
        assert wait(lambda: stage.parsed is not None and stage.parsed.name == "crossing")
        i = next(k for k, (_, _, table) in enumerate(stage._drawn) if table is not None)
        frame, _, table = stage._drawn[i]
        before = tuple(frame.position)
        previewed = threading.Event()

        def drag() -> None:
            stage.preview_obstacle(i, 1.0, 2.0, 0.0)
            previewed.set()

        with session._lock:  # as the ticker holds it while it draws
            threading.Thread(target=drag, daemon=True).start()
            assert not previewed.wait(0.3)
            assert tuple(frame.position) == before
        assert previewed.wait(5)
        with session._lock:
            stage.show_time(1.5)  # the ticker, at a later scene time
            dx, dy = table_offsets(table, 1.5)[0]
            assert tuple(frame.position[:2]) == pytest.approx((1.0 + dx, 2.0 + dy))
