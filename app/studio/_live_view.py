"""Drawing a planner's `Live` record into one client's scene, at UI rate.

`LiveView.tick` is called 25 times a second: in bursts a few times a second, new and rewired
chunks of the tree, fading rewire flashes and the best path when it improved; the step-mode
overlay at once. Every colour it draws is named in `LEGEND`, which the panel shows.
"""

from __future__ import annotations

import html
import math
import time
from dataclasses import dataclass

import numpy as np

import planner
from app.studio._labels import MARKER_PX, step_labels
from app.studio._scene import (
    CURVATURE_RGB,
    CUSP_UNDER_RGB,
    GOAL_RGB,
    MOVER_RGB,
    OBSTACLE_RGB,
    REVERSE_RGB,
    START_RGB,
    Z,
    circle_points,
    marker_size,
    metres_per_px,
    path_layers,
    polyline_segments,
    put_segments,
)
from app.studio._tree import CHUNK, SEG, EdgeChunks
from app.studio._worker import FLASH_S, Live, Step

__all__ = ["LEGEND", "LiveView", "Look", "edge_label", "legend_html"]

TREE_RGB = (70, 150, 235)
TREE_FADED_RGB = (90, 98, 118)  # near the asphalt: the path and the step overlay stand out
PATH_RGB = (255, 90, 200)
RAND_RGB, NEAREST_RGB = (255, 255, 255), (90, 170, 255)
NEW_RGB, NEAR_RGB = (80, 255, 120), (250, 220, 90)
REWIRE_OLD_RGB, REWIRE_NEW_RGB = (255, 160, 60), (80, 255, 220)
BLOCKED_RGB = (255, 40, 40)
LEGEND = (  # (what, colour or colours, drawn as a line, a ring or a filled shape)
    ("tree", TREE_RGB, "line"), ("best path", PATH_RGB, "line"),
    ("reverse: driven backwards", (PATH_RGB, REVERSE_RGB), "dash"),
    ("cusp: stops, changes direction", (REVERSE_RGB, CUSP_UNDER_RGB), "diamond"),
    ("x_rand, the sample", RAND_RGB, "ring"), ("x_nearest", NEAREST_RGB, "ring"),
    ("x_new, its edge from x_min", NEW_RGB, "ring"), ("near set, radius r(n)", NEAR_RGB, "ring"),
    ("rewire: old edge", REWIRE_OLD_RGB, "line"), ("rewire: new edge", REWIRE_NEW_RGB, "line"),
    ("blocked Steer", BLOCKED_RGB, "line"), ("start", START_RGB, "fill"),
    ("goal", GOAL_RGB, "fill"), ("obstacle", OBSTACLE_RGB, "fill"),
    ("moving obstacle", MOVER_RGB, "fill"),
    ("centreline: straight … tightest turn", CURVATURE_RGB, "line"),
)
TREE_PX = 1.2
PICK_RGB = (255, 245, 130)  # the clicked edge's halo
PICK_PX = 10.0  # a click this near an edge (on screen, at scale 1) picks it
# The tree goes out in bursts, with the rewire flashes and the best path: the browser's cost is
# per update it renders, more than per byte. Chromium with software WebGL renders for 250 ms
# after each scene update (viser's settle window), at 135-280 ms a frame on this 2-core machine
# while the planner takes a core: updates every 0.2 s kept it rendering without a pause, at 3-4
# frames/s. A burst goes out every BURST_TICKS (5 a second) while the tree grows by at most
# LIGHT_BURST chunks in that time (any pace up to a few hundred iterations a second, step mode,
# a paused or finished run); a tree growing faster goes out every HEAVY_BURST_TICKS (0.8 s),
# its newest chunks as coarse as the older ones (`EdgeChunks.coarse`), which leaves the
# browser idle between bursts. A burst holds at most 4 chunks of new nodes (a tree growing
# faster is drawn behind the planner and catches up), REWIRED_PER_TICK rewired or re-levelled
# chunks, and the rewire flashes (0.6 s each, the newest 32, every other point of the edge).
# A step goes out at once.
TAIL_PIECES = 4 * CHUNK * SEG
REWIRED_PER_TICK = 8
BURST_TICKS, HEAVY_BURST_TICKS = 5, 20
LIGHT_BURST = 2  # chunks
FLASH_STRIDE = 2
FLASHES_DRAWN = 32


