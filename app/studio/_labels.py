"""Where the step overlay's labels go: each diagonally off its point, on the side where it
clashes least with the scene's edge, the labels placed before it and the other points."""

from __future__ import annotations

import math

import numpy as np

from app.studio._scene import marker_size
from app.studio._worker import Step

__all__ = ["MARKER_PX", "place_labels", "step_labels"]

SIDES = ((1, 1), (1, -1), (-1, 1), (-1, -1))  # a label's quadrant off its point (x, y)
# A label's size on screen at scale 1 (viser: a 12 px em, padded): px per character, padding
# and height.
LABEL_CHAR_PX, LABEL_PAD_PX, LABEL_H_PX = 6.5, 8.0, 18.0
MARKER_PX = 6.0  # a marker's size in the fitted view: the scale when the camera is not known


def _label_box(p: np.ndarray, side, size: np.ndarray, marker: float):
    """(low corner, high corner) of a label of ``size`` a marker off point p toward ``side``."""
    corner = p + marker * np.asarray(side)
    far = corner + size * side
    return np.minimum(corner, far), np.maximum(corner, far)


def _clashes(box, placed: list, points: list, marker: float, bounds) -> int:
    """How badly ``box`` sits: leaving the scene's ``bounds`` counts 4, each ``placed`` box it
    overlaps 2, each point's marker it covers 1."""
    lo, hi = box
    return (4 * int(np.any(lo < bounds[:2]) or np.any(hi > bounds[2:]))
            + 2 * sum(bool(np.all(lo < c[1]) and np.all(c[0] < hi)) for c in placed)
            + sum(bool(np.all(lo - marker < q) and np.all(q < hi + marker)) for q in points))


def place_labels(points: list[tuple[str, str, np.ndarray]], bounds, scale: float = 1.0,
                 m_per_px: float | None = None
                 ) -> list[tuple[str, str, tuple[float, float], str]]:
    """(node, text, position, anchor) for labels of (node, text, point), placed in the order
    given: each sits diagonally off its point, on the side where its box clashes least
    (`_clashes`) with the scene's ``bounds`` (xmin, ymin, xmax, ymax), the labels placed
    before it and the other points; of equal sides, the one away from the other points.
    Labels keep their size on screen: ``m_per_px`` (the view's, when it is known) gives their
    size on the ground. Points that look the same get one label naming both."""
    marker, bounds = marker_size(bounds), np.asarray(bounds, float)
    px = (m_per_px or marker / MARKER_PX) * scale
    merged: list[list] = []
    for node, text, p in points:
        twin = next((m for m in merged if math.dist(m[2], p[:2]) < 0.1 * marker), None)
        if twin is None:
            merged.append([node, text, np.asarray(p[:2], float)])
        else:
            twin[1] += f" = {text}"
    placed, out = [], []
    for node, text, p in merged:
        others = [q for _, _, q in merged if q is not p]
        away = sum(((p - q) / max(float(np.dot(p - q, p - q)), 1e-12) for q in others),
                   np.zeros(2))  # the nearest point pushes hardest
        size = np.array([LABEL_CHAR_PX * len(text) + LABEL_PAD_PX, LABEL_H_PX]) * px
        boxes = {side: _label_box(p, side, size, marker) for side in SIDES}
        side = min(SIDES, key=lambda sd: (_clashes(boxes[sd], placed, others, marker, bounds),
                                          -float(np.dot(sd, away))))
        placed.append(boxes[side])
        anchor = f"{'bottom' if side[1] > 0 else 'top'}-{'left' if side[0] > 0 else 'right'}"
        out.append((node, text, tuple(float(v) for v in p + marker * np.asarray(side)), anchor))
    return out


REWIRE_LABELS = 2  # rewired nodes whose old and new costs a step labels


def step_labels(st: Step, bounds, scale: float = 1.0, m_per_px: float | None = None
                ) -> list[tuple[str, str, tuple[float, float], str]]:
    """The step overlay's labels (see `place_labels`): x_rand, x_nearest, x_new (blocked, or
    added: moved back from a blocked Steer's end, that too) and, for the `REWIRE_LABELS` rewired nodes that got cheapest by most, the cost of
    reaching each by the old and the new edge, at the middle of each (in a big tree one
    iteration rewires many: their labels would stack unread; every edge is still drawn)."""
    points = [("step_rand_l", "x_rand", st.x_rand)]
    if st.nearest is not None:
        points.append(("step_nearest_l", "x_nearest", st.nearest))
    if st.new is not None:
        points.insert(0, ("step_new_l", "x_new", st.new))
        if st.blocked is not None:  # moved back from where Steer was blocked
            points.append(("step_blocked_l", "Steer blocked", st.blocked[0]))
    elif st.blocked is not None:
        points.insert(0, ("step_new_l", "x_new (blocked)", st.blocked[0]))
    most = sorted(st.rewired, key=lambda r: r.now - r.was)[:REWIRE_LABELS]
    for i, (old, new, was, now) in enumerate(most):
        points += [(f"step_was{i}_l", f"old {was:.2f} m", old[len(old) // 2]),
                   (f"step_now{i}_l", f"new {now:.2f} m", new[len(new) // 2])]
    return place_labels(points, bounds, scale, m_per_px)
