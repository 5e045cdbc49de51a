"""Options → simulation: what POST /simulations runs in a worker process.

`SimOptions` are the options of `trackstar simulate` (same names, same defaults) as the API's
body fields; `run_simulation` is a plain top-level function so that the server's worker
processes can run it. It reports progress through a small file the server reads, because a
pool worker has no other channel back while its call is running; the way in is its
`app.pool.StopFlag`, looked at with each progress write.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Literal

from pydantic import ConfigDict, Field

from app.planning import TrackSource, track_loader
from planner.options import TIMINGS, Seed
from planner.steering import CAR_STEERINGS, DEFAULT_STEERING, STEERINGS
from planner.validation import KnownKeys

__all__ = ["MAX_DURATION_S", "SimOptions", "SimulationStopped", "read_progress",
           "run_simulation"]

MAX_DURATION_S = 600.0  # simulated seconds per run: a worker is busy for up to about half that
MIN_RATE_HZ, MAX_RATE_HZ = 0.1, 1_000.0  # replanning, control, sensing: 1e12 Hz ran for ever
MAX_NOISE_M = 100.0  # σ of sensed positions: a sensor that far off senses nothing
MAX_LATENCY_MS = 60_000.0  # a fixed cycle time of a minute
# The prediction's uncertainty: beyond these every mover covers the whole scene anyway.
MAX_PREDICT_ACCEL, MAX_PREDICT_SPEED, MAX_PREDICT_HORIZON_S = 100.0, 100.0, 60.0

Rate = Annotated[float, Field(ge=MIN_RATE_HZ, le=MAX_RATE_HZ, allow_inf_nan=False)]
CarSteering = Literal[CAR_STEERINGS]
PROGRESS_EVERY_S = 0.25  # wall time between progress writes


class SimOptions(KnownKeys):
    """How to simulate: the options of `trackstar simulate`, with the same defaults."""

    model_config = ConfigDict(extra="forbid")

    duration: Annotated[float, Field(gt=0, le=MAX_DURATION_S, allow_inf_nan=False)] = Field(
        60.0, description="simulated seconds at most")
    rate: Rate = Field(30.0, description="replanning cycles per second")
    control_rate: Rate = Field(100.0, description="control ticks per second")
    sense_rate: Rate = Field(10.0, description="sensing instants per second")
    controller: Literal["pure-pursuit", "stanley", "pd"] = "pure-pursuit"
    noise: Annotated[float, Field(ge=0, le=MAX_NOISE_M, allow_inf_nan=False)] = Field(
        0.0, description="σ (m) of sensed positions; the heading gets √2·σ/wheelbase (rad)")
    laps: Annotated[int, Field(ge=1, le=1000)] | None = Field(
        None, description="drive this many laps of the scenario's closed track (rich schema)")
    seed: Seed = 0
    fixed_latency_ms: Annotated[float, Field(ge=0, le=MAX_LATENCY_MS, allow_inf_nan=False)] | None = Field(
        None, description="a fixed cycle time instead of the measured one (reproducible logs)")
    replan: bool = Field(True, description="false: plan once at t = 0 and follow it blind")
    timing: Literal[TIMINGS] = Field(
        "constant", description="optimal: the car may stop for a mover on its path instead of "
                                "going round it")

    predict_accel: Annotated[float, Field(ge=0, le=MAX_PREDICT_ACCEL,
                                          allow_inf_nan=False)] | None = Field(
        None, description="m/s²: the most a mover may change its velocity per second; "
                          "predictions grow by ½·a·τ² with the look-ahead τ (default: the "
                          "scenario's prediction.accel, else 1.0)")
    predict_speed_error: Annotated[float, Field(ge=0, le=MAX_PREDICT_SPEED,
                                                allow_inf_nan=False)] | None = Field(
        None, description="m/s: the most a sensed velocity may be off; predictions grow by it "
                          "times τ (default: the scenario's prediction.speed_error, else 0.1)")
    predict_horizon: Annotated[float, Field(ge=0, le=MAX_PREDICT_HORIZON_S,
                                            allow_inf_nan=False)] | None = Field(
        None, description="s of look-ahead over which the predictions grow; held beyond "
                          "(default: the scenario's prediction.horizon, else 1.5)")
    reverse: bool = Field(True, description="the car may back up to evade a mover")
    steering: CarSteering = Field(
        DEFAULT_STEERING, description="the replanner's steering: " + "; ".join(
            f"{name} {STEERINGS[name].summary}" for name in CAR_STEERINGS))

    def settings(self, **local):
        """The `planner.sim.SimSettings` of these options and of ``local`` ones (the command
        line's ``realtime``)."""
        from planner.sim import SimSettings

        return SimSettings(**self.model_dump(), **local)


def run_simulation(scenario, options: SimOptions, track: TrackSource | None,
                   log_path: Path, progress_path: Path,
                   stop: Callable[[], bool] | None = None) -> dict:
    """Simulate a scenario (a `planner.Scenario` or its JSON object), write the per-tick log CSV
    to ``log_path`` and return the JSON summary.

    While running, the simulated time reached is written to ``progress_path`` about every
    quarter second of wall time (replaced atomically, so a reader never sees half a number),
    and the run ends with `SimulationStopped` if ``stop()`` is true by then; the file is gone
    when the run has ended.
    """
    import planner as core
    from planner.sim import simulate

    if not isinstance(scenario, core.Scenario):
        scenario = core.parse_scenario(scenario)
    load_track = track_loader(track)
    problem = core.compile_problem(scenario, load_track=load_track)
    written = time.monotonic()

    def progress(frame) -> None:
        nonlocal written
        if time.monotonic() - written >= PROGRESS_EVERY_S:
            written = time.monotonic()
            partial = progress_path.with_suffix(".tmp")
            partial.write_text(f"{frame.t:.3f}")
            os.replace(partial, progress_path)
            if stop is not None and stop():
                raise SimulationStopped(f"stopped at {frame.t:.1f} s simulated")

    try:
        run = simulate(problem.scenario, options.settings(), problem, load_track=load_track,
                       observer=progress)
    finally:
        progress_path.unlink(missing_ok=True)
    run.write_log(log_path)
    return run.summary


class SimulationStopped(Exception):
    """A run ended early on request (DELETE /simulations/{id})."""


def read_progress(progress_path: Path) -> float:
    """Simulated seconds reached so far (0 before the first write)."""
    try:
        return float(progress_path.read_text())
    except (FileNotFoundError, ValueError):
        return 0.0
