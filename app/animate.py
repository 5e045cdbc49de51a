"""A plan as an animation: the tree growing, its rewires and the best path, for slides.

`trackstar plan … --animate run.gif` records the planner after each of ``FRAMES`` equal parts of
its budget (`app.planning.run_plan`'s ``observe``; the tree is the one the plan reports) and
draws each with matplotlib, in the PythonRobotics manner: the world in grey, the tree in blue,
the edges rewired since the last frame in orange, the best path in magenta.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from planner.tree import TreeSnapshot

__all__ = ["FRAMES", "Frame", "FrameRecorder", "animation_gif", "check_animation_path", "title",
           "write_animation"]

FRAMES = 40
SIZE_IN, DPI = (8.0, 6.0), 100  # 800 × 600 pixels
TREE, REWIRED, BEST, WORLD = "#4696eb", "#ff8c1a", "#ff5ac8", "#8c8c96"
EDGE_POINTS = 6  # points per drawn edge: curved Dubins and Reeds-Shepp edges stay curved


@dataclass(frozen=True)
class Frame:
    tree: TreeSnapshot
    iterations: int
    cost: float | None


class FrameRecorder:
    """``observe`` for `run_plan`: keeps a snapshot of the tree after each part of the budget."""

    def __init__(self) -> None:
        self.frames: list[Frame] = []
        self.problem = None

    def __call__(self, planner) -> None:
        planner = getattr(planner, "route", planner)  # timing optimal: the tree of the route
        self.problem = planner.problem
        self.frames.append(Frame(planner.snapshot(), planner.iterations, planner.best_cost))


def title(scenario: str, options) -> str:
    return f"{scenario}: {options.planner}, {options.steering}, seed {options.seed}"


def animation_gif(problem, options) -> bytes:
    """The run of ``options`` (an iteration budget) on ``problem`` as a GIF: the tree the
    studio's Run grows with the same settings, for its download."""
    import tempfile

    from app.planning import advance_in_parts
    from planner.rrt import Planner

    recorder = FrameRecorder()
    advance_in_parts(Planner(problem, options), None, options.iterations, FRAMES, recorder)
    name = problem.scenario.name if problem.scenario is not None else "scenario"
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "run.gif"
        write_animation(recorder.frames, problem, title(name, options), path)
        return path.read_bytes()


def check_animation_path(path: Path) -> None:
    """Raise ValueError, before any planning, for a file the animation cannot be written to."""
    if path.suffix.lower() != ".gif":
        raise ValueError(f"{path}: the animation is written as a .gif (for a video: "
                         f"ffmpeg -i run.gif run.mp4)")
    if not path.parent.is_dir():
        raise ValueError(f"{path}: no directory {str(path.parent)!r}")


def write_animation(frames: list[Frame], problem, title: str, path: Path, fps: int = 8) -> None:
    """Draw ``frames`` over the world of ``problem`` into the GIF ``path``. The world and the
    axes are drawn once; each frame redraws only the tree, the path and the title (blitting)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    from PIL import Image

    check_animation_path(path)
    fig, ax = plt.subplots(figsize=SIZE_IN, dpi=DPI)
    _draw_world(ax, problem)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.canvas.draw()
    background = fig.canvas.copy_from_bbox(fig.bbox)
    tree_lines = LineCollection([], colors=TREE, linewidths=0.6, animated=True)
    rewired = LineCollection([], colors=REWIRED, linewidths=1.4, animated=True)
    (best,) = ax.plot([], [], color=BEST, linewidth=2.5, zorder=5, animated=True)
    ax.add_collection(tree_lines)
    ax.add_collection(rewired)
    caption = ax.text(0.01, 0.99, "", transform=ax.transAxes, va="top", fontsize=9,
                      animated=True, bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})
    edges: dict[int, np.ndarray] = {}
    images = []
    for k, frame in enumerate(frames):
        before = frames[k - 1].tree.parent if k else np.zeros(0, np.int64)
        changed = [n for n in range(frame.tree.nodes)
                   if n >= len(before) or before[n] != frame.tree.parent[n]]
        moved = [n for n in changed if n < len(before)]
        for n in changed:
            edges[n] = frame.tree.edge_points(n, EDGE_POINTS)
        tree_lines.set_segments([edges[n] for n in range(frame.tree.nodes)])
        rewired.set_segments([edges[n] for n in moved])
        chain = frame.tree.best_path
        line = np.vstack([edges[n] for n in chain[1:]]) if len(chain) > 1 else np.zeros((0, 2))
        best.set_data(line[:, 0], line[:, 1])
        cost = f"best cost {frame.cost:.2f} m" if frame.cost is not None else "no path yet"
        caption.set_text(f"iteration {frame.iterations}, {frame.tree.nodes} nodes, "
                         f"{len(moved)} rewired, {cost}")
        fig.canvas.restore_region(background)
        for artist in (tree_lines, rewired, best, caption):
            ax.draw_artist(artist)
        fig.canvas.blit(fig.bbox)
        rgba = np.asarray(fig.canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[:, :, :3]).quantize(
            method=Image.Quantize.FASTOCTREE))
    plt.close(fig)
    images[0].save(path, save_all=True, append_images=images[1:], duration=1000 // fps,
                   loop=0)


def _draw_world(ax, problem) -> None:
    """Bounds, the track's edges, the obstacles (movers where they are at t = 0), start and
    goal, from the compiled world: what the planner checks is what is drawn."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle

    from planner.sim.sensing import true_offsets

    w = problem.world
    xmin, ymin, xmax, ymax = problem.bounds
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.plot([xmin, xmax, xmax, xmin, xmin], [ymin, ymin, ymax, ymax, ymin], color=WORLD)

    def at_start(m: int) -> np.ndarray:
        return true_offsets(w, np.array([m]), 0.0)[0, 0]

    segments = [e.reshape(2, 2) for e in w.ring_edges]
    for p, m in enumerate(w.poly_motion):
        edges = w.poly_edges[w.poly_start[p]:w.poly_start[p + 1]]
        segments += [e.reshape(2, 2) + at_start(m) for e in edges]
    ax.add_collection(LineCollection(segments, colors=WORLD, linewidths=1.2))
    for (cx, cy, r), m in zip(w.circ, w.circ_motion):
        ax.add_patch(Circle((cx, cy) + at_start(m), r, color=WORLD, alpha=0.6))
    arrow = 0.03 * np.hypot(xmax - xmin, ymax - ymin)
    for (x, y, th), colour, label in ((problem.start, "tab:green", "start"),
                                      (problem.goal, "tab:red", "goal")):
        ax.annotate("", (x + arrow * np.cos(th), y + arrow * np.sin(th)), (x, y),
                    arrowprops={"arrowstyle": "->", "color": colour, "lw": 2}, zorder=6)
        ax.plot([x], [y], "o", color=colour, label=label, zorder=6)
    ax.legend(loc="upper right", fontsize=8)
