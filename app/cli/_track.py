"""`trackstar track …`: inspect, sample and plot Inkscape tracks.

FILE may also name a library track (`trackstar track sample thesis`) when no such file exists.
Imports of the tracks layer happen inside the commands so that `--help` and bad input stay fast.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path
from typing import Annotated

import typer

from app.cli._errors import user_errors

track_cli = typer.Typer(help="Inspect, sample and plot Inkscape tracks.", no_args_is_help=True,
                        rich_markup_mode=None)

FileArg = Annotated[
    str, typer.Argument(metavar="FILE.svg", help="SVG file, or a library track name.")
]
UnitOpt = Annotated[
    str | None,
    typer.Option("--unit", help="What one user unit measures: m, cm, mm, in, pt, pc, px."),
]
PathOpt = Annotated[
    str | None, typer.Option("--path", help="Element id or inkscape:label (default: longest path).")
]
SpacingOpt = Annotated[float, typer.Option("--spacing", help="Distance between target points [m].")]
WheelbaseOpt = Annotated[float, typer.Option("--wheelbase", help="Wheelbase L [m].")]
SteerOpt = Annotated[float, typer.Option("--max-steer-deg", help="Maximum steering angle [°].")]


def _source(file: str) -> Path:
    from tracks import TrackError, library_names, library_path

    path = Path(file)
    if path.exists():
        return path
    if file in library_names():
        return library_path(file)
    raise TrackError(f"no such file: {file} (nor a library track: {', '.join(library_names())})")


def _load(file: str, path_id: str | None, unit: str | None):
    from tracks import load_svg

    return load_svg(_source(file), path_id=path_id, unit=unit)


@track_cli.command("inspect")
def inspect(
    file: FileArg,
    unit: UnitOpt = None,
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")] = False,
) -> None:
    """List every rendered path with length, bounding box and width (transforms applied)."""
    with user_errors():
        from tracks import inspect_svg

        report = inspect_svg(_source(file), unit=unit)
    if as_json:
        print(json.dumps(report))
        return
    print(f"1 user unit = {report['unit_m']:g} m")
    for p in report["paths"]:
        kind = "loop" if p["closed"] else "road"
        label = p["label"] if p["label"] not in (None, p["selector"]) else None
        name = p["selector"] if label is None else f"{p['selector']} ({label})"
        width = "no width" if p["width_m"] is None else f"width {p['width_m']:.3f} m"
        indent = "  " if p["subpath"] is not None else ""
        print(f"{indent}{name}: {kind}, {p['length_m']:.4f} m, {width}")


@track_cli.command("sample")
def sample(
    file: FileArg,
    path: PathOpt = None,
    unit: UnitOpt = None,
    spacing: SpacingOpt = 0.02,
    wheelbase: WheelbaseOpt = 0.44,
    max_steer_deg: SteerOpt = 26.0,
    as_json: Annotated[bool, typer.Option("--json", help="JSON object on stdout.")] = False,
    as_csv: Annotated[bool, typer.Option("--csv", help="CSV table on stdout.")] = False,
) -> None:
    """Resample the track: s, x, y, heading, curvature, steering angle, feasibility."""
    with user_errors():
        if as_json and as_csv:
            from app.cli._errors import InputError

            raise InputError("choose one of --json and --csv")
        from tracks import check_sampling

        check_sampling(spacing, wheelbase, max_steer_deg)
        profile = _load(file, path, unit).sample(spacing, wheelbase, max_steer_deg)
    if as_json:
        print(json.dumps(profile.to_dict()))
    elif as_csv:
        writer = csv.DictWriter(sys.stdout, fieldnames=profile.COLUMNS, lineterminator="\n")
        writer.writeheader()
        writer.writerows(profile.rows())
    else:
        bad = int((~profile.feasible).sum())
        print(
            f"{'loop' if profile.closed else 'road'} of {profile.length_m:.4f} m, "
            f"{len(profile.s)} points every {spacing} m, "
            f"max |κ| {abs(profile.curvature).max():.4f} 1/m, {bad} beyond ±{max_steer_deg}°"
        )


@track_cli.command("plot")
def plot(
    file: FileArg,
    output: Annotated[Path, typer.Option("-o", "--output", help="profile.png, .svg or .pdf")],
    path: PathOpt = None,
    unit: UnitOpt = None,
    spacing: SpacingOpt = 0.02,
    wheelbase: WheelbaseOpt = 0.44,
    max_steer_deg: SteerOpt = 26.0,
) -> None:
    """Draw the track with its boundaries, and curvature and steering angle over s."""
    with user_errors():
        from tracks import check_sampling
        from tracks.plot import figure_path, plot_profile

        figure_path(output)
        check_sampling(spacing, wheelbase, max_steer_deg)
        track = _load(file, path, unit)
        written = plot_profile(
            track, track.sample(spacing, wheelbase, max_steer_deg), output, max_steer_deg
        )
    print(written)
