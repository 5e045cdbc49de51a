"""Input validation shared by every file format Trackstar reads (scenarios, state machines,
studies): unknown keys fail loudly with the nearest valid one suggested, and a pydantic error
becomes one line that names the field (``obstacles[2].radius: …``)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, ValidationError, model_validator

__all__ = ["StrictModel", "Text", "describe", "location", "suggest"]


def _encodable(text: str) -> str:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise ValueError("must be Unicode text: a lone surrogate (such as \\ud800) is not "
                         "a character") from None
    return text


Text = Annotated[str, AfterValidator(_encodable)]  # a JSON string that UTF-8 can store


def suggest(key: Any, valid: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the nearest of ``valid``, else the list of them."""
    valid = list(valid)
    close = difflib.get_close_matches(str(key), valid, n=1, cutoff=0.5)
    return f" (did you mean '{close[0]}'?)" if close else f" (use one of {', '.join(valid)})"


class StrictModel(BaseModel):
    """A frozen model of finite numbers that names an unknown key and suggests the nearest."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True, defer_build=True)

    @model_validator(mode="before")
    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if isinstance(data, dict):
            for key in data:
                if key not in cls.model_fields:
                    raise ValueError(f"unknown key '{key}'{suggest(key, sorted(cls.model_fields))}")
        return data


def location(loc: tuple, skip: Iterable[str] = ()) -> str:
    """('obstacles', 2, 'circle', 'radius') → 'obstacles[2].radius', leaving out ``skip``
    (union tags) and pydantic's validator labels."""
    skip = set(skip)
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in skip or part.startswith("function-"):
            continue
        else:
            out += f".{part}" if out else str(part)
    return out


def describe(exc: ValidationError, skip: Iterable[str] = ()) -> str:
    """The first error as ``where: what``."""
    err = exc.errors()[0]
    where = location(err["loc"], skip)
    msg = err["msg"].removeprefix("Value error, ")
    if err["type"] == "finite_number":
        msg = "must be a finite number (NaN and infinity are not allowed)"
    return f"{where}: {msg}" if where else msg
