"""Dynamic scenes: the simulated car with 30 Hz replanning vs one plan made at t = 0.

    python benchmarks/bench_simulate.py              # 4 scenes x 20 seeds, replanning on and off
    python benchmarks/bench_simulate.py --seeds 5 --jobs 1

Scenes: the reference crossing, and three of benchmarks/scenarios/ in which a mover stops in the
lane, turns into it, or backs up into it — so that a plan made once at t = 0 collides. Cycle
times are measured wall-clock times on this machine (noisy when it is shared). Writes
benchmarks/results/simulate.md.
"""

from __future__ import annotations

import argparse
import statistics
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SCENES = {
    "crossing": HERE.parents[1] / "shared" / "scenarios" / "crossing.json",
    "stop_in_lane": HERE / "scenarios" / "stop_in_lane.json",
    "turn_into_lane": HERE / "scenarios" / "turn_into_lane.json",
    "back_up": HERE / "scenarios" / "back_up.json",
}


def one(job: tuple[str, int, bool, float]) -> dict:
    import planner
    from planner.sim import SimSettings, simulate

    name, seed, replan, duration = job
    run = simulate(planner.load_scenario(SCENES[name]),
                   SimSettings(duration=duration, seed=seed, replan=replan))
    return {"scene": name, "seed": seed, "replan": replan, **run.summary,
            "cycle_s": [c["ms"] / 1000.0 for c in run.cycles]}


def table(rows: list[dict]) -> str:
    out = [("| scene | replanning | reached | runs with collisions | collisions | min clearance "
            "(m) | emergency stops | cycle p50 / p99 / max (ms) | share ≤ 33 ms / ≤ 250 ms |"),
           "|---|---|---|---|---|---|---|---|---|"]
    for (scene, replan), group in _groups(rows):
        ms = np.concatenate([np.asarray(r["cycle_s"]) * 1000.0 for r in group])
        reached = sum(r["reached_goal"] for r in group)
        hit = sum(r["collisions"] > 0 for r in group)
        timing = (f"{np.percentile(ms, 50):.1f} / {np.percentile(ms, 99):.1f} / {ms.max():.1f} | "
                  f"{np.mean(ms <= 1000 / 30):.3f} / {np.mean(ms <= 250):.3f}") if replan \
            else "one plan | —"
        out.append(f"| {scene} | {'on' if replan else 'off'} | {reached}/{len(group)} | "
                   f"{hit}/{len(group)} | {sum(r['collisions'] for r in group)} | "
                   f"{min(r['min_clearance_m'] for r in group):.3f} | "
                   f"{sum(r['emergency_stops'] for r in group)} | {timing} |")
    return "\n".join(out)


def _groups(rows):
    keys = sorted({(r["scene"], r["replan"]) for r in rows},
                  key=lambda k: (list(SCENES).index(k[0]), not k[1]))
    return [(k, [r for r in rows if (r["scene"], r["replan"]) == k]) for k in keys]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--duration", type=float, default=40.0)
    parser.add_argument("--jobs", type=int, default=1, help="parallel runs (noisier timings)")
    parser.add_argument("--out", type=Path, default=HERE / "results" / "simulate.md")
    args = parser.parse_args(argv)
    jobs = [(name, seed, replan, args.duration) for name in SCENES
            for replan in (True, False) for seed in range(args.seeds)]
    with ProcessPoolExecutor(args.jobs) as pool:
        rows = list(pool.map(one, jobs))
    text = (f"# Simulated car: replanning at 30 Hz vs one plan at t = 0\n\n"
            f"{args.seeds} seeds per scene, {args.duration:g} s at most, defaults otherwise "
            f"(pure pursuit, 100 Hz control, 10 Hz sensing, measured cycle times).\n\n"
            f"{table(rows)}\n")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(text)
    print("median time to goal (replanning):", statistics.median(
        r["time_to_goal_s"] for r in rows if r["replan"] and r["reached_goal"]))


if __name__ == "__main__":
    main()
