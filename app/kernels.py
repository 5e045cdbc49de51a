"""The planner's compiled kernels, loaded before a command's real work, with a word if slow.

The first run after an install compiles them (about a minute on two cores) and stores them in
numba's cache; later runs load them in about a second. A silent minute looks like a hang, so a
load that takes longer than a moment says what it is doing, once, on stderr.

A server loads them in the background (`warm_in_background`): it answers at once, /health says
"warming" and the studio "preparing the planner" until they are `ready`, and plans wait.
"""

from __future__ import annotations

import sys
import threading
import time

NOTICE_AFTER_S = 2.0
_ready = threading.Event()
_loading: list[threading.Thread] = []  # the background load, once started


def warm_kernels(timing: str = "optimal") -> None:
    """Compile or load the planner's kernels, explaining a slow first compile on stderr; those
    of timing optimal only when ``timing`` is (they cost a plan's start-up 0.05 s)."""
    if timing == "optimal":
        from planner.timing import warm_up
    else:
        from planner.rrt import warm_up

    started = time.perf_counter()
    notice = ("compiling the planner's kernels: this happens once after an install and takes "
              "about a minute; later starts load them in a second ...")
    timer = threading.Timer(NOTICE_AFTER_S, _say, (notice,))
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


def warm_in_background() -> None:
    """Start loading the kernels on a daemon thread (once per process)."""
    if not _loading:
        _loading.append(threading.Thread(target=_load, name="kernels", daemon=True))
        _loading[0].start()


def _load() -> None:
    try:
        warm_kernels()
    finally:  # a load that failed fails again, with its message, where a plan needs it
        _ready.set()


def ready() -> bool:
    """Whether the background load has finished."""
    return _ready.is_set()


def wait() -> None:
    """Block until the kernels are loaded (loading them now if nothing has started to)."""
    warm_in_background()
    _ready.wait()
