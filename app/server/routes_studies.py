"""/studies: parameter studies (docs/studies.md) run on the server's worker pool.

A study posted here is the study file as JSON; its scenarios may be bundled names, ids of the
scenario store or inline objects. It is validated as `trackstar study` validates a file (422
naming the key), stored with its scenarios resolved (so a restarted server resumes it without
the store), and run into its own results directory: results.sqlite, results.csv, report.html.
"""

from __future__ import annotations

import asyncio
import sqlite3
from typing import Annotated, Any, Literal

from fastapi import APIRouter, Body, HTTPException, Request, Response
from fastapi.responses import FileResponse, HTMLResponse
from pydantic import BaseModel

import planner
import tracks
from app.server.fair_queue import client_of
from app.server.models import MAX_RUNS
from app.server.routes_scenarios import stored_scenario
from app.study.report import write_report
from app.study.results import TABLES, runs_csv
from app.study.spec import Study, StudyError, parse_study

router = APIRouter(tags=["studies"])

EXAMPLE = {"name": "eps", "scenarios": ["slalom"], "planners": ["rrt", "rrtstar"],
           "parameters": {"eps": [1.0, 2.0]}, "seeds": 3, "budget": {"iterations": 1000}}


class StudyCreated(BaseModel):
    id: str
    total: int


class StudyStatus(BaseModel):
    id: str
    name: str
    status: Literal["queued", "running", "done", "failed", "cancelled"]
    done: int
    total: int
    skipped: int
    failed: int
    error: str | None = None


def _inline(request: Request, body: dict) -> dict:
    """The study with every stored scenario id replaced by its scenario object."""
    sources = body.get("scenarios")
    if not isinstance(sources, list):
        return body
    names = planner.scenario_names()
    inlined = []
    for i, source in enumerate(sources):
        if isinstance(source, str) and source not in names:
            try:
                source = stored_scenario(request, source)["scenario"]
            except HTTPException:
                raise StudyError(f"scenarios[{i}]: no scenario {source!r}: give a bundled "
                                 f"scenario's name, a stored scenario's id or an object") from None
        inlined.append(source)
    return dict(body, scenarios=inlined)


def _parse(body: dict, max_runs: int = MAX_RUNS) -> Study:
    def resolve(source) -> planner.Scenario:
        if isinstance(source, dict):
            scenario = planner.parse_scenario(source)
        else:
            scenario = planner.load_scenario(planner.bundled_scenario_path(source))
        if (scenario.track is not None and scenario.track.embedded is None
                and scenario.track.name not in tracks.library_names()):
            raise planner.ScenarioError("track.name: a study's scenarios use library tracks or "
                                        "an embedded SVG or CSV")
        return scenario

    return parse_study(body, "", resolve, max_runs=max_runs)


def resume_unfinished(store, planning) -> None:
    """At start-up: go on with the studies a stopped server left unfinished."""
    for row in store.unfinished_studies():
        study = _parse(row["body"])
        planning.start_study(row["id"], study, planning.queue.ticket("resumed", len(study.runs)))


def _status(request: Request, study_id: str) -> dict:
    row = request.app.state.store.study(study_id)
    if row is None:
        raise HTTPException(404, f"no study {study_id!r}")
    done = failed = 0
    results = request.app.state.planning.study_dir(study_id) / "results.sqlite"
    if results.exists():
        table = TABLES[row["body"].get("kind", "plan")]
        with sqlite3.connect(f"file:{results}?mode=ro", uri=True) as db:
            stored, failed = db.execute(f"SELECT COUNT(*), COUNT(error) FROM {table}").fetchone()
            done = stored - failed
    return {**{k: row[k] for k in ("id", "name", "status", "total", "skipped", "error")},
            "done": done, "failed": failed}


