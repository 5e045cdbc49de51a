"""The two-up split (issue 20): a second run, B, planned on the same scenario and drawn beside
the first, A, in the same scene (viser has one 3D canvas per tab); the worker steps both on one
clock (`PlannerWorker` with two lanes).

`Split` owns B's half of the scene: a frame ``/b`` moved along +x by the scene's width and a
margin, holding a copy of the track, the obstacles, the start and the goal, B's tree and best
path (drawn by a `LiveView` rooted there, so nothing of B's drawing knows the offset), and a
label over each half naming its run.
"""

from __future__ import annotations

from app.studio._compare import SPLIT_B, hex_rgb
from app.studio._live_view import LiveView
from app.studio._scene import (
    Z,
    draw_obstacles,
    draw_poses,
    draw_track,
    marker_size,
    move_obstacles,
)

__all__ = ["B_RGB", "ROOT", "Split", "offset", "split_bounds"]

ROOT = "/b"  # B's half: everything of B is drawn under this frame
B_RGB = hex_rgb(SPLIT_B)  # B's best path, as in the plots
GAP = 0.12  # the margin between the halves, as a share of the scene's width


def offset(bounds) -> float:
    """How far B's half lies from A's along +x: the scene's width and the margin."""
    xmin, _, xmax, _ = bounds
    return (1.0 + GAP) * (xmax - xmin)


def split_bounds(bounds) -> tuple[float, float, float, float]:
    """The bounds of both halves, which the view fit frames."""
    xmin, ymin, xmax, ymax = bounds
    return xmin, ymin, xmax + offset(bounds), ymax


class Split:
    """B's half of one tab's scene; `hide` takes it away."""

    def __init__(self, scene) -> None:
        self.scene = scene
        self.view: LiveView | None = None  # B's tree and best path
        self._bounds = None  # the scene's, while B's half is shown
        self._drawn: list[tuple] = []  # B's obstacles, for `show_time`

    def show(self, stage, titles: tuple[str, str], live, look, camera) -> None:
        """B's half of the stage's scenario beside A's (anew: an obstacle may have moved), its
        run's ``live`` record drawn there with ``look``, and ``titles`` ("A: …", "B: …") over
        the halves."""
        self.hide()
        self._bounds = bounds = stage.problem.bounds
        xmin, _, _, ymax = bounds
        self.scene.add_frame("/split_a", show_axes=False)  # A's title
        self.scene.add_frame(ROOT, show_axes=False, position=(offset(bounds), 0.0, 0.0))
        draw_track(self.scene, stage.track, 1.0 / stage.parsed.vehicle.turning_radius, ROOT)
        self._drawn = draw_obstacles(self.scene, stage.parsed, stage.track, ROOT)
        move_obstacles(self._drawn, stage.clock.t)
        draw_poses(self.scene, stage.parsed, marker_size(bounds) * 4, ROOT)
        above = (xmin, ymax + 2 * marker_size(bounds), Z["pose"])
        for root, title in zip(("/split_a", ROOT), titles):
            self.scene.add_label(f"{root}/title", title, position=above, anchor="bottom-left",
                                 font_screen_scale=1.3)
        self.view = LiveView(self.scene, live, bounds, look, camera, f"{ROOT}/live", B_RGB)

    def hide(self) -> None:
        if self.view is not None:
            self.view.clear()
        for root in ("/split_a", ROOT):
            self.scene.remove_by_name(root)
        self.view, self._bounds, self._drawn = None, None, []

    def forget(self) -> None:
        """The scene was cleared (a new track), and B's half with it."""
        self.view, self._bounds, self._drawn = None, None, []

    def bounds(self, bounds):
        """What the view fit frames: ``bounds`` (the scene's) and B's half beside it."""
        return bounds if self.view is None else split_bounds(bounds)

    def pick(self, x: float, y: float) -> bool:
        """A click on the ground at (x, y): whether it is in B's half (right of the gap between
        the halves), where B's edge there says its word."""
        if self.view is None:
            return False
        xmin, _, xmax, _ = self._bounds
        dx = offset(self._bounds)
        if x <= xmax + 0.5 * (dx - (xmax - xmin)):
            return False
        self.view.pick(x - dx, y)
        return True

    def show_time(self, t: float) -> None:
        """B's moving obstacles at scene time t, as the stage moves A's."""
        move_obstacles(self._drawn, t)
