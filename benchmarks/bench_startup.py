"""Start-up benchmark: what a command costs before its work, against importing numba alone.

Run: python benchmarks/bench_startup.py   (goal: `trackstar plan … --iterations 1` ≤ 2× numba's
import; commands that do not plan load no numba at all)
Each command runs --runs times as a fresh process, the commands in turn round by round, after
one unmeasured round (which fills numba's cache and Python's bytecode cache:
PYTHONDONTWRITEBYTECODE is dropped for the runs, as numba's own bytecode was written when pip
installed it); the table gives the best and the median wall time, both against numba's import,
and whether the process loaded numba. Prints the table and writes it to benchmarks/results/startup.md.
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


def wall_time(argv: list[str], env: dict) -> tuple[float, bool]:
    """Wall time of one fresh process, and whether it loaded numba."""
    start = time.perf_counter()
    out = subprocess.run(argv, capture_output=True, text=True, env=env, check=True)
    took = time.perf_counter() - start
    return took, argv is BASELINE or out.stderr.strip().endswith("True")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    args = parser.parse_args()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    argvs = {name: BASELINE if cli_args is None else [sys.executable, "-c", CLI, *cli_args]
             for name, cli_args in COMMANDS.items()}
    times: dict[str, list[float]] = {name: [] for name in COMMANDS}
    loaded: dict[str, bool] = {}
    for i in range(args.runs + 1):  # round by round: a change of load hits every command alike
        for name, argv in argvs.items():
            took, loaded[name] = wall_time(argv, env)
            if i:  # the first round fills the caches
                times[name].append(took)
    base = times["python -c 'import numba'"]
    rows = [(name, f"{min(t):.3f}", f"{statistics.median(t):.3f}",
             f"{min(t) / min(base):.2f}", f"{statistics.median(t) / statistics.median(base):.2f}",
             "yes" if loaded[name] else "no") for name, t in times.items()]
    load = os.getloadavg()[0]
    _harness.report(
        "startup",
        f"# Start-up ({args.runs} rounds, the commands in turn in each; load average {load:.1f} "
        f"on {os.cpu_count()} CPUs at the end)",
        ["command", "best s", "median s", "best / numba's best", "median / numba's median",
         "loads numba"], rows)


if __name__ == "__main__":
    _harness.run(main)
