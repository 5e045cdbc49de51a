"""The FastAPI application: settings, lifespan (store and worker pool), limits, routes."""

from __future__ import annotations

from contextlib import asynccontextmanager
from dataclasses import dataclass, field
from importlib.metadata import version
from pathlib import Path

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, JSONResponse
from fastapi.staticfiles import StaticFiles
from fastapi_offline import FastAPIOffline

from app.access import Access
from app.server import (
    guard,
    routes_jobs,
    routes_plan,
    routes_scenarios,
    routes_simulations,
    routes_studies,
    routes_tracks,
)
from app.server.fair_queue import Busy
from app.server.jobs import Planning, WorkerCrashed
from app.server.models import INVALID_SCENARIO, Health
from app.server.store import Store
from planner import ScenarioError
from planner.validation import message

STATIC = Path(__file__).resolve().parents[2] / "static"
DATABASE = "trackstar.sqlite3"
MULTIPART_SLACK = 64 * 1024  # form fields and boundaries around an upload of the full cap


@dataclass(frozen=True)
class ServerSettings:
    data_dir: Path
    max_upload_mb: float = 5.0
    max_plan_s: float = 30.0
    max_sim_s: float = 300.0  # wall time of one simulation on the server
    ui_port: int | None = None
    workers: int | None = None  # default: one per CPU available to the process
    access: Access = field(default_factory=Access)  # who may call (app.access)

    @property
    def max_upload_bytes(self) -> int:
        return int(self.max_upload_mb * 1024 * 1024)


class BodyLimit:
    """Refuse any request body above the cap with 413, before it is read into memory."""

    def __init__(self, app, max_bytes: int) -> None:
        self.app, self.max_bytes = app, max_bytes

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        headers = dict(scope["headers"])
        length = headers.get(b"content-length", b"0")
        if not length.isdigit() or int(length) > self.max_bytes:
            return await self._refuse(scope, receive, send)
        seen, refused = 0, False

        async def limited():
            # Answer 413 ourselves and tell the app the client left: an exception raised here
            # would reach FastAPI's body parsing, which turns any error into a 400.
            nonlocal seen, refused
            message = await receive()
            seen += len(message.get("body", b""))
            if seen <= self.max_bytes:
                return message
            if not refused:
                refused = True
                await self._refuse(scope, receive, send)
            return {"type": "http.disconnect"}

        async def unless_refused(message) -> None:
            if not refused:
                await send(message)

        await self.app(scope, limited, unless_refused)

    async def _refuse(self, scope, receive, send) -> None:
        mb = self.max_bytes / 1024 / 1024
        response = JSONResponse({"detail": f"request body above the limit of {mb:.1f} MB "
                                           "(see --max-upload-mb)"}, status_code=413)
        await response(scope, receive, send)


def _scenario_message(error: dict) -> str:
    """The message of an invalid inline scenario, led by its place in a list of them
    ('scenarios[1]: invalid scenario: start: …')."""
    loc = error["loc"]
    if not any(isinstance(part, int) for part in loc):
        return error["msg"]
    where = "".join(f"[{part}]" if isinstance(part, int) else f".{part}" for part in loc[1:])
    return f"{where.lstrip('.')}: {error['msg']}"


def _document_token(app: FastAPI) -> None:
    """/docs and /openapi.json stay open (they hold no data); they show the bearer scheme on
    /api/ so Swagger UI's Authorize button sends the token."""
    original = app.openapi

    def openapi() -> dict:
        schema = original()
        schema.setdefault("components", {})["securitySchemes"] = {
            "token": {"type": "http", "scheme": "bearer"}}
        for path, operations in schema["paths"].items():
            if path.startswith("/api/"):
                for operation in operations.values():
                    operation["security"] = [{"token": []}]
        return schema

    app.openapi = openapi


def create_app(settings: ServerSettings) -> FastAPI:
    """The API app; the store and the worker pool live from its startup to its shutdown."""

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        store = Store(settings.data_dir / DATABASE)
        planning = Planning(store, settings.max_plan_s, settings.workers, settings.max_sim_s)
        app.state.store, app.state.planning = store, planning
        routes_studies.resume_unfinished(store, planning)
        try:
            yield
        finally:
            await planning.shutdown()
            store.close()

    # /docs and /redoc from packaged assets, not a CDN: they work on an offline lab network.
    app = FastAPIOffline(
        title="Trackstar",
        version=version("trackstar"),
        description="Tracks, scenarios, RRT/RRT* plans, batch jobs and simulated runs for "
                    "car-like robots.",
        lifespan=lifespan,
    )
    app.state.settings = settings
    app.add_middleware(BodyLimit, max_bytes=settings.max_upload_bytes + MULTIPART_SLACK)
    app.add_middleware(guard.Guard, access=settings.access)  # the outer one: refuses first
    if settings.access.token is not None:
        _document_token(app)

    @app.exception_handler(RequestValidationError)
    async def invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
        # Without the echoed input: it may hold NaN or infinity, which JSON cannot carry.
        errors = [{"loc": e["loc"], "msg": message(e), "type": e["type"]} for e in exc.errors()]
        if errors and all(e["type"] == INVALID_SCENARIO for e in errors):
            # Only an inline scenario is wrong: its one-line message, as for any ScenarioError.
            return JSONResponse({"detail": _scenario_message(errors[0])}, status_code=422)
        return JSONResponse({"detail": errors}, status_code=422)

    @app.exception_handler(ScenarioError)
    async def unplannable(request: Request, exc: ScenarioError) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=422)

    @app.exception_handler(Busy)
    async def busy(request: Request, exc: Busy) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=429,
                            headers={"Retry-After": str(exc.retry_after)})

    @app.exception_handler(WorkerCrashed)
    async def worker_crashed(request: Request, exc: WorkerCrashed) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=422)

    @app.get("/health", response_model=Health, tags=["server"])
    def health() -> Health:
        return Health(status="ok" if app.state.planning.started else "warming",
                      version=app.version, ui_port=settings.ui_port)

    @app.get("/", include_in_schema=False)
    def landing() -> FileResponse:
        return FileResponse(STATIC / "index.html")

    app.include_router(guard.router)
    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    for module in (routes_tracks, routes_scenarios, routes_plan, routes_jobs, routes_studies,
                   routes_simulations):
        app.include_router(module.router, prefix="/api/v1")
    return app
