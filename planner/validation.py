"""Input validation shared by every file format Trackstar reads (scenarios, state machines,
studies): unknown keys fail loudly with the nearest valid one suggested, and a pydantic error
becomes one line that names the field (``obstacles[2].radius: …``)."""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterable
from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, ValidationError, model_validator

__all__ = ["KnownKeys", "StrictModel", "Text", "describe", "location", "message", "suggest"]


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
    valid, key = list(valid), str(key)
    spelt = max(valid, key=lambda c: difflib.SequenceMatcher(None, key, c).ratio(), default="")
    nearness = difflib.SequenceMatcher(None, key, spelt).ratio()
    # A typo first ('goal_tolerence'), then a choice the key is made of ('rrt' in 'rrt_turbo').
    made_of = [w for w in re.split(r"[\s_\-.]+", key) if w in valid]
    close = [spelt] if nearness >= 0.8 else made_of[:1] or ([spelt] if nearness >= 0.5 else [])
    return f" (did you mean '{close[0]}'?)" if close else f" (use one of {', '.join(valid)})"


class KnownKeys(BaseModel):
    """Names an unknown key and suggests the nearest (pydantic says only "Extra inputs are not
    permitted"). Every model a user writes — a file, a request body — is one."""

    @model_validator(mode="before")
    @classmethod
    def _known_keys(cls, data: Any) -> Any:
        if isinstance(data, dict):
            for key in data:
                if key not in cls.model_fields:
                    raise ValueError(f"unknown key '{key}'{suggest(key, sorted(cls.model_fields))}")
        return data


class StrictModel(KnownKeys):
    """A frozen model of finite numbers that names an unknown key and suggests the nearest."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True, defer_build=True)


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


def message(err: dict) -> str:
    """One pydantic error's message in our words: a value that is not one of the choices is
    named, with the nearest choice (``'rrt_turbo' is not a planner (did you mean 'rrt'?)``)."""
    if err["type"] == "finite_number":
        return "must be a finite number (NaN and infinity are not allowed)"
    if err["type"] in ("literal_error", "enum"):
        choices = re.findall(r"'([^']*)'", str(err.get("ctx", {}).get("expected", "")))
        names = [p for p in err["loc"] if isinstance(p, str)]
        noun = names[-1] if names else "choice"
        if err["loc"] and isinstance(err["loc"][-1], int):  # an item of a list: planners[1]
            noun = noun.removesuffix("s")
        article = "an" if noun[:1] in "aeiou" else "a"
        return f"{err['input']!r} is not {article} {noun}{suggest(err['input'], choices)}"
    return err["msg"].removeprefix("Value error, ")


def describe(exc: ValidationError, skip: Iterable[str] = ()) -> str:
    """The first error as ``where: what``."""
    err = exc.errors()[0]
    where = location(err["loc"], skip)
    msg = message(err)
    return f"{where}: {msg}" if where else msg
