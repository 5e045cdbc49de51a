"""One browser tab's studio: its parts, the lock they share with its UI ticker, the ticker.

Everything here belongs to one viser client (``client.scene``, ``client.gui``), so what one tab
does never shows in another. Each part owns its state and is its only writer:

- `Stage` (_stage.py): the track and the scenario, compiled and drawn;
- `Editor` (_edit.py): gizmos, selection, obstacles from the panel, polygon and ground clicks;
- `TrackDrawing` (_track_drawing.py): a track being drawn;
- `Sources` (_sources.py): the library, SVG and scenario files, the server's store;
- `PlannerRun` (_planner_run.py): the planner's worker, its drawing, panels and Drive car;
- `SimView` (_sim_view.py): the simulated car and its folder;
- `StudiesView` (_studies.py): the server's parameter studies and their reports;
- `SceneClock` (_clock.py): the one scene time they all draw at.

The session wires the controls to them and does what spans parts: a new track or scenario
resets the rest. UI callbacks only change state and restart workers; the ticker thread pushes
the workers' progress to the browser at ~25 Hz, holding the lock, as does every callback while
it replaces what the ticker draws: directly (`_locked`), or through `apply_scenario` and
`set_track`, which compile outside the lock and take it to swap the drawing (a gizmo's release
goes that way; its drag previews take the lock in `Stage`).
"""

from __future__ import annotations

import threading
import time

import planner
import tracks
from app.studio._clock import SceneClock
from app.studio._compare import comparison_csv, comparison_png
from app.studio._edit import Editor
from app.studio._panel import STEERINGS, build_panel
from app.studio._planner_run import PlannerRun
from app.studio._projector import Projector
from app.studio._scene import ground_point
from app.studio._sim_view import SimView
from app.studio._sources import Sources
from app.studio._stage import Stage
from app.studio._studies import StudiesView
from app.studio._track_drawing import TrackDrawing
from app.studio._vehicle import VehicleForm

__all__ = ["Session"]

TICK_S = 0.04


