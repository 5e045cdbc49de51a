"""What the car knows: sensed obstacle offsets and velocity estimates, and pose measurements.

The true motion of every obstacle (docs/scenario-format.md v1.1 `motion`) is evaluated here in plain
numpy, for the sensors and the log; the planner only ever sees the `Sensing` records these produce.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planner._world import VELOCITY, World
from planner.obstacles import table_offsets

__all__ = ["Sensing", "known_motions", "mover_index", "sense", "true_offsets"]


def mover_index(scenario) -> np.ndarray:
    """Per scenario obstacle, its motion index in the compiled world (-1: static)."""
    out, m = [], 0
    for ob in scenario.obstacles:
        out.append(m if ob.motion is not None else -1)
        m += ob.motion is not None
    return np.array(out, dtype=np.int64)


def known_motions(scenario) -> np.ndarray:
    """Per motion (world order), whether the car is told its timetable (`motion.known`)."""
    return np.array([ob.motion.known for ob in scenario.obstacles if ob.motion is not None],
                    dtype=bool)


def true_offsets(world: World, movers: np.ndarray, times) -> np.ndarray:
    """(len(times), n_obstacles, 2): every obstacle's true offset at each time (0 when static).

    Waypoint motions hold their first/last offset outside their time span, as np.interp does.
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    out = np.zeros((len(times), len(movers), 2))
    for i, m in enumerate(movers):
        if m < 0:
            continue
        if world.m_kind[m] == VELOCITY:
            out[:, i] = times[:, None] * world.m_vel[m]
        else:
            out[:, i] = table_offsets(world.m_wp[world.m_wp_start[m]:world.m_wp_start[m + 1]],
                                      times)
    return out


@dataclass(frozen=True)
class Sensing:
    """One sensing instant: per motion (world order) the offset and velocity estimate."""

    t: float
    offsets: np.ndarray  # (n_motions, 2)
    velocities: np.ndarray  # (n_motions, 2)


def sense(world: World, movers: np.ndarray, t: float, rate: float, noise: float,
          rng: np.random.Generator) -> Sensing:
    """Offsets at t and the finite-difference velocity (offset(t) − offset(t − 1/rate))·rate.

    With noise σ > 0 each sensed offset gets N(0, σ²) per axis; the velocity estimate is the
    difference of two noisy offsets, as a real tracker without filtering would see it.
    """
    moving = movers[movers >= 0]
    order = np.argsort(moving)
    both = true_offsets(world, movers, [t - 1.0 / rate, t])[:, movers >= 0][:, order]
    if noise > 0.0:
        both = both + rng.normal(0.0, noise, both.shape)
    return Sensing(t, both[1], (both[1] - both[0]) * rate)
