"""The study file: YAML or JSON, validated before anything runs, expanded into runs.

A planning run is one (scenario, planner, steering, parameter point, budget, seed), a driven run
(``kind: simulate``) one (scenario, parameter point, seed); the key identifies a run in the
results, so a resumed or extended study redoes nothing. A parameter that a planner does not have
(RRT has no γ, k or informed sampling; OMPL's take only eps and goal_bias) is dropped from its
points, so such a planner runs once
per point of the parameters it has.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import yaml
from pydantic import Field, ValidationError, ValidationInfo, field_validator, model_validator

import planner
from app.simulation import SimOptions
from planner import ompl_bridge
from planner.ompl_bridge import OMPL_PARAMETERS, OMPL_PLANNERS, STEERING_SPACES
from planner.options import PLANNERS, PlanOptions, PositiveFinite, Seed
from planner.steering import STEERINGS, SteeringName
from planner.validation import StrictModel, describe, suggest

__all__ = ["MAX_RUNS", "PARAMETERS", "SIM_PARAMETERS", "Run", "SimRun", "Study", "StudyError",
           "load_study", "parse_study", "study_names"]

# The axes a study may sweep: `trackstar plan`'s and `trackstar simulate`'s options, under the
# same names.
PARAMETERS = ("eps", "gamma", "k_rrt", "goal_bias", "informed", "metric", "speed", "polish",
              "timing")
SIM_PARAMETERS = tuple(k for k in SimOptions.model_fields if k != "seed")
_RRTSTAR_ONLY = ("gamma", "k_rrt", "informed")
TARGETS = (*PLANNERS, *OMPL_PLANNERS)  # ours, and OMPL's with the bench extra

# The most runs one study may expand to here (a server sets its own, lower cap). A study is
# counted from the sizes of its axes before anything is built (`StudyFile.size`), so a short
# file cannot ask for unbounded work just to be refused.
MAX_RUNS = 100_000
Count = Annotated[int, Field(ge=1, le=MAX_RUNS)]
MAX_VALUES = 1_000  # values on one axis of the grid (a parameter's, a budget's)
Axis = Annotated[list[Any], Field(min_length=1, max_length=MAX_VALUES)]


class StudyError(ValueError):
    """A study file that cannot run, with a one-line message naming the key."""


def _as_list(value):
    return value if isinstance(value, list) else [value]


class Budget(StrictModel):
    """Per run: an iteration budget, a time budget, or both (whichever comes first); either
    may be a list, another axis of the grid."""

    iterations: Annotated[list[Count], Field(min_length=1, max_length=MAX_VALUES)] | None = None
    time_s: Annotated[list[PositiveFinite], Field(min_length=1, max_length=MAX_VALUES)] | None = None

    @field_validator("iterations", "time_s", mode="before")
    @classmethod
    def _lists(cls, value: Any) -> Any:
        return None if value is None else _as_list(value)

    @model_validator(mode="after")
    def _some(self) -> Budget:
        if self.iterations is None and self.time_s is None:
            raise ValueError("give iterations, time_s or both")
        return self

    def points(self) -> list[tuple[int | None, float | None]]:
        return list(itertools.product(self.iterations or [None], self.time_s or [None]))


class Range(StrictModel):
    """A parameter's range for a random sample: uniform, or log-uniform with ``log``."""

    min: float
    max: float
    log: bool = False

    @model_validator(mode="after")
    def _ordered(self) -> Range:
        if not self.min < self.max:
            raise ValueError(f"min must be below max, got {self.min} and {self.max}")
        if self.log and self.min <= 0:
            raise ValueError(f"a log range needs min > 0, got {self.min}")
        return self

    def draw(self, rng: np.random.Generator) -> float:
        if self.log:
            return float(np.exp(rng.uniform(np.log(self.min), np.log(self.max))))
        return float(rng.uniform(self.min, self.max))


class Sample(StrictModel):
    """Random parameter points instead of the full grid: ``n`` draws from seed ``seed``."""

    n: Count
    seed: Seed = 0


