"""The simulated car live in one tab (issue 9): `planner.sim` played at wall-clock speed.

A run goes on its own thread (`simulate(..., realtime=True)`); its observer keeps the latest
`Frame`, the plot history and, at most every ``TREE_S``, the current tree's edges — read there,
since a planner's arrays are only safe to read on the thread that runs it. The session's ticker
calls `SimView.tick`, which draws the latest state: the car; the movers where they truly are
(the stage's own obstacles, the scene clock set to the simulation's time); where the car
believes they are (translucent ghosts: the last sensing carried on as the run predicts it, at
constant velocity or along the track's lanes, with a line along where it predicts them over the
next ``PREDICT_S``) and their grown predictions (issue 30:
the shape grown by the run's uncertainty at look-aheads ``LOOK_AHEAD_S``, fading with τ; none
for a mover whose timetable the car is told, `motion.known`); the reachable set of each mover the
car has seen turn at once (an orange outline round where it was sensed: the space the car must
be at rest before entering, `planner.sim.predict.reach_world`); the
committed path, the tree, Soll/Ist steering and lateral error plots, a safety timeline (speed,
what the guard has the car do, contacts) and the metrics. The scene marks where the car braked,
waited, evaded or backed off, and each collision with whose it was.
"""

from __future__ import annotations

import dataclasses
import math
import threading
import time

import numpy as np
import shapely
from pydantic import ValidationError

import planner
from app.simulation import SimOptions
from app.studio._live_view import PATH_RGB, TREE_RGB
from app.studio._panel import build_sim_controls
from app.studio._scene import (
    Z,
    _fill,
    draw_car,
    marker_size,
    polyline_segments,
    put_segments,
    yaw_wxyz,
)
from app.studio._tree import edge_segments
from planner.obstacles import outline
from planner.sim import SimSettings
from planner.sim.predict import REACH_S, Lanes, believed_offsets
from planner.sim.run import GUARD_CODES, Frame, simulate
from planner.sim.sensing import known_motions, mover_index
from planner.validation import describe

__all__ = ["SimView"]

TREE_S = 0.5  # s between tree extractions (≈20 µs per edge, on the simulation's thread)
SLOW_S = 0.5  # s between plot and metrics refreshes (uPlot redraws every point)
PATH_S = 0.2  # s between committed-path updates (a new one arrives with every cycle)
WINDOW_S = 20.0  # s of history in the plots
PLOT_POINTS = 400
PREDICT_S = 2.0  # s of predicted motion drawn ahead of each believed obstacle
PREDICT_POINTS = 9  # points of that line (a lane prediction bends with the track)
EDGE_PIECES = 4  # straight pieces per drawn tree edge
GHOST_RGB = (90, 200, 255)
GHOST_Z = Z["obstacle"] + 0.001
STALL_S = 2.0  # s standing still (not at the goal) that the scene marks as a stall
STILL_V = 1e-3  # m/s below which the car stands
EVENT_RGB = {"collision": (230, 30, 30), "stall": (240, 170, 0), "brake": (255, 120, 0),
             "wait": (60, 160, 255), "evade": (200, 40, 200), "back-off": (120, 90, 200)}
LOOK_AHEAD_S = (0.5, 1.0, 1.5)  # s: grown predictions drawn, fading with the look-ahead
GROWN_OPACITY = (0.22, 0.14, 0.08)
REACH_RGB = (250, 110, 30)


class _Stopped(Exception):
    """Raised by the observer to end a run (`simulate` lets an observer's exception end it)."""


