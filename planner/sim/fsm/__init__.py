"""Behaviour state machines (issue 9): the JSON format and its checks; the runtime is to come."""

from planner.sim.fsm.spec import FsmError, Machine, State, Transition, load_fsm, parse_fsm

__all__ = ["FsmError", "Machine", "State", "Transition", "load_fsm", "parse_fsm"]
