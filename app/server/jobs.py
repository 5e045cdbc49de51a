"""Planning off the event loop: one process pool for single plans and batch jobs.

The pool is sized to the machine plus one worker and started as soon as the server's kernels
are loaded (`app.kernels`; requests wait until then); each worker loads the planner's compiled
kernels once (`warm_up` as its initializer), so no request pays for it. Every call takes a slot
of the `FairQueue` first: plans go ahead of batch work and always find the extra worker free
of it, and the runs of jobs, studies and simulations take turns client by client. At shutdown
the workers are terminated (a plan may have up to --max-plan-s left) and unfinished jobs are
marked failed, so a restart shows what was interrupted.

Cancelling the task that awaits a call (a client gone, DELETE of its job, a simulation past
the server's wall-time cap) asks the worker running it to stop, through the call's `StopFlag`:
the worker is free again within a batch of planning or a quarter second of simulating.

A worker that dies (killed, out of memory, a crash in compiled code) breaks the whole pool and
every call in flight on it. The pool is replaced and each of those calls runs once more, alone
in a process of its own: the calls that were only in the way succeed, and the one that kills
its worker again fails by itself with `WorkerCrashed`, logged with what it was asked to do.
"""

from __future__ import annotations

import asyncio
import functools
import logging
import shutil
import uuid
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

from app import kernels
from app.planning import TrackSource, check_scenario, run_plan
from app.pool import StopFlag, first_line, machine_workers, start_pool, stop_pool
from app.server.fair_queue import FairQueue, Ticket
from app.server.store import Store
from app.simulation import SimOptions, read_progress, run_simulation
from app.study.report import write_report
from app.study.results import Results
from app.study.runner import execute
from app.study.spec import Study
from planner.options import PlanOptions
from planner.report import PlanReport
from planner.scenario import Scenario

__all__ = ["Planning", "WorkerCrashed"]

log = logging.getLogger("trackstar.server")

INTERRUPTED = "interrupted by a server shutdown"
CRASHED = "interrupted: the server stopped before the job finished"


class WorkerCrashed(RuntimeError):
    """A call that killed its worker twice, the second time alone (HTTP 422)."""


def _brief(arg) -> str:
    """An argument as the crash log shows it: a scenario by name, options as JSON."""
    name = getattr(arg, "name", None)
    if isinstance(name, str):
        return f"scenario {name!r}"
    dump = getattr(arg, "model_dump_json", None)
    return dump() if dump is not None else type(arg).__name__


