"""Tracks benchmark: import + resample + profiles of the thesis track, and steering commands.

Run: python benchmarks/bench_tracks.py   (goals: ≤ 10 ms and ≤ 0.1 ms; the 2011 thesis: 5 ms)
Prints the table and writes it to benchmarks/results/tracks.md.
"""

from __future__ import annotations

import statistics
import time

import _harness

from tracks import library_names, library_path, load_library_track, load_svg


def timed(fn, repeat: int) -> tuple[float, float]:
    """Median and best wall time of ``fn`` in seconds."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), min(times)


def main() -> None:
    thesis = library_path("thesis")
    load_svg(thesis).sample()  # warm the imports
    rows = [
        (
            "import + resample 2 cm + profiles (thesis)",
            *timed(lambda: load_svg(thesis).sample(), 200),
            10e-3,
        )
    ]
    for name in library_names():
        rows.append(
            (f"  same, {name}", *timed(lambda n=name: load_library_track(n).sample(), 50), None)
        )
    track = load_svg(thesis)
    prof = track.sample()
    poses = [
        (prof.x[i] + 0.01, prof.y[i] - 0.01, prof.heading[i] + 0.1)
        for i in range(0, len(prof.s), 37)
    ]
    track.steering_commands(*poses[0])
    cycle = iter(poses * 1000)
    rows.append(
        (
            "10 steering commands from a pose (thesis)",
            *timed(lambda: track.steering_commands(*next(cycle)), 2000),
            0.1e-3,
        )
    )
    lines = ["| case | median | best | goal |", "|---|---:|---:|---:|"]
    for label, median, best, goal in rows:
        goal_text = f"{goal * 1e3:.3g} ms" if goal else ""
        lines.append(f"| {label.strip()} | {median * 1e3:.3f} ms | {best * 1e3:.3f} ms | "
                     f"{goal_text} |")
    text = ("# Tracks: SVG import, profiles, steering commands\n\n"
            "Command: `python benchmarks/bench_tracks.py`\n\n" + "\n".join(lines) + "\n")
    print(text)
    _harness.write_result("tracks", text)


if __name__ == "__main__":
    _harness.run(main)
