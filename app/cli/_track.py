"""`trackstar track …`: inspect, sample, plot and export tracks; racelines.

FILE is an Inkscape SVG or a centreline CSV (TUM / F1TENTH layout), or names a library track
(`trackstar track sample thesis`) when no such file exists. Imports of the tracks layer happen
inside the commands so that `--help` and bad input stay fast.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path
from typing import Annotated

import typer

from app.cli._errors import user_errors

track_cli = typer.Typer(help="Inspect, sample, plot and export tracks (Inkscape SVG or "
                             "centreline CSV); racelines.", no_args_is_help=True,
                        rich_markup_mode=None)

FileArg = Annotated[
    str, typer.Argument(metavar="FILE", help="SVG or centreline CSV file, or a library track name.")
]
UnitOpt = Annotated[
    str | None,
    typer.Option("--unit", help="What one user unit measures: m, cm, mm, in, pt, pc, px."),
]
PathOpt = Annotated[
    str | None,
    typer.Option("--path", help="SVG: a selector from inspect (id, label, TAG-K, NAME:K; "
                                "default: the longest path)."),
]
OpenOpt = Annotated[
    bool, typer.Option("--open", help="Read a centreline CSV as a road (default: a loop).")
]
OutputOpt = Annotated[Path | None, typer.Option("-o", "--output", help="File (default: stdout).")]
VMaxOpt = Annotated[
    float | None,
    typer.Option("--v-max", help="Speed limit [m/s] (default: the default vehicle's, 1.0)."),
]
ALatOpt = Annotated[float, typer.Option("--a-lat-max", help="Lateral acceleration limit [m/s²].")]
ALongOpt = Annotated[
    float, typer.Option("--a-long-max", help="Longitudinal acceleration limit [m/s²].")
]
SpacingOpt = Annotated[float, typer.Option("--spacing", help="Distance between target points [m].")]
WheelbaseOpt = Annotated[float, typer.Option("--wheelbase", help="Wheelbase L [m].")]
SteerOpt = Annotated[float, typer.Option("--max-steer-deg", help="Maximum steering angle [°].")]


def _source(file: str) -> Path:
    from tracks import TrackError, library_names, library_path

    path = Path(file)
    if path.is_file():
        return path
    if file in library_names():  # also beside a directory of that name
        return library_path(file)
    if path.exists():
        return path
    raise TrackError(f"no such file: {file} (nor a library track: {', '.join(library_names())})")


def _load(file: str, path_id: str | None, unit: str | None, open_: bool):
    """The track, with a line on stderr when ``path_id`` names an element of several subpaths
    (its longest is taken: a drawing's inner edge, say, may be the one wanted)."""
    track, note = _load_noted(file, path_id, unit, open_)
    if note:
        print(note, file=sys.stderr)
    return track


def _load_noted(file: str, path_id: str | None, unit: str | None, open_: bool):
    """The track and the note `_load` prints (None: nothing to say)."""
    from tracks import inspect_track, load_track

    source, closed = _source(file), False if open_ else None
    track = load_track(source, path_id=path_id, unit=unit, closed=closed)
    if path_id is None:
        return track, None
    paths = inspect_track(source, unit=unit, closed=closed)["paths"]
    element = next((p for p in paths if p["subpath"] is None
                    and path_id in (p["selector"], p["id"], p["label"])), None)
    if element is None:
        return track, None  # a NAME:K selector, or a CSV
    parts = [p for p in paths if p["selector"].startswith(element["selector"] + ":")]
    if len(parts) < 2:
        return track, None
    longest = max(parts, key=lambda p: p["length_m"])["selector"]
    return track, (f"{path_id} has {len(parts)} subpaths; took {longest}, the longest; "
                   f"choose one with {element['selector']}:N")


def _write(text: str, output: Path | None) -> None:
    if output is None:
        sys.stdout.write(text)
        return
    output.write_text(text)
    print(output)


@track_cli.command("inspect")
def inspect(
    file: FileArg,
    unit: UnitOpt = None,
    open_: OpenOpt = False,
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")] = False,
) -> None:
    """List every rendered path with its selector, length, bounding box and width."""
    with user_errors():
        from tracks import inspect_track

        report = inspect_track(_source(file), unit=unit, closed=False if open_ else None)
    if as_json:
        print(json.dumps(report))
        return
    if report["format"] == "svg":
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
    open_: OpenOpt = False,
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
        track, note = _load_noted(file, path, unit, open_)
        profile = track.sample(spacing, wheelbase, max_steer_deg)
    if note:
        print(note, file=sys.stderr)
    if as_json:
        print(json.dumps({**profile.to_dict(), **({"note": note} if note else {})}))
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
    open_: OpenOpt = False,
    spacing: SpacingOpt = 0.02,
    wheelbase: WheelbaseOpt = 0.44,
    max_steer_deg: SteerOpt = 26.0,
    v_max: VMaxOpt = None,
    a_lat_max: ALatOpt = 4.0,
    a_long_max: ALongOpt = 2.0,
) -> None:
    """Draw the track with its boundaries, and curvature, steering angle and the raceline's
    speed over s."""
    with user_errors():
        from app.raceline import raceline_limits
        from tracks import check_sampling
        from tracks.plot import figure_path, plot_profile

        figure_path(output)
        check_sampling(spacing, wheelbase, max_steer_deg)
        limits = raceline_limits(v_max, a_lat_max, a_long_max)
        track = _load(file, path, unit, open_)
        written = plot_profile(
            track, track.sample(spacing, wheelbase, max_steer_deg), output, max_steer_deg, limits
        )
    print(written)


@track_cli.command("export")
def export(
    file: FileArg,
    output: OutputOpt = None,
    fmt: Annotated[
        str, typer.Option("--format", help="tum-centerline (x_m,y_m,w_tr_right_m,w_tr_left_m) "
                                           "or svg (Inkscape, mm).")
    ] = "tum-centerline",
    path: PathOpt = None,
    unit: UnitOpt = None,
    open_: OpenOpt = False,
    spacing: Annotated[
        float, typer.Option("--spacing", help="Distance between CSV rows [m].")
    ] = 0.05,
) -> None:
    """Write the track as a centreline CSV or as an Inkscape SVG."""
    with user_errors():
        from app.cli._errors import InputError
        from tracks import centerline_csv

        if fmt not in ("tum-centerline", "svg"):
            raise InputError(f"--format must be tum-centerline or svg, got {fmt!r}")
        track = _load(file, path, unit, open_)
        text = track.to_svg() if fmt == "svg" else centerline_csv(track, spacing)
        _write(text, output)


@track_cli.command("raceline")
def raceline(
    file: FileArg,
    output: OutputOpt = None,
    path: PathOpt = None,
    unit: UnitOpt = None,
    open_: OpenOpt = False,
    spacing: Annotated[float, typer.Option("--spacing", help="Distance between rows [m].")] = 0.05,
    v_max: VMaxOpt = None,
    a_lat_max: ALatOpt = 4.0,
    a_long_max: ALongOpt = 2.0,
) -> None:
    """The centreline in the TUM raceline layout (s_m; x_m; y_m; psi_rad; kappa_radpm; vx_mps;
    ax_mps2) with the fastest speed profile within the limits."""
    with user_errors():
        from app.raceline import raceline_limits
        from tracks import raceline_csv, raceline_rows

        limits = raceline_limits(v_max, a_lat_max, a_long_max)
        track = _load(file, path, unit, open_)
        _write(raceline_csv(raceline_rows(track.sample(spacing), limits)), output)
