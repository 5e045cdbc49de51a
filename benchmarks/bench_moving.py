"""Moving obstacles: success, time to first solution and cost of RRT* in space-time.

    python benchmarks/bench_moving.py          # crossing, gate, movers; seeds 0-9; 1 s budget

For each scene it also plans the same scene with every obstacle frozen where it is at t = 0,
so the table shows what space-time checking and the rewiring rule cost in iterations/s, and how
many rewires were refused because the rewired subtree would have collided at its new times.
Writes the table to benchmarks/results/moving.md.
"""

from __future__ import annotations

import argparse
import statistics

import _harness
from tqdm import tqdm

import planner
from planner.rrt import warm_up

SCENES = ["crossing", "gate", "movers"]  # bundled scenarios


def frozen(scenario: planner.Scenario) -> planner.Scenario:
    """The same scene with every obstacle held where it is at t = 0."""
    data = scenario.model_dump(exclude_none=True)
    for ob in data["obstacles"]:
        ob.pop("motion", None)
    return planner.parse_scenario(data)


def median(values: list[float]) -> float | None:
    return statistics.median(values) if values else None


def fmt(v: float | None, scale: float = 1.0, digits: int = 2) -> str:
    return "—" if v is None else f"{v * scale:.{digits}f}"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--time", type=float, default=1.0)
    args = parser.parse_args(argv)
    warm_up()
    rows = []
    with tqdm(total=len(SCENES) * args.seeds * 2, unit="run") as bar:
        for name in SCENES:
            scenario = planner.load_scenario(name)
            for label, scn in (("moving", scenario), ("frozen at t=0", frozen(scenario))):
                results = []
                for seed in range(args.seeds):
                    bar.set_postfix_str(f"{name} {label} seed {seed}")
                    results.append(planner.solve(scn, time_limit=args.time, seed=seed))
                    bar.update()
                solved = [r for r in results if r.solved]
                rows.append((
                    name, label, f"{len(solved)}/{len(results)}",
                    fmt(median([r.time_to_first_solution_s for r in solved]), 1000, 1),
                    fmt(median([r.cost for r in solved])),
                    f"{median([r.iterations / r.planning_time_s for r in results]):.0f}",
                    f"{median([r.rewires for r in results]):.0f}",
                    f"{median([r.refused_rewires for r in results]):.0f}"))
    header = ("scene", "obstacles", "solved", "TTFS ms (median)", f"cost @{args.time:g}s",
              "it/s", "rewires", "refused rewires")
    title = f"# Moving obstacles, {args.seeds} seeds, {args.time:g} s budget"
    _harness.report("moving", title, header, rows)


if __name__ == "__main__":
    _harness.run(main)
