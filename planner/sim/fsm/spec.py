"""Behaviour state machines from JSON: parsing and checking (`trackstar fsm check`).

The file is ``{"initial": ID, "states": [{"id", "type", "params", "transitions": [{"type",
"params", "to"}]}]}``; a ``StateMachine`` state nests its own ``initial`` and ``states``. Every
problem is reported as one line naming the element, e.g. ``states[2].transitions[0]: unknown
type 'SensorLvl' (did you mean 'SensorLevel'?)``, so a person can fix the file without a stack
trace.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from planner.validation import suggest

__all__ = ["FsmError", "Machine", "State", "Transition", "load_fsm", "parse_fsm"]

# type -> (required parameters, optional parameters with defaults)
STATE_TYPES: dict[str, tuple[tuple[str, ...], dict]] = {
    "FollowTrack": (("speed",), {}),
    "FollowWall": (("side", "distance_m", "speed"), {"kp": 1.5, "kd": 1.0}),
    "FollowWallRamp": (("side", "from_m", "to_m", "over_m", "speed"), {"kp": 1.5, "kd": 1.0}),
    "ApproachPoint": (("point", "speed", "tolerance_m"), {}),
    "Stop": ((), {}),
    "Idle": ((), {}),
    "StateMachine": ((), {}),
}
TRANSITION_TYPES: dict[str, tuple[tuple[str, ...], dict]] = {
    "Always": ((), {}),
    "Distance": (("meters",), {}),
    "Finished": ((), {}),
    "SensorLevel": (("sensor",), {"below_m": None, "above_m": None}),
    "ObstacleAhead": (("within_m",), {}),
}
SIDES = ("left", "right")
SENSORS = ("left", "front", "right")


class FsmError(ValueError):
    """A state machine file that cannot be run; the message names the element."""


@dataclass(frozen=True)
class Transition:
    type: str
    params: dict
    to: str


@dataclass(frozen=True)
class State:
    id: str
    type: str
    params: dict
    transitions: tuple[Transition, ...]
    machine: Machine | None = None  # the nested machine of a StateMachine state


@dataclass(frozen=True)
class Machine:
    initial: str
    states: dict[str, State] = field(default_factory=dict)


def _params(where: str, kind: str, given, spec) -> dict:
    required, optional = spec
    if given is None:
        given = {}
    if not isinstance(given, dict):
        raise FsmError(f"{where}.params: expected an object")
    for name in given:
        if name not in required and name not in optional:
            raise FsmError(f"{where}.params: unknown parameter '{name}' for {kind}"
                           f"{suggest(name, (*required, *optional))}")
    for name in required:
        if name not in given:
            raise FsmError(f"{where}.params: missing parameter '{name}' for {kind}")
    out = {**{k: v for k, v in optional.items() if v is not None}, **given}
    for name, value in out.items():
        p = f"{where}.params.{name}"
        if name == "side":
            if value not in SIDES:
                raise FsmError(f"{p}: expected one of {', '.join(SIDES)}, got {value!r}")
        elif name == "sensor":
            if value not in SENSORS:
                raise FsmError(f"{p}: expected one of {', '.join(SENSORS)}, got {value!r}")
        elif name == "point":
            if not (isinstance(value, list) and len(value) == 2
                    and all(_finite(v) for v in value)):
                raise FsmError(f"{p}: expected [x, y] in metres, got {value!r}")
        elif not _finite(value) or (value <= 0 and name not in ("from_m", "to_m")) or value < 0:
            raise FsmError(f"{p}: expected a finite number > 0, got {value!r}")
    if kind == "SensorLevel" and ("below_m" in out) == ("above_m" in out):
        raise FsmError(f"{where}.params: give exactly one of 'below_m' and 'above_m'")
    return out


def _finite(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _machine(data, where: str) -> Machine:
    prefix = f"{where}." if where else ""
    if not isinstance(data, dict):
        raise FsmError(f"{where or 'file'}: expected an object with 'initial' and 'states'")
    for key in ("initial", "states"):
        if key not in data:
            raise FsmError(f"{prefix}{key}: missing")
    if not isinstance(data["states"], list) or not data["states"]:
        raise FsmError(f"{prefix}states: expected a non-empty list")
    ids = []
    for i, st in enumerate(data["states"]):
        if not isinstance(st, dict) or not isinstance(st.get("id"), str):
            raise FsmError(f"{prefix}states[{i}].id: missing or not a string")
        if st["id"] in ids:
            raise FsmError(f"{prefix}states[{i}].id: duplicate id '{st['id']}'")
        ids.append(st["id"])
    if data["initial"] not in ids:
        raise FsmError(f"{prefix}initial: unknown state '{data['initial']}'{suggest(data['initial'], ids)}")
    states = {}
    for i, st in enumerate(data["states"]):
        here = f"{prefix}states[{i}]"
        kind = st.get("type")
        if kind not in STATE_TYPES:
            raise FsmError(f"{here}: unknown type '{kind}'{suggest(kind, STATE_TYPES)}")
        nested = None
        if kind == "StateMachine":
            nested = _machine({k: st.get(k) for k in ("initial", "states") if k in st}, here)
            params = {}
        else:
            params = _params(here, kind, st.get("params"), STATE_TYPES[kind])
        transitions = []
        for j, tr in enumerate(st.get("transitions") or []):
            tw = f"{here}.transitions[{j}]"
            if not isinstance(tr, dict):
                raise FsmError(f"{tw}: expected an object")
            tkind = tr.get("type")
            if tkind not in TRANSITION_TYPES:
                raise FsmError(f"{tw}: unknown type '{tkind}'{suggest(tkind, TRANSITION_TYPES)}")
            if tr.get("to") not in ids:
                raise FsmError(f"{tw}.to: unknown state '{tr.get('to')}'{suggest(tr.get('to'), ids)}")
            transitions.append(Transition(tkind, _params(tw, tkind, tr.get("params"),
                                                         TRANSITION_TYPES[tkind]), tr["to"]))
        states[st["id"]] = State(st["id"], kind, params, tuple(transitions), nested)
    return Machine(data["initial"], states)


def parse_fsm(data) -> Machine:
    """Check and build a machine from parsed JSON; raises FsmError naming the element."""
    return _machine(data, "")


def load_fsm(path) -> Machine:
    try:
        data = json.loads(Path(path).read_text())
    except json.JSONDecodeError as exc:
        raise FsmError(f"{path}: not JSON ({exc.msg} at line {exc.lineno})") from None
    return parse_fsm(data)
