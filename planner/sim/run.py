"""The simulation loop: world, sensors, replanner and car on one simulated clock.

Control ticks at ``control_rate`` drive the clock. A replanning cycle that starts at tick time t
hands its plan over at t + max(1/rate, its measured wall time) — or the fixed latency — and the
next cycle starts then; until then the car follows the committed trajectory. The simulation is
not paced to the wall clock unless ``realtime``. An optional observer receives a `Frame` per
control tick (for a live view); without one, nothing is built.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from planner._goal import in_goal, in_goal_rows
from planner._world import clearance, inflated, path_clearances
from planner.options import TIMINGS, PlanOptions
from planner.problem import Problem, compile_problem, resolve_track
from planner.rrt import warm_up
from planner.scenario import Scenario
from planner.sim.control import CONTROLLERS, Reference, Tracker, steer_command
from planner.sim.control import warm_up as warm_up_tracking
from planner.sim.fsm import Machine
from planner.sim.fsm.runtime import Behaviour
from planner.sim.guard import BACK_OFF, FOLLOW, STAND, UNSTICK_S, Decision, guard
from planner.sim.laps import LapCounter, require_track
from planner.sim.metrics import AT_REST, MOVING, collision_runs, contacts, cycle_stats
from planner.sim.predict import (
    Agility,
    Lanes,
    Uncertainty,
    likely_worlds,
    predicted_world,
    reach_rates,
    reach_world,
)
from planner.sim.replan import Replanner
from planner.sim.replan import warm_up as warm_up_replanning
from planner.sim.sensing import Sensing, known_motions, mover_index, sense, true_offsets
from planner.sim.vehicle import Limits, arc_step, limit_commands
from planner.steering import CAR_STEERINGS, DEFAULT_STEERING
from planner.timing import warm_up as warm_up_timing
from planner.tree import TreeSnapshot

__all__ = ["Frame", "SimRun", "SimSettings", "simulate"]


@dataclass(frozen=True)
class SimSettings:
    """Every setting of a run (reported back as ``parameters``)."""

    duration: float = 60.0
    rate: float = 30.0  # replanning cycles per second
    control_rate: float = 100.0
    sense_rate: float = 10.0
    controller: str = "pure-pursuit"
    noise: float = 0.0  # σ (m) of sensed positions; the heading gets √2·σ / wheelbase (rad)
    seed: int = 0
    fixed_latency_ms: float | None = None  # a fixed cycle time instead of the measured one
    replan: bool = True  # False: one plan at t = 0, followed blind
    budget_share: float = 0.3  # planner time per cycle, as a share of 1/rate
    iterations: int = 80  # planner iterations per cycle under a fixed latency
    margin: float = 0.05  # m added to the car's radius when planning
    realtime: bool = False
    timing: str = "constant"  # optimal: the car may stop for a mover instead of going round
    laps: int | None = None  # lap mode: drive this many laps of the scenario's closed track
    goal_ahead: float = 3.0  # m of centreline arc between the car and its rolling goal (laps)
    # The movers' prediction (`Uncertainty`); None: the scenario's `prediction`, else the default.
    predict_accel: float | None = None  # m/s²: how fast a mover may change its velocity
    predict_speed_error: float | None = None  # m/s: error of a sensed velocity
    predict_horizon: float | None = None  # s over which the predictions widen
    reverse: bool = True  # the car may back up to evade
    steering: str = DEFAULT_STEERING  # the replanner's (`planner.STEERINGS`); not a robot's

    def uncertainty(self, scenario: Scenario | None = None) -> Uncertainty:
        """The prediction's parameters: these settings', else the scenario's, else defaults."""
        p = scenario.prediction if scenario is not None else None
        pick = {name: value for name, value in (
            ("accel", self.predict_accel), ("speed_error", self.predict_speed_error),
            ("horizon", self.predict_horizon)) if value is not None}
        dumped = p.model_dump(exclude={"along_track"}) if p is not None else {}
        given = {k: v for k, v in dumped.items() if v is not None}
        return Uncertainty(**{**given, **pick})

    def __post_init__(self) -> None:
        for name in ("duration", "rate", "control_rate", "sense_rate"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"--{name.replace('_', '-')} must be a finite number > 0, "
                                 f"got {v}")
        if self.timing not in TIMINGS:
            raise ValueError(f"--timing must be one of {', '.join(TIMINGS)}, got {self.timing!r}")
        if self.steering not in CAR_STEERINGS:
            raise ValueError(f"--steering must be one of {', '.join(CAR_STEERINGS)} (the "
                             f"simulated car cannot turn on the spot), got {self.steering!r}")
        if self.controller not in CONTROLLERS:
            raise ValueError(f"unknown controller '{self.controller}' "
                             f"(use one of {', '.join(CONTROLLERS)})")
        if not (math.isfinite(self.noise) and self.noise >= 0):
            raise ValueError(f"--noise must be a finite number >= 0, got {self.noise}")
        if self.laps is not None and self.laps < 1:
            raise ValueError(f"--laps must be at least 1, got {self.laps}")
        if self.fixed_latency_ms is not None and not (
                math.isfinite(self.fixed_latency_ms) and self.fixed_latency_ms >= 0):
            raise ValueError(f"--fixed-latency must be a finite number >= 0, "
                             f"got {self.fixed_latency_ms}")
        self.uncertainty()  # checks the prediction's parameters