class Session:
    """The studio for one client. `close` stops its threads."""

    def __init__(self, client, api_url: str) -> None:
        self.client = client
        self.ui = u = build_panel(client.gui)
        self._lock = threading.RLock()
        self._closed = False
        self.clock = SceneClock(u.scene_time, u.play, max_step=4 * TICK_S)
        self.stage = Stage(client, self.clock, self._lock)
        self.planning = PlannerRun(client.gui, client.scene, u, self.stage, self.clock,
                                   self.notify)
        self.sources = Sources(client, u, self.stage, api_url, self.set_track, self.notify)
        self.drawing = TrackDrawing(client, u, self.stage, self.sources.use_track, self.notify)
        self.editor = Editor(client.scene, u, self.stage, self.apply_scenario, self.drawing.add,
                             self.notify)
        self.sim = SimView(client.gui, client.scene, self.clock)
        self.vehicle = VehicleForm(u.vehicle, u.vehicle_note,
                                   lambda: self.stage.scenario.get("vehicle", {}), self.set_vehicle)
        self.studies = StudiesView(client.gui, client, api_url, self.notify)
        self.projector = Projector(client.gui, u)
        self._wire()
        self._unfitted_ticks = 10  # fit the view this many ticks after the browser's camera
        self.sources.show_library("thesis")
        self._ticker = threading.Thread(target=self._tick_loop, daemon=True, name="studio-ui")
        self._ticker.start()

    def _wire(self) -> None:
        """Each control to the part that owns what it changes."""
        u, run, sim = self.ui, self.planning, self.sim
        src, edit, drawing = self.sources, self.editor, self.drawing
        u.track.on_update(lambda _: src.track_chosen())
        u.svg_upload.on_upload(lambda _: src.svg_uploaded())
        u.svg_path.on_update(lambda _: src.svg_path_chosen())
        u.fit.on_click(lambda _: self.fit_view())
        u.projector.on_update(lambda _: self._locked(self._show_projector))
        u.fade_tree.on_update(lambda _: self._locked(lambda: run.set_look(self.projector.look)))
        u.draw.on_update(lambda _: edit.click_mode("track"))
        u.draw_undo.on_click(lambda _: drawing.undo())
        u.draw_close.on_update(lambda _: drawing.changed())
        u.draw_use.on_click(lambda _: drawing.use())
        u.draw_download.on_click(lambda _: drawing.download_svg())
        u.add_circle.on_click(lambda _: edit.add_obstacle("circle"))
        u.add_box.on_click(lambda _: edit.add_obstacle("box"))
        u.polygon.on_update(lambda _: edit.click_mode("polygon"))
        u.close_polygon.on_click(lambda _: edit.close_polygon())
        u.clear_obstacles.on_click(lambda _: edit.clear_obstacles())
        u.handles.on_update(lambda _: edit.show_gizmos())
        u.set_motion.on_click(lambda _: edit.set_motion())
        self.clock.on_change(self._show_time)
        u.scenario_download.on_click(lambda _: src.download_scenario())
        u.scenario_upload.on_upload(lambda _: src.scenario_uploaded())
        u.scenario_save.on_click(lambda _: src.save_to_server())
        u.scenario_load.on_click(lambda _: src.load_from_server())
        for control in (u.planner_name, u.steering, u.timing, u.eps, u.gamma, u.k_rrt,
                        u.goal_bias, u.budget, u.seed):
            control.on_update(lambda _: self._locked(run.reset))
        for control in (u.b_planner, u.b_steering, u.b_seed):
            control.on_update(lambda _: self._locked(run.b_changed))
        u.split.on_update(lambda _: self._split_changed())
        u.reset.on_click(lambda _: self._locked(run.reset))
        # Commands under the lock too: a reset replaces the worker, and they must reach the new one.
        u.rate.on_update(lambda _: self._locked(run.set_rate))
        u.step_node.on_click(lambda _: self._locked(lambda: run.step("node")))
        u.step_rewire.on_click(lambda _: self._locked(lambda: run.step("rewire")))
        for button, command in ((u.run, "run"), (u.pause, "pause"), (u.step, "step")):
            button.on_click(lambda _, c=command: self._locked(lambda: run.resume(c)))
        u.replay.on_update(lambda _: self._locked(lambda: run.replay(int(u.replay.value))))
        u.pin.on_click(lambda _: self._pins_changed(run.pin))
        u.clear_pins.on_click(lambda _: self._pins_changed(run.clear_pins))
        u.comparison_csv.on_click(lambda _: self._download_comparison(png=False))
        u.comparison_png.on_click(lambda _: self._download_comparison(png=True))
        u.drive.on_click(lambda _: self._locked(run.drive))
        u.raceline_download.on_click(lambda _: self._download_raceline())
        u.animation_download.on_click(lambda _: self._download_animation())
        sim.ui.simulate.on_click(lambda _: self._simulate())
        sim.ui.stop.on_click(lambda _: sim.stop())
        self.client.scene.on_click()(self._scene_click)

    def _scene_click(self, ev) -> None:
        """A click on the ground selects the obstacle, start or goal there (its gizmo shows),
        else names the edge there (viser 1.1 reports no hover over the scene), unless the
        click draws a track point or a polygon corner."""
        p = ground_point(ev)
        if p is not None and not self.editor.clicking:
            with self._lock:
                if not self.editor.select_at(p):
                    self.planning.pick(*p)

    def _locked(self, fn) -> None:
        with self._lock:
            fn()

    def _split_changed(self) -> None:
        """The two-up split on or off: the runs start over, the plots get or lose run B's
        series (with their data, at once) and the view frames one half or both."""
        with self.client.atomic(), self._lock:
            self.planning.choose_split()
            self.fit_view()

    def _pins_changed(self, fn) -> None:
        """Pin or clear: the plots' series and their data reach the browser together."""
        with self.client.atomic(), self._lock:
            fn()

    # -- what spans parts ----------------------------------------------------------------------
    def set_track(self, track: tracks.Track, scenario: dict, fit: bool = True) -> None:
        """Show a new track with its scenario: a fresh scene, so every part draws anew (at
        once: new plots with pins get their series and the data that matches them)."""
        with self.client.atomic(), self._lock:
            vehicle = planner.parse_scenario(scenario).vehicle
            self.vehicle.show(vehicle)
            self.sim.clear()  # while its drawing is still in the scene
            self.stage.show_track(track, vehicle)
            self.editor.forget_gizmos()
            self.drawing.forget_gizmos()
            self.planning.new_track(track, vehicle)
            self.apply_scenario(scenario)
            if fit:
                self.fit_view()

    def set_vehicle(self, vehicle: dict) -> str | None:
        """The scenario with a new car, or why it cannot have it (the start or goal no longer
        fits). The track's curvature colours and the profiles' limits are the car's: the track
        is shown anew, in the same view."""
        scenario = dict(self.stage.scenario, vehicle=vehicle)
        try:
            planner.compile_problem(planner.parse_scenario(scenario))
        except (planner.ScenarioError, ValueError) as exc:
            return str(exc)
        self.set_track(self.stage.track, scenario, fit=False)
        return None

    def apply_scenario(self, scenario: dict) -> bool:
        """Compile and show ``scenario`` (start, goal, obstacles); keeps the old one on error.
        Any change to the scenario resets the planner and the simulation: their runs belong to
        the old one."""
        try:
            parsed = planner.parse_scenario(scenario)
            problem = planner.compile_problem(parsed)
        except (planner.ScenarioError, ValueError) as exc:
            self.notify("Scenario not changed", str(exc))
            with self._lock:
                if self.stage.parsed is not None:  # puts a dragged shape and its gizmo back
                    self.stage.draw_scenario()
                    self.editor.place_gizmos()
            return False
        with self._lock:
            self.stage.show_scenario(scenario, parsed, problem)
            self.editor.place_gizmos()
            self.sim.clear()
            self.planning.reset()
        return True

    def _show_time(self, t: float) -> None:
        """The scene clock moved: moving obstacles and the driving car, both at time t."""
        with self._lock:
            self.stage.show_time(t)
            self.planning.show_time(t)

    def fit_view(self) -> None:
        """The whole scenario in view (both halves in the split), beside the panel as wide as
        it is now."""
        self.stage.fit(self.projector.panel_px, self.planning.view_bounds())

    def _show_projector(self) -> None:
        self.projector.apply()
        self.planning.set_look(self.projector.look)
        self.fit_view()

    def _simulate(self) -> None:
        """`Simulate` with the planner panel's steering: the planner's own run is reset out of
        the simulation's way."""
        try:
            settings = self.sim.settings(STEERINGS[self.ui.steering.value])
        except ValueError as exc:
            self.notify("Simulation settings", str(exc))
            return
        with self._lock:
            self.planning.reset()
            self.sim.start(self.stage.problem, settings)

    def _download_raceline(self) -> None:
        text = self.planning.raceline()
        if text is None:
            self.notify("No path yet", "press Run until a path to the goal is found")
            return
        self.client.send_file_download("raceline.csv", text.encode(), save_immediately=True)

    def _download_comparison(self, png: bool) -> None:
        """The pinned runs and the current one: their numbers as CSV or their plots as PNG."""
        with self._lock:
            runs, name = self.planning.compared(), self.stage.parsed.name
        if png:
            content = comparison_png(runs, f"{name}: compared runs")
        else:
            content = comparison_csv(runs).encode()
        self.client.send_file_download(f"comparison.{'png' if png else 'csv'}", content,
                                       save_immediately=True)

    def _download_animation(self) -> None:
        """The current settings' run drawn as a GIF, rendered on a thread of its own (a few
        seconds) while the studio goes on: the run on screen to where it is, when it runs with
        these settings."""
        try:
            options = self.planning.options()
        except ValueError as exc:
            self.notify("Planner options", str(exc))
            return
        with self._lock:
            done = self.planning.iterations_on_screen(options)
        self.client.add_notification("Drawing the animation",
                                     "40 frames (64 where obstacles move), a few seconds",
                                     auto_close_seconds=4.0)
        threading.Thread(target=self._send_animation, args=(self.stage.problem, options, done),
                         daemon=True, name="studio-gif").start()

    def _send_animation(self, problem, options, iterations: int | None) -> None:
        from app.animate import animation_gif

        try:
            gif = animation_gif(problem, options, iterations)
        except ValueError as exc:  # e.g. a robot this steering cannot drive
            self.notify("Animation", str(exc))
            return
        if not self._closed:
            self.client.send_file_download("run.gif", gif, save_immediately=True)

    def notify(self, title: str, body: str) -> None:
        self.client.add_notification(title, body, auto_close_seconds=6.0, color="red")

    # -- the ticker ----------------------------------------------------------------------------
    def _tick_loop(self) -> None:
        due = time.perf_counter()
        while not self._closed:
            try:
                with self._lock:
                    self.tick()
            except Exception as exc:  # noqa: BLE001  (a disconnected client ends the loop)
                if self._closed:
                    return
                print(f"studio: tick failed: {type(exc).__name__}: {exc}")
            # A fixed schedule: a late tick (the planner's thread held the GIL) shortens the next
            # wait instead of pushing every later tick back, so the rate holds under load.
            due = max(due + TICK_S, time.perf_counter() - TICK_S)
            time.sleep(max(0.0, due - time.perf_counter()))

    def tick(self) -> None:
        if self._unfitted_ticks and self.client.camera.update_timestamp != 0.0:
            # The browser reports its camera once it is up, and may set its own view just
            # after: fit a moment later.
            self._unfitted_ticks -= 1
            if self._unfitted_ticks == 0:
                self.fit_view()
        self.editor.hide_gizmos(self.projector.on and self.planning.started)
        self.planning.tick()
        self.sim.tick()
        self.clock.advance(self.planning.car.end)

    def close(self) -> None:
        self._closed = True
        self.sim.stop()
        self.planning.stop()
