"""`trackstar plan` — placeholder until the planner core lands."""

import typer


def register(cli: typer.Typer) -> None:
    """Add the planning commands to the main CLI."""