@dataclass
class SimRun:
    """The outcome: the JSON summary and the per-tick log (columns in ``columns``)."""

    summary: dict
    columns: list[str]
    log: np.ndarray
    cycles: list[dict] = field(default_factory=list)

    def write_log(self, path) -> None:
        np.savetxt(path, self.log, delimiter=",", header=",".join(self.columns), comments="",
                   fmt="%.12g")


@dataclass(frozen=True)
class Frame:
    """One control tick as a viewer sees it: the truth, what the car believes, what it does.

    ``reference`` is the live object, not a copy: a cycle builds a new one and never changes it
    afterwards, so it may be read until the next frame arrives. ``tree`` is a copy of the
    replanner's tree, taken once per cycle, and may be kept.
    """

    t: float
    pose: tuple[float, float, float]  # true rear-axle pose (m, m, rad)
    v: float  # speed command held over [t, t + Δt)
    steer: float  # steering angle commanded (after the limits), rad
    steer_set: float  # steering angle the controller wanted (Soll), rad
    lateral_error: float  # m from the committed trajectory, left positive (NaN: none yet)
    offsets: np.ndarray  # (n_obstacles, 2) true offsets at t, scenario order
    sensing: Sensing | None  # latest sensed offsets and velocities, motion order
    reference: Reference | None  # the committed trajectory the car tracks
    tree: TreeSnapshot | None  # the replanner's current tree
    cycles: int
    replans: int
    cycle_ms: float  # wall time of the latest cycle (NaN before the first)
    guard: str = "follow"  # what the guard has the car do: a key of `GUARD_CODES`
    # Per motion: how fast its reachable set round ``sensing`` widens (m/s; NaN: none), the
    # set held at this times `REACH_S` (`planner.sim.predict.reach_rates`).
    reach: np.ndarray | None = None


def _goal_arc(problem: Problem, ref: Reference) -> float:
    """The arc where ``ref`` is well inside the goal (half its tolerances: the car tracks it
    to a few cm), so the run ends there; inf if it does not get there."""
    k = np.flatnonzero(in_goal_rows(ref.rows, problem.goal_region(0.5)))
    return float(ref.s[k[0]]) if len(k) else math.inf


# The guard keeps this share of the planning margin for tracking errors: the plans, made with
# all of it, pass its check with room to spare.
GUARD_MARGIN = 0.5
OFF_PLAN = 0.3  # m from the plan beyond which the car no longer counts as on it
# The car is stuck when it has stayed this long within this distance of a spot, not by plan (a
# car that edges to and fro is as stuck as one at rest); it then gets going (`Decision.unstick`).
STUCK_S, STUCK_M = 2.0, 0.1
# Per-tick guard codes in the log's ``guard`` column.
GUARD_CODES = {"follow": 0, "wait": 1, "slow": 2, "brake": 3, "evade": 4, "back-off": 5}


def _state(decision: Decision | None, waiting: bool) -> str:
    """What the guard has the car do, as the log's ``guard`` column names it."""
    if waiting:
        return "wait"
    if decision is None or not decision.danger and decision.manoeuvre.name in (FOLLOW, STAND):
        return "follow"
    if not decision.danger:
        return decision.manoeuvre.name
    # In danger: standing or braking on the plan (passive safety) is a brake, the rest evades.
    return "brake" if decision.on_plan or decision.manoeuvre.name == STAND else "evade"


