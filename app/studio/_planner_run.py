"""The planner's run in one tab and everything that shows it: the worker, its live drawing, the
profile plots, the `Status`, `Metrics` and `EXTEND` panels, the car that drives the best path
(`Drive car`), the pinned runs it is compared with and the two-up split (a run B beside it, on
the same clock: `Split`, _split.py).

`PlannerRun` is the only writer of those; it plans the stage's current problem, and any change
of scenario or planner setting starts a fresh run (`reset`): the old tree belongs to the old one.
The pins stay until `Clear pins` or another track.
"""

from __future__ import annotations

import math
import time

import numpy as np
from pydantic import ValidationError

import planner
import tracks
from app.raceline import path_raceline, raceline_limits
from app.studio._compare import CURRENT, SPLIT_B, Pins, Run, settings_words
from app.studio._extend import FIRST_NOTE, explain, near_note, render, until_note
from app.studio._live_view import LiveView, Look
from app.studio._panel import DEFAULT_BUDGET, PLANNERS, SPEEDS, STEERINGS, TIMINGS
from app.studio._plots import Profiles
from app.studio._scenario import goal_fraction
from app.studio._scene import draw_car, marker_size, yaw_wxyz
from app.studio._split import Split
from app.studio._tree import EdgeChunks
from app.studio._worker import PlannerWorker
from planner.validation import describe

__all__ = ["PlannerRun", "pose_at_time"]

SPLIT_REPLAY = "Replay: one run at a time (leave the split to replay)"
PLOT_S = 1.0  # profile plots redraw at most this often (uPlot re-renders all of it)
OLD_EDGES = 300_000  # replayed edges a tree no longer holds, kept at most (a few 10 MB)


