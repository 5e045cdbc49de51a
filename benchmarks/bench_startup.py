"""Start-up benchmark: what a command costs before its work, against importing numba alone.

Run: python benchmarks/bench_startup.py   (goal: `trackstar plan … --iterations 1` ≤ 2× numba's
import; commands that do not plan load no numba at all)
Each command runs --runs times as a fresh process after one unmeasured run (which fills numba's
cache and Python's bytecode cache: PYTHONDONTWRITEBYTECODE is dropped for the runs, as numba's own
bytecode was written when pip installed it); the table gives the best and the median wall time, and
whether the process loaded numba. Prints the table and writes it to benchmarks/results/startup.md.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import _harness

THESIS = Path(__file__).resolve().parents[1] / "tracks" / "library" / "thesis.svg"
BASELINE = [sys.executable, "-c", "import numba"]
COMMANDS = {
    "python -c 'import numba'": None,
    "trackstar plan slalom --iterations 1": ["plan", "slalom", "--iterations", "1"],
    "trackstar --help": ["--help"],
    "trackstar scenario list": ["scenario", "list"],
    "trackstar track inspect thesis.svg": ["track", "inspect", str(THESIS)],
}
# The CLI's entry point, run as `trackstar` runs it, then a word on whether numba was loaded.
CLI = ("import sys\nfrom app.cli import main\nsys.argv = ['trackstar', *sys.argv[1:]]\n"
       "try:\n    main()\nexcept SystemExit:\n    pass\n"
       "print('numba' in sys.modules, file=sys.stderr)")


def wall_times(argv: list[str], runs: int) -> tuple[list[float], bool]:
    """Wall times of ``runs`` fresh processes, and whether the last one loaded numba."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    times, loaded = [], True
    for i in range(runs + 1):
        start = time.perf_counter()
        out = subprocess.run(argv, capture_output=True, text=True, env=env, check=True)
        if i:  # the first run fills the caches
            times.append(time.perf_counter() - start)
        loaded = argv is BASELINE or out.stderr.strip().endswith("True")
    return times, loaded


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    args = parser.parse_args()
    rows, best = [], {}
    for name, cli_args in COMMANDS.items():
        argv = BASELINE if cli_args is None else [sys.executable, "-c", CLI, *cli_args]
        times, loaded = wall_times(argv, args.runs)
        best[name] = min(times)
        ratio = best[name] / best["python -c 'import numba'"]
        rows.append((name, f"{min(times):.3f}", f"{statistics.median(times):.3f}",
                     f"{ratio:.2f}", "yes" if loaded else "no"))
    load = os.getloadavg()[0]
    _harness.report(
        "startup",
        f"# Start-up (best of {args.runs} runs; load average {load:.1f} on {os.cpu_count()} "
        "CPUs at the end)",
        ["command", "best s", "median s", "best / numba import", "loads numba"], rows)


if __name__ == "__main__":
    _harness.run(main)