def _decide(problem: Problem, sensing: Sensing, t: float, uncertainty: Uncertainty,
            lanes: Lanes | None, s: SimSettings,
            limits: Limits, state, ref: Reference | None, stop_s: float, cruise: float,
            commit: float, stuck: bool, back_off: bool, done_s: float, agility: Agility,
            known: np.ndarray, tracker: Tracker) -> Decision:
    """The guard's decision at a cycle's start, in the world the car believes in now (grown
    predictions, the planning margin; the bare car where it already is inside the margin),
    the car at rest before a mover that turns at once could reach it (`reach_world`).
    ``known``: per motion, whether its timetable is known (`known_motions`)."""
    believed = predicted_world(problem.world, sensing, t, uncertainty, known, lanes)
    reach = reach_world(problem.world, sensing, t, agility, uncertainty, known, lanes)
    likely = likely_worlds(believed, problem.world, sensing, t, agility, known, lanes)
    margin = GUARD_MARGIN * s.margin
    margin = margin if clearance(believed, state[0], state[1], 0.0) > margin else 0.0
    i = ref.project(state[0], state[1])[0] if ref is not None else 0
    if ref is not None and math.dist(state[:2], ref.rows[i, :2]) > OFF_PLAN:
        ref = None  # the car is not where the plan is: checks along it would be fiction
    return guard(inflated(believed, margin), margin, state, limits, ref, i, stop_s, cruise,
                 commit, problem.rho, s.reverse, stuck, done_s,
                 inflated(reach, margin) if reach is not None else None, tracker, back_off,
                 [inflated(w, margin) for w in likely])


def _lap_counter(scenario: Scenario, problem: Problem, s: SimSettings, load_track):
    """Lap mode's counter and rolling goal (None in goal mode). Replanning off cannot mean one
    plan for N laps: the cycles go on extending the path, but on the t = 0 sensing alone."""
    if s.laps is None:
        return None
    require_track(scenario)
    return LapCounter(resolve_track(scenario, load_track), problem.start, s.goal_ahead)