class _Run:
    """One simulation on its own thread, and what its observer leaves for the UI."""

    def __init__(self, problem, settings: SimSettings) -> None:
        self.problem = problem
        self.frame: Frame | None = None
        # t, δ set, δ, e, v, guard code, contact (0, 1 moving, 2 at rest)
        self.history: list[tuple[float, ...]] = []
        self.cycle_ms: list[float] = []
        self.clearance, self.min_clearance = math.nan, math.inf
        self.tree = np.zeros((0, 2, 3), np.float32)
        self.tree_version = 0
        self.summary: dict | None = None
        self.error: str | None = None
        # (t, x, y, kind, cause) of each collision and stall: marked in the scene.
        self.events: list[tuple[float, float, float, str, str]] = []
        self._colliding, self._still_since, self._stall_marked = False, None, False
        self._contact = 0
        self._guard, self._v = "follow", 0.0  # the last frame's guard state and speed
        self._tree_of, self._tree_at = None, -math.inf
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._main, args=(settings,), daemon=True,
                                        name="studio-sim")
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()

    @property
    def running(self) -> bool:
        return self._thread.is_alive()

    def _main(self, settings: SimSettings) -> None:
        try:
            self.summary = simulate(self.problem.scenario, settings, self.problem,
                                    observer=self._observe).summary
        except _Stopped:
            pass
        except Exception as exc:  # noqa: BLE001  (shown in the status line)
            self.error = f"{type(exc).__name__}: {exc}"

    def _observe(self, f: Frame) -> None:
        if self._stop.is_set():
            raise _Stopped
        if f.cycles > len(self.cycle_ms):
            self.cycle_ms.append(f.cycle_ms)
        x, y, theta = f.pose
        self.clearance = self.problem.clearance(x, y, f.t, theta)
        self.min_clearance = min(self.min_clearance, self.clearance)
        self._note_events(f)
        contact = 0 if self.clearance > 0.0 else self._contact
        self.history.append((f.t, f.steer_set, f.steer, f.lateral_error, f.v,
                             GUARD_CODES[f.guard], contact))
        self._v = f.v
        now = time.monotonic()
        fresh = f.tree is not None and f.tree is not self._tree_of
        if fresh and now - self._tree_at > TREE_S:
            self._tree_of, self._tree_at = f.tree, now
            self.tree = _tree_segments(f.tree)
            self.tree_version += 1
        self.frame = f


    def _note_events(self, f: Frame) -> None:
        """A collision where the clearance turns ≤ 0; a stall once the car has stood `STALL_S`
        (marked where it began), with its cause: no path yet, or a predicted conflict ahead."""
        x, y, _ = f.pose
        if self.clearance <= 0.0 and not self._colliding:
            # Whose: the car's when it moved into it (the speed held over the tick before).
            moving = abs(self._v) > 1e-9
            self._contact = 1 if moving else 2
            self.events.append((f.t, x, y, "collision",
                                (f"clearance {self.clearance:.2f} m, "
                                 f"{'car moving' if moving else 'car at rest'}")))
        self._colliding = self.clearance <= 0.0
        if f.guard != self._guard and f.guard in EVENT_RGB:
            self.events.append((f.t, x, y, f.guard, f"at {f.v:.2f} m/s"))
        self._guard = f.guard
        if abs(f.v) > STILL_V:
            self._still_since, self._stall_marked = None, False
        elif self._still_since is None:
            self._still_since = f.t
        elif not self._stall_marked and f.t - self._still_since >= STALL_S:
            self._stall_marked = True
            cause = ("no path found" if f.reference is None
                     else "stopped before a predicted conflict")
            self.events.append((self._still_since, x, y, "stall", cause))


def _tree_segments(tree: planner.TreeSnapshot) -> np.ndarray:
    """Every edge as EDGE_PIECES straight pieces along its car path, at the tree's height."""
    if tree.nodes < 2:
        return np.zeros((0, 2, 3), np.float32)
    pts = np.stack([tree.edge_points(i, EDGE_PIECES) for i in range(1, tree.nodes)])
    return edge_segments(pts, Z["tree"])


