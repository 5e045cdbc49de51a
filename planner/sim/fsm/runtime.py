"""Behaviour state machines driving the simulated car (issue 9): the runtime of `spec.Machine`.

Once per control tick the simulation loop calls `Behaviour.step`: each machine, outermost first,
checks the transitions of its current state (after that state's previous tick, in the listed
order, the first that fires wins), a nested machine checking its own before its parent; then
the innermost current state ticks and returns the wanted (v, δ). The loop limits them like any
other command (`limit_commands`), so the car's limits hold whatever a state asks for. A state
that was just entered ticks before its transitions are checked, so ``Always`` gives it exactly
one tick.

Distances driven in a state are Σ|v|·Δt of the commands held while it was current. Sensors read
the true world at the true pose (`rangefinder`); navigation (ApproachPoint) uses the car's pose
estimate, like the planner.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from planner._world import World
from planner.sim.fsm.spec import Machine, State
from planner.sim.rangefinder import (
    LANE_MARGIN,
    lane_ahead,
    scene_at,
    scene_of,
    ultrasonic,
    wall_estimate,
)

__all__ = ["Behaviour"]

WALL_LOST_M = 1.0  # a wall reading this far beyond the wanted clearance is an opening: go straight
AT_REST = 1e-9  # m/s


class Sensors:
    """The car's range sensors at one tick, each cast only when a state or transition asks."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.scene = scene_of(world)
        self.half_width = float(world.discs[:, 1].max()) + LANE_MARGIN
        self._cache: dict = {}

    def update(self, t: float, pose) -> None:
        self.t, self.pose, self._cache = t, pose, {}

    def _targets(self):
        if "targets" not in self._cache:
            self._cache["targets"] = scene_at(self.scene, self.world, self.t)
        return self._cache["targets"]

    def _read(self, key, fn, *args) -> float:
        if key not in self._cache:
            self._cache[key] = fn(*self._targets(), self.pose, *args)
        return self._cache[key]

    def wall(self, side: str) -> tuple[float, float]:
        return self._read(("wall", side), wall_estimate, side)

    def ultrasonic(self, name: str) -> float:
        return self._read(("us", name), ultrasonic, name)

    def lane(self) -> float:
        return self._read("lane", lane_ahead, self.half_width)


@dataclass
class Tick:
    """What a state sees at one control tick."""

    t: float
    dt: float
    est: tuple[float, float, float]  # the car's pose estimate
    v: float  # the speed command held over the last tick
    steer: float
    planned: tuple[float, float] | None  # the planner's (v, δ), None without a plan
    sensors: Sensors
    wheelbase: float


# -- states ----------------------------------------------------------------------------------
class Idle:
    """Stands still: speed 0, steering held. Never finished."""

    def __init__(self, spec: State, path: str, behaviour: Behaviour) -> None:
        self.spec, self.path, self.p = spec, path, spec.params
        self.driven = 0.0  # metres driven while current

    def enter(self, tick: Tick) -> None:
        """Called when the state becomes current."""

    def exit(self, tick: Tick) -> None:
        """Called when a transition leaves the state."""

    def update(self, tick: Tick) -> None:
        """Called before this state's transitions are checked (nested machines step here)."""

    def tick(self, tick: Tick) -> tuple[float, float]:
        return 0.0, tick.steer

    def finished(self, tick: Tick) -> bool:
        return False


class Stop(Idle):
    """Brakes to rest (as hard as the car may); finished once at rest."""

    def finished(self, tick: Tick) -> bool:
        return abs(tick.v) <= AT_REST


class FollowTrack(Idle):
    """Planner-driven: the replanner's command towards the scenario's goal, at most ``speed``.
    The loop runs the replanner only while this state is current (see `Behaviour.planning`)."""

    def tick(self, tick: Tick) -> tuple[float, float]:
        if tick.planned is None:
            return 0.0, tick.steer
        return min(self.p["speed"], tick.planned[0]), tick.planned[1]


