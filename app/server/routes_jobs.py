"""/jobs: batches of plans (scenarios × parameter sets × seeds) run in the background."""

from __future__ import annotations

import asyncio
import csv
import io

from fastapi import APIRouter, HTTPException, Request, Response

from app.server.fair_queue import client_of
from app.server.models import MAX_RUNS, JobCreated, JobRequest, JobStatus
from app.server.routes_plan import plan_options
from app.server.routes_scenarios import resolve
from planner import ScenarioError

router = APIRouter(tags=["jobs"])


@router.post("/jobs", response_model=JobCreated, status_code=202)
async def create_job(request: Request, body: JobRequest) -> JobCreated:
    """Start a batch: every scenario (stored id or inline) × parameter set × seed; poll
    GET /jobs/{id} for progress and results."""
    if body.total > MAX_RUNS:
        raise HTTPException(422, f"{body.total} runs requested; a job may have at most "
                                 f"{MAX_RUNS}")
    planning = request.app.state.planning
    ticket = planning.admit(client_of(request), body.total)  # 429 beyond the queue's limits
    try:
        runs = await asyncio.to_thread(_runs, request, body)  # up to MAX_RUNS: not on the loop
    except BaseException:
        ticket.close()
        raise
    job_id = planning.start_job(runs, ticket)
    return JobCreated(id=job_id, total=len(runs))


def _runs(request: Request, body: JobRequest) -> list:
    """The job's (scenario, options, track) runs, each checked."""
    scenarios = []
    for i, scenario in enumerate(body.scenarios):
        try:
            scenarios.append(resolve(request, scenario))
        except ScenarioError as exc:
            raise ScenarioError(f"scenarios[{i}]: {exc}") from None
    options = [plan_options(request, params, seed=seed)
               for params in body.parameters for seed in body.seeds]
    return [(scenario, opts, track) for scenario, track in scenarios for opts in options]


def _job(request: Request, job_id: str) -> dict:
    job = request.app.state.store.job(job_id)
    if job is None:
        raise HTTPException(404, f"no job {job_id!r}")
    return job


@router.get("/jobs/{job_id}", response_model=JobStatus)
def get_job(request: Request, job_id: str) -> dict:
    return _job(request, job_id)


@router.delete("/jobs/{job_id}", response_model=JobStatus)
async def cancel_job(request: Request, job_id: str) -> dict:
    """Cancel a queued or running job (results so far are kept); a finished job is unchanged."""
    _job(request, job_id)
    request.app.state.planning.cancel(job_id)
    return _job(request, job_id)


@router.get("/jobs/{job_id}/results.csv", response_class=Response,
            responses={200: {"content": {"text/csv": {}}}})
def job_csv(request: Request, job_id: str) -> Response:
    """One row per finished run: the scalar results and every planner parameter."""
    rows = [_flat(result) for result in _job(request, job_id)["results"]]
    out = io.StringIO()
    columns = list(dict.fromkeys(key for row in rows for key in row)) or ["scenario", "seed"]
    writer = csv.DictWriter(out, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return Response(out.getvalue(), media_type="text/csv",
                    headers={"Content-Disposition": f'attachment; filename="{job_id}.csv"'})


def _flat(result: dict) -> dict:
    scalars = {k: v for k, v in result.items() if not isinstance(v, list | dict)}
    return scalars | {f"parameters.{k}": v for k, v in result["parameters"].items()}
