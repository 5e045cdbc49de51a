"""Safety before optimality: every cycle, check what the car commits to and fall back in time.

A state is safe when some manoeuvre from it stays clear of the grown predictions
(`planner.sim.predict`) and of the static world over the whole check horizon, the car at rest at
its end — the idea of inevitable collision states (Fraichard & Asama 2004) with passive safety
(Bouraine et al. 2012): a car that must ever be hit should be hit at rest, and a car at rest
should stand where no predicted mover comes before it has left.

Each cycle the guard tries, fastest first, to go on along the plan at a speed cap for one
cycle (the commitment) followed by a fallback: brake along the plan, or drive on along it for a
while and brake then. The first cap with a clear fallback is what the car drives. If none is
clear, the car is in danger: the guard picks, from the state now, the manoeuvre that stays
clear longest — brake along the plan, brake while swerving, swerve at speed, go on straight,
or back up; and where each of these stays in a mover's likely way, dash aside — and the car
executes it until the next cycle decides again. Where every manoeuvre clear throughout ends at
rest where a likely future comes soon after the horizon (a dead end a shuttle comes up), those
clear of the likely futures come first.

Rollouts are the car's own model (exact arcs with the actuator limits, at ``STEP`` s); along
the plan it is the tracking controller rolled out from where the car is (`control.Tracker`), so
a car whose steering is still swinging, or that lags outside a bend it takes at full lock, is
foreseen where it will drive, not where the plan is. Between two samples k and k + 1 the clearance drops by at
most (|v|·(1 + reach/ρ) + the movers' top speed and growth)·STEP, so two samples whose
clearances add up to more than that cannot hide a contact between them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from planner._world import (CONTACT, REACH, VMAX_OBS, World, path_clearances,
                            path_moving_clearances)
from planner.sim.control import CUSP_REACH, Reference, Tracker
from planner.sim.predict import without_growth
from planner.sim.vehicle import Limits, toward

__all__ = ["BACK_OFF", "FOLLOW", "STAND", "Decision", "Manoeuvre", "guard"]

STEP = 0.02  # s between rollout samples
HORIZON = 4.0  # s checked ahead, the car at rest at its end
CAPS = (1.0, 0.5, 0.0)  # commit speed caps, as shares of the cruise speed, tried in order
GO_ON = (0.0, 1.0, 2.0)  # s driven on along the plan after the commitment before braking
EVADE_S = 1.0  # s an evasive manoeuvre holds its speed before it brakes
REFUGE_S, REFUGE_STEP = 4.0, 0.1  # s after the horizon a rest pose is checked on, and how often
_REFUGE_T = HORIZON + REFUGE_STEP * np.arange(1, int(round(REFUGE_S / REFUGE_STEP)) + 1)
FOLLOW, STAND = "follow", "stand"  # along the plan at cruise; no plan: at rest where it is
BACK_OFF, UNSTICK_S = "back-off", 2.0  # stuck: back up at half the cruise speed this long


@dataclass(frozen=True)
class Manoeuvre:
    """Commands held from the decision on: a speed target for ``hold`` s then 0, and a steering
    target (None: track the plan, the speed capped at ``speed``)."""

    name: str
    speed: float
    hold: float = math.inf
    steer: float | None = None


class Outcome(NamedTuple):
    """How a rollout fares: clear of the grown predictions for ``clear_s`` (inf: the whole
    horizon), clear of the likely futures (constant velocity, not grown) for ``likely_s``, and
    whether the car stands still where it may first be hit — by a likely future where one hits
    it — (passive safety: then the contact is not its own); ``end``: the pose it rests in at
    the horizon (None: the run ends in the goal before)."""

    clear_s: float
    at_rest: bool
    likely_s: float = math.inf
    end: tuple[float, float, float] | None = None

    @property
    def rank(self):
        """Clear of the grown predictions throughout first, then clear of the likely futures
        throughout, then at rest when hit, then clear for longest.

        Standing still is no refuge from a mover that walks straight at the car: a swerve that
        leaves its likely path beats a stop in it."""
        return (self.clear_s == math.inf, self.likely_s == math.inf, self.at_rest,
                self.likely_s, self.clear_s)


@dataclass(frozen=True)
class Decision:
    """What the car does until the next cycle. ``clear_s``: how long the chosen manoeuvre
    stays clear (inf: over the whole horizon); ``danger``: no commitment along the plan was
    clear, so this is an evasive choice; ``unstick``: the car had stood, not by plan, and
    this gets it going (`UNSTICK_S`)."""

    manoeuvre: Manoeuvre
    clear_s: float
    danger: bool
    unstick: bool = False

    @property
    def on_plan(self) -> bool:
        return self.manoeuvre.steer is None


class _Rollouts:
    """Rollouts from one state against one believed world (planner time 0 = the decision)."""

    def __init__(self, world: World, margin: float, state, limits: Limits,
                 ref: Reference | None, i: int, stop_s: float, rho: float,
                 done_s: float, tracker: Tracker, likely: list[World] | None) -> None:
        self.world, self.margin, self.limits, self.ref, self.stop_s = (world, margin, limits,
                                                                      ref, stop_s)
        self.state, self.tracker = state, tracker
        self.reachable: World | None = None  # reachable sets the car must be at rest before
        self.likely = likely or [without_growth(world)]
        self.x, self.y, self.th, self.v, self.steer = state
        self.s0 = float(ref.s[i]) if ref is not None else 0.0
        self.done_s = done_s if self.s0 < done_s else math.inf  # missed it: check on
        self.n = int(round(HORIZON / STEP)) + 1
        self.t = np.arange(self.n) * STEP
        # How fast the believed movers close in, per sample: their speed, plus their
        # growth's rate while it widens (`planner._world.growth`; held beyond its horizon).
        e, e_v, a, age, horizon = (world.m_grow[0] if len(world.m_grow) else np.zeros(5))
        tau = self.t[:-1] + age
        widening = np.where(tau < horizon, e_v + a * np.maximum(tau, 0.0), 0.0)
        self.closing = (world.geo[VMAX_OBS] - (e_v + a * horizon) + widening) * STEP
        self.reach = 1.0 + world.geo[REACH] / rho

    def along(self, cap: float, hold: float) -> Outcome:
        """Clear time of: along the plan at speed ``cap`` for ``hold`` s, then braking; never
        past ``stop_s``, and at rest at each cusp before going on the other way. The speeds
        follow the plan's arc; the poses are the controller's (a car still backing up after
        an evasion brakes first, off the plan where that takes it)."""
        ref, a = self.ref, self.limits.max_accel
        v, s, stretch = self.v, self.s0, ref.stretch
        stretch += ref.turns(stretch, s, v)
        vs, ss = np.empty(self.n), np.empty(self.n)
        stretches = np.empty(self.n, np.int64)
        for k in range(self.n):
            vs[k], ss[k], stretches[k] = v, s, stretch
            d, cusp = ref.signs[stretch], ref.s[ref.bounds[stretch + 1]]
            want = cap if k * STEP < hold else 0.0
            want = d * min(want, math.sqrt(2.0 * a * max(min(self.stop_s, cusp) - s, 0.0)))
            nv = toward(v, want, a * STEP)
            s += 0.5 * (max(d * v, 0.0) + max(d * nv, 0.0)) * STEP
            v = nv
            stretch += ref.turns(stretch, s, v)
        end = int(np.searchsorted(ss, self.done_s)) + 1  # the run ends in the goal
        poses = self.tracker.rollout(ref, self.state, vs[:end], stretches[:end], self.limits,
                                     STEP)
        return self._clear(poses, vs[:end])

    def free(self, m: Manoeuvre) -> Outcome:
        """Clear time of an open-loop manoeuvre: steering towards ``m.steer`` at the rate
        limit, speed towards ``m.speed`` for ``m.hold`` s, then braking."""
        lim = self.limits
        vs = np.empty(self.n)
        steers = np.clip(m.steer, self.steer - lim.max_steer_rate * self.t,
                         self.steer + lim.max_steer_rate * self.t)
        v = self.v
        for k in range(self.n):
            vs[k] = v
            v = toward(v, m.speed if k * STEP < m.hold else 0.0, lim.max_accel * STEP)
        return self._clear(self._poses(vs, steers), vs)

    def _poses(self, vs: np.ndarray, steers: np.ndarray) -> np.ndarray:
        """The car's poses from where it is, at these speeds and steering angles per sample:
        exact arcs per step (commands held over it, as the car does)."""
        v_mid = 0.5 * (vs[:-1] + vs[1:])
        dth = v_mid * STEP * np.tan(steers[:-1]) / self.limits.wheelbase
        th = self.th + np.concatenate([[0.0], np.cumsum(dth)])
        chord = v_mid * STEP * np.sinc(dth / (2.0 * np.pi))
        mid = th[:-1] + 0.5 * dth
        poses = np.empty((len(vs), 3))
        poses[:, 0] = self.x + np.concatenate([[0.0], np.cumsum(chord * np.cos(mid))])
        poses[:, 1] = self.y + np.concatenate([[0.0], np.cumsum(chord * np.sin(mid))])
        poses[:, 2] = th
        return poses

    def _clear(self, poses: np.ndarray, vs: np.ndarray) -> Outcome:
        """The time of the first sample pair that may hide a contact (inf: none): with the
        movers as believed (grown, with the margin), with the static world as it is; if there
        is one, also with the movers' likely futures."""
        n = len(poses)
        samples = np.zeros((n, 6))
        samples[:, :3] = poses
        drive = np.abs(vs[:-1]) * self.reach * STEP
        samples[:, 5] = math.nan  # static obstacles only
        static = _unsure(path_clearances(self.world, samples, True) + self.margin, drive)
        samples[:, 5] = self.t[:n]
        closing = drive + self.closing[:n - 1]
        unsure = _unsure(path_moving_clearances(self.world, samples), closing) | static
        if self.reachable is not None:  # passive safety: at rest before a mover may reach it
            moving = np.maximum(np.abs(vs[:-1]), np.abs(vs[1:])) > 0.0
            unsure |= moving & _unsure(path_moving_clearances(self.reachable, samples),
                                       drive + self.reachable.geo[VMAX_OBS] * STEP)
        bad = np.flatnonzero(unsure)
        end = tuple(poses[-1]) if n == self.n else None
        if len(bad) == 0:
            return Outcome(math.inf, True, end=end)
        k = bad[0]
        hit = static.copy()  # by the first of the likely futures to reach the car
        for world in self.likely:
            hit |= _unsure(path_moving_clearances(world, samples),
                           drive + world.geo[VMAX_OBS] * STEP)
        likely = np.flatnonzero(hit)
        j = likely[0] if len(likely) else k
        return Outcome(float(self.t[k]), max(abs(vs[j]), abs(vs[j + 1])) < 1e-9,
                       float(self.t[likely[0]]) if len(likely) else math.inf, end)

    def refuge(self, out: Outcome) -> bool:
        """Whether a rollout clear throughout ends in the goal, or at rest where no likely
        future comes for `REFUGE_S` after the horizon either. A car that evades into a dead end
        stands clear of a shuttle coming up it for the horizon, and is run into at rest after
        it, with no way out."""
        if out.end is None:
            return True
        samples = np.zeros((len(_REFUGE_T), 6))
        samples[:, :3] = out.end
        samples[:, 5] = _REFUGE_T
        steps = np.full(len(_REFUGE_T) - 1, REFUGE_STEP)
        return not any(_unsure(path_moving_clearances(world, samples),
                               world.geo[VMAX_OBS] * steps).any() for world in self.likely)