class FollowWall(Idle):
    """PD on the wall sensor: δ = ±(kp·e + kd·ė), e = distance − clearance (m), turning towards
    the wall when too far. ė = −speed·(sin ψ + clearance rate), with ψ the car's angle towards
    the wall: the error's rate at the state's speed, so the path converges the same way while
    the car speeds up. Where the wall opens (a junction) it drives straight."""

    def clearance(self) -> float:
        return self.p["distance_m"]

    def clearance_rate(self) -> float:
        """d(clearance)/d(metres driven)."""
        return 0.0

    def tick(self, tick: Tick) -> tuple[float, float]:
        want = self.clearance()
        dist, psi = tick.sensors.wall(self.p["side"])
        if dist > want + WALL_LOST_M:
            return self.p["speed"], 0.0
        e = dist - want
        de = -self.p["speed"] * (math.sin(psi) + self.clearance_rate())
        towards = 1.0 if self.p["side"] == "left" else -1.0
        return self.p["speed"], towards * (self.p["kp"] * e + self.p["kd"] * de)


class FollowWallRamp(FollowWall):
    """Wall following whose clearance moves linearly from ``from_m`` to ``to_m`` over the first
    ``over_m`` metres driven in the state (a lane change); finished when the ramp is done."""

    def clearance(self) -> float:
        f = min(self.driven / self.p["over_m"], 1.0)
        return self.p["from_m"] + f * (self.p["to_m"] - self.p["from_m"])

    def clearance_rate(self) -> float:
        if self.driven >= self.p["over_m"]:
            return 0.0
        return (self.p["to_m"] - self.p["from_m"]) / self.p["over_m"]

    def finished(self, tick: Tick) -> bool:
        return self.driven >= self.p["over_m"]


class ApproachPoint(Idle):
    """Pure pursuit onto ``point`` at ``speed``; finished within ``tolerance_m`` of it."""

    def _offset(self, tick: Tick) -> tuple[float, float]:
        x, y, _ = tick.est
        return self.p["point"][0] - x, self.p["point"][1] - y

    def tick(self, tick: Tick) -> tuple[float, float]:
        dx, dy = self._offset(tick)
        alpha = math.atan2(dy, dx) - tick.est[2]
        dist = max(math.hypot(dx, dy), 1e-6)
        return self.p["speed"], math.atan(2.0 * tick.wheelbase * math.sin(alpha) / dist)

    def finished(self, tick: Tick) -> bool:
        return math.hypot(*self._offset(tick)) <= self.p["tolerance_m"]


class StateMachine(Idle):
    """A nested machine: its states run while it is current; finished once its current state is
    a ``Stop``."""

    def __init__(self, spec: State, path: str, behaviour: Behaviour) -> None:
        super().__init__(spec, path, behaviour)
        self.run = _Run(spec.machine, f"{path}/", behaviour)

    def enter(self, tick: Tick) -> None:
        self.run.enter(tick)

    def exit(self, tick: Tick) -> None:
        self.run.state.exit(tick)

    def update(self, tick: Tick) -> None:
        self.run.check(tick)

    def tick(self, tick: Tick) -> tuple[float, float]:
        return self.run.tick(tick)

    def finished(self, tick: Tick) -> bool:
        return isinstance(self.run.state, Stop)


STATES = {cls.__name__: cls for cls in (Idle, Stop, FollowTrack, FollowWall, FollowWallRamp,
                                        ApproachPoint, StateMachine)}


# -- transitions: (params, the current state, the tick) -> fires ---------------------------------
def _sensor_level(p: dict, state: Idle, tick: Tick) -> bool:
    r = tick.sensors.ultrasonic(p["sensor"])
    return r < p["below_m"] if "below_m" in p else r > p["above_m"]


TRANSITIONS = {
    "Always": lambda p, state, tick: True,
    "Distance": lambda p, state, tick: state.driven >= p["meters"],
    "Finished": lambda p, state, tick: state.finished(tick),
    "SensorLevel": _sensor_level,
    "ObstacleAhead": lambda p, state, tick: tick.sensors.lane() <= p["within_m"],
}


