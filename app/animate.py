"""A plan as an animation: the tree growing, its rewires and the best path, for slides.

`trackstar plan … --animate run.gif` records the planner after each of ``FRAMES`` equal parts of
its budget (`app.planning.run_plan`'s ``observe``; the tree is the one the plan reports) and
draws each with matplotlib, in the PythonRobotics manner: the world in grey, the tree in blue,
the edges rewired since the last frame in orange, the best path in magenta. Where obstacles
move, ``DRIVE_FRAMES`` more frames drive the car along the result, its schedule's waits
included, with the movers where they are at each moment: what the planner avoided in time.
With ``timing: optimal`` the tree drawn is the route tree, as in the studio.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from planner.tree import TreeSnapshot

__all__ = ["DRIVE_FRAMES", "FRAMES", "Frame", "FrameRecorder", "animation_gif",
           "check_animation_path", "title", "write_animation"]

FRAMES = 40
DRIVE_FRAMES = 24  # the car driving the result, where obstacles move
SIZE_IN, DPI = (8.0, 6.0), 100  # 800 × 600 pixels
TREE, REWIRED, BEST, WORLD, MOVER, CAR = ("#4696eb", "#ff8c1a", "#ff5ac8", "#8c8c96",
                                          "#ff9a3c", "#202020")
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
        self.run = None  # the planner observed last

    def __call__(self, run) -> None:
        self.run = run
        tree = getattr(run, "route", run)  # timing optimal: the tree of the route
        self.problem = run.problem
        self.frames.append(Frame(tree.snapshot(), tree.iterations, tree.best_cost))

    def drive(self) -> np.ndarray | None:
        """The result's rows (x, y, θ, κ, direction, t) for the drive frames: None where
        nothing moves, or nothing was found."""
        if self.run is None or not len(self.problem.world.m_kind):
            return None
        path = self.run.result().path
        return path if len(path) > 1 else None


def title(scenario: str, options) -> str:
    timing = ", timing optimal" if options.timing == "optimal" else ""
    return f"{scenario}: {options.planner}, {options.steering}, seed {options.seed}{timing}"


def animation_gif(problem, options, iterations: int | None = None) -> bytes:
    """The run of ``options`` on ``problem`` to ``iterations`` (default: its budget) as a GIF:
    the run the studio's Run grows with the same settings (timing included), for its
    download; ``iterations`` as many as the run on screen has done makes its last frame that
    run's."""
    import tempfile

    from app.planning import advance_in_parts
    from planner.timing import planner_for

    recorder = FrameRecorder()
    advance_in_parts(planner_for(problem, options), None, iterations or options.iterations,
                     FRAMES, recorder)
    name = problem.scenario.name if problem.scenario is not None else "scenario"
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "run.gif"
        write_animation(recorder.frames, problem, title(name, options), path,
                        drive=recorder.drive())
        return path.read_bytes()


def check_animation_path(path: Path) -> None:
    """Raise ValueError, before any planning, for a file the animation cannot be written to."""
    if path.suffix.lower() != ".gif":
        raise ValueError(f"{path}: the animation is written as a .gif (for a video: "
                         f"ffmpeg -i run.gif run.mp4)")
    if not path.parent.is_dir():
        raise ValueError(f"{path}: no directory {str(path.parent)!r}")


def write_animation(frames: list[Frame], problem, title: str, path: Path, fps: int = 8,
                    drive: np.ndarray | None = None) -> None:
    """Draw ``frames`` over the world of ``problem`` into the GIF ``path``, then, given the
    result's rows ``drive``, `DRIVE_FRAMES` of the car driving them among the movers. The world
    and the axes are drawn once; each frame redraws only the tree, the path, the movers, the
    car and the caption (blitting)."""
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
    movers = _Movers(ax, problem.world)
    car = _Car(ax, problem.world)
    caption = ax.text(0.01, 0.99, "", transform=ax.transAxes, va="top", fontsize=9,
                      animated=True, bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})
    edges: dict[int, np.ndarray] = {}
    images = []

    def draw(text: str) -> None:
        caption.set_text(text)
        fig.canvas.restore_region(background)
        for artist in (tree_lines, rewired, best, *movers.artists, *car.artists, caption):
            ax.draw_artist(artist)
        fig.canvas.blit(fig.bbox)
        rgba = np.asarray(fig.canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[:, :, :3]).quantize(
            method=Image.Quantize.FASTOCTREE))

    movers.at(0.0)
    said = ""
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
        said = f"iteration {frame.iterations}, {frame.tree.nodes} nodes, {cost}"
        draw(f"{said}, {len(moved)} rewired")
    if drive is not None:
        rewired.set_segments([])
        best.set_data(drive[:, 0], drive[:, 1])  # the result as driven, waits and all
        end = float(drive[-1, 5])
        for t in np.linspace(0.0, end, DRIVE_FRAMES):
            k = int(np.searchsorted(drive[:, 5], t).clip(0, len(drive) - 1))
            car.at(drive[k, :3])
            movers.at(t)
            draw(f"driving: t = {t:.1f} of {end:.1f} s\n{said}")
    plt.close(fig)
    images[0].save(path, save_all=True, append_images=images[1:], duration=1000 // fps,
                   loop=0)