@router.post("/studies", response_model=StudyCreated, status_code=202)
async def create_study(
    request: Request,
    body: Annotated[dict[str, Any], Body(examples=[EXAMPLE], description=(
        "A study file as JSON (docs/studies.md); scenarios as bundled names, stored "
        "scenario ids or inline objects"))],
) -> StudyCreated:
    """Start a study; poll GET /studies/{id}, then fetch results.csv, report.html or
    results.sqlite. Runs are capped at --max-plan-s each."""
    try:  # in a thread: validating and expanding a study of many runs takes a while
        body = await asyncio.to_thread(_inline, request, body)
        study = await asyncio.to_thread(_parse, body)
    except StudyError as exc:
        raise HTTPException(422, str(exc)) from None
    cap = request.app.state.planning.max_plan_s
    times = [r.budget_time_s for r in study.runs if getattr(r, "budget_time_s", None)]
    if times and max(times) > cap:
        raise HTTPException(422, f"budget.time_s: {max(times)} s is above this server's limit "
                                 f"of {cap} s")
    ticket = request.app.state.planning.admit(client_of(request), len(study.runs))  # or 429
    study_id = request.app.state.store.add_study(study.name, body, len(study.runs))
    request.app.state.planning.start_study(study_id, study, ticket)
    return StudyCreated(id=study_id, total=len(study.runs))


@router.get("/studies", response_model=list[StudyStatus])
def list_studies(request: Request) -> list[dict]:
    return [_status(request, row["id"]) for row in request.app.state.store.studies()]


@router.get("/studies/{study_id}", response_model=StudyStatus)
def get_study(request: Request, study_id: str) -> dict:
    return _status(request, study_id)


@router.delete("/studies/{study_id}", response_model=StudyStatus)
def cancel_study(request: Request, study_id: str) -> dict:
    """Stop a queued or running study; its finished runs are kept."""
    _status(request, study_id)
    request.app.state.planning.cancel_study(study_id)
    return _status(request, study_id)


def _results(request: Request, study_id: str):
    row = _status(request, study_id)
    out = request.app.state.planning.study_dir(study_id)
    if not (out / "results.sqlite").exists():
        raise HTTPException(404, f"study {study_id!r} has no results yet")
    return row, out


@router.get("/studies/{study_id}/results.csv", response_class=Response,
            responses={200: {"content": {"text/csv": {}}}})
def study_csv(request: Request, study_id: str) -> Response:
    """The runs table so far (docs/studies.md), one line per run."""
    row, out = _results(request, study_id)
    kind = request.app.state.store.study(study_id)["body"].get("kind", "plan")
    with sqlite3.connect(f"file:{out / 'results.sqlite'}?mode=ro", uri=True) as db:
        text = runs_csv(db, TABLES[kind])
    return Response(text, media_type="text/csv", headers={
        "Content-Disposition": f'attachment; filename="{row["name"]}.csv"'})


@router.get("/studies/{study_id}/results.sqlite", response_class=FileResponse)
def study_database(request: Request, study_id: str) -> FileResponse:
    """The study's SQLite file (schema in docs/studies.md)."""
    row, out = _results(request, study_id)
    with sqlite3.connect(out / "results.sqlite") as db:  # fold the WAL into the file
        db.execute("PRAGMA wal_checkpoint(PASSIVE)")
    return FileResponse(out / "results.sqlite", media_type="application/vnd.sqlite3",
                        filename=f"{row['name']}.sqlite")


@router.get("/studies/{study_id}/report.html", response_class=HTMLResponse)
async def study_report(request: Request, study_id: str) -> HTMLResponse:
    """The self-contained report, rebuilt from the runs stored so far while the study runs."""
    row, out = _results(request, study_id)
    report = out / "report.html"
    if row["status"] != "done" or not report.exists():
        kind = request.app.state.store.study(study_id)["body"].get("kind", "plan")
        report = await asyncio.to_thread(write_report, out / "results.sqlite", kind, out)
    return HTMLResponse(report.read_text(encoding="utf-8"))
