"""How to plan: the one description of a run's options.

`PlanOptions` is what the planner takes, what `trackstar plan` generates its options from (names,
defaults, help), what the REST API's plan and job bodies are made of and what the studio's
planner panel fills. ``None`` means "derived from the problem" (`resolved` fills it in).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import ConfigDict, Field

from planner.scenario import Margin, ScenarioError, Speed
from planner.steering import DEFAULT_STEERING, STEERINGS, SteeringName
from planner.validation import KnownKeys

__all__ = ["METRICS", "PLANNERS", "TIMINGS", "PlanOptions", "PositiveFinite", "Seed"]

PLANNERS = ("rrt", "rrtstar")
TIMINGS = ("constant", "optimal")
METRICS = ("steering", "se2")  # the kernel's codes are their positions
DEFAULT_TIME_S = 1.0
# Limits no honest run reaches (the time budget is capped by the server's --max-plan-s).
MAX_ITERATIONS = 1_000_000  # 50 times the largest budget of the studies; a bigger tree outgrows memory
MAX_EPS_M = 1_000_000.0  # ε and γ: beyond the diagonal of the largest world (283 km) they change nothing
MAX_K_RRT = 100.0  # OMPL's 5.5 is the usual; k = k_rrt·log n neighbours each iteration

PositiveFinite = Annotated[float, Field(gt=0, allow_inf_nan=False)]
Length = Annotated[float, Field(gt=0, le=MAX_EPS_M, allow_inf_nan=False)]
Seed = Annotated[int, Field(ge=0, lt=2**64)]


class PlanOptions(KnownKeys):
    """Every option of a planning run, with its default; the budget (time, iterations) too."""

    model_config = ConfigDict(extra="forbid", frozen=True, defer_build=True)

    planner: Literal[PLANNERS] = Field(
        "rrtstar", description="Planning algorithm: RRT stops at its first solution, RRT* "
                               "goes on improving it.")
    steering: SteeringName = Field(
        DEFAULT_STEERING, description="Steering: " + "; ".join(
            f"{s.name} {s.summary}" for s in STEERINGS.values()) + ".")
    time: PositiveFinite | None = Field(
        None, description="Time budget in seconds [default: 1.0, or none when an iteration "
                          "budget is given].")
    iterations: Annotated[int, Field(ge=1, le=MAX_ITERATIONS)] | None = Field(
        None, description="Iteration budget.")
    seed: Seed = Field(0, description="Random seed: same seed, same tree.")
    eps: Length | None = Field(
        None, description="Longest extension ε [m] [default: 15 % of the workspace diagonal, "
                          "at least two turning radii].")
    gamma: Length | None = Field(
        None, description="RRT* radius constant γ [default: 2.4 γ* of the free space].")
    k_rrt: Annotated[float, Field(gt=0, le=MAX_K_RRT)] | None = Field(
        None, description="RRT* with the k = k_rrt·log n nearest instead of a radius "
                          "(OMPL: 5.5).")
    goal_bias: Annotated[float, Field(ge=0, lt=1)] = Field(
        0.05, description="Probability of sampling the goal.")
    metric: Literal[METRICS] = Field(
        "steering", description="Nearest-neighbour metric: steering, the exact steering "
                                "length; se2, the cheap sqrt(dx² + dy² + (ρ·dθ)²) many car "
                                "planners start with.")
    informed: bool | None = Field(
        None, description="Informed sampling after the first solution [default: on for RRT*].")
    speed: Speed | None = Field(
        None, description="Planning speed v [m/s] [default: the scenario's vehicle.speed].")
    polish: bool = Field(
        True, description="Polish the best path's poses at the first solution and each "
                          "doubling of the iterations (static scenes; docs/planner.md).")
    timing: Literal[TIMINGS] = Field(
        "constant", description="constant: drive the path at the planning speed; optimal: "
                                "any speed up to vehicle.max_speed, stopping allowed, and the "
                                "objective is the arrival time (waits for movers).")
    safety_margin: Margin | None = Field(
        None, description="Distance [m] the path keeps from every obstacle and boundary "
                          "[default: the scenario's vehicle.safety_margin].")

    @property
    def dimensions(self) -> int:
        """The dimension of the space the tree explores: (x, y, θ) for a car, (x, y) for a
        robot whose heading is free."""
        return 2 if STEERINGS[self.steering].heading_free else 3

    def time_budget(self, max_time: float | None = None) -> float | None:
        """The time limit of the run: 1 s by default, none with only iterations; a server's
        cap ``max_time`` refuses a longer explicit time and bounds the others."""
        budget = DEFAULT_TIME_S if self.time is None and self.iterations is None else self.time
        if max_time is None:
            return budget
        if self.time is not None and self.time > max_time:
            raise ValueError(f"time: {self.time} s is above this server's limit of {max_time} s")
        return max_time if budget is None else min(budget, max_time)

    def resolved(self, problem) -> PlanOptions:
        """Fill the derived defaults from a `planner.Problem`: ε from the workspace size, γ
        from the free space, informed sampling and the speed. Raises `ScenarioError` for a
        robot the steering cannot drive."""
        if STEERINGS[self.steering].heading_free and problem.world.discs[:, 0].any():
            raise ScenarioError(
                f"steering {self.steering!r} turns on the spot, which only a disc centred on "
                f"the pose does without sweeping: give vehicle.radius, not vehicle.footprint")
        xmin, ymin, xmax, ymax = problem.bounds
        diag = math.hypot(xmax - xmin, ymax - ymin)
        eps = self.eps if self.eps is not None else max(0.15 * diag, 2.0 * problem.rho)
        if self.gamma is not None:
            gamma = self.gamma
        else:
            # γ* = (2 (1 + 1/d) μ(X_free) / ζ_d)^(1/d) (Karaman & Frazzoli; OMPL takes the
            # bounds' area, not knowing the free one, and 1.1 γ*): for a car d = 3, μ = free
            # area · 2π, ζ_3 = 4π/3; for a heading-free robot d = 2, μ = free area, ζ_2 = π.
            # We take 2.4 γ*: at our iteration rates log(n)/n shrinks the radius to a fraction
            # of a turning circle within milliseconds, and short rewiring radii cannot
            # straighten a loop (benchmarks/results/planner.md: cost after 1 s).
            d = self.dimensions
            measure = max(problem.free_area, 1e-9) * (2.0 * math.pi if d == 3 else 1.0)
            unit_ball = 4.0 * math.pi / 3.0 if d == 3 else math.pi
            gamma = 2.4 * (2.0 * (1.0 + 1.0 / d) * measure / unit_ball) ** (1.0 / d)
        informed = self.informed if self.informed is not None else self.planner == "rrtstar"
        speed = self.speed if self.speed is not None else problem.speed
        if self.timing == "optimal" and speed > problem.top_speed:
            raise ScenarioError(f"speed: {speed:g} m/s is above vehicle.max_speed "
                                f"({problem.top_speed:g} m/s), the most timing optimal drives")
        margin = self.safety_margin if self.safety_margin is not None else problem.margin
        return self.model_copy(update={"eps": eps, "gamma": gamma, "informed": informed,
                                       "speed": speed, "safety_margin": margin})
