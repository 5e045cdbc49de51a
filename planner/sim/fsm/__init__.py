"""Behaviour state machines (issue 9): the JSON format and its checks (`spec`); the runtime that
drives the simulated car is `runtime.Behaviour`, used by `planner.sim.simulate(behaviour=...)`."""

from planner.sim.fsm.spec import FsmError, Machine, State, Transition, load_fsm, parse_fsm

__all__ = ["FsmError", "Machine", "State", "Transition", "load_fsm", "parse_fsm"]