class PlannerRun:
    def __init__(self, gui, scene, ui, stage, clock, notify) -> None:
        self.gui, self.scene, self.ui = gui, scene, ui
        self.stage, self.clock, self.notify = stage, clock, notify
        self.worker: PlannerWorker | None = None
        self._driving = False  # the car shows the best path at the scene time
        self._view: LiveView | None = None
        self.split = Split(scene)  # run B's half of the scene
        self._choosing_b = False  # `choose_split` sets B's controls
        self.look = Look()  # how it draws the run (`set_look`)
        self._profiles: Profiles | None = None
        self._car = None
        self._shown: dict = {}  # versions of the worker's record already shown
        self.pins = Pins(scene)
        self._track = None  # the pins' track
        self._old_edges: dict[tuple[int, int], np.ndarray] = {}  # (node, parent): its points

    def new_track(self, track: tracks.Track, vehicle) -> None:
        """The stage cleared the scene (the run's drawing went with it): profile plots of the
        new track's centreline, for a vehicle of this size. Pins stay on the same track (a
        car's settings changed: they compare it with the car before)."""
        self._view = self._car = None
        self.split.forget()
        if self._profiles is not None:
            for h in self._profiles.handles:
                h.remove()
        prof = track.sample(track.detail_spacing(), vehicle.wheelbase, vehicle.max_steer_deg)
        with self.ui.plots:
            self._profiles = Profiles(self.gui, prof.s, prof.curvature,
                                      goal_fraction(track.closed) * track.length_m,
                                      vehicle.wheelbase, vehicle.max_steer_deg,
                                      raceline_limits(vehicle=vehicle))
        if track is not self._track:
            self._track = track
            self.pins.clear()
        self._show_pins()

    def options(self) -> planner.PlanOptions:
        """The planner panel as `PlanOptions`: 0 in a number field means "derived". Raises
        ValueError with the model's one-line message for a value it refuses (a typed Budget of
        -5 gets past the field's minimum)."""
        u = self.ui
        try:
            return planner.PlanOptions(
                planner=PLANNERS[u.planner_name.value], steering=STEERINGS[u.steering.value],
                timing=TIMINGS[u.timing.value], eps=u.eps.value or None,
                gamma=u.gamma.value or None, k_rrt=u.k_rrt.value or None,
                goal_bias=float(u.goal_bias.value),
                seed=int(u.seed.value), iterations=int(u.budget.value))
        except ValidationError as exc:
            raise ValueError(describe(exc).replace("iterations:", "Budget:")) from None

    def iterations_on_screen(self, options: planner.PlanOptions) -> int | None:
        """The iterations the run on screen has done when it runs with ``options`` (the
        panel's now; None otherwise): an export then draws that run to where it is."""
        if self.worker is None:
            return None
        lane = self.worker.lanes[0]
        return lane.stepped if lane.options == options and lane.stepped else None

    def _options_b(self, a: planner.PlanOptions, problem) -> planner.PlanOptions | None:
        """Run B's options in the split (A's, with B's planner, steering and seed); None
        outside it. A steering this robot cannot drive is refused: B then plans as A."""
        u = self.ui
        if not u.split.value:
            return None
        b = a.model_copy(update={"planner": PLANNERS[u.b_planner.value],
                                 "steering": STEERINGS[u.b_steering.value],
                                 "seed": int(u.b_seed.value)})
        try:
            b.resolved(problem)
        except ValueError as exc:
            self.notify("Run B's options", str(exc))
            return a
        return b

    @property
    def splitting(self) -> bool:
        """Whether the run is the two-up split (A and B)."""
        return self.worker is not None and len(self.worker.lanes) > 1

    def choose_split(self) -> None:
        """`Split` ticked: B starts as the other planner of A with A's steering and seed (one
        reset for the three, see `b_changed`)."""
        u = self.ui
        if u.split.value:
            self._choosing_b = True
            try:
                u.b_planner.value = next(k for k in PLANNERS if k != u.planner_name.value)
                u.b_steering.value, u.b_seed.value = u.steering.value, u.seed.value
            finally:
                self._choosing_b = False
        self.reset()

    def b_changed(self) -> None:
        """Run B's planner, steering or seed edited: a fresh split (none outside it)."""
        if self.ui.split.value and not self._choosing_b:
            self.reset()

    def view_bounds(self):
        """What the view fit frames: the scene, and B's half beside it in the split."""
        if self.stage.problem is None:
            return None
        return self.split.bounds(self.stage.problem.bounds)

    def reset(self) -> None:
        """A fresh run of the stage's problem with the current settings (the old worker is
        stopped first)."""
        problem = self.stage.problem
        self.stop()
        if self._view is not None:
            self._view.clear()
        try:
            options = self.options()
            options.resolved(problem)  # refuses a robot this steering cannot drive
        except ValueError as exc:
            self.notify("Planner options", str(exc))
            options = planner.PlanOptions(iterations=DEFAULT_BUDGET)
        other = self._options_b(options, problem)
        self.worker = PlannerWorker(problem, options, options.iterations,
                                    SPEEDS[self.ui.rate.value], other)
        camera = self.stage.client.camera
        self._view = LiveView(self.scene, self.worker.live, problem.bounds, self.look, camera)
        if other is None:
            self.split.hide()
        else:
            self.split.show(self.stage, tuple(f"{n}: {' · '.join(settings_words(o))}"
                                              for n, o in (("A", options), ("B", other))),
                            self.worker.lanes[1].live, self.look, camera)
        self._shown = {"metrics": (), "best": (), "step": (), "cost": (), "replay": -1}
        self._old_edges.clear()
        self._driving = False
        if self._car is not None:
            self._car.remove()
            self._car = None
        self.ui.metrics.content = "—"
        self.ui.extend.content = render(None, FIRST_NOTE, star=options.planner == "rrtstar")
        self._show_pins_legend()
        if self._profiles is not None:
            self._profiles.set_steering(options.steering)
            self._profiles.show_path(np.zeros((0, 4)), self.current_b())
            self._profiles.show_cost(*self._compared_now())

    def stop(self) -> None:
        if self.worker is not None:
            self.worker.stop()

    def resume(self, command: str) -> None:
        """`Run`, `Pause` or `Step` (the worker's command); Run and Step go back from a replay
        to the run first."""
        if command != "pause":
            self.replay_end()
        getattr(self.worker, command)()

    def set_rate(self) -> None:
        self.worker.rate = SPEEDS[self.ui.rate.value]

    def step(self, until: str) -> None:
        """`Step until a node is added` ("node") or `Step until a rewire` ("rewire")."""
        if until == "rewire" and all(lane.options.planner == "rrt"
                                     for lane in self.worker.lanes):
            self.notify("RRT never rewires", "choose the planner RRT* to see rewires")
            return
        self.replay_end()
        self.worker.step(until)

    @property
    def started(self) -> bool:
        """Whether the run has iterated (a `reset` starts a new one)."""
        return self.worker is not None and self.worker.started

    def set_look(self, look: Look) -> None:
        """Draw the run, now and from now on, with ``look`` (projector mode, a faded tree)."""
        self.look = look
        for view in (self._view, self.split.view):
            if view is not None:
                view.restyle(look)
        self._draw_pins()

    def raceline(self) -> str | None:
        """The best path in the TUM raceline layout within the scenario vehicle's limits (None
        before a path is found)."""
        path = self.worker.live.best_path if self.worker is not None else None
        if path is None or not len(path):
            return None
        return path_raceline(path, raceline_limits(vehicle=self.stage.parsed.vehicle))

    def pick(self, x: float, y: float) -> None:
        """A click on the ground at (x, y): the edge there says its word (`LiveView.pick`);
        in the split, right of the gap between the halves, run B's edge."""
        if self._view is not None and not self.split.pick(x, y):
            self._view.pick(x, y)

    # -- replay --------------------------------------------------------------------------------
    def replay(self, n: int) -> None:
        """The replay slider at iteration n: the tree and the best path as they stood then, on
        a paused or finished run (the worker's `TreeRecord`); at its last iteration, the run.
        Not in the split (the slider is disabled there)."""
        if self._view is None or self.worker.live.state == "running" or self.splitting:
            return
        record = self.worker.record
        if n >= record.iterations:
            self.replay_end()
            return
        frame = record.frame(n)
        edges = EdgeChunks(capacity=1)
        edges.fill(self._replayed_edges(frame))
        self._view.replay(edges, frame.path)
        self.ui.replay_note.content = _replay_md(frame, record)

    def replay_end(self) -> None:
        """Back to the run from a replay: the slider at its end."""
        if self._view is None or not self._view.replaying:
            return
        self._view.live_again()
        end = self.worker.record.iterations
        self.ui.replay_note.content = _replay_md(None, self.worker.record)
        self.ui.replay.value = end

    def _replayed_edges(self, frame) -> np.ndarray:
        """The edges of ``frame``'s tree: as drawn live where a node's parent is still the
        one it had then, else the steering between the two poses (a rewire replaced the edge;
        kept for the next frames). A record that stopped steers every edge (the live tree
        went on from where it ends)."""
        record, n = self.worker.record, frame.nodes
        pts = self.worker.live.chunks.points(n)
        if record.note is None:
            final = record.frame(record.iterations).parent[:n]
            old = np.flatnonzero(frame.parent != final)
        else:
            old = np.arange(1, n)
        poses = record.poses(n)
        if len(self._old_edges) + len(old) > OLD_EDGES:
            self._old_edges.clear()
        for node in old.tolist():
            up = int(frame.parent[node])
            edge = self._old_edges.get((node, up))
            if edge is None:
                edge = self._old_edges[node, up] = self.worker.steer_points(poses[up],
                                                                             poses[node])
            pts[node] = edge
        return pts

    def _tick_replay(self, live) -> None:
        """The slider follows the record: usable once the run is paused or done, at its end
        while the run is shown."""
        slider, end = self.ui.replay, self.worker.record.iterations
        usable = live.state != "running" and end > 0 and not self.splitting
        if slider.disabled == usable:
            slider.disabled = not usable
        if self._view.replaying or self._shown["replay"] == end:
            return
        self._shown["replay"] = end
        slider.max = max(end, 1)
        slider.value = end
        self.ui.replay_note.content = (SPLIT_REPLAY if self.splitting
                                       else _replay_md(None, self.worker.record))

    # -- compare runs --------------------------------------------------------------------------
    def current(self) -> Run | None:
        """The current run as compared: its record as the worker last published it (metrics at
        most 0.5 s behind a running planner); None before the first run."""
        if self.worker is None:
            return None
        return self._run_of(0, "A" if self.splitting else "this run", CURRENT)

    def current_b(self) -> Run | None:
        """Run B of the split, as compared (None outside it)."""
        return self._run_of(1, "B", SPLIT_B) if self.splitting else None

    def _run_of(self, lane: int, name: str, colour: str) -> Run:
        lane = self.worker.lanes[lane]
        live = lane.live
        path = live.best_path if live.best_path is not None else np.zeros((0, 6))
        return Run(lane.options, dict(live.metrics), path, list(live.cost_over_time),
                   self.stage.parsed.vehicle, name, colour)

    def _compared_now(self) -> tuple[Run | None, Run | None]:
        """The current run and run B (None outside the split) with metrics of one moment."""
        if self.worker is None:
            return None, None
        with self.worker.published:
            return self.current(), self.current_b()

    def compared(self) -> list[Run]:
        """The pinned runs, oldest first, the current one and, in the split, run B."""
        a, b = self._compared_now()
        return [*self.pins.runs, a, *([b] if b is not None else [])]

    def pin(self) -> None:
        """`Pin this run`: its best path, profiles and cost over time stay drawn in a colour of
        their own while the next runs grow over them."""
        run = self.current()
        if run is None or not len(run.path):
            self.notify("No path yet", "press Run until a path to the goal is found")
        elif any(p.path is run.path for p in self.pins.runs):
            self.notify("Pinned already", "this run's best path is pinned as it is")
        else:
            self.pins.add(run)
            self._show_pins()

    def clear_pins(self) -> None:
        self.pins.clear()
        self._show_pins()

    def _draw_pins(self) -> None:
        """The pins with cusps sized like the scene's markers (pins exist only once a problem
        was planned: before, there is nothing to size)."""
        marker = marker_size(self.stage.problem.bounds) if self.pins.runs else 0.0
        self.pins.draw(marker, self.look.scale)

    def _show_pins(self) -> None:
        self._draw_pins()
        self._show_pins_legend()
        self._profiles.set_pins(self.pins.runs)

    def _show_pins_legend(self) -> None:
        """The pins' legend, ending with the current run (A and B in the split) and how it
        differs from the first pin; shown while there are pins."""
        if self.pins.runs:
            self.ui.pins_legend.content = self.pins.legend_html(
                tuple(r for r in self._compared_now() if r is not None))
        self.ui.pins_legend.visible = bool(self.pins.runs)

    # -- the car -------------------------------------------------------------------------------
    def drive(self) -> None:
        """`Drive car`: the scene clock restarts at 0 and plays; the car and the moving
        obstacles share it, so what the planner avoided in time is what you see avoided."""
        path = self.worker.live.best_path
        if path is None or not len(path):
            self.notify("No path yet", "press Run until a path to the goal is found")
            return
        self._driving = True
        self.clock.reach(path[-1, 5])
        self.show_car(0.0)  # the clock may be at 0 already: then setting it draws nothing
        self.clock.play_from_start()

    @property
    def drive_end(self) -> float | None:
        """When the driving car reaches the goal (the scene clock loops there); None when no
        car drives."""
        path = self.worker.live.best_path if self._driving else None
        return float(path[-1, 5]) if path is not None and len(path) else None

    def show_time(self, t: float) -> None:
        """The scene clock at t: run B's moving obstacles (the stage moves A's) and the driving
        car."""
        self.split.show_time(t)
        self.show_car(t)

    def show_car(self, t: float) -> None:
        """The driving car where the best path is at time t."""
        path = self.worker.live.best_path if self.worker is not None else None
        if not self._driving or path is None or not len(path):
            return
        x, y, th = pose_at_time(path, t)
        if self._car is None:
            problem = self.stage.problem
            self._car = draw_car(self.scene, "/live/car", problem.scenario.vehicle,
                                 marker_size(problem.bounds), (x, y, th))
        self._car.position = (x, y, 0.0)
        self._car.wxyz = yaw_wxyz(th)

    # -- the ticker ----------------------------------------------------------------------------
    def tick(self) -> None:
        """Draw the worker's progress and update the panels with what changed."""
        if self._view is None:
            return
        lives = [lane.live for lane in self.worker.lanes]
        for view in (self._view, self.split.view):
            if view is not None:
                view.tick()
        self._tick_replay(lives[0])
        status = "Status: " + ", ".join(
            (f"{name} " if len(lives) > 1 else "") + f"**{live.state}**"
            + (f" — {live.error}" if live.error else "") for name, live in zip("AB", lives))
        if self.worker.can_run_on:
            status += f" — Run goes on for {self.worker.run_on:,} iterations more"
        if status != self.ui.status.content:  # GUI updates re-render the panel: only changes
            self.ui.status.content = status
        with self.worker.published:
            versions = tuple(live.metrics_version for live in lives)
            metrics = [live.metrics for live in lives]
        if versions != self._shown["metrics"]:
            self._shown["metrics"] = versions
            self.ui.metrics.content = _metrics_md(*metrics)
            self._show_pins_legend()  # this run's numbers and difference
        if time.monotonic() - self._shown.get("plotted", 0.0) > PLOT_S:
            self._plot(lives)
        steps = tuple(live.step_version for live in lives)
        if steps != self._shown["step"] and lives[0].step is not None:
            self._shown["step"] = steps
            self.ui.extend.content = _extend_html([live.step for live in lives])

    def _plot(self, lives: list) -> None:
        """The profiles when a best path changed, the cost curves when the metrics did (they
        run on to the planning time so far); run B's too in the split."""
        now = time.monotonic()
        paths = tuple(live.best_version for live in lives)
        if paths != self._shown["best"]:
            self._shown["best"], self._shown["plotted"] = paths, now
            path = lives[0].best_path
            self._profiles.show_path(path if path is not None else np.zeros((0, 4)),
                                     self.current_b())
        costs = tuple(live.metrics_version for live in lives)
        if costs != self._shown["cost"]:
            self._shown["cost"], self._shown["plotted"] = costs, now
            self._profiles.show_cost(*self._compared_now())


