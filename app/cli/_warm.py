"""The planner's compiled kernels, loaded before a command's real work, with a word if slow.

The first run after an install compiles them (about a minute on two cores) and stores them in
numba's cache; later runs load them in about a second. A silent minute looks like a hang, so a
load that takes longer than a moment says what it is doing, once, on stderr.
"""

from __future__ import annotations

import sys
import threading
import time

NOTICE_AFTER_S = 2.0


def warm_kernels(timing: str = "optimal") -> None:
    """Compile or load the planner's kernels, explaining a slow first compile on stderr; those
    of timing optimal only when ``timing`` is (they cost a plan's start-up 0.05 s)."""
    if timing == "optimal":
        from planner.timing import warm_up
    else:
        from planner.rrt import warm_up

    started = time.perf_counter()
    timer = threading.Timer(NOTICE_AFTER_S, _say, (
        "compiling the planner's kernels: this happens once after an install and takes about "
        "a minute; later starts load them in a second ...",))
    timer.daemon = True
    timer.start()
    try:
        warm_up()
    finally:
        timer.cancel()
    took = time.perf_counter() - started
    if took > NOTICE_AFTER_S:
        _say(f"kernels ready ({took:.0f} s)")


def _say(message: str) -> None:
    print(message, file=sys.stderr, flush=True)