class SimView:
    """The `Simulate` folder and the drawing of its runs in one tab's scene, their only writer;
    it shows the simulated time on the scene ``clock`` (`SceneClock`)."""

    def __init__(self, gui, scene, clock) -> None:
        self.scene, self.clock = scene, clock
        self.ui = build_sim_controls(gui)
        self.run: _Run | None = None
        self._handles: dict[str, object] = {}
        self._movers = np.zeros(0, np.int64)  # per scenario obstacle: its motion (-1: static)
        self._centres: dict[int, np.ndarray] = {}  # per mover: its declared centre (m)
        self._shapes: dict[int, shapely.Polygon] = {}  # per mover: its outline there, in m
        self._reach_rings: dict[tuple[int, float], np.ndarray] = {}  # (mover, m) → ring
        self._shown = {"frame": None, "reference": None, "path_at": 0.0, "tree": 0, "slow": 0.0,
                       "events": 0}

    # -- commands ------------------------------------------------------------------------------
    def settings(self, steering: str) -> SimSettings:
        """The folder's settings and the planner panel's ``steering``, within the limits of
        `trackstar simulate` (one ValueError line naming the field when not)."""
        u = self.ui
        try:
            options = SimOptions(rate=float(u.rate.value), controller=u.controller.value,
                                 noise=float(u.noise.value), seed=int(u.seed.value),
                                 steering=steering)
        except ValidationError as exc:
            raise ValueError(describe(exc)) from None
        return dataclasses.replace(options.settings(), realtime=True)

    def start(self, problem, settings: SimSettings) -> None:
        """A new run of ``problem`` (the caller keeps the planner's own run out of its way)."""
        self.clear()
        self._uncertainty = settings.uncertainty(problem.scenario)
        self._lanes = Lanes.of(problem.scenario)
        self._draw_static(problem)
        self.clock.reach(settings.duration)
        self.run = _Run(problem, settings)
        self.ui.status.content = "Simulation: **starting**"

    def stop(self) -> None:
        if self.run is not None:
            self.run.stop()

    def clear(self) -> None:
        """Stop the run and remove its drawing (before the scene or scenario changes)."""
        self.stop()
        self.run = None
        for h in self._handles.values():
            h.remove()
        self._handles.clear()
        self._shown.update(frame=None, reference=None, tree=0, events=0)

    # -- drawing -------------------------------------------------------------------------------
    def _draw_static(self, problem) -> None:
        """Meshes drawn once per run and then only moved: the car and the movers' ghosts."""
        scene, scn = self.scene, problem.scenario
        self._handles["car"] = draw_car(scene, "/sim/car", scn.vehicle,
                                        marker_size(problem.bounds), scn.start)
        self._movers = mover_index(scn)
        known = known_motions(scn)  # the car is told these: no belief of its own to draw
        self._centres.clear()
        self._shapes.clear()
        self._reach_rings.clear()
        for i, ob in enumerate(scn.obstacles):
            if self._movers[i] < 0 or known[self._movers[i]]:
                continue
            (x, y, yaw), local = outline(ob)  # offsets move the declared pose
            self._centres[i] = np.array([x, y])
            c, sn = math.cos(yaw), math.sin(yaw)
            self._shapes[i] = shapely.Polygon(local @ np.array([[c, sn], [-sn, c]]))
            self._handles[f"ghost{i}"] = scene.add_frame(
                f"/sim/ghost{i}", show_axes=False, position=(x, y, 0.0), wxyz=yaw_wxyz(yaw))
            _fill(scene, f"/sim/ghost{i}/shape", [local], GHOST_Z, GHOST_RGB,
                  opacity=0.35)
            shape = shapely.Polygon(local)
            for k, (tau, alpha) in enumerate(zip(LOOK_AHEAD_S, GROWN_OPACITY)):
                grown = shape.buffer(float(self._uncertainty.growth(tau)), quad_segs=8)
                self._handles[f"grown{i}_{k}"] = scene.add_frame(
                    f"/sim/grown{i}_{k}", show_axes=False, position=(x, y, 0.0),
                    wxyz=yaw_wxyz(yaw))
                _fill(scene, f"/sim/grown{i}_{k}/shape", [np.asarray(grown.exterior.coords)],
                      GHOST_Z - 0.0005 * (k + 1), GHOST_RGB, opacity=alpha)

    def _put(self, name: str, seg: np.ndarray, rgb, px: float) -> None:
        put_segments(self.scene, self._handles, name, f"/sim/{name}", seg, rgb, px)

    def tick(self) -> None:
        """Draw what is new since the last tick (called by the session's ticker)."""
        run = self.run
        if run is None:
            return
        finished = not run.running  # read first: then the frame below is the run's last
        f = run.frame
        if f is not None and f is not self._shown["frame"]:
            self._shown["frame"] = f
            self._draw_frame(f)
        self._mark_events(run)
        if run.tree_version != self._shown["tree"]:
            self._shown["tree"] = run.tree_version
            self._put("tree", run.tree, TREE_RGB, 1.0)
        now = time.monotonic()
        if now - self._shown["slow"] > SLOW_S or finished:
            self._shown["slow"] = now
            self._plots(run)
            self._status(run, f)
        if finished:
            self.run = None  # finished: the last drawing stays until the next run or scenario

    def _mark_events(self, run: _Run) -> None:
        """A disc and a label for each new collision or stall: where, when and why."""
        for k in range(self._shown["events"], len(run.events)):
            t, x, y, kind, cause = run.events[k]
            size = marker_size(run.problem.bounds)
            self._handles[f"event{k}"] = self.scene.add_icosphere(
                f"/sim/event{k}", radius=2.5 * size, color=EVENT_RGB[kind],
                position=(x, y, Z["path"]), opacity=0.6)
            self._handles[f"event{k}/label"] = self.scene.add_label(
                f"/sim/event{k}/label", f"{kind} at t = {t:.1f} s: {cause}",
                position=(0.0, 0.0, 0.05), anchor="bottom-left")
        self._shown["events"] = len(run.events)

    def _draw_frame(self, f: Frame) -> None:
        x, y, th = f.pose
        car = self._handles["car"]
        car.position, car.wxyz = (x, y, 0.0), yaw_wxyz(th)
        self.clock.set(f.t)  # the stage draws the true movers at the scene clock
        lines = []
        sensing = f.sensing
        if sensing is not None and self._centres:
            taus = np.concatenate([[0.0], LOOK_AHEAD_S,
                                   np.linspace(0.0, PREDICT_S, PREDICT_POINTS)])
            believed = believed_offsets(sensing, f.t, taus, self._lanes)
            for i, c in self._centres.items():
                at = c + believed[:, self._movers[i]]
                self._handles[f"ghost{i}"].position = (*at[0], 0.0)
                for k in range(len(LOOK_AHEAD_S)):
                    self._handles[f"grown{i}_{k}"].position = (*at[1 + k], 0.0)
                ahead = at[1 + len(LOOK_AHEAD_S):]
                lines.extend(np.stack([ahead[:-1], ahead[1:]], axis=1))
        seg = np.zeros((len(lines), 2, 3), np.float32)
        if lines:
            seg[:, :, :2], seg[:, :, 2] = lines, GHOST_Z
        self._put("prediction", seg, GHOST_RGB, 2.0)
        self._put("reachable", self._reachable(f), REACH_RGB, 2.0)
        now = time.monotonic()
        if (f.reference is not None and f.reference is not self._shown["reference"]
                and now - self._shown["path_at"] > PATH_S):
            self._shown["reference"], self._shown["path_at"] = f.reference, now
            self._put("committed", polyline_segments(f.reference.rows[:, :2], Z["path"]),
                      PATH_RGB, 4.0)

    def _reachable(self, f: Frame) -> np.ndarray:
        """The outline of each reachable set, held at its `REACH_S` extent, round where its
        mover was sensed (one buffering per mover and cm of growth)."""
        rings = []
        if f.sensing is not None and f.reach is not None:
            for i, c in self._centres.items():
                m = self._movers[i]
                if not math.isfinite(f.reach[m]):
                    continue
                key = (i, round(float(f.reach[m]) * REACH_S, 2))
                if key not in self._reach_rings:
                    grown = self._shapes[i].buffer(key[1], quad_segs=8)
                    self._reach_rings[key] = np.asarray(grown.exterior.coords)
                rings.append(polyline_segments(self._reach_rings[key] + c + f.sensing.offsets[m],
                                               GHOST_Z))
        return np.concatenate(rings) if rings else np.zeros((0, 2, 3), np.float32)

    def _plots(self, run: _Run) -> None:
        h = run.history[:]
        if len(h) < 2:
            return
        t = np.array([r[0] for r in h])
        keep = np.flatnonzero(t >= t[-1] - WINDOW_S)
        keep = keep[:: max(1, len(keep) // PLOT_POINTS)]
        a = np.array(h)[keep]
        self.ui.steering.data = (a[:, 0], np.degrees(a[:, 1]), np.degrees(a[:, 2]))
        self.ui.safety.data = (a[:, 0], a[:, 4], a[:, 5], a[:, 6])
        a = a[np.isfinite(a[:, 3])]  # no error before the first plan; uPlot cannot scale NaN
        if len(a):
            self.ui.lateral.data = (a[:, 0], 100.0 * a[:, 3])

    def _status(self, run: _Run, f: Frame | None) -> None:
        if run.error:
            text = f"Simulation: **failed** — {run.error}"
        elif run.summary is not None:
            sm = run.summary
            end = (f"goal reached at t = {sm['time_to_goal_s']:.2f} s" if sm["reached_goal"]
                   else f"goal not reached in {sm['duration_s']:.1f} s")
            text = (f"Simulation: **done** — {end}, {sm['collisions']} collisions "
                    f"({sm['collisions_moving']} moving, {sm['collisions_at_rest']} at rest)")
        elif not run.running:
            text = "Simulation: **stopped**"
        else:
            text = "Simulation: **running**" if f is not None else "Simulation: **starting**"
        if text != self.ui.status.content:
            self.ui.status.content = text
        if f is None:
            return
        ms = np.array(run.cycle_ms)
        self.ui.metrics.content = "\n".join([
            f"| t | {f.t:.2f} s |", "|---|---|",
            f"| speed | {f.v:.2f} m/s |",
            f"| guard | {f.guard} |",
            f"| cycles | {f.cycles} |",
            f"| replans | {f.replans} |",
            f"| cycle ms (last, p50) | {f.cycle_ms:.1f}, {np.median(ms):.1f} |",
            f"| clearance (now, min) | {run.clearance:.3f} m, {run.min_clearance:.3f} m |",
            f"| tree nodes | {f.tree.nodes if f.tree is not None else 0} |",
        ])
