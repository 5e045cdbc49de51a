"""A track being drawn in the scene: the clicked `Draft`, a gizmo per anchor and per handle tip,
the curve and its handle bars; `Use drawn track` and `Download track SVG`.

`TrackDrawing` owns the draft and its gizmos; a finished track goes to ``use_track`` (which puts
it on the stage with a scenario of its own).
"""

from __future__ import annotations

import numpy as np

import tracks
from app.studio._custom import Draft
from app.studio._gizmo import gizmo
from app.studio._scene import DRAFT_RGB, Z, polyline_segments

__all__ = ["TrackDrawing"]


def _bezier_points(ctrl: np.ndarray, n: int = 24) -> np.ndarray:
    t = np.linspace(0.0, 1.0, n)[:, None]
    return ((1 - t) ** 3 * ctrl[0] + 3 * (1 - t) ** 2 * t * ctrl[1]
            + 3 * (1 - t) * t ** 2 * ctrl[2] + t ** 3 * ctrl[3])


class TrackDrawing:
    def __init__(self, client, ui, stage, use_track, notify) -> None:
        self.client, self.scene, self.ui, self.stage = client, client.scene, ui, stage
        self._use_track, self.notify = use_track, notify
        self._draft = Draft()
        self._gizmos: list[tuple] = []  # (anchor, handle tip) per point

    def add(self, p) -> None:
        """A ground click: a new point at the end."""
        self._draft.add(p)
        self.changed()

    def undo(self) -> None:
        self._draft.undo()
        self.changed()

    def forget_gizmos(self) -> None:
        """The scene was cleared, and the gizmos with it."""
        self._gizmos = []

    def changed(self) -> None:
        """Redraw the drawn track with a gizmo per anchor (drags the point) and per handle tip
        (drags the tangent, which stops following Catmull-Rom)."""
        for anchor, tip in self._gizmos:
            anchor.remove()
            tip.remove()
        self._gizmos = []
        d, closed = self._draft, bool(self.ui.draw_close.value)
        for i, p in enumerate(d.points):
            tip = p + d.handle(i, closed)
            self._gizmos.append((
                gizmo(self.scene, f"/draft/a{i}", (*p, 0.0),
                      lambda x, y, _, i=i: self._move_anchor(i, x, y), rotate=False, px=60),
                gizmo(self.scene, f"/draft/h{i}", (*tip, 0.0),
                      lambda x, y, _, i=i: self._move_handle(i, x, y), rotate=False, px=35)))
        self._draw_lines()
        self.ui.draw.label = f"Draw (click the ground) — {len(d.points)} points"

    def use(self) -> None:
        """`Use drawn track`: the drawing ends and its track goes on the stage."""
        track = self._track()
        if track is not None:
            self.ui.draw.value = False
            self._use_track(track)
            self._draft = Draft()
            self.changed()

    def download_svg(self) -> None:
        """The drawn track, or the stage's when nothing is drawn, as an SVG file."""
        track = self._track() if self._draft.points else self.stage.track
        if track is not None:
            self.client.send_file_download(f"{track.name or 'track'}.svg",
                                           track.to_svg().encode(), save_immediately=True)

    def _track(self) -> tracks.Track | None:
        try:
            return self._draft.track(float(self.ui.draw_width.value),
                                     bool(self.ui.draw_close.value))
        except (ValueError, tracks.TrackError) as exc:
            self.notify("Track not drawn", str(exc))
            return None

    def _draw_lines(self) -> None:
        """The curve through the anchors and each anchor's handle bar (mirrored both ways)."""
        d, closed = self._draft, bool(self.ui.draw_close.value)
        curves = [polyline_segments(_bezier_points(c), Z["pose"]) for c in d.beziers(closed)]
        bars = [polyline_segments(np.array([p - h, p + h]), Z["pose"])
                for p, h in ((d.points[i], d.handle(i, closed)) for i in range(len(d.points)))]
        empty = np.zeros((0, 2, 3), np.float32)
        self.scene.add_line_segments("/draft/line", np.concatenate(curves) if curves else empty,
                                     DRAFT_RGB, thickness=2.0, thickness_units="screen",
                                     visible=bool(curves))
        self.scene.add_line_segments("/draft/bars", np.concatenate(bars) if bars else empty,
                                     (255, 200, 120), thickness=1.0, thickness_units="screen",
                                     visible=bool(bars))

    def _move_anchor(self, i: int, x: float, y: float) -> None:
        self._draft.points[i] = np.array([x, y])
        self._place_handle_tips()
        self._draw_lines()

    def _move_handle(self, i: int, x: float, y: float) -> None:
        self._draft.handles[i] = np.array([x, y]) - self._draft.points[i]
        self._draw_lines()

    def _place_handle_tips(self) -> None:
        """Automatic handles follow their neighbours: keep their gizmos on the tips."""
        d, closed = self._draft, bool(self.ui.draw_close.value)
        for i, (_, tip) in enumerate(self._gizmos):
            if d.handles[i] is None:
                tip.position = (*(d.points[i] + d.handle(i, closed)), Z["pose"])