class StudyFile(StrictModel):
    """The keys of a study file (docs/studies.md)."""

    name: Annotated[str, Field(pattern=r"^[A-Za-z0-9_.-]+$", max_length=100)]
    description: str | None = None
    kind: Literal["plan", "simulate"] = "plan"
    scenarios: Annotated[list[str | dict[str, Any]], Field(min_length=1)]
    planners: Annotated[list[Literal[TARGETS]], Field(min_length=1)] | None = None
    steering: Annotated[list[SteeringName], Field(min_length=1)] | None = None
    parameters: dict[str, Axis | Range] = Field(default_factory=dict)
    sample: Sample | None = None
    seeds: Annotated[list[Seed], Field(min_length=1, max_length=MAX_RUNS)] = Field(
        default_factory=lambda: [0])
    budget: Budget | None = None

    @field_validator("seeds", mode="before")
    @classmethod
    def _count(cls, seeds: Any) -> Any:
        """``seeds: N`` means 0..N-1."""
        if isinstance(seeds, int) and not isinstance(seeds, bool):
            if not 1 <= seeds <= MAX_RUNS:
                raise ValueError(f"a count of seeds is 1 to {MAX_RUNS}, got {seeds}")
            return list(range(seeds))
        return seeds

    @field_validator("sample", mode="before")
    @classmethod
    def _sample_count(cls, sample: Any) -> Any:
        """``sample: N`` means N points from seed 0."""
        return {"n": sample} if isinstance(sample, int) and not isinstance(sample, bool) \
            else sample

    @field_validator("parameters", mode="before")
    @classmethod
    def _ranges(cls, parameters: Any) -> Any:
        """A mapping as a value is a range: validated here, so its error names it."""
        if not isinstance(parameters, dict):
            return parameters
        out = {}
        for key, values in parameters.items():
            try:
                out[key] = Range.model_validate(values) if isinstance(values, dict) else values
            except ValidationError as exc:
                raise ValueError(f"{key}: {describe(exc)}") from None
        return out

    @field_validator("parameters")
    @classmethod
    def _values(cls, parameters: dict, info: ValidationInfo) -> dict:
        """Known names, and each value (a range's ends) as `PlanOptions` (or `SimOptions`)
        validates it, so the study and `trackstar plan` (`simulate`) agree."""
        simulate = info.data.get("kind") == "simulate"
        names, model = (SIM_PARAMETERS, SimOptions) if simulate else (PARAMETERS, PlanOptions)
        for key, values in parameters.items():
            if key not in names:
                hint = ("; it is an option of trackstar simulate: add 'kind: simulate'"
                        if not simulate and key in SIM_PARAMETERS else "")
                raise ValueError(f"unknown parameter '{key}'{suggest(key, names)}{hint}")
            named = ([(f"{key}.min", values.min), (f"{key}.max", values.max)]
                     if isinstance(values, Range) else
                     [(f"{key}[{i}]", v) for i, v in enumerate(values)])
            for where, value in named:
                try:
                    model(**{key: value})
                except ValidationError as exc:
                    msg = exc.errors()[0]["msg"]
                    raise ValueError(f"{where} = {value!r}: {msg}") from None
        return parameters

    @model_validator(mode="after")
    def _keys_of_the_kind(self) -> StudyFile:
        """A planning study names its planners and budget; a driven one replans as `trackstar
        simulate` does (RRT*, Dubins, its budget per cycle), so it has none of the three."""
        if self.kind == "plan":
            for key in ("planners", "budget"):
                if getattr(self, key) is None:
                    raise ValueError(f"{key}: required for a planning study")
        else:
            for key in ("planners", "steering", "budget"):
                if getattr(self, key) is not None:
                    raise ValueError(f"{key}: a simulate study replans as trackstar simulate "
                                     f"does; leave it out")
        return self

    @model_validator(mode="after")
    def _ompl_steering(self) -> StudyFile:
        """OMPL's targets plan Dubins or Reeds-Shepp only."""
        ompl = [p for p in self.planners or () if p in OMPL_PLANNERS]
        other = [s for s in self.steering or () if s not in STEERING_SPACES]
        if ompl and other:
            raise ValueError(f"steering: {ompl[0]} plans {' or '.join(STEERING_SPACES)} only, "
                             f"not '{other[0]}'")
        return self

    @model_validator(mode="after")
    def _ranges_need_a_sample(self) -> StudyFile:
        for key, values in self.parameters.items():
            if isinstance(values, Range) and self.sample is None:
                raise ValueError(f"parameters.{key}: a range needs 'sample' (random points); "
                                 f"give a list of values for the grid")
        return self

    @model_validator(mode="after")
    def _bounded(self) -> StudyFile:
        if self.size() > MAX_RUNS:
            raise ValueError(self.too_many(MAX_RUNS))
        return self

    def size(self) -> int:
        """The runs the study expands to at most (fewer where a planner ignores a parameter),
        counted from the sizes of its axes."""
        points = self.sample.n if self.sample is not None else math.prod(
            len(v) for v in self.parameters.values())
        budgets = len(self.budget.points()) if self.budget is not None else 1
        return (len(self.scenarios) * len(self.planners or [None])
                * len(self.steering or [None]) * points * budgets * len(self.seeds))

    def too_many(self, cap: int) -> str:
        return (f"this study expands to {self.size():,} runs (scenarios × planners × steering "
                f"× parameter points × budgets × seeds); at most {cap:,}")

    def points(self) -> list[dict]:
        """The parameter points: the grid's, or ``sample.n`` random ones."""
        keys = list(self.parameters)
        if self.sample is None:
            return [dict(zip(keys, values, strict=True))
                    for values in itertools.product(*self.parameters.values())]
        rng = np.random.default_rng(self.sample.seed)
        return [{k: v.draw(rng) if isinstance(v, Range) else v[int(rng.integers(len(v)))]
                 for k, v in self.parameters.items()} for _ in range(self.sample.n)]