def _unsure(c: np.ndarray, drop: np.ndarray) -> np.ndarray:
    """Per sample pair: may the clearance reach contact between them?"""
    return (c[:-1] <= CONTACT) | (c[:-1] + c[1:] <= drop + 2.0 * CONTACT)


def _commitments(cruise: float, commit: float):
    """(manoeuvre, s held) along the plan, fastest first: each speed cap for the commitment
    and then for a while longer (`GO_ON`), braking last."""
    for share in CAPS:
        m = Manoeuvre(FOLLOW if share == 1.0 else "slow" if share > 0 else "brake",
                      share * cruise)
        for go_on in GO_ON if share > 0.0 else (0.0,):
            yield m, commit + go_on


def _evasive(v: float, cruise: float, limits: Limits, reverse: bool) -> list[Manoeuvre]:
    """The manoeuvres off the plan: braking while swerving, swerving at speed, going on
    straight, and backing up where the car may."""
    s_max = limits.max_steer
    evasive = [Manoeuvre("brake-left", 0.0, steer=s_max),
               Manoeuvre("brake-right", 0.0, steer=-s_max),
               Manoeuvre("swerve-left", max(v, 0.5 * cruise), EVADE_S, s_max),
               Manoeuvre("swerve-right", max(v, 0.5 * cruise), EVADE_S, -s_max),
               Manoeuvre("go-on", limits.max_speed, EVADE_S, 0.0)]
    if reverse:
        evasive += [Manoeuvre("back-up", -cruise, EVADE_S, 0.0),
                    Manoeuvre("back-up-left", -cruise, EVADE_S, s_max),
                    Manoeuvre("back-up-right", -cruise, EVADE_S, -s_max)]
    return evasive


