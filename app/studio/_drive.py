"""`Drive car`: the car driving the run's best path on the scene clock, which the moving
obstacles share, so what the planner avoided in time is what you see avoided."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from app.studio._run_text import pose_at_time
from app.studio._scene import draw_car, marker_size, yaw_wxyz

__all__ = ["DrivenCar"]


class DrivenCar:
    """The car of `Drive car` in one scene; it drives whatever the best path is now."""

    def __init__(self, scene, clock, best_path: Callable[[], np.ndarray | None]) -> None:
        self.scene, self.clock, self._best_path = scene, clock, best_path
        self.driving = False
        self._car = None

    def drive(self, problem) -> bool:
        """The clock restarts at 0 and plays to the path's end; False: no path to drive."""
        path = self._best_path()
        if path is None or not len(path):
            return False
        self._problem, self.driving = problem, True
        self.clock.reach(path[-1, 5])
        self.show(0.0)  # the clock may be at 0 already: then setting it draws nothing
        self.clock.play_from_start()
        return True

    @property
    def end(self) -> float | None:
        """When the car reaches the goal (the scene clock loops there); None when none drives."""
        path = self._best_path() if self.driving else None
        return float(path[-1, 5]) if path is not None and len(path) else None

    def show(self, t: float) -> None:
        """The car where the best path is at time t."""
        path = self._best_path()
        if not self.driving or path is None or not len(path):
            return
        x, y, th = pose_at_time(path, t)
        if self._car is None:
            self._car = draw_car(self.scene, "/live/car", self._problem.scenario.vehicle,
                                 marker_size(self._problem.bounds), (x, y, th))
        self._car.position = (x, y, 0.0)
        self._car.wxyz = yaw_wxyz(th)

    def stop(self) -> None:
        """No car: a new run."""
        self.driving = False
        if self._car is not None:
            self._car.remove()
            self._car = None

    def forget(self) -> None:
        """The scene was cleared: the car's node went with it."""
        self._car = None
