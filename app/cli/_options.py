"""Command-line options generated from a pydantic model: one description, every edge.

`model_options(Model)` adds one ``--option`` per field of ``Model`` to a typer command (name,
default and help from the field) and hands the command a validated ``options: Model``, so
`trackstar plan` and POST /api/v1/plan cannot drift apart. A value outside a field's range
exits 2 with one line naming the option (`user_errors`).
"""

from __future__ import annotations

import functools
import inspect
import types
import typing
from typing import Annotated

import typer
from pydantic import BaseModel

from app.cli._errors import user_errors


def model_options(model: type[BaseModel]):
    """Decorate ``command(…, options: model, …)``: the model's fields take the place of
    ``options`` among the command's parameters; the others stay as they are."""

    def decorate(command):
        signature = inspect.signature(command, eval_str=True)
        fields = [inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=field.default,
                                    annotation=Annotated[_cli_type(field.annotation),
                                                         typer.Option(help=field.description)])
                  for name, field in model.model_fields.items()]

        @functools.wraps(command)
        def wrapper(**kwargs):
            values = {name: kwargs.pop(name) for name in model.model_fields}
            with user_errors():
                options = model(**values)
            return command(options=options, **kwargs)

        parameters = [q.replace(kind=inspect.Parameter.KEYWORD_ONLY)  # typer passes keywords
                      for p in signature.parameters.values()  # the fields stand in for options
                      for q in (fields if p.name == "options" else [p])]
        wrapper.__signature__ = signature.replace(parameters=parameters)
        # typer reads the type hints too: the evaluated ones, not the command's strings.
        wrapper.__annotations__ = {p.name: p.annotation for p in parameters}
        return wrapper

    return decorate


def _cli_type(annotation):
    """The type typer parses: constraints dropped (the model checks them), Literal and
    Optional kept."""
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        return _cli_type(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        kept = [_cli_type(a) for a in typing.get_args(annotation) if a is not type(None)]
        return kept[0] | None if len(kept) == 1 else annotation
    return annotation