class _Movers:
    """The moving obstacles as patches of their own, placed at a time for each frame."""

    def __init__(self, ax, w) -> None:
        from matplotlib.patches import Circle, Polygon

        self.w = w
        self.artists, self._base, self._motion = [], [], []
        for (cx, cy, r), m in zip(w.circ, w.circ_motion):
            if m >= 0:
                self.artists.append(ax.add_patch(Circle((cx, cy), r, color=MOVER, alpha=0.8,
                                                        animated=True)))
                self._base.append(np.array([cx, cy]))
                self._motion.append(m)
        for p, m in enumerate(w.poly_motion):
            if m >= 0:
                edges = w.poly_edges[w.poly_start[p]:w.poly_start[p + 1]]
                self.artists.append(ax.add_patch(Polygon(edges[:, :2], color=MOVER, alpha=0.8,
                                                         animated=True)))
                self._base.append(edges[:, :2])
                self._motion.append(m)

    def at(self, t: float) -> None:
        from planner.sim.sensing import true_offsets

        offsets = true_offsets(self.w, np.array(self._motion, np.int64), t)[0]
        for artist, base, d in zip(self.artists, self._base, offsets):
            if base.ndim == 1:
                artist.set_center(base + d)
            else:
                artist.set_xy(base + d)


class _Car:
    """The car in the drive frames: its footprint discs (a dot for a point) and its heading."""

    def __init__(self, ax, w) -> None:
        from matplotlib.patches import Circle

        self.discs = w.discs
        span = max(float(np.ptp(ax.get_xlim())), float(np.ptp(ax.get_ylim())))
        self.nose = max(float((w.discs[:, 0] + w.discs[:, 1]).max()), 0.02 * span)
        self.circles = [ax.add_patch(Circle((np.nan, np.nan), max(r, 0.006 * span), color=CAR,
                                            alpha=0.7, animated=True)) for r in w.discs[:, 1]]
        (self.heading,) = ax.plot([], [], color=CAR, linewidth=2.0, animated=True, zorder=7)
        self.artists = [*self.circles, self.heading]

    def at(self, pose) -> None:
        x, y, th = pose
        c, s = np.cos(th), np.sin(th)
        for circle, a in zip(self.circles, self.discs[:, 0]):
            circle.set_center((x + a * c, y + a * s))
        self.heading.set_data([x, x + self.nose * c], [y, y + self.nose * s])


def _draw_world(ax, problem) -> None:
    """Bounds, the track's edges, the static obstacles, start and goal, from the compiled
    world: what the planner checks is what is drawn (the movers: `_Movers`)."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle

    w = problem.world
    xmin, ymin, xmax, ymax = problem.bounds
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.plot([xmin, xmax, xmax, xmin, xmin], [ymin, ymin, ymax, ymax, ymin], color=WORLD)
    segments = [e.reshape(2, 2) for e in w.ring_edges]
    for p in np.flatnonzero(w.poly_motion < 0):
        segments += [e.reshape(2, 2) for e in w.poly_edges[w.poly_start[p]:w.poly_start[p + 1]]]
    ax.add_collection(LineCollection(segments, colors=WORLD, linewidths=1.2))
    for (cx, cy, r), m in zip(w.circ, w.circ_motion):
        if m < 0:
            ax.add_patch(Circle((cx, cy), r, color=WORLD, alpha=0.6))
    arrow = 0.03 * np.hypot(xmax - xmin, ymax - ymin)
    for (x, y, th), colour, label in ((problem.start, "tab:green", "start"),
                                      (problem.goal, "tab:red", "goal")):
        ax.annotate("", (x + arrow * np.cos(th), y + arrow * np.sin(th)), (x, y),
                    arrowprops={"arrowstyle": "->", "color": colour, "lw": 2}, zorder=6)
        ax.plot([x], [y], "o", color=colour, label=label, zorder=6)
    ax.legend(loc="upper right", fontsize=8)
