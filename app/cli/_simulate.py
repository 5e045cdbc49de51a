"""`trackstar simulate`: drive a scenario's car with 30 Hz replanning among moving obstacles."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import typer

from app.cli._errors import user_errors
from app.cli._plan import ScenarioArg
from app.kernels import warm_kernels
from planner.steering import CAR_STEERINGS


def simulate(
    scenario: ScenarioArg,
    duration: Annotated[float, typer.Option(help="Simulated seconds at most.")] = 60.0,
    rate: Annotated[float, typer.Option(help="Replanning cycles per second.")] = 30.0,
    control_rate: Annotated[float, typer.Option(help="Control ticks per second.")] = 100.0,
    sense_rate: Annotated[float, typer.Option(help="Sensing instants per second.")] = 10.0,
    controller: Annotated[str, typer.Option(help="pure-pursuit, stanley or pd.")] = "pure-pursuit",
    noise: Annotated[float, typer.Option(
        help="σ (m) of sensed positions; the sensed heading gets √2·σ/wheelbase (rad).")] = 0.0,
    laps: Annotated[int | None, typer.Option(
        help="Drive N laps of the scenario's closed track (rich schema) behind a rolling goal; "
             "the scenario's goal is not used.")] = None,
    behaviour: Annotated[Path | None, typer.Option(help="Drive by this state machine (JSON).")]
    = None,
    seed: Annotated[int, typer.Option(help="Random seed (planner and noise).")] = 0,
    fixed_latency: Annotated[float | None, typer.Option(
        help="A fixed cycle time (ms) instead of the measured one: the same seed then gives "
             "the same log, byte for byte.")] = None,
    no_replan: Annotated[bool, typer.Option(
        "--no-replan", help="Plan once at t = 0 and follow that plan blind.")] = False,
    timing: Annotated[str, typer.Option(
        help="constant or optimal: the car may stop for a mover on its path instead of going "
             "round it (when it can go on within 10 s).")] = "constant",
    predict_accel: Annotated[float | None, typer.Option(
        help="m/s²: the most a mover may change its velocity per second; predictions grow by "
             "½·a·τ² with the look-ahead τ. Default: the scenario's prediction.accel, else "
             "1.0.")] = None,
    predict_speed_error: Annotated[float | None, typer.Option(
        help="m/s: the most a sensed velocity may be off; predictions grow by it times τ. "
             "Default: the scenario's prediction.speed_error, else 0.1.")] = None,
    predict_horizon: Annotated[float | None, typer.Option(
        help="s of look-ahead over which the predictions grow; held beyond. Default: the "
             "scenario's prediction.horizon, else 1.5.")] = None,
    reverse: Annotated[bool, typer.Option(
        help="The car may back up to evade a mover.")] = True,
    steering: Annotated[str, typer.Option(
        help="The replanner's steering: " + ", ".join(CAR_STEERINGS)
             + " (cc: continuous curvature, which a steering servo can follow).")] = "dubins",
    realtime: Annotated[bool, typer.Option(help="Pace the run to the wall clock.")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    log: Annotated[Path | None, typer.Option(help="Write the per-tick log (CSV).")] = None,
    raceline: Annotated[Path | None, typer.Option(
        "--raceline", help="Also write the driven path in the TUM raceline layout (the fastest "
                           "speed along it within the vehicle's max speed, 4 m/s² lateral, "
                           "2 m/s² longitudinal).")] = None,
) -> None:
    """Simulate the car: sense, replan at --rate, track the plan, report the metrics."""
    import planner as core
    from app.simulation import SimOptions
    from planner.sim import simulate as run_simulation

    with user_errors():
        machine = None
        if behaviour is not None:
            from planner.sim.fsm import load_fsm

            machine = load_fsm(behaviour)  # a bad file is reported first, naming the element
        settings = SimOptions(duration=duration, rate=rate, control_rate=control_rate,
                              sense_rate=sense_rate, controller=controller, noise=noise,
                              seed=seed, fixed_latency_ms=fixed_latency, replan=not no_replan,
                              laps=laps, timing=timing, predict_accel=predict_accel,
                              predict_speed_error=predict_speed_error,
                              predict_horizon=predict_horizon,
                              reverse=reverse, steering=steering).settings(realtime=realtime)
        problem = core.compile_problem(core.load_scenario(scenario))
        for name, out in (("--log", log), ("--raceline", raceline)):
            if out is not None and not out.parent.is_dir():
                raise ValueError(f"{name}: directory {str(out.parent)!r} does not exist")
        warm_kernels(timing)
        result = run_simulation(problem.scenario, settings, problem, behaviour=machine)
        if log is not None:
            result.write_log(log)
        if raceline is not None:
            from app.raceline import path_raceline, raceline_limits

            driven = result.log[:, [result.columns.index(c) for c in ("x", "y", "theta")]]
            raceline.write_text(path_raceline(driven, raceline_limits(
                vehicle=problem.scenario.vehicle)))
    summary = result.summary
    if as_json:
        typer.echo(json.dumps(summary, allow_nan=False, default=_finite))
        return
    _print_summary(problem.scenario.name, summary)


def _finite(value):
    raise TypeError(f"not JSON serialisable: {value!r}")


def _print_summary(name: str, s: dict) -> None:
    goal = (f"goal reached at t = {s['time_to_goal_s']:.2f} s" if s["reached_goal"]
            else f"goal not reached in {s['duration_s']:.1f} s")
    typer.echo(f"{name}: {goal}, {s['distance_m']:.2f} m driven")
    if "behaviour" in s:
        b = s["behaviour"]
        typer.echo(f"  behaviour: {len(b['transitions'])} transitions, "
                   f"final state '{b['final_state']}'")
    typer.echo(f"  collisions {s['collisions']} ({s['collisions_moving']} moving, "
               f"{s['collisions_at_rest']} at rest), min clearance {s['min_clearance_m']:.3f} m")
    typer.echo(f"  emergency stops {s['emergency_stops']}, planned waits {s['planned_waits']}, "
               f"brakes {s['brakes']}, evasions {s['evasions']}")
    c = s["cycle_ms"]
    if c["p50"] is not None:
        typer.echo(f"  {s['cycles']} cycles, {s['replans']} replans; cycle ms p50 {c['p50']:.1f}"
                   f" p95 {c['p95']:.1f} p99 {c['p99']:.1f} max {c['max']:.1f}; "
                   f"≤ 30 Hz {100 * s['share_30hz']:.1f} %, ≤ 4 Hz {100 * s['share_4hz']:.1f} %")
    e = s["cross_track_error_m"]
    if e["mean"] is not None and math.isfinite(e["mean"]):
        typer.echo(f"  cross-track error mean {e['mean']:.3f} m, max {e['max']:.3f} m")


fsm_cli = typer.Typer(help="Behaviour state machines (JSON).", no_args_is_help=True,
                      rich_markup_mode=None)


@fsm_cli.command("check")
def fsm_check(path: Annotated[Path, typer.Argument(help="State machine JSON file.")]) -> None:
    """Check a state machine file; exit 2 with one line naming the bad element."""
    from planner.sim.fsm import load_fsm

    with user_errors():
        machine = load_fsm(path)
    typer.echo(f"{path.name}: ok ({len(machine.states)} states, initial '{machine.initial}')")


def register(cli: typer.Typer) -> None:
    """Add `simulate` and `fsm` to the main CLI."""
    cli.command("simulate")(simulate)
    cli.add_typer(fsm_cli, name="fsm")
