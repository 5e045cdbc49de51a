"""The process pool that plans off the caller's process: the server's jobs and the studies.

Each worker loads the planner's compiled kernels once (its initializer), leaves Ctrl-C to its
parent (which terminates it) and ends with its parent even when that is killed with -9 (nothing
could terminate it then). Workers are spawned, not forked: the parent may run threads (uvicorn,
viser, sqlite). A call that is running can be asked to stop through a `StopFlag`.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

__all__ = ["StopFlag", "first_line", "machine_workers", "start_pool", "stop_pool"]

PARENT_POLL_S = 0.5


def _worker_start(parent: int) -> None:
    from planner.timing import warm_up  # here: importing the pool loads no kernels

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_with_parent, args=(parent,), daemon=True,
                     name="exit-with-parent").start()
    warm_up()


def _exit_with_parent(parent: int) -> None:
    """End this worker, mid-run or idle, once its parent is gone (re-parented away; this may
    have happened before the worker got here)."""
    while os.getppid() == parent:
        time.sleep(PARENT_POLL_S)
    os._exit(1)


def start_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of ``workers`` processes, every one started now (not at the first task)."""
    pool = ProcessPoolExecutor(workers, multiprocessing.get_context("spawn"),
                               initializer=_worker_start, initargs=(os.getpid(),))
    for _ in range(workers):
        pool.submit(int)
    return pool


def stop_pool(pool: ProcessPoolExecutor) -> None:
    """Stop now: queued tasks are cancelled and running ones terminated with their workers.

    A worker terminated while it writes a result leaves half a message in the result pipe, and
    the pool's manager thread waits for the rest for ever; the interpreter joins that thread at
    exit, so a server hung on SIGTERM. Closing our own end of the pipe once the workers are
    gone ends that wait (end of file: the pool counts as broken, which it is)."""
    processes = list(pool._processes.values())  # no public way to stop a running plan
    results = pool._result_queue
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()
    for process in processes:
        process.join(2.0)
        if process.is_alive():  # deaf to SIGTERM (stuck in compiled code)
            process.kill()
            process.join(1.0)
    if results is not None and not any(p.is_alive() for p in processes):
        results._writer.close()


class StopFlag:
    """Asks a call running in a worker to stop: a file that the caller creates and the call
    looks for between batches of its work (a busy worker has no other way in). Picklable."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def __call__(self) -> bool:
        return self.path.exists()

    def set(self) -> None:
        self.path.touch()

    def clear(self) -> None:
        self.path.unlink(missing_ok=True)


def first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def machine_workers() -> int:
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
               else os.cpu_count() or 1)
