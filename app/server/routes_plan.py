"""POST /plan: one plan in a worker process, answered with the `trackstar plan --json` object."""

from __future__ import annotations

import asyncio

from fastapi import APIRouter, HTTPException, Request

from app.server.models import PlanRequest
from app.server.routes_scenarios import resolve
from planner.options import PlanOptions
from planner.report import PlanReport

router = APIRouter(tags=["planning"])

DISCONNECT_POLL_S = 0.25


def plan_options(request: Request, body: PlanOptions, **override) -> PlanOptions:
    """The planner options of a request body, checked against the server's time cap (422)."""
    fields = body.model_dump(include=set(PlanOptions.model_fields)) | override
    options = PlanOptions.model_validate(fields)
    try:
        options.time_budget(request.app.state.settings.max_plan_s)
    except ValueError as exc:
        raise HTTPException(422, str(exc)) from None
    return options


@router.post("/plan", response_model=PlanReport)
async def plan(request: Request, body: PlanRequest) -> PlanReport:
    """Plan one scenario (inline or by id) with the options of `trackstar plan`; the time
    budget, which covers compiling the scenario, is capped by the server's --max-plan-s. A
    client that disconnects stops its plan."""
    options = plan_options(request, body)
    scenario, track = resolve(
        request, body.scenario if body.scenario is not None else body.scenario_id)
    return await _while_connected(request, request.app.state.planning.plan(scenario, options,
                                                                          track))


async def _while_connected(request: Request, work):
    """Await ``work``; if the client goes away first, cancel it (its worker stops planning)."""
    task = asyncio.ensure_future(work)
    try:
        while not (await asyncio.wait({task}, timeout=DISCONNECT_POLL_S))[0]:
            if await request.is_disconnected():
                raise HTTPException(499, "the client closed the connection: plan stopped")
        return task.result()
    finally:
        task.cancel()