# -- machines --------------------------------------------------------------------------------
class _Run:
    """One (possibly nested) machine while it runs: its current state and whether it ticked."""

    def __init__(self, machine: Machine, prefix: str, behaviour: Behaviour) -> None:
        self.machine, self.prefix, self.behaviour = machine, prefix, behaviour

    def enter(self, tick: Tick) -> None:
        self._enter(self.machine.initial, tick)

    def _enter(self, sid: str, tick: Tick) -> None:
        spec = self.machine.states[sid]
        self.state = STATES[spec.type](spec, self.prefix + sid, self.behaviour)
        self.ticked = False
        self.state.enter(tick)

    def check(self, tick: Tick) -> None:
        """After the current state's last tick: its transitions, in order; the first wins."""
        if not self.ticked:
            return
        self.state.driven += abs(tick.v) * tick.dt
        self.state.update(tick)
        for tr in self.state.spec.transitions:
            if TRANSITIONS[tr.type](tr.params, self.state, tick):
                self.state.exit(tick)
                before = self.state.path
                self._enter(tr.to, tick)
                self.behaviour.transitions.append(  # t without k·Δt's float noise
                    {"t": round(tick.t, 9), "from": before, "to": self.state.path})
                return

    def tick(self, tick: Tick) -> tuple[float, float]:
        self.ticked = True
        return self.state.tick(tick)

    def leaf(self) -> Idle:
        state = self.state
        return state.run.leaf() if isinstance(state, StateMachine) else state


def _leaf_paths(machine: Machine, prefix: str = "") -> list[str]:
    out = []
    for sid, st in machine.states.items():
        out += (_leaf_paths(st.machine, f"{prefix}{sid}/") if st.machine is not None
                else [prefix + sid])
    return out


class Behaviour:
    """A machine driving the car; the simulation loop calls `step` once per control tick.

    ``planning`` says whether the current state is FollowTrack (the loop runs the replanner only
    then); ``planner_switched`` whether that changed in the last step (the loop then restarts the
    replanner from the car's pose). ``trace`` holds, per step, the index of the innermost current
    state in ``states`` (nested states as ``outer/inner``).
    """

    def __init__(self, machine: Machine, world: World, wheelbase: float, dt: float) -> None:
        self.wheelbase, self.dt = wheelbase, dt
        self.sensors = Sensors(world)
        self.states = _leaf_paths(machine)
        self.transitions: list[dict] = []
        self.trace: list[int] = []
        self.root = _Run(machine, "", self)
        self.started = False  # the initial states are entered at the first step, at t = 0
        first = machine.states[machine.initial]
        while first.machine is not None:
            first = first.machine.states[first.machine.initial]
        self.planning = first.type == "FollowTrack"
        self.planner_switched = False

    def step(self, t: float, pose, est, v: float, steer: float,
             planned: tuple[float, float] | None) -> tuple[float, float]:
        """The wanted (v, δ) for the tick starting at t; ``pose`` is the true pose (sensors),
        ``v``/``steer`` the commands held over the last tick."""
        self.sensors.update(t, pose)
        tick = Tick(t, self.dt, est, v, steer, planned, self.sensors, self.wheelbase)
        if not self.started:
            self.root.enter(tick)
            self.started = True
        self.root.check(tick)
        command = self.root.tick(tick)
        leaf = self.root.leaf()
        self.trace.append(self.states.index(leaf.path))
        planning = isinstance(leaf, FollowTrack)
        self.planner_switched, self.planning = planning != self.planning, planning
        return command

    def done(self, v: float) -> bool:
        """The top-level machine is in a Stop state and the car is at rest."""
        return isinstance(self.root.state, Stop) and abs(v) <= AT_REST

    def report(self) -> dict:
        return {"final_state": self.root.leaf().path, "states": self.states,
                "transitions": self.transitions}
