"""Trackstar's edges: the `trackstar` CLI, the REST API (FastAPI) and the browser studio (viser)."""
