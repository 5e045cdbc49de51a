"""`trackstar plan` and `trackstar scenario …`: plan a scenario, list, check and describe them."""

from __future__ import annotations

import json
from enum import Enum
from typing import Annotated

import typer

from app.cli._errors import user_errors
from app.cli._warm import warm_kernels


class Algorithm(str, Enum):
    rrt = "rrt"
    rrtstar = "rrtstar"


class Steering(str, Enum):
    dubins = "dubins"
    reeds_shepp = "reeds-shepp"


scenario_cli = typer.Typer(help="Scenarios: the bundled ones, validation and the schema.",
                           no_args_is_help=True, rich_markup_mode=None)

ScenarioArg = Annotated[str, typer.Argument(
    show_default=False, help="A bundled scenario's name (trackstar scenario list) or a scenario "
                             "JSON file (FORMAT.md or the rich schema).")]


def plan(
    scenario: ScenarioArg,
    planner: Annotated[Algorithm, typer.Option(help="Planning algorithm.")] = Algorithm.rrtstar,
    steering: Annotated[Steering, typer.Option(help="Car steering.")] = Steering.dubins,
    time: Annotated[float | None, typer.Option(help="Time budget in seconds [default: 1.0, "
                                                    "or none when --iterations is given].")] = None,
    iterations: Annotated[int | None, typer.Option(min=1, help="Iteration budget.")] = None,
    seed: Annotated[int, typer.Option(help="Random seed: same seed, same tree.")] = 0,
    eps: Annotated[float | None, typer.Option(help="Longest extension ε (m).")] = None,
    gamma: Annotated[float | None, typer.Option(help="RRT* radius constant γ.")] = None,
    k_rrt: Annotated[float | None, typer.Option(help="RRT* with the k = k_rrt·log n nearest "
                                                     "instead of a radius (OMPL: 5.5).")] = None,
    goal_bias: Annotated[float, typer.Option(help="Probability of sampling the goal.")] = 0.05,
    informed: Annotated[bool | None, typer.Option(help="Informed sampling after the first "
                                                       "solution [default: on for RRT*].")] = None,
    speed: Annotated[float | None, typer.Option(help="Planning speed v (m/s) [default: the "
                                                     "scenario's vehicle.speed].")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Plan a path for the car from start to goal with RRT or RRT*."""
    import planner as core
    from app.planning import PlanOptions, run_plan

    with user_errors():
        if time is not None and not time > 0:
            raise ValueError(f"--time must be > 0, got {time}")
        options = PlanOptions(
            planner=planner.value, steering=steering.value, time=time, iterations=iterations,
            seed=seed, eps=eps, gamma=gamma, k_rrt=k_rrt, goal_bias=goal_bias,
            informed=informed, speed=speed)
        scenario_model = core.load_scenario(scenario)
        warm_kernels()
        report = run_plan(scenario_model, options)
    if as_json:
        typer.echo(report.model_dump_json())
        return
    _print_summary(report)


def _print_summary(report) -> None:
    p = report.parameters
    typer.echo(f"{report.scenario}: {p['algorithm']} with {p['steering']} steering, seed {p['seed']}")
    if not report.solved:
        typer.echo(f"  not solved within the budget ({report.iterations} iterations, "
                   f"{report.nodes} nodes)")
        return
    typer.echo(f"  cost {report.cost:.3f} m, first solution after "
               f"{1000 * report.time_to_first_solution_s:.1f} ms")
    stop = " (RRT stops at its first solution; RRT* improves it)" if p["algorithm"] == "rrt" else ""
    typer.echo(f"  {report.iterations} iterations{stop}, {report.nodes} nodes, "
               f"{report.collision_checks} motion checks, {report.rewires} rewires")
    typer.echo(f"  min clearance {report.min_clearance_m:.3f} m, "
               f"max |curvature| {report.max_abs_curvature:.3f} 1/m")
    if report.arrival_time_s is not None:
        typer.echo(f"  arrives at t = {report.arrival_time_s:.2f} s")


@scenario_cli.command("schema")
def schema() -> None:
    """Print the JSON Schema of the rich scenario format."""
    from planner import scenario_schema

    typer.echo(json.dumps(scenario_schema(), indent=2))


@scenario_cli.command("list")
def list_scenarios(
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON array.")] = False,
) -> None:
    """The bundled scenarios: name, static or moving obstacles, description."""
    import planner as core

    rows = []
    for name in core.scenario_names():
        scenario = core.load_scenario(core.bundled_scenario_path(name))
        rows.append({"name": name, "moving": scenario.has_motion,
                     "track": scenario.track.name if scenario.track else None,
                     "description": scenario.description})
    if as_json:
        typer.echo(json.dumps(rows))
        return
    width = max(len(r["name"]) for r in rows)
    for r in rows:
        kind = "moving" if r["moving"] else "static"
        typer.echo(f"{r['name']:<{width}}  {kind}  {r['description']}")


@scenario_cli.command("check")
def check(scenario: ScenarioArg) -> None:
    """Validate a scenario (schema, start and goal free); exit 2 with one line if it is not."""
    import planner as core

    with user_errors():
        problem = core.compile_problem(core.load_scenario(scenario))
    typer.echo(f"{problem.scenario.name}: ok")


def register(cli: typer.Typer) -> None:
    """Add the planning commands to the main CLI."""
    cli.command("plan")(plan)
    cli.add_typer(scenario_cli, name="scenario")
