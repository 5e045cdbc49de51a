"""The two-up split (issue 20), without a browser: a real studio (viser server, a websocket
client as the tab) plans run B beside run A on one clock — after N steps both have done N
iterations and hold the trees of same-seed planners stepped N times, B is drawn in a frame
moved by the scene's width and a margin, the metrics, plots and comparison CSV name both, and
leaving the split takes B away; the profiles send a chart's data and series in the order
viser's client needs."""

from __future__ import annotations

import csv
import io
import time
from types import SimpleNamespace

import numpy as np
import pytest
from PIL import Image

import planner
from app.raceline import raceline_limits
from app.studio._compare import SPLIT_B, Run, comparison_csv, comparison_png
from app.studio._plots import Profiles
from app.studio._split import B_RGB, ROOT, offset
from app.studio._tree import SEG
from planner.scenario import Vehicle
from tests._studio_tab import open_tab, wait
from tests.test_studio_pins import reversing_path

STEPS = 25


@pytest.fixture(scope="module")
def session():
    """One studio tab's session (the thesis track), its client connected until the end."""
    with open_tab() as session:
        yield session


def _node(session, name: str):
    return session.client.scene._handle_from_node_name.get(name)


def _iterations(run) -> list:
    with run.worker.published:
        return [lane.live.metrics.get("iterations") for lane in run.worker.lanes]


