"""Bodies and responses of the REST API: one pydantic model each, so /docs shows them all.

Plan results are `planner.report.PlanReport`, the model `trackstar plan --json` prints; the
planning options are `planner.PlanOptions`, from which the CLI's options are generated.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, model_validator
from pydantic_core import PydanticCustomError

from app.simulation import SimOptions
from planner.options import PlanOptions, Seed
from planner.report import PlanReport
from planner.scenario import Scenario, ScenarioError, parse_scenario
from planner.validation import KnownKeys

Point = tuple[float, float]

SCENARIO_EXAMPLE = {
    "name": "two-cones", "bounds": [0, 0, 10, 6],
    "vehicle": {"wheelbase": 0.44, "max_steer_deg": 26, "radius": 0.2},
    "start": [1, 3, 0], "goal": [9, 3, 0],
    "obstacles": [{"type": "circle", "center": [4, 3], "radius": 0.8},
                  {"type": "box", "center": [7, 2], "size": [1.0, 0.6], "angle_deg": 30,
                   "motion": {"velocity": [0, 0.3]}}],
}


INVALID_SCENARIO = "invalid_scenario"  # the error type of a scenario that does not validate


def _parse_scenario(data: Any) -> Any:
    """A JSON object → `planner.Scenario` by `planner.parse_scenario`, the one validation of an
    inline scenario: its one-line message (``invalid scenario: obstacles[0].radius: …``) is the
    error's message, and app.py answers it as before. Anything else (a stored scenario's id, a
    list) is left to the annotated type, so a list is "not a valid dictionary"."""
    if not isinstance(data, dict):
        return data
    try:
        return parse_scenario(data)
    except ScenarioError as exc:
        raise PydanticCustomError(INVALID_SCENARIO, "{detail}", {"detail": str(exc)}) from None


# The request bodies' scenario: typed as `planner.Scenario`, so /openapi.json carries its schema.
ScenarioBody = Annotated[Scenario, BeforeValidator(_parse_scenario)]
ScenarioOrId = Annotated[str | Scenario, BeforeValidator(_parse_scenario)]


class _OneScenario(BaseModel):
    """A body with a scenario inline or by id. Exactly one is checked before the fields, so a
    body with both is refused for that, whatever its inline scenario holds."""

    @model_validator(mode="before")
    @classmethod
    def _one_scenario(cls, data: Any) -> Any:
        if isinstance(data, dict) and ((data.get("scenario") is None)
                                       == (data.get("scenario_id") is None)):
            raise ValueError("give exactly one of 'scenario' and 'scenario_id'")
        return data


class _Body(KnownKeys):
    model_config = ConfigDict(extra="forbid")


MAX_RUNS = 10_000  # runs of one job or study on this server


def _at_most(n: int):
    """A list's length checked before its items are validated: a 3 MB body of a million
    parameter sets took 8 s to validate item by item before its length was refused."""
    def check(value):
        if isinstance(value, list) and len(value) > n:
            raise PydanticCustomError("too_long", "List should have at most {max} items, not "
                                      "{length}", {"max": n, "length": len(value)})
        return value
    return BeforeValidator(check)


class Health(BaseModel):
    status: Literal["ok", "warming"] = Field(
        description="warming: the planner's kernels are still loading (the first start after "
                    "an install compiles them, about a minute) or its workers starting; plans "
                    "wait for them")
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
    selector: str = Field(description="what the upload's 'path' takes: the id, else the label, "
                                      "else TAG-K (document order); NAME:K for a subpath")
    id: str | None
    label: str | None
    subpath: int | None = Field(description="the subpath's index; null for the whole element")
    closed: bool
    length_m: float = Field(description="an element's: all its subpaths (getTotalLength)")
    length_user: float
    bbox_m: tuple[float, float, float, float]
    width_m: float | None = Field(description="null: a zero stroke width")


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
    scenario: dict[str, Any] = Field(
        description="as posted (docs/scenario-format.md or the rich schema)")


class PlanRequest(PlanOptions, _OneScenario):
    """One plan: a scenario inline or by id, and the options of `trackstar plan`."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"scenario": SCENARIO_EXAMPLE, "time": 0.5}]})

    scenario: ScenarioBody | None = Field(
        None, description="docs/scenario-format.md or the rich schema (GET /scenarios/schema)")
    scenario_id: str | None = None


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

    scenarios: Annotated[list[ScenarioOrId], _at_most(MAX_RUNS)] = Field(
        min_length=1, description="stored scenario ids or inline scenarios")
    parameters: Annotated[list[JobOptions], _at_most(MAX_RUNS)] = Field(
        default_factory=lambda: [JobOptions()], min_length=1)
    seeds: Annotated[list[Seed], _at_most(MAX_RUNS)] = Field(default_factory=lambda: [0],
                                                             min_length=1)

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


class SimulationRequest(SimOptions, _OneScenario):
    """One simulated run: a scenario inline or by id, and the options of `trackstar simulate`."""

    model_config = ConfigDict(json_schema_extra={"examples": [
        {"scenario": SCENARIO_EXAMPLE, "duration": 20, "seed": 1},
        {"scenario_id": "<a stored thesis-track scenario>", "laps": 2}]})

    scenario: ScenarioBody | None = Field(
        None, description="docs/scenario-format.md or the rich schema (GET /scenarios/schema)")
    scenario_id: str | None = None

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
