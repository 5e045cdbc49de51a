"""Scenarios: the minimal format (docs/scenario-format.md v1–v1.2) and Trackstar's richer schema.

One pydantic model reads both, because the rich schema is a superset: a scenario may name a
library track as its drivable region (then ``bounds`` may be omitted), use oriented boxes, and
let obstacles follow a track. Every object rejects unknown keys and suggests the nearest valid
one, so a typo fails loudly instead of silently meaning a default.
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, ValidationError, model_validator

from planner.obstacles import box_corners
from planner.validation import StrictModel, Text, describe, location, suggest

__all__ = [
    "MAX_EXTENT_M",
    "MAX_SPEED_M_S",
    "MAX_WHEELBASE_M",
    "MIN_SPEED_M_S",
    "Scenario",
    "ScenarioError",
    "bundled_scenario_path",
    "load_scenario",
    "parse_scenario",
    "scenario_names",
    "scenario_schema",
]

LIBRARY = Path(__file__).parent / "scenarios"
# Physical limits no honest scenario reaches (a 60 m field of 120 obstacles, a stadium lap, real
# cars at 30 m/s are far inside); beyond them the planner's arithmetic overflows, its kernels
# crash or its work has no end. The table with the reasons: docs/server.md#limits.
MAX_EXTENT_M = 100_000.0  # every coordinate and arc length: 100 km from the origin
MAX_WHEELBASE_M = 100.0  # longer than any vehicle; 1e308 overflowed ε
MAX_SIZE_M = 1_000.0  # radii, box sides, track width, goal tolerance, turning radius (1e300 crashed)
MIN_TURNING_RADIUS_M = 1e-3  # a millimetre: smaller, the steering functions divide by ~0
MAX_FOOTPRINT_M = 50.0  # a footprint's length, width and overhang: a road train is 50 m
MAX_FOOTPRINT_DISCS = 100  # ⌈length / width⌉ discs cover it, each checked in every motion
MAX_SPEED_M_S = 100.0  # the car's and every obstacle's speed (360 km/h); 1e8 planned for ever
MIN_SPEED_M_S = 1e-3  # the car's planning speed: at 1e-300 a space-time plan never ended
MAX_ACCEL_M_S2 = 100.0  # 10 g
MAX_STEER_RATE_DEG_S = 3_600.0  # ten turns of the wheel a second
MAX_HORIZON_S = 3_600.0  # waypoint times and follow_track horizons: 1e6 s took 1.2 GB
MAX_OBSTACLES = 10_000  # 100 000 circles took a minute to compile
MAX_POLYGON_POINTS = 1_000  # per polygon
MAX_VERTICES = 100_000  # all the polygons' points together
MAX_WAYPOINTS = 10_000  # per obstacle
MAX_NAME_CHARS = 200  # a scenario's and a track's name
MAX_DESCRIPTION_CHARS = 10_000
MAX_EMBEDDED_CHARS = 10_000_000  # an embedded track file (SVG or CSV)


class ScenarioError(ValueError):
    """A scenario that cannot be planned, with a one-line message naming the field."""


Coordinate = Annotated[float, Field(ge=-MAX_EXTENT_M, le=MAX_EXTENT_M)]
Pose = tuple[Coordinate, Coordinate, Coordinate]
Point = tuple[Coordinate, Coordinate]
Size = Annotated[float, Field(gt=0, le=MAX_SIZE_M)]
FootprintSize = Annotated[float, Field(gt=0, le=MAX_FOOTPRINT_M)]
Speed = Annotated[float, Field(ge=MIN_SPEED_M_S, le=MAX_SPEED_M_S, allow_inf_nan=False)]
SignedSpeed = Annotated[float, Field(ge=-MAX_SPEED_M_S, le=MAX_SPEED_M_S)]  # an obstacle's
Time = Annotated[float, Field(ge=-MAX_HORIZON_S, le=MAX_HORIZON_S)]
Name = Annotated[Text, Field(max_length=MAX_NAME_CHARS)]
Margin = Annotated[float, Field(ge=0, le=MAX_SIZE_M, allow_inf_nan=False)]
Embedded = Annotated[Text, Field(max_length=MAX_EMBEDDED_CHARS)]


class Footprint(StrictModel):
    """An oriented rectangle (rich schema): the car's outline, with the rear axle — the pose's
    reference point — ``rear_overhang`` metres in front of the rear bumper."""

    type: Literal["rectangle"]
    length: FootprintSize
    width: FootprintSize
    rear_overhang: Annotated[float, Field(ge=0, le=MAX_FOOTPRINT_M)] | None = None

    @model_validator(mode="after")
    def _few_discs(self) -> Footprint:
        if self.disc_count > MAX_FOOTPRINT_DISCS:
            raise ValueError(f"length / width = {self.length / self.width:.6g} needs "
                             f"{self.disc_count} discs, at most {MAX_FOOTPRINT_DISCS}")
        return self

    @property
    def disc_count(self) -> int:
        """n = ⌈length / width⌉: the discs that cover the rectangle."""
        return max(1, math.ceil(self.length / self.width - 1e-9))

    def overhang(self, wheelbase: float) -> float:
        """The rear overhang: as given, else the wheelbase centred in the length."""
        if self.rear_overhang is not None:
            return self.rear_overhang
        return max(self.length - wheelbase, 0.0) / 2

    def discs(self, wheelbase: float) -> list[tuple[float, float]]:
        """Cover the rectangle exactly by n = ⌈length / width⌉ equal discs along its axis:
        (offset from the rear axle along the heading, radius) rows."""
        overhang = self.overhang(wheelbase)
        n = self.disc_count
        half = self.length / (2 * n)
        radius = math.hypot(half, self.width / 2)
        return [(-overhang + half * (2 * i + 1), radius) for i in range(n)]


class Vehicle(StrictModel):
    """The car: geometry for planning (v1), speed (v1.1) and limits for simulation (v1.2).

    The footprint is a disc of ``radius`` (docs/scenario-format.md) or, in the rich schema, a
    rectangle.
    """

    wheelbase: Annotated[float, Field(gt=0, le=MAX_WHEELBASE_M)] = 0.44
    max_steer_deg: Annotated[float, Field(gt=0, lt=90)] = 26.0
    min_turning_radius: Annotated[float, Field(ge=MIN_TURNING_RADIUS_M, le=MAX_SIZE_M)] | None \
        = None
    radius: Annotated[float, Field(ge=0, le=MAX_SIZE_M)] = 0.0
    footprint: Footprint | None = None
    speed: Speed = 1.0
    max_speed: Speed | None = None
    max_accel: Annotated[float, Field(gt=0, le=MAX_ACCEL_M_S2)] = 1.0
    max_steer_rate_deg_s: Annotated[float, Field(gt=0, le=MAX_STEER_RATE_DEG_S)] = 180.0
    safety_margin: Margin = Field(
        0.0, description="Distance (m) that planned paths keep from every obstacle and "
                         "boundary, beyond the footprint.")

    @model_validator(mode="after")
    def _consistent(self) -> Vehicle:
        if self.max_speed is not None and self.max_speed < self.speed:
            raise ValueError(f"max_speed ({self.max_speed}) is below speed ({self.speed})")
        if self.footprint is not None and self.radius > 0:
            raise ValueError("give either 'radius' (a disc) or 'footprint', not both")
        if not MIN_TURNING_RADIUS_M <= self.turning_radius <= MAX_SIZE_M:
            raise ValueError(f"the turning radius wheelbase / tan(max_steer_deg) = "
                             f"{self.turning_radius:.6g} m is outside "
                             f"[{MIN_TURNING_RADIUS_M}, {MAX_SIZE_M}] m")
        return self

    def discs(self) -> list[tuple[float, float]]:
        """The footprint as (offset along the heading, radius) discs."""
        if self.footprint is None:
            return [(0.0, self.radius)]
        return self.footprint.discs(self.wheelbase)

    @property
    def turning_radius(self) -> float:
        """ρ = L / tan δmax unless given explicitly."""
        if self.min_turning_radius is not None:
            return self.min_turning_radius
        return self.wheelbase / math.tan(math.radians(self.max_steer_deg))


class GoalTolerance(StrictModel):
    position: Size = 0.25
    heading_deg: Annotated[float, Field(gt=0, le=180)] = 20.0


class Motion(StrictModel):
    """Exactly one of: constant velocity, timed waypoints, or following a library track."""

    velocity: tuple[SignedSpeed, SignedSpeed] | None = None
    waypoints: Annotated[list[tuple[Time, Coordinate, Coordinate]],
                         Field(max_length=MAX_WAYPOINTS)] | None = None
    follow_track: FollowTrack | None = None
    # The simulated car is told this motion instead of predicting it from sensing: a door,
    # barrier or train that runs to a timetable (docs/simulation.md, "Known timetables").
    known: bool = False

    @model_validator(mode="after")
    def _exactly_one(self) -> Motion:
        given = [k for k in ("velocity", "waypoints", "follow_track") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError("give exactly one of 'velocity' and 'waypoints' "
                             f"(or 'follow_track'), got {given or 'none'}")
        if self.waypoints is not None:
            if not self.waypoints:
                raise ValueError("'waypoints' is empty: give at least one [t, dx, dy]")
            times = [w[0] for w in self.waypoints]
            if any(b <= a for a, b in zip(times, times[1:])):
                raise ValueError(f"waypoint times must be strictly increasing, got {times}")
        if self.speed > MAX_SPEED_M_S:
            raise ValueError(f"moves at {self.speed:.6g} m/s, at most {MAX_SPEED_M_S} m/s")
        return self

    @property
    def speed(self) -> float:
        """The fastest speed of the motion in m/s: the velocity's, or between two waypoints
        (a track follower's speed is checked by its field)."""
        if self.velocity is not None:
            return math.hypot(*self.velocity)
        return max((math.hypot(x1 - x0, y1 - y0) / (t1 - t0) for (t0, x0, y0), (t1, x1, y1)
                    in itertools.pairwise(self.waypoints or [])), default=0.0)


class FollowTrack(StrictModel):
    """Drive along the scenario's track centreline at ``speed`` from arc length ``start_s``."""

    speed: SignedSpeed
    start_s: Coordinate = 0.0
    horizon_s: Annotated[float, Field(gt=0, le=MAX_HORIZON_S)] = 120.0


class Circle(StrictModel):
    type: Literal["circle"]
    center: Point
    radius: Size
    motion: Motion | None = None


class Polygon(StrictModel):
    type: Literal["polygon"]
    points: Annotated[list[Point], Field(min_length=3, max_length=MAX_POLYGON_POINTS)]
    motion: Motion | None = None


class Box(StrictModel):
    """An oriented rectangle (rich schema): centre, size (length, width), heading in degrees."""

    type: Literal["box"]
    center: Point
    size: tuple[Size, Size]
    angle_deg: float = 0.0
    motion: Motion | None = None

    def corners(self) -> list[Point]:
        return box_corners(self.center, self.size, self.angle_deg)


Obstacle = Annotated[Circle | Polygon | Box, Field(discriminator="type")]


class TrackRef(StrictModel):
    """The drivable region (rich schema): a library track by name, or any track embedded as
    the Inkscape SVG `Track.to_svg` writes or as a centreline CSV (TUM / F1TENTH layout), so a
    scenario drawn or uploaded in the studio is self-contained (``name`` then only labels it).
    ``closed`` reads a CSV as a loop (default) or a road."""

    name: Name
    width_m: Size | None = None
    svg: Embedded | None = None
    csv: Embedded | None = None
    closed: bool | None = None

    @model_validator(mode="after")
    def _one_file(self) -> TrackRef:
        if self.svg is not None and self.csv is not None:
            raise ValueError("give one of 'svg' and 'csv'")
        return self

    @property
    def embedded(self) -> str | None:
        """The embedded track file's text (SVG or CSV); None for a track named only."""
        return self.svg if self.svg is not None else self.csv


class Prediction(StrictModel):
    """How erratic the scene's movers are, for a simulated car that predicts them
    (docs/simulation.md, `planner.sim.predict.Uncertainty`); unset fields take its defaults."""

    accel: Annotated[float, Field(ge=0, le=MAX_ACCEL_M_S2)] | None = Field(
        None, description="m/s²: the most a mover changes its velocity per second")
    speed_error: Annotated[float, Field(ge=0, le=MAX_SPEED_M_S)] | None = Field(
        None, description="m/s: the most a sensed velocity is off")
    horizon: Annotated[float, Field(ge=0, le=MAX_HORIZON_S)] | None = Field(
        None, description="s of look-ahead over which the predictions widen; held beyond")
    along_track: bool = Field(
        False, description="the movers keep to the track: predict each along its centreline "
                           "at its sensed speed along it, not straight on (needs a 'track')")


class Scenario(StrictModel):
    """A planning problem. Units: metres and radians, except the ``*_deg`` fields."""

    name: Name
    description: Annotated[Text, Field(max_length=MAX_DESCRIPTION_CHARS)] = ""
    bounds: tuple[Coordinate, Coordinate, Coordinate, Coordinate] | None = None
    track: TrackRef | None = None
    vehicle: Vehicle = Vehicle()
    start: Pose
    goal: Pose
    goal_tolerance: GoalTolerance = GoalTolerance()
    obstacles: list[Obstacle] = Field([], max_length=MAX_OBSTACLES)
    prediction: Prediction = Prediction()

    @model_validator(mode="after")
    def _region(self) -> Scenario:
        if self.bounds is None and self.track is None:
            raise ValueError("give 'bounds' (or a 'track' as the drivable region)")
        if self.bounds is not None:
            xmin, ymin, xmax, ymax = self.bounds
            if not (xmin < xmax and ymin < ymax):
                raise ValueError(f"bounds must be [xmin, ymin, xmax, ymax] with min < max, "
                                 f"got {list(self.bounds)}")
        if self.prediction.along_track and self.track is None:
            raise ValueError("prediction.along_track needs a 'track'")
        for i, ob in enumerate(self.obstacles):
            if ob.motion and ob.motion.follow_track and self.track is None:
                raise ValueError(f"obstacles[{i}].motion.follow_track needs a 'track'")
        vertices = sum(len(ob.points) for ob in self.obstacles if isinstance(ob, Polygon))
        if vertices > MAX_VERTICES:
            raise ValueError(f"obstacles: the polygons have {vertices} points together, "
                             f"at most {MAX_VERTICES}")
        return self

    @property
    def has_motion(self) -> bool:
        """True when any obstacle moves: then plans are timed ([x, y, θ, t])."""
        return any(ob.motion is not None for ob in self.obstacles)


_TAGS = ("circle", "polygon", "box")  # the obstacle union's tags, left out of locations


def _describe(exc: ValidationError) -> str:
    err = exc.errors()[0]
    if err["type"] == "union_tag_invalid":
        tag = str(err.get("input", {}).get("type", ""))
        where = location(err["loc"], _TAGS)
        return f"{where}: unknown obstacle type '{tag}'{suggest(tag, sorted(_TAGS))}"
    if err["type"] == "union_tag_not_found":
        return f"{location(err['loc'], _TAGS)}: obstacle without 'type' (circle, polygon or box)"
    if "waypoints" in err["loc"] and err["type"] in ("missing", "too_long", "tuple_type"):
        where = location(err["loc"], _TAGS).split(".waypoints")[0] + ".waypoints"
        return f"{where}: each waypoint is [t, dx, dy], got {err.get('input')!r}"
    return describe(exc, _TAGS)


def parse_scenario(data: Any) -> Scenario:
    """Validate a decoded JSON object; raises ScenarioError with a one-line message."""
    if not isinstance(data, dict):
        raise ScenarioError(f"a scenario is a JSON object, got {type(data).__name__}")
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        raise ScenarioError(f"invalid scenario: {_describe(exc)}") from None


def scenario_names() -> list[str]:
    """Names of the scenarios bundled with Trackstar (planner/scenarios/), sorted."""
    return sorted(p.stem for p in LIBRARY.glob("*.json"))


def bundled_scenario_path(name: str) -> Path:
    """The file of bundled scenario ``name``: the reference scenarios, the benchmark scenes and
    half laps of the thesis track (`scenario_names()` lists them)."""
    if name not in scenario_names():
        raise ScenarioError(f"no bundled scenario {name!r}; choose from "
                            f"{', '.join(scenario_names())}")
    return LIBRARY / f"{name}.json"


def load_scenario(source: str | Path) -> Scenario:
    """Read and validate a scenario: a file (the minimal format of docs/scenario-format.md or
    the rich schema) or, when no such file exists, the name of a bundled scenario
    (``load_scenario("slalom")``)."""
    path = Path(source)
    if not path.is_file() and str(source) in scenario_names():
        path = bundled_scenario_path(str(source))
    elif not path.exists():
        hint = f" (bundled: {', '.join(scenario_names())})" if path.suffix == "" else ""
        raise ScenarioError(f"no such scenario file or bundled scenario: {source}{hint}")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"cannot read scenario {path}: {exc}") from None
    try:
        data = json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise ScenarioError(f"{path}: not valid JSON ({exc.msg} at line {exc.lineno})") from None
    return parse_scenario(data)


def _reject_constant(name: str) -> float:
    raise ScenarioError(f"{name} is not allowed in a scenario: numbers must be finite")


def scenario_schema() -> dict:
    """The JSON Schema of the rich scenario format."""
    return Scenario.model_json_schema()