def _dashes(limits: Limits) -> list[Manoeuvre]:
    """The last resort when every other manoeuvre stays in the way of a mover's likely future
    (a walker that turns at the car 1.5 m off: a swerve at the car's speed is too slow):
    steering fully aside while speeding up to the top speed. Tried only then, since it leaves
    the car moving fast where a stop would have been clear of the likely futures."""
    return [Manoeuvre(f"dash-{side}", limits.max_speed, EVADE_S, sign * limits.max_steer)
            for side, sign in (("left", 1.0), ("right", -1.0))]


def _unstick(r: _Rollouts, cruise: float, commit: float, reverse: bool,
             back_off: bool) -> Decision | None:
    """A car that has stood a while, not by plan, gets going, judged without the reachable
    sets (a mover parked beside the way, seen to turn once, never frees it): along a plan
    that leads on (a fresh plan for a car that stood without one is followed, not swerved
    from); else, as a forward-only planner finds no way round an obstacle right in
    front, backing off a little once; else, if a plan leads on, by the first forward
    manoeuvre off it that is clear throughout (a plan timed for a car at speed can pass a
    mover's grown prediction that a car setting off from rest cannot). None: it stands."""
    leads_on = r.ref is not None and r.stop_s - r.s0 > CUSP_REACH  # not a wait where it is
    if leads_on:
        for m, hold in _commitments(cruise, commit):
            if m.speed > 0.0 and r.along(m.speed, hold).clear_s == math.inf:
                return Decision(m, math.inf, False, unstick=True)
    moves = [Manoeuvre(BACK_OFF, -0.5 * cruise, steer=0.0)] if reverse and back_off else []
    if leads_on:
        moves += [m for m in _evasive(r.v, cruise, r.limits, False) if m.speed > 0.0]
    for m in moves:
        if r.free(m).clear_s == math.inf:
            return Decision(m, math.inf, m.name != BACK_OFF, unstick=True)
    return None


