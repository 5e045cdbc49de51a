"""The replay slider of a tab's run (issue 20): the tree and the best path as they stood after
any past iteration, rebuilt from the worker's `TreeRecord`, drawn by the run's `LiveView`."""

from __future__ import annotations

import numpy as np

from app.studio._tree import EdgeChunks

__all__ = ["NO_REPLAY", "ReplaySlider", "replay_md"]

NO_REPLAY = "Replay: pause or finish a run"
SPLIT_REPLAY = "Replay: one run at a time (leave the split to replay)"
OLD_EDGES = 300_000  # replayed edges a tree no longer holds, kept at most (a few 10 MB)


class ReplaySlider:
    """The slider and its line under it, for one run (a new run gets a new one)."""

    def __init__(self, ui) -> None:
        self.ui = ui
        self._shown: int | str = -1  # the iterations it was last set to, or "running"
        self._old_edges: dict[tuple[int, int], np.ndarray] = {}  # (node, parent): its points

    def show(self, n: int, worker, view) -> None:
        """Iteration n of a paused or finished run; at its last iteration, the run."""
        record = worker.record
        if n >= record.iterations:
            self.end(worker, view)
            return
        frame = record.frame(n)
        edges = EdgeChunks(capacity=1)
        edges.fill(self._edges(worker, frame))
        view.replay(edges, frame.path)
        self.ui.replay_note.content = replay_md(frame, record)

    def end(self, worker, view) -> None:
        """Back to the run from a replay: the slider at its end."""
        if not view.replaying:
            return
        view.live_again()
        self.ui.replay_note.content = replay_md(None, worker.record)
        self.ui.replay.value = worker.record.iterations

    def _edges(self, worker, frame) -> np.ndarray:
        """The edges of ``frame``'s tree: as drawn live where a node's parent is still the
        one it had then, else the steering between the two poses (a rewire replaced the edge;
        kept for the next frames). A record that stopped steers every edge (the live tree
        went on from where it ends)."""
        record, n = worker.record, frame.nodes
        pts = worker.live.chunks.points(n)
        if record.note is None:
            final = record.frame(record.iterations).parent[:n]
            old = np.flatnonzero(frame.parent != final)
        else:
            old = np.arange(1, n)
        poses = record.poses(n)
        if len(self._old_edges) + len(old) > OLD_EDGES:
            self._old_edges.clear()
        for node in old.tolist():
            up = int(frame.parent[node])
            edge = self._old_edges.get((node, up))
            if edge is None:
                edge = self._old_edges[node, up] = worker.steer_points(poses[up], poses[node])
            pts[node] = edge
        return pts

    def tick(self, worker, view, splitting: bool) -> None:
        """The slider follows the record: usable once the run is paused or done, at its end
        while the run is shown. While the run goes on it is left alone (disabled): its three
        GUI updates a tick, arriving while scene updates waited for a frame, kept the browser
        rendering without a pause."""
        slider, end = self.ui.replay, worker.record.iterations
        running = worker.live.state == "running"
        usable = not running and end > 0 and not splitting
        if slider.disabled == usable:
            slider.disabled = not usable
        shown = "running" if running else end
        if view.replaying or self._shown == shown:
            return
        self._shown = shown
        if running:
            self.ui.replay_note.content = NO_REPLAY
            return
        slider.max = max(end, 1)
        slider.value = end
        self.ui.replay_note.content = (SPLIT_REPLAY if splitting
                                       else replay_md(None, worker.record))


def replay_md(frame, record) -> str:
    """The replay's line under its slider: the iteration shown of those recorded, its nodes
    and best cost (None: the run itself)."""
    end = record.iterations
    if frame is None:
        text = (f"Replay: iteration {end:,} of {end:,} (the run)" if end
                else NO_REPLAY)
    else:
        cost = "no path yet" if frame.cost is None else f"best cost {frame.cost:.4g} m"
        text = (f"Replay: iteration {frame.iteration:,} of {end:,} · {frame.nodes:,} nodes · "
                f"{cost}")
        if frame.cost is not None and frame.path_iteration != frame.cost_iteration:
            text += (" (no path drawn for it)" if frame.path is None else
                     f" (the path drawn is the one of iteration {frame.path_iteration:,}: "
                     "the cost fell again inside one of the planner's batches)")
    return text + (f". {record.note}." if record.note else "")
