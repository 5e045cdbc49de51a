"""Planning off the event loop: one process pool for single plans and batch jobs.

The pool is sized to the machine and started with the server; each worker loads the planner's
compiled kernels once (`warm_up` as its initializer), so no request pays for it. A job feeds
the pool at most one run per worker at a time, so a single POST /plan waits for one run, not
for a whole batch. At shutdown the workers are terminated (a plan may have up to --max-plan-s
left) and unfinished jobs are marked failed, so a restart shows what was interrupted.
"""

from __future__ import annotations

import asyncio
import functools
import multiprocessing
import os
import signal
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

from app.planning import TrackSource, check_scenario, run_plan
from app.server.store import Store
from app.simulation import SimOptions, read_progress, run_simulation
from planner.options import PlanOptions
from planner.report import PlanReport
from planner.rrt import warm_up
from planner.scenario import Scenario

__all__ = ["Planning", "first_line", "machine_workers"]

INTERRUPTED = "interrupted by a server shutdown"
CRASHED = "interrupted: the server stopped before the job finished"
PARENT_POLL_S = 0.5


def _worker_start(server: int) -> None:
    """Workers leave Ctrl-C to the server (which terminates them), end with it even when it is
    killed (-9: nothing terminates them then), and load the kernels now."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_with_parent, args=(server,), daemon=True,
                     name="exit-with-server").start()
    warm_up()


def _exit_with_parent(server: int) -> None:
    """End this worker, mid-run or idle, once its server is gone (re-parented away; this may
    have happened before the worker got here)."""
    while os.getppid() == server:
        time.sleep(PARENT_POLL_S)
    os._exit(1)


def first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def machine_workers() -> int:
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
               else os.cpu_count() or 1)


class Planning:
    """The worker pool plus the asyncio tasks that run batch jobs on it."""

    def __init__(self, store: Store, max_plan_s: float, workers: int | None = None) -> None:
        self.store = store
        self.max_plan_s = max_plan_s
        self.workers = workers or machine_workers()
        self.pool = self._start_pool()
        self._jobs: dict[str, asyncio.Task] = {}  # batch jobs and simulations
        self.sim_dir = store.path.parent / "simulations"  # per-run log CSV and progress files
        self.sim_dir.mkdir(exist_ok=True)
        store.fail_unfinished(CRASHED)

    def _start_pool(self) -> ProcessPoolExecutor:
        # spawn, not fork: the server process runs threads (uvicorn, viser, sqlite).
        pool = ProcessPoolExecutor(self.workers, multiprocessing.get_context("spawn"),
                                   initializer=_worker_start, initargs=(os.getpid(),))
        for _ in range(self.workers):  # start every worker now, not at the first request
            pool.submit(int)
        return pool

    async def _call(self, fn, *args, **kwargs):
        loop = asyncio.get_running_loop()
        pool = self.pool
        try:
            return await loop.run_in_executor(pool, functools.partial(fn, *args, **kwargs))
        except BrokenProcessPool:  # a worker died (killed, out of memory): replace the pool
            if self.pool is pool:
                self.pool = self._start_pool()
                pool.shutdown(wait=False, cancel_futures=True)
            raise

    async def check(self, scenario: Scenario, track: TrackSource | None) -> None:
        """Raise ScenarioError unless the scenario compiles (done in a worker: it may be slow)."""
        await self._call(check_scenario, scenario, track)

    async def plan(self, scenario: Scenario, options: PlanOptions,
                   track: TrackSource | None) -> PlanReport:
        return await self._call(run_plan, scenario, options, max_time=self.max_plan_s,
                                track=track)

    def start_job(self, runs: list[tuple[Scenario, PlanOptions, TrackSource | None]]) -> str:
        """Store a job and run it in the background; returns its id."""
        job_id = self.store.add_job(len(runs))
        self._jobs[job_id] = asyncio.get_running_loop().create_task(self._run(job_id, runs))
        return job_id

    async def _run(self, job_id: str, runs) -> None:
        free = asyncio.Semaphore(self.workers)

        async def one(idx: int, scenario, options: PlanOptions, track) -> None:
            async with free:
                self.store.set_job_status(job_id, "running")
                report = await self.plan(scenario, options, track)
            row = {**report.model_dump(mode="json", exclude={"path"}), "seed": options.seed}
            self.store.add_result(job_id, idx, row)

        try:
            async with asyncio.TaskGroup() as group:  # one failure cancels the other runs
                for idx, run in enumerate(runs):
                    group.create_task(one(idx, *run))
        except ExceptionGroup as failed:  # a run's scenario or options failed: keep results
            self.store.set_job_status(job_id, "failed", first_line(failed.exceptions[0]))
        else:
            self.store.set_job_status(job_id, "done")
        finally:
            self._jobs.pop(job_id, None)

    def start_simulation(self, scenario: Scenario, options: SimOptions,
                         track: TrackSource | None) -> str:
        """Store a simulation and run it in the background on the pool; returns its id."""
        sim_id = self.store.add_simulation(scenario.name, options.model_dump())
        task = self._simulate(sim_id, scenario, options, track)
        self._jobs[sim_id] = asyncio.get_running_loop().create_task(task)
        return sim_id

    def sim_log(self, sim_id: str) -> Path:
        return self.sim_dir / f"{sim_id}.csv"

    def sim_time(self, sim_id: str) -> float:
        """Simulated seconds a running simulation has reached."""
        return read_progress(self.sim_dir / f"{sim_id}.progress")

    async def _simulate(self, sim_id: str, scenario: Scenario, options: SimOptions,
                        track) -> None:
        progress = self.sim_dir / f"{sim_id}.progress"
        try:
            self.store.set_simulation(sim_id, "running")
            summary = await self._call(run_simulation, scenario, options, track,
                                       self.sim_log(sim_id), progress)
        except Exception as exc:  # noqa: BLE001  (any failure is the run's result, not a hang)
            self.store.set_simulation(sim_id, "failed", error=first_line(exc))
        else:
            self.store.set_simulation(sim_id, "done", summary=summary)
        finally:
            progress.unlink(missing_ok=True)
            self._jobs.pop(sim_id, None)

    def cancel(self, job_id: str) -> None:
        self.store.set_job_status(job_id, "cancelled")
        task = self._jobs.get(job_id)
        if task is not None:
            task.cancel()

    async def shutdown(self) -> None:
        """Stop now: mark unfinished jobs, stop their tasks, terminate the workers."""
        self.store.fail_unfinished(INTERRUPTED)
        for task in list(self._jobs.values()):
            task.cancel()
        await asyncio.gather(*self._jobs.values(), return_exceptions=True)
        processes = list(self.pool._processes.values())  # no public way to stop a running plan
        self.pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.terminate()
        for process in processes:
            await asyncio.to_thread(process.join, 2.0)
