"""The tree as fixed-size chunks of edges: what to send the browser, and when.

Each node owns the edge from its parent (a rewire changes only that edge), drawn as ``SEG``
straight pieces along the car's curve. Node i lives in chunk i // CHUNK. The tail chunk (where
new nodes land) is re-sent at UI rate; a full chunk is re-sent only when a rewire touched it, a
few per slow tick. So the bytes per second depend on the chunk size and the rates, never on the
size of the tree.

Level of detail: the browser redraws every line piece whenever anything in the scene changes,
and with software WebGL each piece costs ~12 µs a frame (Chromium's SwiftShader: 12 000 pieces
drew 6.5 frames/s, 48 000 drew 1.5). Only the newest ``FULL_CHUNKS`` chunks (where the tree
grows, and step mode looks) keep ``SEG`` pieces per edge; an older chunk is re-sent once with
``OLD_SEG`` pieces per edge (a chord alone would cut across the infield), and past
``OLD_PIECES`` of those only every k-th edge is drawn. So the drawn pieces stay under
FULL_CHUNKS·CHUNK·SEG + OLD_PIECES whatever the tree's size; the best path and the step overlay
are drawn in full on top. While the tree grows faster than the eye can follow its edges
(``coarse``), the newest chunks too go out in ``OLD_SEG`` pieces.

Each edge also keeps its local path in segment form (kinds, signed lengths), so that a click on
it can be answered with its steering word (`nearest`, `planner.path_word`).
"""

from __future__ import annotations

import math
import threading

import numpy as np

__all__ = ["CHUNK", "FULL_CHUNKS", "OLD_PIECES", "OLD_SEG", "SEG", "EdgeChunks", "edge_segments"]

# Straight pieces per edge: the longest edges on the thesis track (1.8 m, turning up to 115°
# at ρ = 0.9 m) bend under 10° per piece, so edges read as the car's curves.
SEG = 12
CHUNK = 96  # nodes per chunk: SEG · CHUNK pieces (28 kB) per message
FULL_CHUNKS = 2  # the newest chunks drawn with their curves: 2304 pieces
OLD_SEG = 3  # pieces per older edge: a 115° turn bends under 40° per piece
OLD_PIECES = 2_000  # pieces drawn at most for the older edges


def edge_segments(pts: np.ndarray, z: float = 0.0) -> np.ndarray:
    """Edges as points along them, (n, k + 1, 2), as (n·k, 2, 3) line segments at height z:
    how every tree the studio shows (live, replayed, the simulation's replanner's) is drawn."""
    seg = np.full((len(pts), pts.shape[1] - 1, 2, 3), z, np.float32)
    seg[:, :, 0, :2] = pts[:, :-1]
    seg[:, :, 1, :2] = pts[:, 1:]
    return seg.reshape(-1, 2, 3)


