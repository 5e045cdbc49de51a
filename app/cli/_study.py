"""`trackstar study`: run a parameter study described in one file, resumably."""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path
from typing import Annotated, Literal

import typer

from app.cli._errors import user_errors
from app.study.backends import BACKENDS

Backend = Literal[tuple(BACKENDS)]


def study(
    file: Annotated[str, typer.Argument(show_default=False, metavar="STUDY", help=(
        "A study file (.yaml, .yml or .json; docs/studies.md) or the name of a study bundled "
        "in app/study/library."))],
    out: Annotated[Path | None, typer.Option(help="Results directory [default: "
                                             "studies/NAME/].", show_default=False)] = None,
    workers: Annotated[int | None, typer.Option(min=1, help="Worker processes [default: the "
                                                "CPU count].", show_default=False)] = None,
    backend: Annotated[Backend, typer.Option(help="Where the runs execute: this machine's "
                                             "process pool, or Ray (the cluster in RAY_ADDRESS, "
                                             "else a local one; pip install "
                                             "'trackstar[ray]').")] = "local",
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Run every planning run of a study; runs already stored in --out are skipped."""
    from app.pool import machine_workers
    from app.study.results import StudyMismatch
    from app.study.runner import run_study
    from app.study.spec import load_study

    with user_errors():
        BACKENDS[backend].check()
        spec = load_study(file)
        out = out or Path("studies") / spec.name
        try:
            summary = run_study(spec, out, workers or machine_workers(), backend)
        except StudyMismatch as exc:
            raise ValueError(str(exc)) from None
        except KeyboardInterrupt:
            print(f"\nstopped: runs finished so far are stored in {out / 'results.sqlite'}; "
                  f"run the same command again to go on", file=sys.stderr)
            raise typer.Exit(130) from None
    if as_json:
        typer.echo(json.dumps(dataclasses.asdict(summary)))
    else:
        typer.echo(f"study {summary.study}: {summary.done} of {summary.total} runs done "
                   f"({summary.skipped} skipped, {summary.failed} failed) in "
                   f"{summary.wall_s:.1f} s; table: {summary.csv}")
    if summary.failed:
        raise typer.Exit(1)


def register(cli: typer.Typer) -> None:
    cli.command("study")(study)
