"""`trackstar plan` and `trackstar scenario …`: plan a scenario, list, check and describe them."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer

from app.cli._errors import user_errors
from app.cli._options import model_options
from app.kernels import warm_kernels
from planner.options import PlanOptions

scenario_cli = typer.Typer(help="Scenarios: the bundled ones, validation and the schema.",
                           no_args_is_help=True, rich_markup_mode=None)

ScenarioArg = Annotated[str, typer.Argument(
    show_default=False, help="A bundled scenario's name (trackstar scenario list) or a scenario "
                             "JSON file (docs/scenario-format.md or the rich schema).")]


@model_options(PlanOptions)
def plan(
    scenario: ScenarioArg,
    options: PlanOptions,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    raceline: Annotated[Path | None, typer.Option(
        "--raceline", help="Also write the best path in the TUM raceline layout (speed within "
                           "the vehicle's max speed, 4 m/s² lateral, 2 m/s² longitudinal).",
    )] = None,
    animate: Annotated[Path | None, typer.Option(
        "--animate", show_default=False,
        help="Also write an animation of the run, for slides: the tree growing, its rewires "
             "and the best path, 40 frames at 800x600 (.gif); where obstacles move, 24 more "
             "drive the car along the result among them.")] = None,
) -> None:
    """Plan a path for the car from start to goal with RRT or RRT*."""
    import planner as core
    from app.animate import FRAMES, FrameRecorder, check_animation_path, title, write_animation
    from app.planning import run_plan

    with user_errors():
        if animate is not None:
            check_animation_path(animate)
        scenario_model = core.load_scenario(scenario)
        warm_kernels(options.timing)
        recorder = FrameRecorder()
        report = run_plan(scenario_model, options, observe=recorder if animate else None,
                          chunks=FRAMES if animate else 1)
        if animate is not None:
            write_animation(recorder.frames, recorder.problem,
                            title(report.scenario, options), animate, drive=recorder.drive())
        if raceline is not None and report.solved:
            from app.raceline import path_raceline, raceline_limits  # loads the tracks package

            limits = raceline_limits(vehicle=scenario_model.vehicle)
            raceline.write_text(path_raceline(report.path, limits))
        elif raceline is not None:
            print(f"{raceline} not written: no path was found", file=sys.stderr)
    if as_json:
        typer.echo(report.model_dump_json())
        return
    _print_summary(report)


def _print_summary(report) -> None:
    p = report.parameters
    typer.echo(f"{report.scenario}: {p['planner']} with {p['steering']} steering, seed {p['seed']}")
    if not report.solved:
        typer.echo(f"  not solved within the budget ({report.iterations} iterations, "
                   f"{report.nodes} nodes)")
        return
    if report.objective == "time":
        typer.echo(f"  arrives after {report.cost:.2f} s (waiting {report.waited_s:.2f} s) on a "
                   f"path of {report.length_m:.3f} m, first solution after "
                   f"{1000 * report.time_to_first_solution_s:.1f} ms")
    else:
        typer.echo(f"  cost {report.cost:.3f} m, first solution after "
                   f"{1000 * report.time_to_first_solution_s:.1f} ms")
    stop = " (RRT stops at its first solution; RRT* improves it)" if p["planner"] == "rrt" else ""
    typer.echo(f"  {report.iterations} iterations{stop}, {report.nodes} nodes, "
               f"{report.collision_checks} motion checks, {report.rewires} rewires")
    typer.echo(f"  min clearance {report.min_clearance_m:.3f} m, "
               f"max |curvature| {report.max_abs_curvature:.3f} 1/m")
    if report.arrival_time_s is not None and report.objective != "time":
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
