"""One way for every command to fail on bad input: one line on stderr, exit status 2."""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Iterator

import typer
from pydantic import ValidationError


class InputError(ValueError):
    """Bad input detected at the CLI edge (missing file, bad option combination)."""


@contextlib.contextmanager
def user_errors() -> Iterator[None]:
    """Turn domain errors (ValueError and OSError on input files) into exit 2 with one line."""
    try:
        yield
    except ValidationError as exc:  # an option outside its range, caught by PlanOptions
        err = exc.errors()[0]
        where = ".".join(str(part) for part in err["loc"])
        print(f"error: --{where.replace('_', '-')}: {err['msg']}", file=sys.stderr)
        raise typer.Exit(code=2) from None
    except (ValueError, OSError) as exc:
        message = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        print(f"error: {message}", file=sys.stderr)
        raise typer.Exit(code=2) from None
