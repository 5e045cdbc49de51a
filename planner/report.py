"""The machine-readable outcome of a plan: one pydantic model for the CLI's JSON and the API."""

from __future__ import annotations

import math

from pydantic import BaseModel, Field

from planner.rrt import Result

__all__ = ["PlanReport", "plan_report"]


class PlanReport(BaseModel):
    """What `trackstar plan --json` prints (and POST /plan returns)."""

    scenario: str
    solved: bool
    cost: float | None = Field(description="the objective's value for the best path: its "
                                           "driven length (m), or with timing optimal its "
                                           "arrival time (s)")
    objective: str = Field("length", description="what cost measures: length or time")
    length_m: float | None = Field(None, description="driven length of the best path (m)")
    waited_s: float | None = Field(None, description="time the car stands still on the path "
                                                     "(timing optimal)")
    time_to_first_solution_s: float | None
    iterations: int
    nodes: int
    collision_checks: int = Field(description="motion checks (each exact, over a whole edge)")
    min_clearance_m: float | None = Field(
        description="of the returned rows joined by straight chords, every 5 mm, in space-time")
    max_abs_curvature: float | None
    arrival_time_s: float | None = Field(None, description="with moving obstacles or timing "
                                                            "optimal")
    planning_time_s: float
    polish_s: float = Field(description="of planning_time_s, spent polishing the best path "
                                        "(at most a fifth of the run's clearance evaluations)")
    rewires: int
    refused_rewires: int = Field(description="rewires refused: the subtree would collide at "
                                             "its new arrival times")
    cost_over_time: list[tuple[float, float, int]] = Field(
        description="[t_s, cost, iteration] at each improvement of the best cost: the iteration "
                    "is exact for a seed, the time interpolated inside its batch")
    path: list[list[float]] = Field(description="[x, y, theta] (plus t with moving obstacles or "
                                                "timing optimal) every ≤ 0.05 m (and ≤ 0.1 s "
                                                "with timing optimal) from the start to the "
                                                "goal node")
    curvature: list[float] = Field(
        [], description="κ (1/m) at each path row, as the steering drives it (positive: left): "
                        "the steering angle there is atan(wheelbase·κ)")
    parameters: dict


def _clean(v: float | None) -> float | None:
    return None if v is None or not math.isfinite(v) else float(v)


def plan_report(result: Result, scenario_name: str, budget: dict) -> PlanReport:
    """Build the report; ``budget`` holds the time/iteration limits the run was given."""
    columns = [0, 1, 2, 5] if result.timed else [0, 1, 2]
    path = result.path[:, columns].round(6).tolist() if result.solved else []
    return PlanReport(
        scenario=scenario_name, solved=result.solved, cost=_clean(result.cost),
        objective=result.objective, length_m=_clean(result.length_m),
        waited_s=result.waited_s if result.objective == "time" and result.solved else None,
        time_to_first_solution_s=_clean(result.time_to_first_solution_s),
        iterations=result.iterations, nodes=result.nodes,
        collision_checks=result.collision_checks, min_clearance_m=_clean(result.min_clearance_m),
        max_abs_curvature=_clean(result.max_abs_curvature),
        arrival_time_s=result.arrival_time_s if result.timed else None,
        planning_time_s=result.planning_time_s, polish_s=result.polish_s,
        rewires=result.rewires,
        refused_rewires=result.refused_rewires,
        cost_over_time=[(round(t, 6), c, i) for t, c, i in result.cost_over_time], path=path,
        curvature=result.path[:, 3].round(6).tolist() if result.solved else [],
        parameters={**result.options.model_dump(), **budget,
                    "motion_check": "exact (clearance stepping)"},
    )