class Planning:
    """The worker pool plus the asyncio tasks that run batch jobs on it."""

    def __init__(self, store: Store, max_plan_s: float, workers: int | None = None,
                 max_sim_s: float = 300.0) -> None:
        self.store = store
        self.max_plan_s = max_plan_s
        self.max_sim_s = max_sim_s  # wall time a simulation may keep a worker busy
        self.workers = workers or machine_workers()
        self.queue = FairQueue(self.workers)
        # Started once the kernels are loaded (`app.kernels`): the workers then load them from
        # numba's cache instead of each compiling them beside the server on a first start.
        self.pool: ProcessPoolExecutor | None = None
        self._pool_started = asyncio.Event()
        self._opening = asyncio.create_task(self._open_pool())
        self._jobs: dict[str, asyncio.Task] = {}  # batch jobs and simulations
        self.sim_dir = store.path.parent / "simulations"  # per-run log CSV and progress files
        self.sim_dir.mkdir(exist_ok=True)
        self.studies_dir = store.path.parent / "studies"  # one results directory per study
        self.stop_dir = store.path.parent / "stop"  # the StopFlags of calls asked to stop
        shutil.rmtree(self.stop_dir, ignore_errors=True)  # left by a server that was killed
        self.stop_dir.mkdir()
        store.fail_unfinished(CRASHED)

    def _start_pool(self) -> ProcessPoolExecutor:
        return start_pool(self.queue.slots)

    @property
    def started(self) -> bool:
        """Whether the kernels are loaded and the workers started (/health: "ok")."""
        return self._pool_started.is_set()

    async def _open_pool(self) -> None:
        kernels.warm_in_background()  # `trackstar serve` has started it; an app served otherwise
        while not kernels.ready():  # polled, not awaited in a thread: a stop must not wait
            await asyncio.sleep(0.05)
        self.pool = self._start_pool()
        self._pool_started.set()

    def _flag(self) -> StopFlag:
        return StopFlag(self.stop_dir / uuid.uuid4().hex)

    async def _call(self, fn, *args, ticket: Ticket | None = None, **kwargs):
        """``fn(*args, **kwargs)`` in a worker, in the interactive lane, or with a ``ticket``
        in the batch lane; a ``stop`` keyword is the call's StopFlag."""
        call = functools.partial(fn, *args, **kwargs)
        await self._pool_started.wait()  # plans wait for the kernels, they do not fail
        async with self.queue.slot(ticket):
            pool = self.pool
            try:
                return await _submit(pool, call)
            except BrokenProcessPool:  # a worker died with this call in flight: a new pool
                if self.pool is pool:
                    self.pool = self._start_pool()
                    pool.shutdown(wait=False, cancel_futures=True)
            return await self._alone(call)

    @staticmethod
    async def _alone(call: functools.partial):
        """Run ``call`` in a one-worker pool of its own: if it kills that worker too, it is the
        call that crashes workers, and nothing else goes down with it."""
        quarantine = start_pool(1)
        try:
            return await _submit(quarantine, call)
        except BrokenProcessPool:
            log.error("a planning worker died twice running %s(%s)", call.func.__name__,
                      ", ".join(_brief(a) for a in call.args))
            raise WorkerCrashed(f"this request stops the planning worker that runs it (twice, "
                                f"the second time alone): {call.func.__name__} refused; the "
                                f"server and other requests are not affected") from None
        finally:
            quarantine.shutdown(wait=False, cancel_futures=True)

    async def check(self, scenario: Scenario, track: TrackSource | None) -> None:
        """Raise ScenarioError unless the scenario compiles (done in a worker: it may be slow)."""
        await self._call(check_scenario, scenario, track)

    async def plan(self, scenario: Scenario, options: PlanOptions,
                   track: TrackSource | None, ticket: Ticket | None = None) -> PlanReport:
        return await self._call(run_plan, scenario, options, max_time=self.max_plan_s,
                                track=track, stop=self._flag(), ticket=ticket)

    def admit(self, client: str, runs: int) -> Ticket:
        """Admit a batch submission of ``runs`` runs or raise `fair_queue.Busy` (429)."""
        return self.queue.admit(client, runs)

    def start_job(self, runs: list[tuple[Scenario, PlanOptions, TrackSource | None]],
                  ticket: Ticket) -> str:
        """Store a job and run it in the background; returns its id."""
        job_id = self.store.add_job(len(runs))
        task = self._run(job_id, runs, ticket)
        self._jobs[job_id] = asyncio.get_running_loop().create_task(task)
        return job_id

    async def _run(self, job_id: str, runs, ticket: Ticket) -> None:
        ticket.on_start = lambda: self.store.set_job_status(job_id, "running")

        async def one(idx: int, scenario, options: PlanOptions, track) -> None:
            report = await self.plan(scenario, options, track, ticket)
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
            ticket.close()
            self._jobs.pop(job_id, None)

    def start_simulation(self, scenario: Scenario, options: SimOptions,
                         track: TrackSource | None, ticket: Ticket) -> str:
        """Store a simulation and run it in the background on the pool; returns its id."""
        sim_id = self.store.add_simulation(scenario.name, options.model_dump())
        task = self._simulate(sim_id, scenario, options, track, ticket)
        self._jobs[sim_id] = asyncio.get_running_loop().create_task(task)
        return sim_id

    def sim_log(self, sim_id: str) -> Path:
        return self.sim_dir / f"{sim_id}.csv"

    def _progress(self, sim_id: str) -> Path:
        return self.sim_dir / f"{sim_id}.progress"

    def sim_time(self, sim_id: str) -> float:
        """Simulated seconds a running simulation has reached."""
        return read_progress(self._progress(sim_id))

    def cancel_simulation(self, sim_id: str) -> None:
        """Mark it cancelled and stop its worker's run (the worker is freed, not killed)."""
        self.store.set_simulation(sim_id, "cancelled")
        task = self._jobs.get(sim_id)
        if task is not None:
            task.cancel()

    async def _simulate(self, sim_id: str, scenario: Scenario, options: SimOptions,
                        track, ticket: Ticket) -> None:
        progress = self._progress(sim_id)
        ticket.on_start = lambda: self.store.set_simulation(sim_id, "running")
        try:
            summary = await asyncio.wait_for(
                self._call(run_simulation, scenario, options, track, self.sim_log(sim_id),
                           progress, stop=self._flag(), ticket=ticket), self.max_sim_s)
        except TimeoutError:
            self.store.set_simulation(sim_id, "failed", error=(
                f"stopped after {self.max_sim_s:g} s of wall time, this server's limit for a "
                f"simulation (--max-sim-s): simulate fewer seconds or at lower rates"))
        except Exception as exc:  # noqa: BLE001  (any failure is the run's result, not a hang)
            self.store.set_simulation(sim_id, "failed", error=first_line(exc))
        else:
            self.store.set_simulation(sim_id, "done", summary=summary)
        finally:
            ticket.close()
            progress.unlink(missing_ok=True)
            self._jobs.pop(sim_id, None)

    # -- studies: the runs of app.study, each stored in the study's own results directory
    def study_dir(self, study_id: str) -> Path:
        return self.studies_dir / study_id

    def start_study(self, study_id: str, study: Study, ticket: Ticket) -> None:
        """Run (or resume) a study in the background: the runs its directory does not hold."""
        task = self._study(study_id, study, ticket)
        self._jobs[study_id] = asyncio.get_running_loop().create_task(task)

    async def _study(self, study_id: str, study: Study, ticket: Ticket) -> None:
        out = self.study_dir(study_id)
        results = Results(out, study.name, study.kind, study.text)

        async def one(run) -> None:
            try:
                outcome, curve = await self._call(execute, study.scenarios[run.scenario], run,
                                                  self.max_plan_s, stop=self._flag(),
                                                  ticket=ticket)
            except WorkerCrashed as exc:  # stored like any failed run; the others go on
                outcome, curve = {"error": first_line(exc)}, []
            results.add(run, outcome, curve)

        try:
            done = results.done()
            todo = [run for run in study.runs if run.key not in done]
            self.store.set_study(study_id, "running", skipped=len(study.runs) - len(todo))
            async with asyncio.TaskGroup() as group:
                for run in todo:
                    group.create_task(one(run))
            results.write_csv(out / "results.csv")
            await asyncio.to_thread(write_report, results.path, study.kind, out)
        except* Exception as failed:  # noqa: BLE001  (a worker died: the stored runs stay)
            self.store.set_study(study_id, "failed", error=first_line(failed.exceptions[0]))
        else:
            self.store.set_study(study_id, "done")
        finally:
            ticket.close()
            results.close()
            self._jobs.pop(study_id, None)

    def cancel_study(self, study_id: str) -> None:
        self.store.set_study(study_id, "cancelled")
        task = self._jobs.get(study_id)
        if task is not None:
            task.cancel()

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
        self._opening.cancel()
        if self.pool is not None:
            await asyncio.to_thread(stop_pool, self.pool)


async def _submit(pool: ProcessPoolExecutor, call: functools.partial):
    """``call`` on ``pool``. Cancelled while the call runs, it sets the call's ``stop`` flag
    (if it has one), which is cleared once the call has returned."""
    future = pool.submit(call)
    try:
        return await asyncio.wrap_future(future)
    except asyncio.CancelledError:
        stop = call.keywords.get("stop")
        if stop is not None and not future.done():
            stop.set()
            future.add_done_callback(lambda _: stop.clear())
        raise
