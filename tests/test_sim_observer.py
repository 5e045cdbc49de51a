"""The simulation's observer hook (the studio's live view reads it): frames agree with the log,
and observing a run does not change it."""

from __future__ import annotations

import math

import numpy as np
import pytest

import planner
from planner.sim import SimSettings, simulate

SETTINGS = SimSettings(duration=4.0, fixed_latency_ms=20.0, seed=3)


@pytest.fixture(scope="module")
def crossing():
    return planner.load_scenario("crossing")


@pytest.fixture(scope="module")
def observed(crossing):
    frames = []
    return simulate(crossing, SETTINGS, observer=frames.append), frames


def test_frames_are_the_log_rows(observed):
    run, frames = observed
    log, col = run.log, {c: i for i, c in enumerate(run.columns)}
    assert len(frames) == len(log)
    got = np.array([(f.t, *f.pose, f.v, f.steer, f.steer_set, *f.offsets[0]) for f in frames])
    want = log[:, [col[c] for c in ("t", "x", "y", "theta", "v", "steer", "steer_set",
                                    "obs0_dx", "obs0_dy")]]
    assert np.array_equal(got, want)
    e = np.array([f.lateral_error for f in frames])
    assert np.array_equal(np.isnan(e), np.isnan(log[:, col["lateral_error"]]))
    assert np.array_equal(e[~np.isnan(e)], log[~np.isnan(e), col["lateral_error"]])
    assert [f.tree.nodes if f.tree else 0 for f in frames] == list(log[:, col["tree_nodes"]])


def test_frames_show_the_cars_belief_and_progress(observed):
    run, frames = observed
    rate = SETTINGS.sense_rate
    for f in frames:
        # The latest sensing instant, never one from the future.
        assert f.t - 1.0 / rate - 1e-9 < f.sensing.t <= f.t + 1e-9
        assert f.sensing.offsets.shape == f.sensing.velocities.shape == (1, 2)
    # Without noise the sensed offset is the truth at the sensing instant.
    f = frames[-1]
    back = next(g for g in reversed(frames) if abs(g.t - f.sensing.t) < 1e-9)
    assert np.allclose(f.sensing.offsets[0], back.offsets[0])
    cycles = [f.cycles for f in frames]
    assert cycles[0] == 1 and np.all(np.diff(cycles) >= 0)
    assert cycles[-1] == run.summary["cycles"] and not math.isnan(frames[0].cycle_ms)
    assert frames[-1].replans == run.summary["replans"]
    assert frames[-1].reference is not None and len(frames[-1].reference.rows) > 2


def test_observing_does_not_change_the_run(crossing, observed):
    run, _ = observed
    plain = simulate(crossing, SETTINGS)
    assert plain.columns == run.columns
    assert np.array_equal(plain.log, run.log, equal_nan=True)
    assert plain.summary == run.summary


def test_an_observer_can_end_the_run(crossing):
    class Enough(Exception):
        pass

    seen = []

    def observer(frame):
        seen.append(frame.t)
        if len(seen) == 5:
            raise Enough

    with pytest.raises(Enough):
        simulate(crossing, SETTINGS, observer=observer)
    assert len(seen) == 5
