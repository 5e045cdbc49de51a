"""The steering functions a planner can use, registered under one name each.

Every edge of the system takes its list from `STEERINGS`: the options model (`PlanOptions`),
`trackstar plan --steering`, the REST schema, the studio's dropdown and the planner's kernel
(through `reverses`). The compiled implementations live in `_dubins.py` and `_reeds_shepp.py`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

__all__ = ["STEERINGS", "Steering", "SteeringName"]


@dataclass(frozen=True)
class Steering:
    """One registered steering function: its name, a label for people, whether it reverses."""

    name: str
    label: str
    reverses: bool
    summary: str


STEERINGS = {s.name: s for s in (
    Steering("dubins", "Dubins", False, "forward only (Dubins 1957)"),
    Steering("reeds-shepp", "Reeds-Shepp", True, "forward and reverse (Reeds & Shepp 1990)"),
)}

SteeringName = Literal[tuple(STEERINGS)]  # the names, for pydantic and typer
