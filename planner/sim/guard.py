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
clear longest — brake along the plan, brake while swerving, swerve at speed, go on straight, or
back up — and the car executes it until the next cycle decides again.

Rollouts are the car's own model (`vehicle.arc_step` with the actuator limits, at
``STEP`` s); along the plan the car is where the reference is at the driven arc (it tracks it to
a few cm, within the planning margin). Between two samples k and k + 1 the clearance drops by at
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
from planner.sim.control import Reference
from planner.sim.vehicle import Limits, toward

__all__ = ["BACK_OFF", "FOLLOW", "STAND", "Decision", "Manoeuvre", "guard"]

STEP = 0.02  # s between rollout samples
HORIZON = 4.0  # s checked ahead, the car at rest at its end
CAPS = (1.0, 0.5, 0.0)  # commit speed caps, as shares of the cruise speed, tried in order
GO_ON = (0.0, 1.0, 2.0)  # s driven on along the plan after the commitment before braking
EVADE_S = 1.0  # s an evasive manoeuvre holds its speed before it brakes
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
    it — (passive safety: then the contact is not its own)."""

    clear_s: float
    at_rest: bool
    likely_s: float = math.inf

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
    clear, so this is an evasive choice."""

    manoeuvre: Manoeuvre
    clear_s: float
    danger: bool

    @property
    def on_plan(self) -> bool:
        return self.manoeuvre.steer is None


