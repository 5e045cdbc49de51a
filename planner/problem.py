"""A planning problem: a validated scenario compiled into a `World` plus start, goal and car.

This is the one place that turns scenario objects (circles, boxes, polygons, motions, a track)
into the arrays the kernels read, and that rejects problems no planner can solve (start or goal
in collision or outside the region).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from planner._jit import float64, typeof
from planner._world import RADIUS, World, build_world, pose_clearance
from planner.obstacles import follow_waypoints
from planner.scenario import Box, Circle, Scenario, ScenarioError

__all__ = ["Problem", "check_room", "compile_problem", "resolve_track"]


@dataclass(frozen=True)
class Problem:
    """What a planner needs, in SI units. ``timed``: some obstacle moves."""

    scenario: Scenario
    world: World
    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    goal_position_tol: float
    goal_heading_tol: float  # radians
    rho: float
    speed: float
    timed: bool
    margin: float = 0.0  # the vehicle's safety margin: planned paths keep it
    max_speed: float | None = None  # the vehicle's top speed (None: ``speed``)
    max_steer_rate: float = math.inf  # rad/s the steering turns at most
    wheelbase: float = 1.0

    def sharpness(self, speed: float) -> float:
        """σmax (1/m²): the most a path driven at ``speed`` may change its curvature per metre
        so that the steering angle δ = atan(Lκ) turns no faster than the servo can:
        dδ/dt = Lσv/(1 + L²κ²) ≤ Lσv, so σmax = max_steer_rate/(v·L) is safe at any δ, with
        the margin 1/cos²δ at the steering angle δ (docs/planner.md)."""
        return self.max_steer_rate / (speed * self.wheelbase)

    @property
    def top_speed(self) -> float:
        """The fastest the car may drive (timing optimal): vehicle.max_speed, else speed."""
        return self.max_speed if self.max_speed is not None else self.speed

    def goal_region(self, share: float = 1.0) -> np.ndarray:
        """The goal region as `planner._goal` tests it, its tolerances shrunk to ``share``."""
        return np.array([*self.goal, share * self.goal_position_tol,
                         share * self.goal_heading_tol])

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        return tuple(float(v) for v in self.world.geo[:4])

    @property
    def free_area(self) -> float:
        """Area (m²) where the footprint's smallest disc fits among the static obstacles, from
        the clearance grid: the measure of the free space that RRT*'s radius depends on."""
        xmin, ymin, xmax, ymax = self.bounds
        fits = np.mean(self.world.sdf > self.world.geo[RADIUS] + self.margin)
        return float(fits) * (xmax - xmin) * (ymax - ymin)

    def clearance(self, x: float, y: float, t: float = 0.0, theta: float = 0.0) -> float:
        """Signed clearance of the car's footprint at pose (x, y, theta) at time t (NaN: static
        obstacles only)."""
        return float(self._pose_clearance(self.world, x, y, theta, t))

    @cached_property
    def _pose_clearance(self):
        """`pose_clearance` compiled for this world's types, called past numba's dispatcher:
        typing a record of 17 arrays on every call makes it ~4.4 µs, the compiled entry ~2.0 µs,
        which matters to callers that check pose by pose (OMPL's validity checker)."""
        pose_clearance(self.world, 0.0, 0.0, 0.0, math.nan)  # compiles (or loads) it
        return pose_clearance.overloads[(typeof(self.world),) + (float64,) * 4].entry_point

    def __getstate__(self) -> dict:
        """Pickled without the compiled entry point (a process compiles or loads its own)."""
        return {k: v for k, v in self.__dict__.items() if k != "_pose_clearance"}


def resolve_track(scenario: Scenario, load_track=None):
    """The scenario's track: embedded SVG or CSV, else ``load_track(name)`` (default: the
    library)."""
    import tracks  # imported lazily: a track is optional, and tracks needs svg libraries

    if load_track is None:
        load_track = tracks.load_library_track
    try:
        if scenario.track.embedded is not None:
            track = tracks.load_track(scenario.track.embedded.encode(),
                                      closed=scenario.track.closed)
        else:
            track = load_track(scenario.track.name)
    except (KeyError, ValueError) as exc:
        raise ScenarioError(f"track: {exc}") from None
    if scenario.track.width_m is not None:
        track = track.with_width(scenario.track.width_m)
    return track


def compile_problem(scenario: Scenario, load_track=None) -> Problem:
    """Compile and sanity-check a scenario; raises ScenarioError for unplannable input.

    ``load_track(name) -> tracks.Track`` resolves ``scenario.track.name`` (default: the track
    library); the server passes one that also knows uploaded tracks.
    """
    track = resolve_track(scenario, load_track) if scenario.track is not None else None
    rings = track.region_rings() if track is not None else []
    if scenario.bounds is not None:
        bounds = scenario.bounds
    else:
        pts = np.vstack(rings)
        margin = 0.01
        bounds = (*(pts.min(axis=0) - margin), *(pts.max(axis=0) + margin))
    motions, circles, polygons = [], [], []
    for ob in scenario.obstacles:
        m = -1
        if ob.motion is not None:
            m = len(motions)
            if ob.motion.velocity is not None:
                motions.append(("velocity", ob.motion.velocity))
            elif ob.motion.waypoints is not None:
                motions.append(("waypoints", ob.motion.waypoints))
            else:
                motions.append(("waypoints", follow_waypoints(track, ob.motion.follow_track)))
        if isinstance(ob, Circle):
            circles.append((*ob.center, ob.radius, m))
        elif isinstance(ob, Box):
            polygons.append((ob.corners(), m))
        else:
            polygons.append((ob.points, m))
    centreline = None
    if track is not None:
        prof = track.sample(spacing=0.05)
        centreline = np.column_stack([prof.x, prof.y, prof.heading])
    world = build_world(bounds, scenario.vehicle.radius, circles, polygons, motions, rings,
                        centreline, scenario.vehicle.discs())
    tol = scenario.goal_tolerance
    problem = Problem(
        scenario=scenario, world=world, start=tuple(scenario.start), goal=tuple(scenario.goal),
        goal_position_tol=tol.position, goal_heading_tol=math.radians(tol.heading_deg),
        rho=scenario.vehicle.turning_radius, speed=scenario.vehicle.speed,
        timed=scenario.has_motion, margin=scenario.vehicle.safety_margin,
        max_speed=scenario.vehicle.max_speed,
        max_steer_rate=math.radians(scenario.vehicle.max_steer_rate_deg_s),
        wheelbase=scenario.vehicle.wheelbase)
    check_room(problem, problem.margin)
    return problem


def check_room(problem: Problem, margin: float) -> None:
    """Raise ScenarioError unless start and goal keep ``margin`` from everything."""
    kept = f" with the safety margin of {margin:g} m" if margin > 0 else ""
    start_clearance = problem.clearance(*problem.start[:2], 0.0, problem.start[2])
    if start_clearance <= margin:
        raise ScenarioError(f"start {list(problem.start)} is in collision or outside the region "
                            f"at t = 0{kept} (clearance {start_clearance:.3f} m)")
    goal_clearance = problem.clearance(*problem.goal[:2], math.nan, problem.goal[2])
    if goal_clearance <= margin:
        raise ScenarioError(f"goal {list(problem.goal)} is in collision or outside the region"
                            f"{kept} (clearance {goal_clearance:.3f} m)")
