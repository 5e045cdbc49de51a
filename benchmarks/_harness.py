"""What every benchmark script shares: where results go, and a clean Ctrl-C.

A benchmark writes its table to benchmarks/results/NAME.md (and prints it); Ctrl-C stops it with
one line instead of a traceback, keeping whatever it wrote so far.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results"


def write_result(name: str, text: str) -> Path:
    """Write ``text`` to results/``name``.md and say where."""
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / f"{name}.md"
    path.write_text(text)
    print(f"written to {path.relative_to(RESULTS.parents[1])}", file=sys.stderr, flush=True)
    return path


def markdown_table(header, rows) -> str:
    """A Markdown table of ``rows`` (sequences of cells) under ``header``."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows])


def report(name: str, title: str, header, rows) -> None:
    """Print the table and write it with its title and command to results/``name``.md."""
    table = markdown_table(header, rows)
    print(table)
    write_result(name, f"{title}\n\nCommand: `python benchmarks/bench_{name}.py`\n\n{table}\n")


def run(main: Callable[[], object]) -> None:
    """Run a benchmark's ``main``; Ctrl-C ends it with status 130 and one line."""
    try:
        main()
    except KeyboardInterrupt:
        print("\ninterrupted: results written so far are kept in benchmarks/results/",
              file=sys.stderr)
        sys.exit(130)