def _extend_html(steps: list) -> str:
    """The EXTEND panel after a step: run A's line highlighted and explained; in the split, a
    line more on what run B's same iteration did."""
    step = steps[0]
    line, note = explain(step["info"], step["star"])
    notes = [until_note(*step["until"]), f"Iteration {step['info'].iteration}: {note}",
             near_note(step["info"], step["options"])]
    if len(steps) > 1 and steps[1] is not None:
        notes.append(f"B, its iteration {steps[1]['info'].iteration}: "
                     f"{explain(steps[1]['info'], steps[1]['star'])[1]}")
    return render(line, *notes, star=step["star"])


def pose_at_time(path: np.ndarray, t: float) -> tuple[float, float, float]:
    """The pose (x, y, θ) on a path's rows at time t, by their t column: through a wait (rows of
    one pose, t rising) the car stands still."""
    k = int(np.searchsorted(path[:, 5], t).clip(0, len(path) - 1))
    return tuple(float(v) for v in path[k, :3])


def _replay_md(frame, record) -> str:
    """The replay's line under its slider: the iteration shown of those recorded, its nodes
    and best cost (None: the run itself)."""
    end = record.iterations
    if frame is None:
        text = (f"Replay: iteration {end:,} of {end:,} (the run)" if end
                else "Replay: pause or finish a run")
    else:
        cost = "no path yet" if frame.cost is None else f"best cost {frame.cost:.4g} m"
        text = (f"Replay: iteration {frame.iteration:,} of {end:,} · {frame.nodes:,} nodes · "
                f"{cost}")
        if frame.cost is not None and frame.path_iteration != frame.cost_iteration:
            text += (" (no path drawn for it)" if frame.path is None else
                     f" (the path drawn is the one of iteration {frame.path_iteration:,}: "
                     "the cost fell again inside one of the planner's batches)")
    return text + (f". {record.note}." if record.note else "")


