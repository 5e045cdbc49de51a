"""/simulations: the simulated car (`trackstar simulate`) as a background job with progress."""

from __future__ import annotations

from fastapi import APIRouter, HTTPException, Request
from fastapi.responses import FileResponse

from app.server.fair_queue import client_of
from app.server.models import SimulationCreated, SimulationRequest, SimulationStatus
from app.server.routes_scenarios import resolve
from planner.sim.laps import require_track

router = APIRouter(tags=["simulations"])


@router.post("/simulations", response_model=SimulationCreated, status_code=202)
async def create_simulation(request: Request, body: SimulationRequest) -> SimulationCreated:
    """Start a simulation of a scenario (inline or a stored id) with the options of
    `trackstar simulate`, e.g. `laps` for lap mode on a closed track; poll
    GET /simulations/{id} for progress and the summary, then GET /simulations/{id}/log."""
    scenario, track = resolve(request, body.scenario_id or body.scenario)
    options = body.options()
    if options.laps is not None:
        try:
            require_track(scenario)
        except ValueError as exc:
            raise HTTPException(422, str(exc).removeprefix("--")) from None
    planning = request.app.state.planning
    await planning.check(scenario, track)
    sim_id = planning.start_simulation(scenario, options, track,
                                       planning.admit(client_of(request), 1))
    return SimulationCreated(id=sim_id)


def _simulation(request: Request, sim_id: str) -> dict:
    sim = request.app.state.store.simulation(sim_id)
    if sim is None:
        raise HTTPException(404, f"no simulation {sim_id!r}")
    return sim


@router.get("/simulations/{sim_id}", response_model=SimulationStatus)
def get_simulation(request: Request, sim_id: str) -> dict:
    """Status, progress in simulated time and, once done, the summary (`--json` of the CLI)."""
    sim = _simulation(request, sim_id)
    if sim["status"] == "done":
        t = sim["summary"]["duration_s"]
        return {**sim, "sim_time_s": t, "progress": 1.0}
    t = request.app.state.planning.sim_time(sim_id)
    return {**sim, "sim_time_s": t, "progress": min(t / sim["settings"]["duration"], 1.0)}


@router.delete("/simulations/{sim_id}", response_model=SimulationStatus)
async def cancel_simulation(request: Request, sim_id: str) -> dict:
    """Stop a queued or running simulation within about a second (status `cancelled`, no
    log); a finished one is unchanged."""
    _simulation(request, sim_id)
    request.app.state.planning.cancel_simulation(sim_id)
    return get_simulation(request, sim_id)


@router.get("/simulations/{sim_id}/log", response_class=FileResponse,
            responses={200: {"content": {"text/csv": {}}}, 409: {}})
def simulation_log(request: Request, sim_id: str) -> FileResponse:
    """The per-tick log of a finished run: the CSV of `trackstar simulate --log`."""
    sim = _simulation(request, sim_id)
    if sim["status"] != "done":
        raise HTTPException(409, f"simulation {sim_id!r} is {sim['status']}: its log exists "
                                 f"once it is done")
    return FileResponse(request.app.state.planning.sim_log(sim_id), media_type="text/csv",
                        filename=f"{sim_id}.csv")