def simulate(scenario: Scenario, settings: SimSettings | None = None,
             problem: Problem | None = None, load_track=None,
             observer: Callable[[Frame], None] | None = None,
             behaviour: Machine | None = None) -> SimRun:
    """Drive the scenario's car to its goal; raises ScenarioError / ValueError on bad input.

    ``observer`` gets a `Frame` per control tick, on this thread; an exception it raises ends
    the run (and propagates). ``behaviour``: a state machine drives instead of the planner's
    goal; the replanner runs only while its current state is FollowTrack.
    """
    s = settings or SimSettings()
    problem = problem or compile_problem(scenario)
    counter = _lap_counter(scenario, problem, s, load_track)  # before the slow warm-up
    warm_up()
    warm_up_replanning()
    warm_up_tracking()
    if s.timing == "optimal":
        warm_up_timing()
    vehicle = scenario.vehicle
    limits = Limits.of(vehicle)
    dt = 1.0 / s.control_rate
    n_ticks = round(s.duration * s.control_rate)
    movers = mover_index(scenario)
    rng = np.random.default_rng(s.seed)
    fixed = s.fixed_latency_ms / 1000.0 if s.fixed_latency_ms is not None else None
    uncertainty = s.uncertainty(scenario)
    lanes = Lanes.of(scenario, load_track)
    goal = problem.goal_region()
    fsm = Behaviour(behaviour, problem.world, limits.wheelbase, dt) if behaviour else None
    # FollowTrack caps its own speed; timing optimal drives as fast as the car may.
    cruise = vehicle.speed if fsm is None and s.timing == "constant" else limits.max_speed

    def new_replanner() -> Replanner:
        # No polishing: a cycle's budget is a few milliseconds, and the next cycle replans.
        return Replanner(problem, PlanOptions(seed=s.seed, polish=False, timing=s.timing,
                                              steering=s.steering,
                                              speed=cruise if fsm is None else None),
                         seed=s.seed,
                         budget_s=s.budget_share / s.rate,
                         iterations=s.iterations if fixed is not None else None,
                         margin=s.margin, uncertainty=uncertainty, lanes=lanes)

    replanner = new_replanner()
    tracker = Tracker(s.controller, dt=dt)
    # Heading noise as if θ came from two position fixes a wheelbase apart.
    pose_sigma = (s.noise, s.noise, math.sqrt(2.0) * s.noise / limits.wheelbase)
    x, y, th = problem.start
    est = (x, y, th)
    v = steer = 0.0
    e_old = math.nan
    sensing, j_sense = None, 0
    agility = Agility.none(int((movers >= 0).sum()))  # what each mover was seen to do
    known = known_motions(scenario)
    ref, stop_s, conflict, done_s = None, 0.0, False, math.inf
    pending, next_cycle = None, 0.0 if fsm is None or fsm.planning else math.inf
    walls, cycles, replans, stops, waits, was_stopped = [], [], 0, 0, 0, False
    planned = False  # the current stop is a planned wait (timing optimal), not an emergency
    # The guard's decision (FOLLOW until the first): what the car does until the next cycle.
    guarded = fsm is None and s.replan
    decision, decided_at, codes, evasions, brakes = None, 0.0, [], 0, 0
    planless_since = unstuck_at = 0.0  # since when the car has stayed near stood_at, not by plan
    stood_at = problem.start[:2]
    backed_off = False
    rows, lat = [], []
    tree_of, tree = None, None  # the planner last shown to the observer, and its copy
    wall0 = time.perf_counter()
    reached = False
    for k in range(n_ticks + 1):
        t = k * dt
        while j_sense / s.sense_rate <= t + 1e-9:  # sensing instants up to now
            ts = j_sense / s.sense_rate
            if s.replan or sensing is None:  # replanning off: the car knows only t = 0
                sensing = sense(problem.world, movers, ts, s.sense_rate, s.noise, rng)
                agility.see(sensing, uncertainty)
            noise = rng.normal(0.0, pose_sigma) if s.noise > 0 else (0.0, 0.0, 0.0)
            est = (x + noise[0], y + noise[1], th + noise[2])
            j_sense += 1
        if pending is not None and pending[0] <= t + 1e-9:
            cyc = pending[1]
            if cyc.reference is not None:
                ref = cyc.reference
                done_s = _goal_arc(problem, ref) if counter is None and fsm is None else math.inf
            stop_s, conflict = cyc.stop_s, cyc.conflict and s.replan
            planned = cyc.planned_wait
            replans += cyc.replaced
            pending = None
        if pending is None and t >= next_cycle - 1e-9 and (
                s.replan or ref is None or counter is not None):
            if counter is not None:
                replanner.aim(counter.goals())
            lead = max(1.0 / s.rate, fixed if fixed is not None else
                       (walls[-1] if walls else 0.0))
            checked = time.perf_counter()
            if guarded:
                before = decision
                unsticking = (before is not None and before.unstick
                              and t - unstuck_at < UNSTICK_S)  # runs its course
                if planned or (math.dist(est[:2], stood_at) > STUCK_M and not unsticking):
                    stood_at, planless_since = est[:2], t  # not stuck: waiting by plan, or driving
                    backed_off = backed_off and v <= 0.0
                decision = _decide(problem, sensing, t, uncertainty, lanes, s, limits,
                                   (*est, v, steer),
                                   ref, stop_s, cruise, lead,
                                   unsticking or t - planless_since >= STUCK_S,
                                   not backed_off or (unsticking
                                                      and before.manoeuvre.name == BACK_OFF),
                                   done_s,
                                   agility, known, tracker)
                decided_at = t
                if decision.unstick and not unsticking:
                    unstuck_at = t
                # Backs off once, until the car drives on again.
                backed_off = backed_off or decision.manoeuvre.name == BACK_OFF
                brakes += decision.manoeuvre.name == "brake" and (
                    before is None or before.manoeuvre.name != "brake")
                evasions += not decision.on_plan and decision.danger and (
                    before is None or before.on_plan or not before.danger)
                if not decision.on_plan and ref is not None:  # off the plan: plan afresh
                    replanner, ref, conflict = new_replanner(), None, False
            checked = time.perf_counter() - checked
            s_now = ref.s[ref.project(est[0], est[1])[0]] if ref is not None else 0.0
            cyc = replanner.cycle(t, sensing, est, v, s_now, lead, checked)
            latency = fixed if fixed is not None else cyc.wall_s + checked
            walls.append(latency)
            cycles.append({"t": t, "ms": (cyc.wall_s + checked) * 1000.0,
                           "replaced": cyc.replaced,
                           "nodes": cyc.nodes})
            pending = (t + max(1.0 / s.rate, latency), cyc)
            next_cycle = pending[0]
        # Control: track the committed trajectory at cruise speed, governed to stop in time.
        want_v, want_steer, e = 0.0, steer, math.nan
        if ref is not None:
            i, e = ref.project(est[0], est[1])
            if ref.advance(v):  # at rest at a cusp: on along the next stretch
                i, e = ref.project(est[0], est[1])
            room = stop_s - ref.s[i] if (s.replan or not conflict) else math.inf
            if not s.replan:
                room = ref.length - ref.s[i]
            room = min(room, ref.stretch_end - ref.s[i])
            cap = cruise if decision is None else min(cruise, decision.manoeuvre.speed)
            want_v = ref.direction * min(cap, math.sqrt(2.0 * limits.max_accel * max(room, 0.0)))
            want_steer = steer_command(s.controller, ref, i, e, e_old, est, v,
                                       limits.wheelbase, dt, tracker.gains)
        if decision is not None and not decision.on_plan:  # the guard's manoeuvre
            m = decision.manoeuvre
            want_v = m.speed if t - decided_at < m.hold else 0.0
            want_steer = m.steer
        if fsm is not None:  # the state machine drives; FollowTrack passes the plan on
            want_v, want_steer = fsm.step(t, (x, y, th), est, v, steer,
                                          (want_v, want_steer) if ref is not None else None)
            if fsm.planner_switched:  # FollowTrack entered or left: plan afresh from here
                replanner, ref, pending, conflict = new_replanner(), None, None, False
                next_cycle = t + dt if fsm.planning else math.inf
        v_cmd, steer_cmd = limit_commands(v, steer, want_v, want_steer, limits, dt)
        e_old = e
        guarding = decision is not None and decision.manoeuvre.name not in (FOLLOW, STAND)
        stopped = abs(v_cmd) < 1e-9 and ((ref is not None and conflict) or guarding)
        planned_now = planned and not guarding
        stops += stopped and not was_stopped and not planned_now
        waits += stopped and not was_stopped and planned_now
        state = _state(decision, planned_now and stopped)
        codes.append(GUARD_CODES[state])
        was_stopped = stopped
        rows.append((t, x, y, th, v_cmd, steer_cmd, want_steer, e,
                     replanner.planner.nodes if replanner.planner else 0))
        lat.append(abs(e))
        if observer is not None:
            if replanner.planner is not tree_of:  # a new cycle's tree: copy it once
                tree_of = replanner.planner
                tree = tree_of.snapshot() if tree_of is not None else None
            observer(Frame(t, (x, y, th), v_cmd, steer_cmd, want_steer, e,
                           true_offsets(problem.world, movers, t)[0], sensing, ref,
                           tree, len(cycles), int(replans),
                           cycles[-1]["ms"] if cycles else math.nan, state,
                           reach_rates(agility, uncertainty, known, lanes)))
        v, steer = v_cmd, steer_cmd
        if counter is not None:
            counter.update(t, x, y)
        if (counter.laps >= s.laps) if counter is not None else in_goal(x, y, th, goal):
            reached = True
            break
        if fsm is not None and fsm.done(v):  # the machine's Stop reached, at rest
            break
        if k == n_ticks:
            break
        x, y, th = arc_step(x, y, th, v, steer, limits.wheelbase, dt)
        est = arc_step(*est, v, steer, limits.wheelbase, dt)  # dead reckoning on the commands
        if s.realtime:
            time.sleep(max(0.0, t + dt - (time.perf_counter() - wall0)))
    log = np.array(rows, dtype=float)
    offsets = true_offsets(problem.world, movers, log[:, 0])
    samples = np.zeros((len(log), 6))
    samples[:, :3] = log[:, 1:4]
    samples[:, 5] = log[:, 0]
    clear = path_clearances(problem.world, samples, True)
    lat = np.asarray(lat)
    lat = lat[np.isfinite(lat)]
    columns = ["t", "x", "y", "theta", "v", "steer"]
    columns += [f"obs{i}_{a}" for i in range(len(movers)) for a in ("dx", "dy")]
    contact = contacts(clear, log[:, 4])
    columns += ["steer_set", "lateral_error", "tree_nodes", "clearance", "contact", "guard"]
    table = np.column_stack([log[:, :6], offsets.reshape(len(log), -1), log[:, 6:], clear,
                             contact, codes])
    summary = {
        "reached_goal": reached,
        "time_to_goal_s": float(log[-1, 0]) if reached else None,
        "duration_s": float(log[-1, 0]),
        "collisions": collision_runs(clear),
        "collisions_moving": collision_runs(np.where(contact == MOVING, -1.0, 1.0)),
        "collisions_at_rest": collision_runs(np.where(contact == AT_REST, -1.0, 1.0)),
        "min_clearance_m": float(clear.min()),
        "cycles": len(walls),
        "replans": int(replans),
        **cycle_stats(walls),
        "emergency_stops": int(stops),
        "planned_waits": int(waits),
        "brakes": int(brakes),
        "evasions": int(evasions),
        "cross_track_error_m": {"mean": float(lat.mean()) if len(lat) else None,
                                "max": float(lat.max()) if len(lat) else None},
        "distance_m": float(np.abs(log[:, 4]).sum() * dt) - float(abs(log[-1, 4]) * dt),
        "parameters": asdict(s),
    }
    if counter is not None:
        summary.update(laps=counter.laps, lap_times_s=counter.lap_times)
    if fsm is not None:
        columns.append("state")  # index into summary["behaviour"]["states"]
        table = np.column_stack([table, fsm.trace])
        summary["behaviour"] = fsm.report()
    return SimRun(summary, columns, table, cycles)
