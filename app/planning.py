"""Options → plan report: the one function behind `trackstar plan`, POST /plan and batch jobs.

`PlanOptions` is the single description of a run's knobs (the CLI's options, the API's body
fields); `run_plan` compiles a scenario, plans it and builds the `PlanReport`. It is a plain
top-level function so that the server's worker processes can run it.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

from planner.report import PlanReport

__all__ = ["PlanOptions", "Seed", "TrackSource", "check_scenario", "run_plan", "track_loader"]

PositiveFinite = Annotated[float, Field(gt=0, allow_inf_nan=False)]
Seed = Annotated[int, Field(ge=0, lt=2**64)]


class PlanOptions(BaseModel):
    """How to plan: the options of `trackstar plan`, with the same defaults."""

    model_config = ConfigDict(extra="forbid")

    planner: Literal["rrt", "rrtstar"] = "rrtstar"
    steering: Literal["dubins", "reeds-shepp"] = "dubins"
    time: PositiveFinite | None = Field(
        None, description="time budget (s); default 1.0, or none when iterations is given")
    iterations: Annotated[int, Field(ge=1)] | None = None
    seed: Seed = 0
    eps: PositiveFinite | None = Field(None, description="longest extension ε (m)")
    gamma: PositiveFinite | None = Field(None, description="RRT* radius constant γ")
    k_rrt: PositiveFinite | None = Field(None, description="RRT* with k = k_rrt·log n nearest")
    goal_bias: Annotated[float, Field(ge=0, lt=1)] = 0.05
    informed: bool | None = Field(None, description="informed sampling (default: on for RRT*)")
    speed: PositiveFinite | None = Field(None, description="planning speed (m/s)")

    def time_budget(self, max_time: float | None = None) -> float | None:
        """The time limit of the run: 1 s by default, none with only iterations; a server's
        cap ``max_time`` refuses a longer explicit time and bounds the others."""
        budget = 1.0 if self.time is None and self.iterations is None else self.time
        if max_time is None:
            return budget
        if self.time is not None and self.time > max_time:
            raise ValueError(f"time: {self.time} s is above this server's limit of {max_time} s")
        return max_time if budget is None else min(budget, max_time)


class TrackSource(BaseModel):
    """An uploaded SVG track that a scenario may name (by ``id``) as its drivable region."""

    id: str
    svg: bytes
    path: str | None = None
    unit: str | None = None


def track_loader(track: TrackSource | None):
    """``load_track(name)`` for `planner.compile_problem`: the uploaded track, else the library."""
    import tracks

    def load_track(name: str):
        if track is not None and name == track.id:
            return tracks.load_svg(track.svg, path_id=track.path, unit=track.unit)
        return tracks.load_library_track(name)

    return load_track


def _compile(scenario, track: TrackSource | None):
    import planner as core

    if not isinstance(scenario, core.Scenario):
        scenario = core.parse_scenario(scenario)
    return core.compile_problem(scenario, load_track=track_loader(track))


def check_scenario(scenario, track: TrackSource | None = None) -> None:
    """Raise `planner.ScenarioError` unless the scenario can be planned (start and goal free)."""
    _compile(scenario, track)


def run_plan(scenario, options: PlanOptions, *, max_time: float | None = None,
             track: TrackSource | None = None) -> PlanReport:
    """Plan a scenario (a `planner.Scenario` or its JSON object) and report the result.

    Raises `planner.ScenarioError` (a ValueError) for scenarios that cannot be planned and
    ValueError for bad options, each with a message that names the problem.
    """
    import planner as core
    from planner.report import plan_report

    budget_time = options.time_budget(max_time)
    problem = _compile(scenario, track)
    settings = core.PlannerSettings(
        algorithm=options.planner, steering=options.steering, eps=options.eps,
        gamma=options.gamma, k_rrt=options.k_rrt, goal_bias=options.goal_bias,
        informed=options.informed, seed=options.seed, speed=options.speed)
    result = core.Planner(problem, settings).solve(budget_time, options.iterations)
    return plan_report(result, problem.scenario.name,
                       {"time": budget_time, "iterations": options.iterations})