@dataclass(frozen=True)
class Look:
    """How a run is drawn: ``scale`` multiplies line widths and label sizes (projector mode);
    ``faded`` draws the tree in a colour near the asphalt's."""

    scale: float = 1.0
    faded: bool = False

    @property
    def tree_rgb(self) -> tuple[int, int, int]:
        return TREE_FADED_RGB if self.faded else TREE_RGB


def legend_html() -> str:
    """`LEGEND` as a two-column grid of swatches, for the panel."""
    def swatch(rgb, kind: str) -> str:
        paint = (f"linear-gradient(90deg,{','.join(f'rgb{c}' for c in rgb)})"
                 if isinstance(rgb[0], tuple) else f"rgb{rgb}")
        if kind == "dash":  # the colour's dashes on the other
            paint = f"repeating-linear-gradient(90deg,rgb{rgb[0]} 0 4px,rgb{rgb[1]} 4px 8px)"
        shape = {"line": "width:18px;height:4px", "dash": "width:18px;height:4px",
                 "ring": f"width:9px;height:9px;border-radius:50%;border:3px solid rgb{rgb}",
                 "diamond": f"width:7px;height:7px;transform:rotate(45deg);"
                            f"border:2px solid rgb{rgb[1]};margin-left:3px",
                 "fill": "width:12px;height:10px"}[kind]
        if kind == "diamond":
            paint = f"rgb{rgb[0]}"
        fill = "" if kind == "ring" else f";background:{paint}"
        return (f"<span style='display:inline-block;{shape}{fill};outline:1px solid #999;"
                f"margin-right:5px;vertical-align:middle'></span>")
    cells = "".join(f"<div>{swatch(rgb, kind)}{html.escape(what)}</div>"
                    for what, rgb, kind in LEGEND)
    return ("<div style='font-size:12px;display:grid;grid-template-columns:1fr 1fr;"
            f"gap:3px 8px;margin-top:6px'>{cells}</div>")


def _circle(x: float, y: float, r: float, z: float, n: int = 40) -> np.ndarray:
    return polyline_segments(circle_points(x, y, r, n), z, True)


def _edges(pts_list: list[np.ndarray], z: float) -> np.ndarray:
    if not pts_list:
        return np.zeros((0, 2, 3), np.float32)
    return np.concatenate([polyline_segments(p, z) for p in pts_list])


def edge_label(kinds: np.ndarray, lens: np.ndarray, place: str) -> str:
    """What a clicked edge says: its steering word, its driven length and where it is
    ("LSL · 1.84 m · best path, edge 2 of 5")."""
    return f"{planner.path_word(kinds, lens)} · {planner.path_length(kinds, lens):.2f} m · {place}"