class _Point:
    parameters: dict

    @property
    def parameters_json(self) -> str:
        """The run's parameter values as a JSON object, keys sorted: part of its key."""
        return json.dumps(self.parameters, sort_keys=True)


@dataclass(frozen=True)
class SimRun(_Point):
    """One driven run: what `trackstar simulate` does with these options."""

    scenario: str
    parameters: dict = field(hash=False, compare=False)
    seed: int

    @property
    def key(self) -> tuple:
        return (self.scenario, self.parameters_json, self.seed)

    def options(self) -> SimOptions:
        return SimOptions(seed=self.seed, **self.parameters)


@dataclass(frozen=True)
class Run(_Point):
    """One planning run: what `trackstar plan` does with these options."""

    scenario: str  # the scenario's name
    planner: str
    steering: str
    parameters: dict = field(hash=False, compare=False)
    budget_iterations: int | None
    budget_time_s: float | None
    seed: int

    @property
    def key(self) -> tuple:
        return (self.scenario, self.planner, self.steering, self.parameters_json,
                self.budget_iterations, self.budget_time_s, self.seed)

    def options(self) -> PlanOptions:
        """The options `trackstar plan` would take for this run."""
        return PlanOptions(planner=self.planner, steering=self.steering, seed=self.seed,
                           iterations=self.budget_iterations, time=self.budget_time_s,
                           **self.parameters)


@dataclass(frozen=True)
class Study:
    """A validated study: its file's text, its scenarios (by name) and its runs."""

    name: str
    kind: str
    text: str
    scenarios: dict[str, planner.Scenario]
    runs: list[Run] | list[SimRun]


def _has(planner_name: str, point: dict) -> dict:
    """The part of a parameter point that ``planner_name`` has."""
    if planner_name in OMPL_PLANNERS:
        return {k: v for k, v in point.items()
                if k in OMPL_PARAMETERS[OMPL_PLANNERS[planner_name]]}
    return {k: v for k, v in point.items()
            if planner_name == "rrtstar" or k not in _RRTSTAR_ONLY}


