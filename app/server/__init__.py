"""The REST API (FastAPI) behind `trackstar serve`: tracks, scenarios, plans and batch jobs."""

from app.server.app import ServerSettings, create_app

__all__ = ["ServerSettings", "create_app"]
