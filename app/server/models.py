"""Bodies and responses of the REST API: one pydantic model each, so /docs shows them all.

Plan results are `planner.report.PlanReport`, the model `trackstar plan --json` prints; the
planning options are `planner.PlanOptions`, from which the CLI's options are generated.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from app.simulation import SimOptions
from planner.options import PlanOptions, Seed
from planner.report import PlanReport

Point = tuple[float, float]

SCENARIO_EXAMPLE = {
    "name": "two-cones", "bounds": [0, 0, 10, 6],
    "vehicle": {"wheelbase": 0.44, "max_steer_deg": 26, "radius": 0.2},
    "start": [1, 3, 0], "goal": [9, 3, 0],
    "obstacles": [{"type": "circle", "center": [4, 3], "radius": 0.8},
                  {"type": "box", "center": [7, 2], "size": [1.0, 0.6], "angle_deg": 30,
                   "motion": {"velocity": [0, 0.3]}}],
}


class _Body(BaseModel):
    model_config = ConfigDict(extra="forbid")


class Health(BaseModel):
    status: Literal["ok"]
    version: str
    ui_port: int | None


class TrackSummary(BaseModel):
    id: str = Field(description="library tracks: their name; uploads: a generated id")
    name: str
    source: Literal["library", "upload"]
    closed: bool
    length_m: float
    width_m: float


class TrackGeometry(BaseModel):
    """Centreline and edges in metres, world frame (x right, y up)."""

    id: str
    name: str
    closed: bool
    length_m: float
    width_m: float
    centerline: list[Point]
    left: list[Point]
    right: list[Point]


class SvgPath(BaseModel):
    id: str | None
    label: str | None
    closed: bool
    length_m: float
    length_user: float
    bbox_m: tuple[float, float, float, float]
    width_m: float


class SvgPaths(BaseModel):
    """Every rendered path of a track's SVG file: the object of `trackstar track inspect --json`."""

    unit_m: float
    paths: list[SvgPath]


class ProfilePoint(BaseModel):
    s: float
    x: float
    y: float
    heading: float
    curvature: float
    steering_deg: float
    feasible: bool


class TrackProfile(BaseModel):
    """The object of `trackstar track sample --json`."""

    length_m: float
    closed: bool
    points: list[ProfilePoint]


class ScenarioRecord(BaseModel):
    id: str = Field(description="bundled scenarios: their name; posted ones: a generated id")
    name: str
    source: Literal["library", "upload"]
    scenario: dict[str, Any] = Field(description="as posted (FORMAT.md or the rich schema)")


class PlanRequest(PlanOptions):
    """One plan: a scenario inline or by id, and the options of `trackstar plan`."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"scenario": SCENARIO_EXAMPLE, "time": 0.5}]})

    scenario: dict[str, Any] | None = Field(
        None, description="FORMAT.md or the rich schema (GET /scenarios/schema)")
    scenario_id: str | None = None

    @model_validator(mode="after")
    def _one_scenario(self) -> PlanRequest:
        if (self.scenario is None) == (self.scenario_id is None):
            raise ValueError("give exactly one of 'scenario' and 'scenario_id'")
        return self


class JobOptions(PlanOptions):
    """Planner options of one parameter set of a job (its seeds come from the job's `seeds`)."""

    @model_validator(mode="before")
    @classmethod
    def _no_seed(cls, data: Any) -> Any:
        if isinstance(data, dict) and "seed" in data:
            raise ValueError("give seeds in the job's 'seeds' list, not in 'parameters'")
        return data


class JobRequest(_Body):
    """A batch: every scenario × every parameter set × every seed."""

    scenarios: list[str | dict[str, Any]] = Field(
        min_length=1, description="stored scenario ids or inline scenarios")
    parameters: list[JobOptions] = Field(default_factory=lambda: [JobOptions()], min_length=1)
    seeds: list[Seed] = Field(default_factory=lambda: [0], min_length=1)

    @property
    def total(self) -> int:
        return len(self.scenarios) * len(self.parameters) * len(self.seeds)


class JobCreated(BaseModel):
    id: str
    total: int


class JobResult(PlanReport):
    """One run of a job: its plan report without the path, and the seed it ran with."""

    seed: int
    path: None = Field(None, exclude=True)


class JobStatus(BaseModel):
    id: str
    status: Literal["queued", "running", "done", "failed", "cancelled"]
    done: int
    total: int
    error: str | None = None
    results: list[JobResult]


class SimulationRequest(SimOptions):
    """One simulated run: a scenario inline or by id, and the options of `trackstar simulate`."""

    model_config = ConfigDict(json_schema_extra={"examples": [
        {"scenario": SCENARIO_EXAMPLE, "duration": 20, "seed": 1},
        {"scenario_id": "<a stored thesis-track scenario>", "laps": 2}]})

    scenario: dict[str, Any] | None = Field(
        None, description="FORMAT.md or the rich schema (GET /scenarios/schema)")
    scenario_id: str | None = None

    @model_validator(mode="after")
    def _one_scenario(self) -> SimulationRequest:
        if (self.scenario is None) == (self.scenario_id is None):
            raise ValueError("give exactly one of 'scenario' and 'scenario_id'")
        return self

    def options(self) -> SimOptions:
        return SimOptions(**self.model_dump(exclude={"scenario", "scenario_id"}))


class SimulationCreated(BaseModel):
    id: str


class SimulationStatus(BaseModel):
    """A simulation's state; ``summary`` is the object of `trackstar simulate --json` once done."""

    id: str
    status: Literal["queued", "running", "done", "failed", "cancelled"]
    scenario: str = Field(description="the scenario's name")
    settings: dict[str, Any] = Field(description="the options it runs with")
    sim_time_s: float = Field(description="simulated seconds reached so far")
    progress: float = Field(description="sim_time_s / duration, 1 when done (a run that "
                                        "reaches its goal or finishes its laps ends early)")
    error: str | None = None
    summary: dict[str, Any] | None = None