def guard(world: World, margin: float, state, limits: Limits, ref: Reference | None, i: int,
          stop_s: float, cruise: float, commit: float, rho: float, reverse: bool,
          stuck: bool = False, done_s: float = math.inf, reach: World | None = None,
          tracker: Tracker | None = None, back_off: bool = True,
          likely: list[World] | None = None) -> Decision:
    """The car's manoeuvre until the next decision, ``commit`` s from now.

    ``state``: (x, y, θ, v, δ) now; ``ref``/``i``: the plan and the car's row on it (None: no
    plan yet); ``stop_s``: the arc where the plan wants the car at rest (a planned wait or the
    plan's end); ``world``: the grown prediction with planner time 0 now, inflated by
    ``margin`` (which the static check gives back: the car may come as near a wall as it is);
    ``stuck``: the car has stood, not by plan, for a while: it gets going if it can
    (`_unstick`); ``back_off``: whether it may back off then (once, until it has driven on);
    ``done_s``: the arc where the plan enters the goal and the run ends (inf: none) — a goal in
    a stream of traffic is reached, not stood in, so the check along the plan ends there;
    ``reach``: the movers' reachable sets (`planner.sim.predict.reach_world`, inflated like
    ``world``): a commitment along the plan must have the car at rest before one of them
    reaches it; if only that fails, the car brakes along the plan (a walker may turn into
    it). Getting unstuck and the evasive manoeuvres are judged without them;
    ``tracker``: the controller the car tracks the plan with (None: pure pursuit at 100 Hz),
    rolled out along it; ``likely``: the movers' likely futures, inflated like ``world``, by
    which the manoeuvres in danger are ranked (None: ``world`` without its growth; see
    `planner.sim.predict.likely_worlds`).
    """
    r = _Rollouts(world, margin, state, limits, ref, i, stop_s, rho, done_s,
                  tracker or Tracker(), likely)
    tried: list[tuple[Outcome, Manoeuvre]] = []
    if stuck:
        unstick = _unstick(r, cruise, commit, reverse, back_off)
        if unstick is not None:
            return unstick
    r.reachable = reach
    if ref is not None:
        for m, hold in _commitments(cruise, commit):
            out = r.along(m.speed, hold)
            if out.clear_s == math.inf:
                return Decision(m, out.clear_s, False)
            tried.append((out, m))
        if reach is not None:  # clear but for the reachable sets: brake (passive safety)
            r.reachable = None
            if r.along(0.0, commit).clear_s == math.inf:
                return Decision(Manoeuvre("brake", 0.0), math.inf, False)
    else:  # no plan: standing (or braking) where it is, if that is clear
        m = Manoeuvre(STAND, 0.0, steer=state[4])
        out = r.free(m)
        if out.clear_s == math.inf:
            return Decision(m, out.clear_s, False)
        tried.append((out, m))
    # In danger the likely and grown futures rank the manoeuvres; a reachable set would shut
    # out every one that moves, backing away from a walker included. The options along the
    # plan tried above keep their outcomes with the sets: where a walker may turn into the
    # plan, a swerve clear of its likely future is preferred to driving on along it.
    r.reachable = None
    for m in _evasive(r.v, cruise, limits, reverse):
        tried.append((r.free(m), m))
    if all(out.likely_s < math.inf for out, _ in tried):  # each one stays in a mover's way
        for m in _dashes(limits):
            tried.append((r.free(m), m))
    # Where every way clear throughout ends in a trap (`_Rollouts.refuge`), a way clear of the
    # likely futures comes first: going on past a shuttle beats evading into the dead end it
    # comes up.
    clear = [out for out, _ in tried if out.clear_s == math.inf]
    trapped = bool(clear) and not any(r.refuge(out) for out in clear)
    out, m = max(tried, key=lambda om: (trapped and om[0].clear_s < math.inf
                                        and om[0].likely_s == math.inf, *om[0].rank))
    return Decision(m, out.clear_s, True)  # the first of the best
