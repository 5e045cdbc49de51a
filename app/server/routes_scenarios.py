"""/scenarios: the bundled library and stored planning problems, and the one way any route
resolves a scenario (inline, a bundled name, or a stored id)."""

from __future__ import annotations

import json
from typing import Annotated

from fastapi import APIRouter, Body, HTTPException, Request, Response

import planner
import tracks
from app.planning import TrackSource
from app.server.models import SCENARIO_EXAMPLE, ScenarioBody, ScenarioRecord

router = APIRouter(tags=["scenarios"])


def _library_record(name: str) -> dict:
    body = json.loads(planner.bundled_scenario_path(name).read_text(encoding="utf-8"))
    return {"id": name, "name": name, "source": "library", "scenario": body}


def stored_scenario(request: Request, scenario_id: str) -> dict:
    """The record of a bundled scenario (its name is its id) or of a stored one."""
    if scenario_id in planner.scenario_names():
        return _library_record(scenario_id)
    record = request.app.state.store.scenario(scenario_id)
    if record is None:
        raise HTTPException(404, f"no scenario {scenario_id!r} (GET /api/v1/scenarios lists them)")
    return record


def resolve(request: Request, scenario: planner.Scenario | str
            ) -> tuple[planner.Scenario, TrackSource | None]:
    """A scenario (inline, already validated with its body, or a stored id, validated here)
    with the uploaded track it names if any.

    Raises ScenarioError (→ 422) naming the field, or 404 for an unknown scenario id.
    """
    if isinstance(scenario, str):
        scenario = planner.parse_scenario(stored_scenario(request, scenario)["scenario"])
    if (scenario.track is None or scenario.track.embedded is not None
            or scenario.track.name in tracks.library_names()):
        return scenario, None
    row = request.app.state.store.track(scenario.track.name)
    if row is None:
        raise planner.ScenarioError(f"track.name: no track {scenario.track.name!r}: give a "
                                    f"library name or an uploaded track's id")
    return scenario, TrackSource(id=row["id"], svg=row["svg"], path=row["path"],
                                 unit=row["unit"], closed=bool(row["closed"]))


@router.get("/scenarios/schema")
def schema() -> dict:
    """The JSON Schema of the rich scenario format (minimal ones, docs/scenario-format.md, are
    valid too)."""
    return planner.scenario_schema()


@router.post("/scenarios", response_model=ScenarioRecord, status_code=201)
async def create_scenario(
    request: Request,
    scenario: Annotated[ScenarioBody, Body(examples=[SCENARIO_EXAMPLE])],
) -> ScenarioRecord:
    """Store a scenario (docs/scenario-format.md or the rich schema) once it is known to be
    plannable: valid fields, start and goal free. Its track may be a library name or an uploaded
    track's id."""
    scenario, track = resolve(request, scenario)
    await request.app.state.planning.check(scenario, track)
    # Stored as posted, not as the parsed model (which would add every default): the JSON
    # object FastAPI decoded the body into (Starlette keeps it; this does not decode again).
    posted = await request.json()
    scenario_id = request.app.state.store.add_scenario(scenario.name, posted)
    return ScenarioRecord(id=scenario_id, name=scenario.name, source="upload", scenario=posted)


@router.get("/scenarios", response_model=list[ScenarioRecord])
def list_scenarios(request: Request) -> list[dict]:
    """Every scenario: the bundled library first (read-only, named by their names), then the
    stored ones in the order they were posted."""
    library = [_library_record(name) for name in planner.scenario_names()]
    return library + request.app.state.store.scenarios()


@router.get("/scenarios/{scenario_id}", response_model=ScenarioRecord)
def get_scenario(request: Request, scenario_id: str) -> dict:
    return stored_scenario(request, scenario_id)


@router.delete("/scenarios/{scenario_id}", status_code=204)
def delete_scenario(request: Request, scenario_id: str) -> Response:
    """Delete a stored scenario (bundled ones are read-only: 403)."""
    if scenario_id in planner.scenario_names():
        raise HTTPException(403, f"{scenario_id!r} is a bundled scenario; only stored ones can "
                                 "be deleted")
    if not request.app.state.store.delete_scenario(scenario_id):
        raise HTTPException(404, f"no scenario {scenario_id!r}")
    return Response(status_code=204)
