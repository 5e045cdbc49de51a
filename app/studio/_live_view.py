"""Drawing a planner's `Live` record into one client's scene, at UI rate.

`LiveView.tick` is called ~20 times a second: tail chunks every tick, rewired chunks a few per
slow tick, fading rewire flashes, the best path when it improves, the step-mode overlay.
"""

from __future__ import annotations

import math
import time

import numpy as np

from app.studio._scene import Z, polyline_segments
from app.studio._worker import FLASH_S, Live

__all__ = ["LiveView", "step_labels"]

TREE_RGB = (70, 150, 235)
PATH_RGB = (255, 90, 200)
OLD_RGB, NEW_RGB = (255, 60, 60), (80, 255, 120)
REWIRED_PER_SLOW_TICK = 4
SLOW_EVERY = 5  # ticks
# Rewire flashes (up to 96 edges, 0.6 s each) change every tick while RRT* rewires: re-sent every
# other tick with every other point of the edge, a quarter of the bytes of a full redraw.
FLASH_EVERY = 2  # ticks
FLASH_STRIDE = 2


def _circle(x: float, y: float, r: float, z: float, n: int = 40) -> np.ndarray:
    a = np.linspace(0, 2 * math.pi, n, endpoint=False)
    return polyline_segments(np.column_stack([x + r * np.cos(a), y + r * np.sin(a)]), z, True)


def _edges(pts_list: list[np.ndarray], z: float) -> np.ndarray:
    if not pts_list:
        return np.zeros((0, 2, 3), np.float32)
    return np.concatenate([polyline_segments(p, z) for p in pts_list])


def step_labels(st: dict, marker: float) -> list[tuple[str, str, tuple[float, float], str]]:
    """(node, text, position, anchor) of the step's labels, right of their points: x_nearest
    above, x_new below, x_rand above when x_new is elsewhere (then it is ε from x_nearest) and
    below when not, so that close points keep their labels apart. A Steer that reached the
    sample puts x_new on x_rand: one label names both."""
    def at(pose, above: bool) -> tuple[tuple[float, float], str]:
        dy = marker if above else -marker
        return (float(pose[0]) + marker, float(pose[1]) + dy), ("bottom-left" if above
                                                               else "top-left")

    rand, new = st["x_rand"], st["new"]
    same = new is not None and math.dist(rand[:2], new[:2]) < 0.1 * marker
    elsewhere = new is not None and not same
    out = [("step_rand_l", "x_new = x_rand" if same else "x_rand", *at(rand, elsewhere))]
    if st["nearest"] is not None:
        out.append(("step_nearest_l", "x_nearest", *at(st["nearest"], True)))
    if elsewhere:
        out.append(("step_new_l", "x_new", *at(new, False)))
    return out


class LiveView:
    """One run's drawing in one client's scene; `clear` removes all of it."""

    def __init__(self, scene, live: Live, marker: float) -> None:
        self.scene, self.live, self.marker = scene, live, marker
        self._chunks: dict[int, object] = {}
        self._handles: dict[str, object] = {}
        self._seen = {"best": 0, "step": 0}
        self._ticks = 0
        self.sent_chunks = 0

    def _put(self, name: str, seg: np.ndarray, rgb, px: float, z: float | None = None):
        """Create or update a line-segments node (hidden when empty)."""
        h = self._handles.get(name)
        if len(seg) == 0:
            if h is not None:
                h.visible = False
            return
        if h is None:
            self._handles[name] = self.scene.add_line_segments(
                f"/live/{name}", seg, rgb, thickness=px, thickness_units="screen")
        else:
            h.points = seg
            h.visible = True

    def tick(self) -> None:
        self._ticks += 1
        chunks = self.live.chunks
        sends = chunks.take_tail()
        if self._ticks % SLOW_EVERY == 0:
            sends += chunks.take_rewired(REWIRED_PER_SLOW_TICK)
        for c, seg in sends:
            seg[:, :, 2] = Z["tree"]
            h = self._chunks.get(c)
            if h is None:
                self._chunks[c] = self.scene.add_line_segments(
                    f"/live/tree/c{c}", seg, TREE_RGB, thickness=1.2, thickness_units="screen")
            else:
                h.points = seg
            self.sent_chunks += 1
        if self._ticks % FLASH_EVERY == 0:
            self._flashes()
        if self.live.best_version != self._seen["best"]:
            self._seen["best"] = self.live.best_version
            path = self.live.best_path
            self._put("best", polyline_segments(path[:, :2], Z["path"]), PATH_RGB, 4.0)
        if self.live.step_version != self._seen["step"]:
            self._seen["step"] = self.live.step_version
            self._step_overlay(self.live.step)

    def _flashes(self) -> None:
        now = time.monotonic()
        fl = [f for f in list(self.live.flashes) if now - f[0] < FLASH_S]
        if not fl and "flash_old" not in self._handles:
            return
        self._put("flash_old", _edges([f[1][::FLASH_STRIDE] for f in fl], Z["flash"]), OLD_RGB, 2.5)
        self._put("flash_new", _edges([f[2][::FLASH_STRIDE] for f in fl], Z["flash"]), NEW_RGB, 2.5)

    def _step_overlay(self, st: dict | None) -> None:
        """x_rand, x_nearest, x_new, the near radius and nodes, the chosen parent edge."""
        for name in [n for n in self._handles if n.startswith("step_")]:
            self._handles[name].visible = False
        if st is None:
            return
        m, z = self.marker, Z["step"]
        xr = st["x_rand"]
        self._put("step_rand", _circle(xr[0], xr[1], m, z, 12), (255, 255, 255), 3.0)
        if st["nearest"] is not None:
            self._put("step_nearest", _circle(*st["nearest"][:2], m, z, 12), (90, 170, 255), 3.0)
        for label in step_labels(st, m):
            self._label(*label)
        if st["new"] is not None:
            nx, ny = st["new"][:2]
            self._put("step_new", _circle(nx, ny, m, z, 12), NEW_RGB, 3.0)
            if st["radius"] > 0 and math.isfinite(st["radius"]):
                self._put("step_radius", _circle(nx, ny, st["radius"], z, 64), (250, 220, 90), 1.5)
            near = [_circle(x, y, 0.4 * m, z, 8) for x, y, _ in st["near"]]
            self._put("step_near", np.concatenate(near) if near else near, (250, 220, 90), 2.0)
            self._put("step_parent", _edges([st["parent_edge"]], z), NEW_RGB, 5.0)
        self._put("step_rewired", _edges([n for _, n in st["rewired"]], z), (80, 255, 220), 4.0)

    def _label(self, name: str, text: str, where, anchor: str) -> None:
        h = self._handles.get(name)
        pos = (*where, Z["step"])
        if h is None:
            self._handles[name] = self.scene.add_label(f"/live/{name}", text, position=pos,
                                                       anchor=anchor)
        else:
            h.position, h.text, h.anchor, h.visible = pos, text, anchor, True

    def clear(self) -> None:
        for h in [*self._chunks.values(), *self._handles.values()]:
            h.remove()
        self._chunks.clear()
        self._handles.clear()
