"""Trackstar's edges: the CLI (and later the REST API and the browser studio)."""
