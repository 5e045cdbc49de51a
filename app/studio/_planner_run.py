"""The planner's run in one tab and everything that shows it: the worker, its live drawing, the
profile plots, the `Status`, `Metrics` and `EXTEND` panels, the car that drives the best path
(`Drive car`), the pinned runs it is compared with and the two-up split (a run B beside it, on
the same clock: `Split`, _split.py).

`PlannerRun` is the only writer of those; it plans the stage's current problem, and any change
of scenario or planner setting starts a fresh run (`reset`): the old tree belongs to the old one.
The pins stay until `Clear pins` or another track.
"""

from __future__ import annotations

import time

import numpy as np
from pydantic import ValidationError

import planner
import tracks
from app.raceline import path_raceline, raceline_limits
from app.studio._compare import CURRENT, SPLIT_B, Pins, Run, settings_words
from app.studio._drive import DrivenCar
from app.studio._extend import FIRST_NOTE, render
from app.studio._live_view import LiveView, Look
from app.studio._panel import DEFAULT_BUDGET, PLANNERS, SPEEDS, STEERINGS, TIMINGS
from app.studio._plots import Profiles
from app.studio._replay_slider import ReplaySlider
from app.studio._run_text import extend_html, metrics_md
from app.studio._scenario import goal_fraction
from app.studio._scene import marker_size
from app.studio._split import Split
from app.studio._worker import PlannerWorker
from planner.validation import describe

__all__ = ["PlannerRun"]

PLOT_S = 1.0  # profile plots redraw at most this often (uPlot re-renders all of it)


class PlannerRun:
    def __init__(self, gui, scene, ui, stage, clock, notify) -> None:
        self.gui, self.scene, self.ui = gui, scene, ui
        self.stage, self.clock, self.notify = stage, clock, notify
        self.worker: PlannerWorker | None = None
        self.car = DrivenCar(scene, clock, lambda: (self.worker.live.best_path
                                                    if self.worker is not None else None))
        self._view: LiveView | None = None
        self.split = Split(scene)  # run B's half of the scene
        self._choosing_b = False  # `choose_split` sets B's controls
        self.look = Look()  # how it draws the run (`set_look`)
        self._profiles: Profiles | None = None
        self._shown: dict = {}  # versions of the worker's record already shown
        self.pins = Pins(scene)
        self._track = None  # the pins' track
        self.replayer = ReplaySlider(ui)

    def new_track(self, track: tracks.Track, vehicle) -> None:
        """The stage cleared the scene (the run's drawing went with it): profile plots of the
        new track's centreline, for a vehicle of this size. Pins stay on the same track (a
        car's settings changed: they compare it with the car before)."""
        self._view = None
        self.car.forget()
        self.split.forget()
        if self._profiles is not None:
            for h in self._profiles.handles:
                h.remove()
        prof = track.sample(track.detail_spacing(), vehicle.wheelbase, vehicle.max_steer_deg)
        with self.ui.plots:
            self._profiles = Profiles(self.gui, prof.s, prof.curvature,
                                      goal_fraction(track.closed) * track.length_m,
                                      vehicle.wheelbase, vehicle.max_steer_deg,
                                      vehicle.max_steer_rate_deg_s,
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
        self._shown = {"metrics": (), "best": (), "step": (), "cost": ()}
        self.replayer = ReplaySlider(self.ui)
        self.car.stop()
        self.ui.metrics.content = "—"
        self.ui.extend.content = render(None, FIRST_NOTE, star=options.planner == "rrtstar")
        self._show_pins_legend()
        if self._profiles is not None:
            self._profiles.set_steering(
                options.steering, other.steering if other is not None else None,
                problem.sharpness(options.speed or problem.speed))
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
        """The replay slider at iteration n (`ReplaySlider.show`); not while the run runs, nor
        in the split (the slider is disabled there)."""
        if self._view is not None and self.worker.live.state != "running" and not self.splitting:
            self.replayer.show(n, self.worker, self._view)

    def replay_end(self) -> None:
        """Back to the run from a replay: the slider at its end."""
        if self._view is not None:
            self.replayer.end(self.worker, self._view)

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
        """`Drive car`: the car drives the best path from the scene time 0."""
        if not self.car.drive(self.stage.problem):
            self.notify("No path yet", "press Run until a path to the goal is found")

    def show_time(self, t: float) -> None:
        """The scene clock at t: run B's moving obstacles (the stage moves A's) and the driving
        car."""
        self.split.show_time(t)
        self.car.show(t)

    # -- the ticker ----------------------------------------------------------------------------
    def tick(self) -> None:
        """Draw the worker's progress and update the panels with what changed."""
        if self._view is None:
            return
        lives = [lane.live for lane in self.worker.lanes]
        for view in (self._view, self.split.view):
            if view is not None:
                view.tick()
        self.replayer.tick(self.worker, self._view, self.splitting)
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
            self.ui.metrics.content = metrics_md(*metrics)
            self._show_pins_legend()  # this run's numbers and difference
        if time.monotonic() - self._shown.get("plotted", 0.0) > PLOT_S:
            self._plot(lives)
        steps = tuple(live.step_version for live in lives)
        if steps != self._shown["step"] and lives[0].step is not None:
            self._shown["step"] = steps
            self.ui.extend.content = extend_html([live.step for live in lives])

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
