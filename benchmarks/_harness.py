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


def run(main: Callable[[], object]) -> None:
    """Run a benchmark's ``main``; Ctrl-C ends it with status 130 and one line."""
    try:
        main()
    except KeyboardInterrupt:
        print("\ninterrupted: results written so far are kept in benchmarks/results/",
              file=sys.stderr)
        sys.exit(130)
