"""Who runs next on the worker pool: a fair queue with two lanes (issue 32).

Interactive calls (POST /plan, a scenario check) take any free worker, ahead of every batch
call; batch calls (the runs of jobs, studies and simulations) take turns client by client and
leave one worker to the interactive lane, so a plan never waits behind a flood of batch work,
even one from its own address. A client is its address: the server has one token, so tokens
never tell two clients apart.

A batch submission is admitted for its number of runs (`admit` → a `Ticket`), up to
`PER_CLIENT` runs queued or running per client and `IN_ALL` in all; beyond, it is refused with
`Busy` (HTTP 429 with Retry-After) before anything is stored or started.
"""

from __future__ import annotations

import asyncio
import math
from collections import deque
from contextlib import asynccontextmanager

__all__ = ["IN_ALL", "PER_CLIENT", "Busy", "FairQueue", "Ticket", "client_of"]

PER_CLIENT = 10_000  # runs queued or running per client: one study or job at its largest
IN_ALL = 40_000  # runs queued or running in all


def client_of(request) -> str:
    """Who is asking: the address a request came from."""
    return request.client.host if request.client is not None else "unknown"


class Busy(Exception):
    """Refused: too many runs queued (HTTP 429); ``retry_after`` in seconds."""

    def __init__(self, message: str, retry_after: int) -> None:
        super().__init__(message)
        self.retry_after = retry_after


class Ticket:
    """A batch submission's admission: its client and the runs it still holds in the queue."""

    def __init__(self, queue: FairQueue, client: str, runs: int) -> None:
        self.queue, self.client, self.left = queue, client, runs
        self.on_start = None  # called as each run gets its worker (a job turns "running")

    def run_done(self) -> None:
        if self.left > 0:
            self.left -= 1
            self.queue._release_runs(self.client, 1)

    def close(self) -> None:
        """The submission has ended (done, failed, cancelled): its runs leave the queue."""
        self.queue._release_runs(self.client, self.left)
        self.left = 0


class FairQueue:
    """Slots on ``workers + 1`` worker processes: batch calls use at most ``workers`` of them."""

    def __init__(self, workers: int) -> None:
        self.slots = workers + 1
        self.batch_slots = workers
        self.busy = self.batch_busy = 0
        self._interactive: deque[asyncio.Future] = deque()
        self._batch: dict[str, deque[asyncio.Future]] = {}  # waiting, per client
        self._served: dict[str, int] = {}  # per client, when it last got a worker
        self._grants = 0
        self._runs: dict[str, int] = {}  # admitted runs not yet done, per client
        self._run_s = 1.0  # a running mean of how long a batch call takes, for Retry-After

    # -- admission -------------------------------------------------------------------------
    def admit(self, client: str, runs: int) -> Ticket:
        """A ticket for ``runs`` batch runs of ``client``; raises `Busy` beyond the limits."""
        mine, total = self._runs.get(client, 0), sum(self._runs.values())
        if mine + runs > PER_CLIENT:
            self._refuse(f"{mine} runs of yours are queued or running; {runs} more would pass "
                         f"the limit of {PER_CLIENT} per client", mine + runs - PER_CLIENT)
        if total + runs > IN_ALL:
            self._refuse(f"{total} runs are queued or running; {runs} more would pass this "
                         f"server's limit of {IN_ALL}", total + runs - IN_ALL)
        return self.ticket(client, runs)

    def ticket(self, client: str, runs: int) -> Ticket:
        """A ticket without the limits (a study the server resumes after a restart)."""
        self._runs[client] = self._runs.get(client, 0) + runs
        return Ticket(self, client, runs)

    def _refuse(self, why: str, excess: int) -> None:
        wait = math.ceil(min(3600.0, max(1.0, excess * self._run_s / self.batch_slots)))
        raise Busy(f"too much work queued: {why}; try again in {wait} s", wait)

    def _release_runs(self, client: str, runs: int) -> None:
        left = self._runs.get(client, 0) - runs
        if left > 0:
            self._runs[client] = left
        else:
            self._runs.pop(client, None)
            self._served.pop(client, None)

    # -- slots -----------------------------------------------------------------------------
    @asynccontextmanager
    async def slot(self, ticket: Ticket | None):
        """Hold a worker for one call: interactive without a ticket, else the ticket's batch
        run (which counts as done when the slot is released)."""
        batch = ticket is not None
        waiter = asyncio.get_running_loop().create_future()
        if batch:
            self._batch.setdefault(ticket.client, deque()).append(waiter)
        else:
            self._interactive.append(waiter)
        self._dispatch()
        try:
            await waiter
        except asyncio.CancelledError:
            if waiter.done() and not waiter.cancelled():  # granted as it was cancelled
                self._free(batch)
            else:
                self._forget(waiter, ticket)
            raise
        started = asyncio.get_running_loop().time()
        try:
            if batch and ticket.on_start is not None:
                ticket.on_start()
            yield
        finally:
            self._free(batch)
            if batch:
                took = asyncio.get_running_loop().time() - started
                self._run_s = 0.9 * self._run_s + 0.1 * took
                ticket.run_done()

    def _dispatch(self) -> None:
        while self.busy < self.slots:
            if self._interactive:
                waiter, batch = self._interactive.popleft(), False
            elif self._batch and self.batch_busy < self.batch_slots:
                # Round robin: the waiting client served least recently (ties: first come).
                client = min(self._batch, key=lambda c: self._served.get(c, -1))
                waiting = self._batch[client]
                waiter, batch = waiting.popleft(), True
                if not waiting:
                    del self._batch[client]
                self._grants += 1
                self._served[client] = self._grants
            else:
                return
            if waiter.done():  # cancelled, and not yet forgotten
                continue
            self.busy += 1
            self.batch_busy += batch
            waiter.set_result(None)

    def _free(self, batch: bool) -> None:
        self.busy -= 1
        self.batch_busy -= batch
        self._dispatch()

    def _forget(self, waiter: asyncio.Future, ticket: Ticket | None) -> None:
        """Take a cancelled waiter out of its lane (`_dispatch` may have dropped it already)."""
        waiting = self._interactive if ticket is None else self._batch.get(ticket.client, ())
        if waiter in waiting:
            waiting.remove(waiter)
        if ticket is not None and not waiting:
            self._batch.pop(ticket.client, None)
