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
from app.studio._extend import explain, render
from app.studio._live_view import LiveView
from app.studio._panel import ALGORITHMS, SPEEDS, STEERINGS, build_panel
from app.studio._plots import Profiles
from app.studio._scenario import default_scenario, goal_fraction
from app.studio._scene import (
    draw_obstacles,
    draw_poses,
    draw_track,
    fit_camera,
)
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
        self.region: list[dict] = []  # a custom track's outside, as polygons
        self.scenario: dict = {}
        self.problem = None
        self.worker: PlannerWorker | None = None
        self.view: LiveView | None = None
        self.profiles: Profiles | None = None
        self.draft: list[tuple[float, float]] = []  # points of a track being drawn
        self._obstacle_handles: list = []
        self._drive_t0: float | None = None
        self._lock = threading.RLock()
        self._closed = False
        _actions.wire(self)
        self._unfitted_ticks = 10  # fit the view this many ticks after the browser's camera
        self.load_library("thesis")
        self._ticker = threading.Thread(target=self._tick_loop, daemon=True, name="studio-ui")
        self._ticker.start()

    # -- scenario ------------------------------------------------------------------------------
    def load_library(self, name: str) -> None:
        self.set_track(tracks.load_library_track(name), default_scenario(name), [])

    def set_track(self, track: tracks.Track, scenario: dict, region: list[dict]) -> None:
        """Show a new track with its scenario; redraws everything and resets the planner."""
        with self._lock:
            self.track, self.region = track, region
            vehicle = planner.parse_scenario(scenario).vehicle
            self.scene.reset()
            self.scene.set_up_direction("+z")
            self.scene.add_grid("/grid", 200, 200, plane="xy", cell_size=1.0, section_size=5.0,
                                position=(0, 0, -0.03), cell_color=(225, 225, 225),
                                section_color=(190, 190, 190))
            draw_track(self.scene, track, 1.0 / vehicle.turning_radius)
            self._obstacle_handles = []
            self.view = None
            self._make_profiles(track, vehicle)
            self.apply_scenario(scenario)
            self.fit()

    def _make_profiles(self, track: tracks.Track, vehicle) -> None:
        if self.profiles is not None:
            for h in (self.profiles.curvature, self.profiles.steering, self.profiles.cost):
                h.remove()
        prof = track.sample(0.05, vehicle.wheelbase, vehicle.max_steer_deg)
        with self.ui.plots:
            self.profiles = Profiles(self.client.gui, prof.s, prof.curvature,
                                     goal_fraction(track.closed) * track.length_m,
                                     vehicle.wheelbase, vehicle.max_steer_deg)

    def apply_scenario(self, scenario: dict) -> bool:
        """Compile and show ``scenario`` (start, goal, obstacles); keeps the old one on error."""
        full = dict(scenario, obstacles=[*scenario.get("obstacles", []), *self.region])
        try:
            problem = planner.compile_problem(planner.parse_scenario(full))
        except (planner.ScenarioError, ValueError) as exc:
            self.notify("Scenario not changed", str(exc))
            return False
        with self._lock:
            self.scenario, self.problem = copy.deepcopy(scenario), problem
            self.draw_scenario(self.ui.scene_time.value)
            self.reset()
        return True

    def draw_scenario(self, t: float = 0.0) -> None:
        """Obstacles (where they are at scene time t), start and goal."""
        for h in self._obstacle_handles:
            if h is not None:
                h.remove()
        user = planner.parse_scenario(dict(self.scenario, obstacles=self.scenario["obstacles"]))
        self._obstacle_handles = draw_obstacles(self.scene, user, t)
        draw_poses(self.scene, user, self.marker() * 4)

    def marker(self) -> float:
        xmin, ymin, xmax, ymax = self.problem.bounds if self.problem else (0, 0, 10, 10)
        return 0.006 * max(xmax - xmin, ymax - ymin)

    def scenario_json(self) -> str:
        """The scenario as the user sees it; a custom track's region goes in as obstacles."""
        out = dict(self.scenario, name=self.ui.scenario_name.value or "studio")
        out["obstacles"] = [*self.scenario["obstacles"], *self.region]
        return json.dumps(out, indent=2)

    # -- planner -------------------------------------------------------------------------------
    def settings(self) -> planner.PlannerSettings:
        u = self.ui
        return planner.PlannerSettings(
            algorithm=ALGORITHMS[u.algorithm.value], steering=STEERINGS[u.steering.value],
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
                settings = self.settings()
            except ValueError as exc:
                self.notify("Planner settings", str(exc))
                settings = planner.PlannerSettings()
            self.worker = PlannerWorker(self.problem, settings, int(self.ui.budget.value),
                                        SPEEDS[self.ui.rate.value])
            self.view = LiveView(self.scene, self.worker.live, self.marker())
            self._shown = {"metrics": -1, "best": 0, "step": 0, "costs": 0}
            self._drive_t0 = None
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
        while not self._closed:
            t0 = time.perf_counter()
            try:
                with self._lock:
                    self.tick()
            except Exception as exc:  # noqa: BLE001  (a disconnected client ends the loop)
                if self._closed:
                    return
                print(f"studio: tick failed: {type(exc).__name__}: {exc}")
            time.sleep(max(0.0, TICK_S - (time.perf_counter() - t0)))

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
        """Scene time for moving obstacles; the car driving the best path."""
        if self.ui.play.value:
            t = self.ui.scene_time.value + TICK_S
            self.ui.scene_time.value = 0.0 if t > self.ui.scene_time.max else t
        if self._drive_t0 is not None and self.worker.live.best_path is not None:
            _actions.drive_step(self, time.monotonic() - self._drive_t0)

    def close(self) -> None:
        self._closed = True
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