class EdgeChunks:
    """Edges by node, with the bookkeeping of which chunks the browser has not seen yet.

    Written by the planner's thread, read by the UI's; every method takes the lock.
    """

    def __init__(self, seg: int = SEG, chunk: int = CHUNK, capacity: int = 4096,
                 full_chunks: int = FULL_CHUNKS, old_seg: int = OLD_SEG,
                 old_pieces: int = OLD_PIECES) -> None:
        self.seg, self.chunk, self.full_chunks = seg, chunk, full_chunks
        self.old_seg, self.old_pieces = min(old_seg, seg), old_pieces
        self._drawn: dict[int, tuple[int, int]] = {}  # chunk: the level it was sent with
        self._pts = np.zeros((capacity, seg + 1, 2), np.float32)
        self._kinds = np.zeros((capacity, 0), np.int8)  # as wide as the steering's paths
        self._lens = np.zeros((capacity, 0))
        self._n = 0
        self._tail_dirty = False
        self._sent_n = 0  # nodes the browser had at the last tail push
        self._dirty: dict[int, None] = {}  # full chunks touched by rewires, oldest first
        self._coarse = False
        self._lock = threading.Lock()

    @property
    def count(self) -> int:
        return self._n

    def get(self, node: int) -> np.ndarray:
        with self._lock:
            return self._pts[node].copy()

    def points(self, count: int) -> np.ndarray:
        """The first ``count`` nodes' edges, (count, seg + 1, 2) (a copy)."""
        with self._lock:
            return self._pts[:count].copy()

    def fill(self, pts: np.ndarray) -> None:
        """Hold exactly these edges, (count, seg + 1, 2), node i's at i (a replayed tree)."""
        with self._lock:
            self._pts = np.array(pts, np.float32)
            self._kinds = np.zeros((len(pts), 0), np.int8)
            self._lens = np.zeros((len(pts), 0))
            self._n = len(pts)

    @property
    def chunks(self) -> int:
        """How many chunks the edges fill."""
        return -(-self._n // self.chunk)

    def edge(self, node: int) -> tuple[np.ndarray, np.ndarray]:
        """Node's local path from its parent: kinds and signed lengths (copies)."""
        with self._lock:
            return self._kinds[node].copy(), self._lens[node].copy()

    def set(self, node: int, pts: np.ndarray, kinds=None, lens=None) -> None:
        """Record node's edge (a new node, or a rewired one): its points and, when given, its
        local path in segment form."""
        with self._lock:
            if node >= len(self._pts):
                size = max(2 * len(self._pts), node + 1)
                self._pts, self._kinds, self._lens = (
                    np.concatenate([a, np.zeros((size - len(a), *a.shape[1:]), a.dtype)])
                    for a in (self._pts, self._kinds, self._lens))
            self._pts[node] = pts
            if kinds is not None:
                if len(kinds) != self._kinds.shape[1]:  # the first edge: the run's width
                    self._kinds = np.zeros((len(self._pts), len(kinds)), np.int8)
                    self._lens = np.zeros((len(self._pts), len(kinds)))
                self._kinds[node], self._lens[node] = kinds, lens
            self._n = max(self._n, node + 1)
            c = node // self.chunk
            if c >= self._sent_n // self.chunk:
                self._tail_dirty = True
            else:
                self._dirty[c] = None

    def distances(self, p) -> np.ndarray:
        """How far each node's edge passes from the point p (x, y): (count,) metres."""
        with self._lock:
            pts = self._pts[:self._n].astype(float)
        a, b = pts[:, :-1], pts[:, 1:]
        ab, ap = b - a, np.asarray(p, float) - a
        u = np.clip(np.sum(ap * ab, -1) / np.maximum(np.sum(ab * ab, -1), 1e-18), 0.0, 1.0)
        return np.hypot(*np.moveaxis(ap - u[..., None] * ab, -1, 0)).min(axis=1)

    def _tail_chunk(self) -> int:
        return max(self._n - 1, 0) // self.chunk

    def segments(self, c: int) -> np.ndarray:
        """Chunk c as (m·seg, 2, 3) line segments at z = 0."""
        with self._lock:
            return self._segments(c)

    @property
    def coarse(self) -> bool:
        return self._coarse

    @coarse.setter
    def coarse(self, on: bool) -> None:
        """Coarse: the newest chunks too are drawn like the older ones (a tree growing faster
        than the eye can follow its edges); back from it, they are re-sent in full."""
        with self._lock:
            if on == self._coarse:
                return
            self._coarse = on
            tail = self._tail_chunk()
            for c in range(max(tail + 1 - self.full_chunks, 0), tail + 1):
                if c in self._drawn and self._drawn[c] != self.level(c):
                    self._dirty[c] = None

    def level(self, c: int) -> tuple[int, int]:
        """How chunk c is drawn now: (pieces per edge, every k-th edge)."""
        old = self._tail_chunk() + 1 - self.full_chunks  # chunks below this are old
        if c >= old:
            return (self.old_seg if self._coarse else self.seg), 1
        need = -(-old * self.chunk * self.old_seg // self.old_pieces)
        return self.old_seg, 1 << (need - 1).bit_length()  # doubling: rarely re-levelled

    def _segments(self, c: int) -> np.ndarray:
        pieces, every = self._drawn[c] = self.level(c)
        lo = c * self.chunk
        p = self._pts[lo + (-lo) % every:min(lo + self.chunk, self._n):every]
        return edge_segments(p[:, np.linspace(0, self.seg, pieces + 1).astype(int)])

    def take_tail(self, limit: float = math.inf) -> list[tuple[int, np.ndarray]]:
        """The chunks new nodes went into since the last call (the tail, and any it filled),
        oldest first, as many as ``limit`` pieces hold (at least one): a tree growing faster
        than that is drawn behind the planner, and catches up."""
        with self._lock:
            if not self._tail_dirty:
                return []
            first = self._sent_n // self.chunk
            out = []
            for c in range(first, self._tail_chunk() + 1):
                seg = self._segments(c)
                if out and len(seg) > limit:
                    break
                out.append((c, seg))
                limit -= len(seg)
            self._sent_n = min(self._n, (out[-1][0] + 1) * self.chunk)
            self._tail_dirty = self._sent_n < self._n
            for c in range(first):  # chunks the tree's growth made old, or sparser
                if self._drawn.get(c) != self.level(c):
                    self._dirty[c] = None
            return out

    def take_rewired(self, limit: int) -> list[tuple[int, np.ndarray]]:
        """Up to ``limit`` full chunks to re-send: those rewires changed, and those whose level
        of detail changed; those drawn with the most pieces first (a tree growing fast leaves
        chunks to re-level faster than they go out, and every piece drawn costs the browser
        each frame), else oldest first. The browser's cost is per scene node replaced, more
        than per piece, so the limit counts chunks."""
        with self._lock:
            out = []
            for c in sorted(self._dirty, key=self._drawn_pieces, reverse=True)[:limit]:
                del self._dirty[c]
                out.append((c, self._segments(c)))
            return out

    def _drawn_pieces(self, c: int) -> float:
        pieces, every = self._drawn.get(c, (0, 1))
        return pieces / every

    def new_chunks(self) -> int:
        """How many chunks new nodes went into since the tail last went out."""
        with self._lock:
            return self._tail_chunk() + 1 - self._sent_n // self.chunk if self._tail_dirty else 0

    def pending_rewired(self) -> int:
        with self._lock:
            return len(self._dirty)
