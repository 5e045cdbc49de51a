"""Dynamic scenes: a simulated car that senses, replans at a fixed rate and tracks its plan.

    from planner import load_scenario
    from planner.sim import SimSettings, simulate
    run = simulate(load_scenario("crossing.json"), SimSettings(duration=30, seed=1))
    run.summary["collisions"], run.write_log("run.csv")
"""

from __future__ import annotations

from planner.sim.run import SimRun, SimSettings, simulate

__all__ = ["SimRun", "SimSettings", "simulate"]
