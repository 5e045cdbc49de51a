"""`trackstar track …` — placeholder until the tracks layer lands."""

import typer

track_cli = typer.Typer(help="Inspect, sample and plot Inkscape tracks.", no_args_is_help=True)
