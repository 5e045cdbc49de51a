"""One browser tab's studio: its scenario, its planner worker, its drawing, its UI ticker.

Everything here belongs to one viser client (``client.scene``, ``client.gui``), so what one tab
does never shows in another. UI callbacks only change state and restart the worker; the ticker
thread pushes the worker's progress to the browser at ~20 Hz.
"""

from __future__ import annotations

import copy
import json
import math
import threading
import time

import numpy as np

import planner
import tracks
from app.studio import _actions
from app.studio._custom import Draft
from app.studio._edit import place_gizmos
from app.studio._extend import explain, render
from app.studio._live_view import LiveView
from app.studio._panel import PLANNERS, SPEEDS, STEERINGS, build_panel
from app.studio._plots import Profiles
from app.studio._scenario import default_scenario, goal_fraction
from app.studio._scene import (
    add_grid,
    draw_car,
    draw_obstacles,
    draw_poses,
    draw_track,
    fit_camera,
    marker_size,
    move_obstacles,
    yaw_wxyz,
)
from app.studio._sim_view import SimView
from app.studio._worker import PlannerWorker

__all__ = ["Session"]

TICK_S = 0.04
PLOT_S = 1.0  # profile plots redraw at most this often (uPlot re-renders all of it)


class Session:
    """The studio for one client. `close` stops its threads."""

    def __init__(self, client, api_url: str) -> None:
        self.client, self.scene, self.api_url = client, client.scene, api_url
        self.ui = build_panel(client.gui)
        self.track: tracks.Track | None = None
        self.scenario: dict = {}
        self.parsed: planner.Scenario | None = None  # self.scenario, validated
        self.problem = None
        self.worker: PlannerWorker | None = None
        self.view: LiveView | None = None
        self.profiles: Profiles | None = None
        self.draft = Draft()  # a track being drawn
        self.draft_gizmos: list = []
        self.polygon: list[tuple[float, float]] = []  # corners of a polygon being clicked
        self.click_mode: str | None = None
        self.drawn: list[tuple] = []  # (frame, pose, motion table) per obstacle
        self.pose_frames: dict = {}
        self.gizmos: list = []
        self.selected: int | None = None  # the obstacle `Set motion of selected` changes
        self.driving = False  # the car footprint shows the best path at scene time
        self._car = None
        self._played_at = time.monotonic()
        self._lock = threading.RLock()
        self._closed = False
        _actions.wire(self)
        self.sim = SimView(self)
        self._unfitted_ticks = 10  # fit the view this many ticks after the browser's camera
        self.load_library("thesis")
        self._ticker = threading.Thread(target=self._tick_loop, daemon=True, name="studio-ui")
        self._ticker.start()

    # -- scenario ------------------------------------------------------------------------------
    def load_library(self, name: str) -> None:
        self.set_track(tracks.load_library_track(name), default_scenario(name))

    def set_track(self, track: tracks.Track, scenario: dict) -> None:
        """Show a new track with its scenario; redraws everything and resets the planner."""
        with self._lock:
            self.track = track
            vehicle = planner.parse_scenario(scenario).vehicle
            self.sim.clear()
            self.scene.reset()
            self.scene.set_up_direction("+z")
            add_grid(self.scene, track.bbox())
            draw_track(self.scene, track, 1.0 / vehicle.turning_radius)
            self.drawn, self.gizmos, self.draft_gizmos, self._car = [], [], [], None
            self.view = None
            self._make_profiles(track, vehicle)
            self.apply_scenario(scenario)
            self.fit()

    def _make_profiles(self, track: tracks.Track, vehicle) -> None:
        if self.profiles is not None:
            for h in (self.profiles.curvature, self.profiles.steering, self.profiles.cost):
                h.remove()
        prof = track.sample(track.detail_spacing(), vehicle.wheelbase,
                            vehicle.max_steer_deg)
        with self.ui.plots:
            self.profiles = Profiles(self.client.gui, prof.s, prof.curvature,
                                     goal_fraction(track.closed) * track.length_m,
                                     vehicle.wheelbase, vehicle.max_steer_deg)

    def apply_scenario(self, scenario: dict) -> bool:
        """Compile and show ``scenario`` (start, goal, obstacles); keeps the old one on error.
        Any change to the scenario resets the planner: its tree belongs to the old one."""
        try:
            parsed = planner.parse_scenario(scenario)
            problem = planner.compile_problem(parsed)
        except (planner.ScenarioError, ValueError) as exc:
            self.notify("Scenario not changed", str(exc))
            with self._lock:
                if self.parsed is not None:
                    self.draw_scenario()  # puts a dragged gizmo back
            return False
        with self._lock:
            self.scenario, self.parsed, self.problem = copy.deepcopy(scenario), parsed, problem
            self.draw_scenario()
            self.sim.clear()
            self.reset()
        return True

    def draw_scenario(self) -> None:
        """Obstacles (where they are at the scene time), start, goal and their gizmos."""
        for frame, _, _ in self.drawn:
            frame.remove()
        self.drawn = draw_obstacles(self.scene, self.parsed, self.track)
        move_obstacles(self.drawn, self.ui.scene_time.value)
        self.pose_frames = draw_poses(self.scene, self.parsed, self.marker() * 4)
        place_gizmos(self)

    def add_obstacle(self, ob: dict) -> None:
        _actions.add_obstacle(self, ob)

    def show_time(self, t: float) -> None:
        """The scene clock: moving obstacles and the driving car, both at time t."""
        with self._lock:
            move_obstacles(self.drawn, t)
            path = self.worker.live.best_path if self.worker is not None else None
            if self.driving and path is not None and len(path):
                self._show_car(path, t)

    def _show_car(self, path: np.ndarray, t: float) -> None:
        """The car (`draw_car`) where the best path is at time t (its column 5)."""
        k = int(np.searchsorted(path[:, 5], t).clip(0, len(path) - 1))
        x, y, th = (float(v) for v in path[k, :3])
        if self._car is None:
            self._car = draw_car(self.scene, "/live/car", self.parsed.vehicle, self.marker(),
                                 (x, y, th))
        self._car.position = (x, y, 0.0)
        self._car.wxyz = yaw_wxyz(th)

    def drive(self) -> None:
        """`Drive car`: the scene clock restarts at 0 and plays; the car and the moving
        obstacles share it, so what the planner avoided in time is what you see avoided."""
        path = self.worker.live.best_path
        if path is None or not len(path):
            self.notify("No path yet", "press Run until a path to the goal is found")
            return
        self.driving = True
        self.ui.scene_time.max = max(self.ui.scene_time.max, math.ceil(path[-1, 5]))
        self.ui.scene_time.value = 0.0
        self.ui.play.value = True
        self.show_time(0.0)

    def marker(self) -> float:
        return marker_size(self.problem.bounds)

    def scenario_json(self) -> str:
        """The scenario as planned (a custom track embedded), named by the `Name` field."""
        return json.dumps(dict(self.scenario, name=self.ui.scenario_name.value or "studio"),
                          indent=2)

    # -- planner -------------------------------------------------------------------------------
    def options(self) -> planner.PlanOptions:
        """The planner panel as `PlanOptions`: 0 in a number field means "derived"."""
        u = self.ui
        return planner.PlanOptions(
            planner=PLANNERS[u.planner_name.value], steering=STEERINGS[u.steering.value],
            eps=u.eps.value or None, gamma=u.gamma.value or None, k_rrt=u.k_rrt.value or None,
            goal_bias=float(u.goal_bias.value), seed=int(u.seed.value),
            speed=u.speed_v.value or None)

    def reset(self) -> None:
        """A fresh run with the current settings (the old worker is stopped first)."""
        with self._lock:
            if self.worker is not None:
                self.worker.stop()
            if self.view is not None:
                self.view.clear()
            try:
                options = self.options()
                options.resolved(self.problem)  # refuses a robot this steering cannot drive
            except ValueError as exc:
                self.notify("Planner options", str(exc))
                options = planner.PlanOptions()
            self.worker = PlannerWorker(self.problem, options, int(self.ui.budget.value),
                                        SPEEDS[self.ui.rate.value])
            self.view = LiveView(self.scene, self.worker.live, self.marker())
            self._shown = {"metrics": -1, "best": 0, "step": 0, "costs": 0}
            self.driving = False
            if self._car is not None:
                self._car.remove()
                self._car = None
            self.ui.metrics.content = "—"
            self.ui.extend.content = render(None, "Press Step to run one iteration.")
            if self.profiles is not None:
                self.profiles.show_path(np.zeros((0, 4)))

    def fit(self) -> None:
        if self.problem is not None and self.client.camera.update_timestamp != 0.0:
            fit_camera(self.client, self.problem.bounds)


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
        w, view = self.worker, self.view
        if w is None or view is None:
            return
        live = w.live
        if self._unfitted_ticks and self.client.camera.update_timestamp != 0.0:
            # The browser reports its camera once it is up, and may set its own view just
            # after: fit a moment later.
            self._unfitted_ticks -= 1
            if self._unfitted_ticks == 0:
                self.fit()
        view.tick()
        self.sim.tick()
        status = f"Status: **{live.state}**" + (f" — {live.error}" if live.error else "")
        if status != self.ui.status.content:  # GUI updates re-render the panel: only changes
            self.ui.status.content = status
        if live.metrics_version != self._shown["metrics"]:
            self._shown["metrics"] = live.metrics_version
            self.ui.metrics.content = _metrics_md(live.metrics)
        slow_tick = time.monotonic() - self._shown.get("plotted", 0.0) > PLOT_S
        if live.best_version != self._shown["best"] and live.best_path is not None and slow_tick:
            self._shown["best"], self._shown["plotted"] = live.best_version, time.monotonic()
            self.profiles.show_path(live.best_path)
            self.profiles.show_cost(list(live.cost_over_time))
        if live.step_version != self._shown["step"] and live.step is not None:
            self._shown["step"] = live.step_version
            line, note = explain(live.step["info"], live.step["star"])
            self.ui.extend.content = render(line, f"Iteration {live.step['info'].iteration}: "
                                                  + note)
        self._animate()

    def _animate(self) -> None:
        """Advance the scene clock while playing (setting it moves obstacles and car); a
        driving car loops at its path's end, else the clock loops at the slider's end."""
        now, last = time.monotonic(), self._played_at
        self._played_at = now
        if self.ui.play.value:
            path = self.worker.live.best_path
            end = (path[-1, 5] if self.driving and path is not None and len(path)
                   else self.ui.scene_time.max)
            t = self.ui.scene_time.value + min(now - last, 4 * TICK_S)  # real time, no jumps
            self.ui.scene_time.value = 0.0 if t > end else t

    def close(self) -> None:
        self._closed = True
        self.sim.stop()
        if self.worker is not None:
            self.worker.stop()


def _fmt(v, unit: str = "", digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return f"{v:.{digits}g}{unit}" if isinstance(v, float) else f"{v}{unit}"


def _metrics_md(m: dict) -> str:
    if not m:
        return "—"
    return "\n".join([
        f"| iterations | {m['iterations']} |", "|---|---|",
        f"| nodes | {m['nodes']} |",
        f"| rewires | {m['rewires']} |",
        f"| time to first solution | {_fmt(m['time_to_first_solution_s'], ' s')} |",
        f"| cost | {_fmt(m['cost'], ' m', 4)} |",
        f"| min clearance | {_fmt(m['min_clearance_m'], ' m')} |",
        f"| iterations/s | {_fmt(m['iterations_per_s'], '', 4)} |",
    ])