def parse_study(data: Any, text: str, resolve: Callable[[Any], planner.Scenario],
                origin: str = "", max_runs: int = MAX_RUNS) -> Study:
    """Validate and expand a decoded study; ``resolve`` turns an entry of ``scenarios`` (a
    name, a path, an id, an object) into a `planner.Scenario` or raises ScenarioError.
    Raises StudyError naming the key, led by ``origin`` (the file) when given, and refuses a
    study of more than ``max_runs`` runs before expanding it."""
    lead = f"{origin}: " if origin else ""
    if not isinstance(data, dict):
        raise StudyError(f"{lead}a study is a mapping of keys, got {type(data).__name__}")
    try:
        spec = StudyFile.model_validate(data)
    except ValidationError as exc:
        raise StudyError(f"{lead}{describe(exc)}") from None
    if spec.size() > max_runs:
        raise StudyError(f"{lead}{spec.too_many(max_runs)}")
    scenarios = {}
    for i, source in enumerate(spec.scenarios):
        try:
            scenario = resolve(source)
        except planner.ScenarioError as exc:
            shown = f" ({source})" if isinstance(source, str) else ""
            raise StudyError(f"{lead}scenarios[{i}]{shown}: {exc}") from None
        if scenario.has_motion and any(p in OMPL_PLANNERS for p in spec.planners or ()):
            raise StudyError(f"{lead}scenarios[{i}] ({scenario.name}): has moving obstacles, "
                             f"which OMPL's planners cannot plan; leave out the ompl: "
                             f"planners or this scenario")
        scenarios.setdefault(scenario.name, scenario)
    ompl = [p for p in spec.planners or () if p in OMPL_PLANNERS]
    if ompl and not ompl_bridge.available():  # last: a file with other errors names those
        raise StudyError(f"{lead}planners: {ompl[0]} needs OMPL: pip install 'trackstar[bench]'")
    return Study(spec.name, spec.kind, text, scenarios, _runs(spec, list(scenarios)))


LIBRARY = Path(__file__).parent / "library"


def study_names() -> list[str]:
    """The studies bundled with Trackstar (app/study/library/)."""
    return sorted(p.stem for p in LIBRARY.glob("*.yaml"))


def load_study(source: str | Path) -> Study:
    """Read, validate and expand a study file — or, when no such file exists, a bundled
    study by name; raises StudyError naming the key. Scenarios are paths relative to the
    file, else bundled scenarios' names (or inline objects)."""
    path = Path(source)
    if not path.exists() and str(source) in study_names():
        path = LIBRARY / f"{source}.yaml"
    elif not path.exists():
        raise StudyError(f"no such study file or bundled study: {source} (bundled: "
                         f"{', '.join(study_names())})")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise StudyError(f"cannot read study {path}: {exc}") from None
    try:
        data = (json.loads(text) if path.suffix == ".json" else yaml.safe_load(text))
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise StudyError(f"{path}: not valid {'JSON' if path.suffix == '.json' else 'YAML'} "
                         f"({str(exc).splitlines()[0]})") from None

    def resolve(source) -> planner.Scenario:
        if isinstance(source, dict):
            return planner.parse_scenario(source)
        beside = path.parent / source
        return planner.load_scenario(beside if beside.is_file() else source)

    return parse_study(data, text, resolve, str(path))


def _runs(spec: StudyFile, scenarios: list[str]) -> list[Run] | list[SimRun]:
    """Every run of the study, in grid order, each once."""
    points = spec.points()
    if spec.kind == "simulate":
        return [SimRun(name, point, seed)
                for name, point, seed in itertools.product(scenarios, points, spec.seeds)]
    runs, seen = [], set()
    steering = spec.steering or [next(iter(STEERINGS))]
    for name, planner_name, steer in itertools.product(scenarios, spec.planners, steering):
        for point in (_has(planner_name, p) for p in points):
            for (iterations, time_s), seed in itertools.product(spec.budget.points(),
                                                                spec.seeds):
                run = Run(name, planner_name, steer, point, iterations, time_s, seed)
                if run.key not in seen:
                    seen.add(run.key)
                    runs.append(run)
    return runs
