"""The server's fair queue (issue 32): interactive calls first and never short of a worker,
batch runs in turns client by client, and admission that refuses beyond the limits."""

from __future__ import annotations

import asyncio

import pytest

from app.server.fair_queue import IN_ALL, PER_CLIENT, Busy, FairQueue


def run(coro):
    return asyncio.run(coro)


async def _order(queue: FairQueue, calls) -> list[str]:
    """Start every call (name, ticket) at once; each holds its slot for one tick. Returns
    the names in the order they got a worker."""
    got: list[str] = []

    async def one(name, ticket):
        async with queue.slot(ticket):
            got.append(name)
            await asyncio.sleep(0.01)

    await asyncio.gather(*(one(name, ticket) for name, ticket in calls))
    return got


def _holders(queue: FairQueue, ticket, n: int) -> tuple[list[asyncio.Task], asyncio.Event]:
    """``n`` tasks that each take a slot with ``ticket`` and hold it until the event is set."""
    release = asyncio.Event()

    async def hold():
        async with queue.slot(ticket):
            await release.wait()

    return [asyncio.create_task(hold()) for _ in range(n)], release


def test_batch_runs_take_turns_by_client_and_leave_a_worker_to_plans():
    async def main():
        queue = FairQueue(workers=1)  # two slots: one for batch work, one kept for plans
        a, b = queue.admit("10.0.0.1", 4), queue.admit("10.0.0.2", 2)
        calls = [(f"a{i}", a) for i in range(4)] + [(f"b{i}", b) for i in range(2)]
        order = await _order(queue, calls)
        assert order == ["a0", "b0", "a1", "b1", "a2", "a3"]  # not a0 a1 a2 a3 b0 b1
        assert a.left == 0 and b.left == 0 and queue._runs == {}

    run(main())


def test_a_plan_gets_a_worker_at_once_while_batch_work_floods_the_pool():
    async def main():
        queue = FairQueue(workers=2)
        tasks, release = _holders(queue, queue.admit("10.0.0.1", 50), 50)
        await asyncio.sleep(0.01)
        assert queue.batch_busy == 2 and queue.busy == 2  # the third worker stays free
        async with asyncio.timeout(0.5):
            async with queue.slot(None):  # the same address's plan: interactive, not queued
                assert queue.busy == 3
        release.set()
        await asyncio.gather(*tasks)

    run(main())


def test_plans_go_ahead_of_waiting_batch_runs():
    async def main():
        queue = FairQueue(workers=1)
        batch = queue.admit("10.0.0.1", 3)
        calls = [("b0", batch), ("b1", batch), ("b2", batch), ("p0", None), ("p1", None)]
        order = await _order(queue, calls)
        assert order.index("p1") < order.index("b2")

    run(main())


def test_admission_refuses_beyond_each_clients_limit_and_the_servers():
    queue = FairQueue(workers=2)
    queue.admit("a", PER_CLIENT)
    with pytest.raises(Busy, match="per client") as busy:
        queue.admit("a", 1)
    assert busy.value.retry_after >= 1
    for client in ("b", "c", "d"):
        queue.admit(client, PER_CLIENT)
    assert sum(queue._runs.values()) == IN_ALL
    with pytest.raises(Busy, match="this server's limit"):
        queue.admit("e", 1)


def test_a_cancelled_waiter_leaves_the_queue_and_a_closed_ticket_frees_its_runs():
    async def main():
        queue = FairQueue(workers=1)
        ticket = queue.admit("a", 3)
        (first, second), _ = _holders(queue, ticket, 2)
        await asyncio.sleep(0.01)
        second.cancel()  # waiting for a slot
        first.cancel()  # holding one
        await asyncio.gather(first, second, return_exceptions=True)
        assert queue.busy == 0 and not queue._batch
        ticket.close()
        assert queue._runs == {}
        queue.admit("a", PER_CLIENT)  # all of them are free again

    run(main())


def test_cancelling_a_whole_job_frees_every_slot():
    """A job's runs are cancelled together: a run that gives its slot back must not hand it
    to a waiter that is cancelled already (the slot leaked, and every later job queued for
    ever)."""
    async def main():
        queue = FairQueue(workers=2)
        ticket = queue.admit("a", 40)

        async def one():
            async with queue.slot(ticket):
                await asyncio.sleep(0.05)

        async def job():
            try:
                async with asyncio.TaskGroup() as group:
                    for _ in range(40):
                        group.create_task(one())
            finally:
                ticket.close()

        task = asyncio.create_task(job())
        await asyncio.sleep(0.12)
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)
        assert (queue.busy, queue.batch_busy, queue._batch, queue._runs) == (0, 0, {}, {})

    run(main())
