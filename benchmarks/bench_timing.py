"""Time-optimal planning: arrival times of ``timing: optimal`` against ``constant``.

    python benchmarks/bench_timing.py          # crossing, gate, movers, train; seeds 0-9; 3 s

Each scene and seed is planned both ways with the same seed and time budget (``trackstar plan
SCENE --timing … --time 3``). The table gives the median arrival of each, how often each
arrives first, the median planning wall time, and for the scenes where the best possible arrival
is known from their geometry (gate, train: see tests/test_timing.py) the worst optimal arrival
over it. Writes benchmarks/results/timing.md.
"""

from __future__ import annotations

import argparse
import statistics
import time

import _harness
from tqdm import tqdm

import planner
from planner.rrt import warm_up

SCENES = ["crossing", "gate", "movers", "train"]  # bundled scenarios with movers
BEST_POSSIBLE_S = {"gate": 14.86, "train": 21.08}  # lower bounds, derived in tests/test_timing.py


def fmt(v: float | None, digits: int = 2) -> str:
    return "—" if v is None else f"{v:.{digits}f}"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--time", type=float, default=3.0)
    args = parser.parse_args(argv)
    warm_up()
    planner.solve("train", time_limit=None, iterations=10, timing="optimal")  # compile
    rows = []
    with tqdm(total=len(SCENES) * args.seeds * 2, unit="run") as bar:
        for name in SCENES:
            scenario = planner.load_scenario(name)
            arrivals = {"constant": [], "optimal": []}
            walls = {"constant": [], "optimal": []}
            for seed in range(args.seeds):
                for timing in arrivals:
                    bar.set_postfix_str(f"{name} {timing} seed {seed}")
                    started = time.perf_counter()
                    r = planner.solve(scenario, time_limit=args.time, seed=seed, timing=timing)
                    walls[timing].append(time.perf_counter() - started)
                    arrivals[timing].append(r.arrival_time_s)
                    bar.update()
            pairs = list(zip(arrivals["constant"], arrivals["optimal"]))
            wins = sum(o is not None and (c is None or o < c - 1e-9) for c, o in pairs)
            ties = sum(o is not None and c is not None and abs(o - c) <= 1e-9 for c, o in pairs)
            solved = {k: [a for a in v if a is not None] for k, v in arrivals.items()}
            bound = BEST_POSSIBLE_S.get(name)
            rows.append((
                name, f"{len(solved['constant'])}/{args.seeds}",
                fmt(statistics.median(solved["constant"]) if solved["constant"] else None),
                f"{len(solved['optimal'])}/{args.seeds}",
                fmt(statistics.median(solved["optimal"]) if solved["optimal"] else None),
                f"{wins} / {ties} / {args.seeds - wins - ties}",
                fmt(statistics.median(walls["constant"])), fmt(statistics.median(walls["optimal"])),
                fmt(max(solved["optimal"]) / bound, 3) if bound and solved["optimal"] else "—"))
    header = ("scene", "constant solved", "constant arrival s (median)", "optimal solved",
              "optimal arrival s (median)", "optimal earlier / tie / later",
              "constant wall s", "optimal wall s", "optimal worst / best possible")
    title = f"# Timing optimal against constant, {args.seeds} seeds, {args.time:g} s budget"
    _harness.report("timing", title, header, rows)


if __name__ == "__main__":
    _harness.run(main)
