"""The `trackstar` command line.

Each command group lives in its own module; this one only assembles them and keeps the promise
every command makes: bad input (a usage error, or a domain error of `tracks` and `planner`,
all `ValueError` subclasses with a message a person can act on) ends with one line on stderr
and exit status 2. Help is plain text, so bracketed defaults and units such as ``[m]`` show.
"""

from __future__ import annotations

import sys

import typer

from app.cli._errors import InputError

# typer exports click's BadParameter only (newer releases vendor click); its bases are click's
# UsageError and ClickException, which every parsing error derives from.
UsageError = typer.BadParameter.__base__
ClickException = UsageError.__base__


def _groups():
    """Each command group: the names it adds to the command line, and how it adds them."""
    from app.cli import _plan, _serve, _simulate, _study, _track

    return [(("track",), lambda app: app.add_typer(_track.track_cli, name="track")),
            (("plan", "scenario"), _plan.register), (("serve",), _serve.register),
            (("simulate", "fsm"), _simulate.register), (("study",), _study.register)]


def _assemble(command: str | None = None) -> typer.Typer:
    """The command line: every group, or only the one that provides ``command`` (typer converts
    every command it holds on each run, 0.02 s for all of them)."""
    app = typer.Typer(name="trackstar", help="Plan the motion of car-like robots on race tracks.",
                      no_args_is_help=True, add_completion=False, pretty_exceptions_enable=False,
                      rich_markup_mode=None)
    for names, register in _groups():
        if command is None or command in names:
            register(app)
    if command is not None:
        app.callback()(lambda: None)  # stays a group, as `trackstar serve`, with one command
    return app


cli = _assemble()


def main() -> None:
    """Console-script entry point."""
    named = sys.argv[1] if len(sys.argv) > 1 else ""
    known = any(named in names for names, _ in _groups())
    try:
        code = (_assemble(named) if known else cli)(standalone_mode=False)
    except ClickException as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":  # a bare group: its help, as click does
            exc.show()
            sys.exit(2)
        where = f"{exc.ctx.command_path}: " if getattr(exc, "ctx", None) else ""
        message = exc.format_message().replace("Value error, ", "")
        print(f"error: {where}{message}", file=sys.stderr)
        sys.exit(2)
    except typer.Abort:
        print("aborted", file=sys.stderr)
        sys.exit(130)
    except InputError as exc:  # raised outside a command (rare: option parsing helpers)
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
    sys.exit(code if isinstance(code, int) else 0)