def _fmt(v, unit: str = "", digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return f"{v:.{digits}g}{unit}" if isinstance(v, float) else f"{v}{unit}"


def _metric_cells(m: dict) -> dict[str, str]:
    """One run's column of the metrics table, by row name."""
    if not m:
        return {}
    arrival = {} if m.get("arrival_s") is None else {  # timing optimal, once solved
        "arrives after": f"{_fmt(m['arrival_s'], ' s')} (waits {_fmt(m['waited_s'], ' s')})"}
    return {"iterations": f"{m['iterations']}", "nodes": f"{m['nodes']}",
            "rewires": f"{m['rewires']}",
            # The planner's own time, not the paced run's: at 20 it/s a 0.01 s solution takes
            # seconds to watch, so its iteration comes first.
            "first solution": "—" if m.get("first_solution_iteration") is None else (
                f"iteration {m['first_solution_iteration']:,} "
                f"({_fmt(m['time_to_first_solution_s'], ' s')} of planning)"),
            "cost": _fmt(m["cost"], " m", 4), **arrival,
            "min clearance": _fmt(m["min_clearance_m"], " m"),
            "iterations/s": _fmt(m["iterations_per_s"], "", 4)}


def _metrics_md(*runs: dict) -> str:
    """The metrics table: a column per run, headed A and B in the split."""
    cols = [_metric_cells(m) for m in runs]
    if not any(cols):
        return "—"
    rows = [f"| {k} | " + " | ".join(c.get(k, "—") for c in cols) + " |"
            for k in dict.fromkeys(k for c in cols for k in c)]
    if len(cols) == 1:  # the first row heads the table
        return "\n".join([rows[0], "|---|---|", *rows[1:]])
    return "\n".join(["| | A | B |", "|---|---|---|", *rows])