def test_split_steps_both_runs_on_one_clock_and_draws_b_beside_a(session):
    ui, run = session.ui, session.planning
    ui.seed.value = 1
    ui.split.value = True  # as the checkbox's callback: B is the other planner, same seed
    assert wait(lambda: run.splitting)
    assert (ui.b_planner.value, ui.b_steering.value, ui.b_seed.value) == (
        "RRT", ui.steering.value, 1)
    ui.b_planner.value, ui.b_steering.value, ui.b_seed.value = "RRT*", "Reeds-Shepp", 2
    lanes = run.worker.lanes
    assert [(o.planner, o.steering, o.seed) for o in (lane.options for lane in lanes)] == [
        ("rrtstar", "dubins", 1), ("rrtstar", "reeds-shepp", 2)]

    for _ in range(STEPS):
        run.resume("step")
    assert wait(lambda: _iterations(run) == [STEPS, STEPS])
    problem = session.stage.problem
    for lane in lanes:  # each tree is a same-seed planner's stepped STEPS single iterations
        same = planner.planner_for(problem, lane.options)
        for _ in range(STEPS):
            same.step(1)
        ours, theirs = lane.run.snapshot(), same.snapshot()
        assert lane.run.iterations == same.iterations == STEPS
        assert np.array_equal(ours.parent, theirs.parent)
        assert np.allclose(ours.pose, theirs.pose)
    assert not np.array_equal(lanes[0].run.snapshot().pose, lanes[1].run.snapshot().pose)

    # B in a frame moved along +x by the scene's width and a margin, its edges as planned.
    xmin, _, xmax, _ = problem.bounds
    frame = _node(session, ROOT)
    assert tuple(frame.position) == pytest.approx((offset(problem.bounds), 0.0, 0.0))
    assert offset(problem.bounds) > xmax - xmin
    b = lanes[1].live
    assert wait(lambda: sum(len(h.points) for h in run.split.view._chunks.values())
                 == SEG * b.chunks.count)
    view = run.split.view
    drawn = np.concatenate([view._chunks[c].points for c in sorted(view._chunks)])
    edges = b.chunks.points(b.chunks.count)
    assert np.allclose(drawn[:, 0, :2], edges[:, :-1].reshape(-1, 2))
    assert all(h.name.startswith(f"{ROOT}/live/") for h in view._chunks.values())
    x, y = b.chunks.get(1)[SEG // 2]  # a click on B's first edge, where it is drawn
    assert run.split.pick(x + offset(problem.bounds), y) and view._handles["pick_l"].visible
    assert not run.split.pick(x, y)  # in A's half: A's edge
    assert _node(session, f"{ROOT}/track/centre") is not None
    assert _node(session, "/split_a/title").text == "A: RRT* · Dubins · seed 1"
    assert _node(session, f"{ROOT}/title").text == "B: RRT* · Reeds-Shepp · seed 2"
    assert wait(lambda: f"| iterations | {STEPS} | {STEPS} |" in ui.metrics.content)
    assert "| | A | B |" in ui.metrics.content
    bounds = run.view_bounds()
    assert bounds[2] == pytest.approx(xmax + offset(problem.bounds))  # the fit frames both
    assert ui.replay.disabled

    ui.split.value = False  # back to the single run
    assert not run.splitting and run.split.view is None
    assert _node(session, ROOT) is None and _node(session, "/split_a") is None
    assert run.view_bounds() == problem.bounds
    assert all("B" not in s["label"] for s in run._profiles.curvature.series)


def test_split_runs_with_the_pace_on_one_clock_and_the_comparison_has_b(session):
    """A and B run 400 iterations at 200 it/s: at every moment the UI reads, they have done
    as many; the plots and the comparison CSV name A and B."""
    ui, run = session.ui, session.planning
    ui.rate.value = "200 it/s"
    ui.budget.value = 400
    ui.split.value = True
    ui.b_planner.value, ui.b_seed.value = "RRT*", 2  # RRT would stop at its first solution
    run.resume("run")
    seen = set()
    deadline = time.monotonic() + 30
    while run.worker.lanes[0].live.state != "done" and time.monotonic() < deadline:
        seen.add(tuple(_iterations(run)))
        time.sleep(0.003)
    assert len(seen - {(None, None)}) >= 3  # published twice a second over 2 s
    assert all(a == b for a, b in seen)
    assert wait(lambda: _iterations(run) == [400, 400])
    assert wait(lambda: ui.status.content == "Status: A **done**, B **done** — Run goes on "
                                             "for 400 iterations more")

    assert wait(lambda: "B κ" in [s["label"] for s in run._profiles.curvature.series])
    for chart, a_label, b_label in ((run._profiles.curvature, "A κ", "B κ"),
                                    (run._profiles.steering, "A δ", "B δ"),
                                    (run._profiles.cost, "A best cost (m)", "B")):
        labels = [s["label"] for s in chart.series]
        assert a_label in labels and labels[-1] == b_label
        assert chart.series[-1]["stroke"] == SPLIT_B
    rows = list(csv.DictReader(io.StringIO(comparison_csv(run.compared()))))
    assert [(r["run"], r["seed"], r["colour"]) for r in rows] == [
        ("A", "1", "#ff5ac8"), ("B", "2", SPLIT_B)]
    assert [int(r["iterations"]) for r in rows] == [400, 400]
    png = comparison_png(run.compared(), "thesis: A and B")
    assert Image.open(io.BytesIO(png)).size == (800, 900)
    assert tuple(np.ravel(run.split.view._handles["best"].colors)[:3]) == B_RGB
    ui.split.value = False



class _Chart(SimpleNamespace):
    """A uPlot handle that logs what is assigned to it ("data", "series"), in order."""

    def __setattr__(self, name: str, value) -> None:
        self.log.append(name)
        super().__setattr__(name, value)


def test_a_chart_gets_its_data_before_new_series_of_the_same_number():
    """viser's client rebuilds a chart whose series change and keeps its x zoom relative to
    the data it had: series that arrive with a new x range left the split's profiles showing
    0–45 m of a 9 m path. A cusp (new series, as many) goes after its data; a new run B (more
    series) goes first, with the data that matches it."""
    charts = []
    gui = SimpleNamespace(add_uplot=lambda data, series, **k: charts.append(
        _Chart(log=[], data=data, series=series)) or charts[-1],
                          add_markdown=lambda content: SimpleNamespace(content=content))
    profiles = Profiles(gui, np.linspace(0, 14, 50), np.zeros(50), 10.0, 0.44, 26.0, 180.0,
                        raceline_limits(vehicle=Vehicle()))
    curvature = charts[0]
    profiles.show_path(np.zeros((0, 6)))
    curvature.log.clear()
    profiles.show_path(reversing_path())  # a cusp: the points' filter changes
    assert curvature.log == ["data", "series"]
    b = Run(planner.PlanOptions(seed=2), {}, reversing_path(), [], Vehicle(), "B", SPLIT_B)
    curvature.log.clear()
    profiles.show_path(reversing_path(), b)
    assert curvature.log == ["series", "data"]
    assert len(curvature.series) == len(curvature.data)
