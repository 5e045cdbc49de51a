"""The track and the scenario one tab shows, compiled and drawn.

`Stage` is the only writer of them; the editor, the planner run and the simulation read
``track``, ``scenario``, ``parsed`` and ``problem``, and the session swaps them in (a new track
clears the scene; a new scenario redraws obstacles, start and goal).

A gizmo's drag previews on viser's event loop while the session's ticker moves the same
obstacles along the scene clock: the previews take the session's lock, as the ticker does, and
a dragged obstacle keeps moving along its motion from where it is dragged to.
"""

from __future__ import annotations

import copy
import json

import planner
import tracks
from app.studio._scene import (
    add_grid,
    draw_obstacles,
    draw_poses,
    draw_track,
    fit_camera,
    marker_size,
    move_obstacles,
    yaw_wxyz,
)
from planner.obstacles import table_offsets

__all__ = ["Stage"]


class Stage:
    def __init__(self, client, clock, lock) -> None:
        self.client, self.scene, self.clock, self.lock = client, client.scene, clock, lock
        self.track: tracks.Track | None = None
        self.scenario: dict = {}
        self.parsed: planner.Scenario | None = None  # self.scenario, validated
        self.problem = None
        self._drawn: list[tuple] = []  # (frame, pose, motion table) per obstacle
        self._poses: dict = {}  # the start's and goal's frames

    def show_track(self, track: tracks.Track, vehicle) -> None:
        """A fresh scene with ``track`` on it: everything drawn before is gone."""
        self.scene.reset()
        self.scene.set_up_direction("+z")
        add_grid(self.scene, track.bbox())
        draw_track(self.scene, track, 1.0 / vehicle.turning_radius)
        self.track, self._drawn = track, []

    def show_scenario(self, scenario: dict, parsed: planner.Scenario, problem) -> None:
        self.scenario, self.parsed, self.problem = copy.deepcopy(scenario), parsed, problem
        self.draw_scenario()

    def draw_scenario(self) -> None:
        """Obstacles (where they are at the scene time), start and goal; also puts back what a
        refused drag moved."""
        for frame, _, _ in self._drawn:
            frame.remove()
        self._drawn = draw_obstacles(self.scene, self.parsed, self.track)
        move_obstacles(self._drawn, self.clock.t)
        self._poses = draw_poses(self.scene, self.parsed, marker_size(self.problem.bounds) * 4)

    def show_time(self, t: float) -> None:
        move_obstacles(self._drawn, t)

    def preview_obstacle(self, i: int, x: float, y: float, yaw: float) -> None:
        """Obstacle i drawn at pose (x, y, yaw), plus its motion's offset at the scene time,
        while a gizmo drags it."""
        with self.lock:
            frame, _, table = self._drawn[i]
            self._drawn[i] = (frame, (x, y, yaw), table)
            dx, dy = table_offsets(table, self.clock.t)[0]
            _move_frame(frame, x + dx, y + dy, yaw)

    def preview_pose(self, key: str, x: float, y: float, yaw: float) -> None:
        """The start or the goal (``key``) drawn at (x, y, yaw) while a gizmo drags it."""
        with self.lock:
            _move_frame(self._poses[key], x, y, yaw)

    def scenario_json(self, name: str) -> str:
        """The scenario as planned (a custom track embedded), named ``name``."""
        return json.dumps(dict(self.scenario, name=name), indent=2)

    def fit(self, panel_px: float, bounds) -> None:
        """Look at ``bounds`` (the scenario's, or both halves of the split) beside a panel
        ``panel_px`` wide, once the browser has reported its camera."""
        if self.problem is not None and self.client.camera.update_timestamp != 0.0:
            fit_camera(self.client, bounds, panel_px)


def _move_frame(frame, x: float, y: float, yaw: float) -> None:
    frame.position = (x, y, 0.0)
    frame.wxyz = yaw_wxyz(yaw)