class LiveView:
    """One run's drawing in one client's scene; `clear` removes all of it."""

    def __init__(self, scene, live: Live, bounds, look: Look = Look(), camera=None,
                 root: str = "/live", path_rgb=PATH_RGB) -> None:
        """``bounds``: the scene's (xmin, ymin, xmax, ymax), which sizes the markers;
        ``camera``: the client's, whose view sizes the step labels; ``root``: the scene node
        it draws under (the split's second run: in a frame moved beside the first);
        ``path_rgb``: its best path's colour."""
        self.scene, self.live, self.bounds, self.look = scene, live, bounds, look
        self.root, self.path_rgb = root, path_rgb
        self.camera = camera
        self.marker = marker_size(bounds)
        self._chunks: dict[int, object] = {}
        self._handles: dict[str, object] = {}
        self._px: dict[str, float] = {}  # each line node's width at scale 1
        self._seen = {"best": 0, "step": 0}
        self._ticks = 0
        self._burst_tick = -HEAVY_BURST_TICKS  # the first tick draws what there is
        self.sent_chunks = 0
        self.replaying = False  # the scene shows a past iteration (`replay`), not the run

    def restyle(self, look: Look) -> None:
        """Draw what is there, and what comes, with ``look``."""
        self.look = look
        for h in self._chunks.values():
            h.thickness, h.colors = TREE_PX * look.scale, np.array(look.tree_rgb)
        for name, h in self._handles.items():
            if name in self._px:
                h.thickness = self._px[name] * look.scale
            else:
                h.font_screen_scale = look.scale

    def _put(self, name: str, seg: np.ndarray, rgb, px: float) -> None:
        """Create or update a line-segments node (hidden when empty); ``px`` at scale 1."""
        self._px.setdefault(name, px)
        put_segments(self.scene, self._handles, name, f"{self.root}/{name}", seg, rgb,
                     px * self.look.scale)

    def tick(self) -> None:
        if self.replaying:  # the past iteration stays until `live_again`
            return
        self._ticks += 1
        stepped = self.live.step_version != self._seen["step"]
        since = self._ticks - self._burst_tick
        chunks = self.live.chunks
        light = self.live.state != "running" or chunks.new_chunks() <= LIGHT_BURST
        if stepped or since >= HEAVY_BURST_TICKS or (since >= BURST_TICKS and light):
            self._burst_tick = self._ticks  # one burst: the browser renders it once
            chunks.coarse = not light
            self._send_chunks(chunks.take_tail(TAIL_PIECES)
                              + chunks.take_rewired(REWIRED_PER_TICK))
            self._flashes()
            if self.live.best_version != self._seen["best"]:
                self._seen["best"] = self.live.best_version
                self._draw_path(self.live.best_path)
        if stepped:
            self._seen["step"] = self.live.step_version
            self._step_overlay(self.live.step)

    def _send_chunks(self, sends: list[tuple[int, np.ndarray]]) -> None:
        """Chunks of tree edges (`EdgeChunks.segments`) into the scene, each in its node."""
        for c, seg in sends:
            seg[:, :, 2] = Z["tree"]
            h = self._chunks.get(c)
            if h is None:
                self._chunks[c] = self.scene.add_line_segments(
                    f"{self.root}/tree/c{c}", seg, self.look.tree_rgb,
                    thickness=TREE_PX * self.look.scale, thickness_units="screen")
            else:
                h.points = seg
                if not h.visible:
                    h.visible = True
            self.sent_chunks += 1

    def _draw_path(self, path: np.ndarray | None) -> None:
        """The best path's layers (`path_layers`); None (no path) hides them."""
        if path is None or len(path) < 2:
            for name, h in self._handles.items():
                if name.startswith("best"):
                    h.visible = False
            return
        for suffix, seg, rgb, px in path_layers(path, self.path_rgb, self.marker, Z["path"]):
            self._put(f"best{suffix}", seg, rgb, px)

    def replay(self, edges: EdgeChunks, path: np.ndarray | None) -> None:
        """Show a past iteration instead of the run: the tree of ``edges`` (drawn like the
        live tree, chunk by chunk, the chunks past it hidden) and its best path; the rewire
        flashes, the step overlay and a clicked edge's label go."""
        self.replaying = True
        self._send_chunks([(c, edges.segments(c)) for c in range(edges.chunks)])
        for c, h in self._chunks.items():
            if c >= edges.chunks and h.visible:
                h.visible = False
        self._draw_path(path)
        for name, h in self._handles.items():
            if name.startswith(("step_", "flash_", "pick")):
                h.visible = False

    def live_again(self) -> None:
        """Back from `replay` to the run: every chunk, the best path and the step overlay are
        drawn anew from the run's record."""
        if not self.replaying:
            return
        self.replaying = False
        chunks = self.live.chunks
        self._send_chunks([(c, chunks.segments(c)) for c in range(chunks.chunks)])
        self._seen = {"best": -1, "step": -1}

    def _flashes(self) -> None:
        now = time.monotonic()
        fl = [f for f in list(self.live.flashes) if now - f[0] < FLASH_S][-FLASHES_DRAWN:]
        if not fl and "flash_old" not in self._handles:
            return
        self._put("flash_old", _edges([f[1][::FLASH_STRIDE] for f in fl], Z["flash"]),
                  REWIRE_OLD_RGB, 2.5)
        self._put("flash_new", _edges([f[2][::FLASH_STRIDE] for f in fl], Z["flash"]),
                  REWIRE_NEW_RGB, 2.5)

    def _step_overlay(self, st: Step | None) -> None:
        """x_rand, x_nearest, x_new (or where a blocked Steer ended, and its motion), the near
        radius and nodes, the chosen parent edge, the rewired edges old and new; labelled."""
        for name in [n for n in self._handles if n.startswith("step_")]:
            self._handles[name].visible = False
        if st is None:
            return
        m, z = self.marker, Z["step"]
        xr = st.x_rand
        self._put("step_rand", _circle(xr[0], xr[1], m, z, 12), RAND_RGB, 3.0)
        if st.nearest is not None:
            self._put("step_nearest", _circle(*st.nearest[:2], m, z, 12), NEAREST_RGB, 3.0)
        if st.blocked is not None:
            end, pts = st.blocked
            # A dark line under the red one keeps it visible across a red obstacle.
            self._put("step_blocked_under", _edges([pts], z - 1e-4), (30, 30, 30), 7.0)
            self._put("step_blocked", _edges([pts], z), BLOCKED_RGB, 3.5)
            self._put("step_blocked_end", _circle(end[0], end[1], m, z, 12), BLOCKED_RGB, 3.0)
        if st.new is not None:
            nx, ny = st.new[:2]
            self._put("step_new", _circle(nx, ny, m, z, 12), NEW_RGB, 3.0)
            if st.radius > 0 and math.isfinite(st.radius):
                self._put("step_radius", _circle(nx, ny, st.radius, z, 64), NEAR_RGB, 1.5)
            near = [_circle(x, y, 0.4 * m, z, 8) for x, y, _ in st.near]
            self._put("step_near", np.concatenate(near) if near else near, NEAR_RGB, 2.0)
            self._put("step_parent", _edges([st.parent_edge], z), NEW_RGB, 5.0)
        self._put("step_was", _edges([r.old for r in st.rewired], z - 1e-4), REWIRE_OLD_RGB,
                  1.5)
        self._put("step_rewired", _edges([r.new for r in st.rewired], z), REWIRE_NEW_RGB, 4.0)
        view = metres_per_px(self.camera) if self.camera is not None else None
        for label in step_labels(st, self.bounds, self.look.scale, view):
            self._label(*label)

    def _label(self, name: str, text: str, where, anchor: str) -> None:
        h = self._handles.get(name)
        pos = (*where, Z["step"])
        if h is None:
            self._handles[name] = self.scene.add_label(f"{self.root}/{name}", text, position=pos,
                                                       anchor=anchor,
                                                       font_screen_scale=self.look.scale)
        else:
            h.position, h.text, h.anchor, h.visible = pos, text, anchor, True

    def pick(self, x: float, y: float) -> str | None:
        """A click on the ground at (x, y): the edge drawn there — of the best path first,
        else of the tree — gets a halo and a label with its word (`edge_label`); a click
        beside every edge takes them away. Returns the label's text (None: no edge). The
        live tree's edges only: while a past iteration is shown, clicks name nothing."""
        if self.replaying:
            return None
        chunks = self.live.chunks
        view = metres_per_px(self.camera) if self.camera is not None else None
        reach = PICK_PX * self.look.scale * (view or self.marker / MARKER_PX)
        near = chunks.distances((x, y))
        words = [(int(i), *chunks.edge(int(i))) for i in np.flatnonzero(near <= reach)]
        words = [w for w in words if np.any(w[2] != 0.0)]  # the root has no edge
        best = list(self.live.best_nodes)
        on_best = [w for w in words if w[0] in best]
        if not (on_best or words):
            for name in ("pick", "pick_l"):
                if name in self._handles:
                    self._handles[name].visible = False
            return None
        node, kinds, lens = min(on_best or words, key=lambda w: near[w[0]])
        place = (f"best path, edge {best.index(node)} of {len(best) - 1}" if on_best
                 else f"tree edge into node {node}")
        text = edge_label(kinds, lens, place)
        self._put("pick", polyline_segments(chunks.get(node), Z["path"] - 1e-4), PICK_RGB,
                  PICK_PX)
        self._label("pick_l", text, (x, y), "bottom-left")
        return text

    def clear(self) -> None:
        for h in [*self._chunks.values(), *self._handles.values()]:
            h.remove()
        self._chunks.clear()
        self._handles.clear()
        self._px.clear()