class _Rollouts:
    """Rollouts from one state against one believed world (planner time 0 = the decision)."""

    def __init__(self, world: World, margin: float, state, limits: Limits,
                 ref: Reference | None, i: int, stop_s: float, rho: float,
                 done_s: float = math.inf, off: float = 0.0) -> None:
        self.world, self.margin, self.limits, self.ref, self.stop_s = (world, margin, limits,
                                                                      ref, stop_s)
        self.reachable: World | None = None  # reachable sets the car must be at rest before
        self.off = off  # how far the car is from the plan beyond the margin (along the plan)
        likely = world.m_grow.copy()
        likely[:, 1:3] = 0.0  # no growth: each mover where its sensed velocity takes it
        self.likely = world._replace(m_grow=likely)
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
        past ``stop_s``, and at rest at each cusp before going on the other way. A car moving
        against the plan's direction (still backing up after an evasion) brakes first, off
        the plan where that takes it, and then counts how far that is from its row as off
        the plan."""
        ref, a = self.ref, self.limits.max_accel
        v, s, stretch = self.v, self.s0, ref.stretch
        stretch += ref.turns(stretch, s, v)
        d0 = ref.signs[stretch]
        vs, ss = np.empty(self.n), np.empty(self.n)
        for k in range(self.n):
            vs[k], ss[k] = v, s
            d, cusp = ref.signs[stretch], ref.s[ref.bounds[stretch + 1]]
            want = cap if k * STEP < hold else 0.0
            want = d * min(want, math.sqrt(2.0 * a * max(min(self.stop_s, cusp) - s, 0.0)))
            nv = toward(v, want, a * STEP)
            s += 0.5 * (max(d * v, 0.0) + max(d * nv, 0.0)) * STEP
            v = nv
            stretch += ref.turns(stretch, s, v)
        j = np.clip(np.searchsorted(ref.s, ss) - 1, 0, len(ref.s) - 2)
        u = np.clip((ss - ref.s[j]) / np.maximum(ref.s[j + 1] - ref.s[j], 1e-12), 0.0, 1.0)
        poses = np.empty((self.n, 3))
        poses[:, :2] = ref.rows[j, :2] + u[:, None] * (ref.rows[j + 1, :2] - ref.rows[j, :2])
        poses[:, 2] = np.where(u < 0.5, ref.rows[j, 2], ref.rows[j + 1, 2])
        off = np.full(self.n, self.off)
        back = int(np.argmax(vs * d0 >= 0.0))  # the sample where it no longer moves against
        if back:
            poses[:back + 1] = self._poses(vs, np.full(self.n, self.steer))[:back + 1]
            off[back + 1:] += math.dist(poses[back, :2], poses[back + 1, :2])
        end = int(np.searchsorted(ss, self.done_s)) + 1  # the run ends in the goal
        return self._clear(poses[:end], vs[:end], off[:end])

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

    def _clear(self, poses: np.ndarray, vs: np.ndarray, off=0.0) -> Outcome:
        """The time of the first sample pair that may hide a contact (inf: none): with the
        movers as believed (grown, with the margin), with the static world as it is; if there
        is one, also with the movers' likely futures. ``off`` (m, or per sample): the car may be
        this far from the poses (it is off the plan it tracks), so every clearance counts that
        much less."""
        n = len(poses)
        samples = np.zeros((n, 6))
        samples[:, :3] = poses
        drive = np.abs(vs[:-1]) * self.reach * STEP
        samples[:, 5] = math.nan  # static obstacles only
        static = _unsure(path_clearances(self.world, samples, True) + self.margin - off, drive)
        samples[:, 5] = self.t[:n]
        closing = drive + self.closing[:n - 1]
        unsure = _unsure(path_moving_clearances(self.world, samples) - off, closing) | static
        if self.reachable is not None:  # passive safety: at rest before a mover may reach it
            moving = np.maximum(np.abs(vs[:-1]), np.abs(vs[1:])) > 0.0
            unsure |= moving & _unsure(path_moving_clearances(self.reachable, samples) - off,
                                       drive + self.reachable.geo[VMAX_OBS] * STEP)
        bad = np.flatnonzero(unsure)
        if len(bad) == 0:
            return Outcome(math.inf, True)
        k = bad[0]
        likely = np.flatnonzero(_unsure(path_moving_clearances(self.likely, samples) - off,
                                        closing) | static)
        j = likely[0] if len(likely) else k
        return Outcome(float(self.t[k]), max(abs(vs[j]), abs(vs[j + 1])) < 1e-9,
                       float(self.t[likely[0]]) if len(likely) else math.inf)


def _unsure(c: np.ndarray, drop: np.ndarray) -> np.ndarray:
    """Per sample pair: may the clearance reach contact between them?"""
    return (c[:-1] <= CONTACT) | (c[:-1] + c[1:] <= drop + 2.0 * CONTACT)


def guard(world: World, margin: float, state, limits: Limits, ref: Reference | None, i: int,
          stop_s: float, cruise: float, commit: float, rho: float, reverse: bool,
          stuck: bool = False, done_s: float = math.inf, off: float = 0.0,
          reach: World | None = None) -> Decision:
    """The car's manoeuvre until the next decision, ``commit`` s from now.

    ``state``: (x, y, θ, v, δ) now; ``ref``/``i``: the plan and the car's row on it (None: no
    plan yet); ``stop_s``: the arc where the plan wants the car at rest (a planned wait or the
    plan's end); ``world``: the grown prediction with planner time 0 now, inflated by
    ``margin`` (which the static check gives back: the car may come as near a wall as it is);
    ``stuck``: the car has stood, not by plan, for a while — a forward-only planner finds no
    way round an obstacle right in front, so it backs off a little if that is clear;
    ``done_s``: the arc where the plan enters the goal and the run ends (inf: none) — a goal in
    a stream of traffic is reached, not stood in, so the check along the plan ends there;
    ``off``: how far the car is from its row on the plan beyond what the margin allows: the
    checks along the plan count it off every clearance (a car that lags outside a tight
    turn stays outside it), the open-loop manoeuvres start from where the car is;
    ``reach``: the movers' reachable sets (`planner.sim.predict.reach_world`, inflated like
    ``world``): a commitment along the plan must have the car at rest before one of them
    reaches it; if only that fails, the car brakes along the plan (a walker may turn into
    it). Backing off when stuck and the evasive manoeuvres are judged without them.
    """
    r = _Rollouts(world, margin, state, limits, ref, i, stop_s, rho, done_s, off)
    tried: list[tuple[Outcome, Manoeuvre]] = []
    if stuck and reverse:  # a forward-only plan finds no way on: make room behind
        m = Manoeuvre(BACK_OFF, -0.5 * cruise, steer=0.0)
        out = r.free(m)
        if out.clear_s == math.inf:
            return Decision(m, out.clear_s, False)
    r.reachable = reach
    if ref is not None:
        for share in CAPS:
            m = Manoeuvre(FOLLOW if share == 1.0 else "slow" if share > 0 else "brake",
                          share * cruise)
            for go_on in GO_ON if share > 0.0 else (0.0,):
                out = r.along(m.speed, commit + go_on)
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
    s_max = limits.max_steer
    evasive = [Manoeuvre("brake-left", 0.0, steer=s_max),
               Manoeuvre("brake-right", 0.0, steer=-s_max),
               Manoeuvre("swerve-left", max(r.v, 0.5 * cruise), EVADE_S, s_max),
               Manoeuvre("swerve-right", max(r.v, 0.5 * cruise), EVADE_S, -s_max),
               Manoeuvre("go-on", limits.max_speed, EVADE_S, 0.0)]
    if reverse:
        evasive += [Manoeuvre("back-up", -cruise, EVADE_S, 0.0),
                    Manoeuvre("back-up-left", -cruise, EVADE_S, s_max),
                    Manoeuvre("back-up-right", -cruise, EVADE_S, -s_max)]
    for m in evasive:
        tried.append((r.free(m), m))
    out, m = max(tried, key=lambda om: om[0].rank)  # the first of the best
    return Decision(m, out.clear_s, True)
