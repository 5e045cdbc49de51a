"""The `trackstar` command line.

Each command group lives in its own module; this one only assembles them and turns the domain
errors of `tracks` and `planner` (all `ValueError` subclasses with a message a person can act on)
into one line on stderr and exit status 2.
"""

from __future__ import annotations

import sys

import typer

from app.cli._errors import InputError

cli = typer.Typer(
    name="trackstar",
    help="Plan the motion of car-like robots on race tracks.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _register() -> None:
    from app.cli import _plan, _serve, _simulate, _track

    cli.add_typer(_track.track_cli, name="track")
    _plan.register(cli)
    _serve.register(cli)
    _simulate.register(cli)


_register()


def main() -> None:
    """Console-script entry point."""
    try:
        cli(standalone_mode=True)
    except InputError as exc:  # raised outside a command (rare: option parsing helpers)
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
