"""Every returned path is valid as written: its rows joined by straight chords, as a consumer
joins them, re-checked every 1 mm by the independent checker (tests/checker.py)."""

import math

import numpy as np
import pytest
from checker import first_collision
from conftest import scenario_dict
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import planner
from planner._rows import chord_sag, polyline, polyline_clearance
from planner.obstacles import follow_waypoints
from planner.problem import resolve_track
from planner.scenario import ScenarioError

BUNDLED = [p.stem for p in sorted(planner.bundled_scenario_path("slalom").parent.glob("*.json"))]


def checker_scene(name: str) -> dict:
    """The scenario as the checker reads it: a track scene gets its drivable region's rings
    (from the tracks layer), bounds around them, and its track-following movers as waypoints."""
    scn = scenario_dict(name)
    if "track" not in scn:
        return scn
    parsed = planner.parse_scenario(scn)
    track = resolve_track(parsed)
    rings = track.region_rings()
    pts = np.vstack(rings)
    obstacles = []
    for ob, model in zip(scn["obstacles"], parsed.obstacles):
        follow = model.motion.follow_track if model.motion is not None else None
        if follow is not None:
            ob = {**ob, "motion": {"waypoints": follow_waypoints(track, follow).tolist()}}
        obstacles.append(ob)
    return {**scn, "obstacles": obstacles, "region": [r.tolist() for r in rings],
            "bounds": [*(pts.min(axis=0) - 1.0), *(pts.max(axis=0) + 1.0)]}


def chords_valid(scn: dict, result) -> None:
    """The rows, with their times where the scene moves, pass the chord check at 1 mm."""
    path = result.path[:, [0, 1, 2, 5]] if result.timed else result.path[:, :3]
    assert first_collision(scn, path, step=0.001, along="chords") is None
    assert result.min_clearance_m > 0


@pytest.mark.parametrize("name", BUNDLED)
def test_every_planner_steering_and_timing_returns_rows_valid_along_their_chords(name):
    scn = scenario_dict(name)
    seen = checker_scene(name)
    solved = 0
    for algorithm in ("rrt", "rrtstar"):
        for steering in planner.STEERINGS:
            for timing in ("constant", "optimal"):
                try:
                    result = planner.solve(planner.parse_scenario(scn), time_limit=None,
                                           iterations=2500, planner=algorithm,
                                           steering=steering, timing=timing, seed=1)
                except ScenarioError as e:  # the one refusal: a turn on the spot and a box
                    assert "footprint" in str(e) and steering == "straight", e
                    continue
                if result.solved:
                    solved += 1
                    chords_valid(seen, result)
    assert solved >= 4, f"{name}: only {solved} of 12 runs solved, too few to check"


@settings(max_examples=12, deadline=None)
@given(discs=st.lists(st.tuples(st.floats(1.5, 8.5), st.floats(1.5, 8.5), st.floats(0.2, 1.0)),
                      min_size=1, max_size=8),
       steering=st.sampled_from(list(planner.STEERINGS)), seed=st.integers(0, 5))
def test_random_scenes_return_rows_valid_along_their_chords(discs, steering, seed):
    scn = {"name": "random", "bounds": [0, 0, 10, 10], "start": [0.5, 0.5, 0.0],
           "goal": [9.5, 9.5, 0.0], "goal_tolerance": {"position": 0.3, "heading_deg": 30},
           "vehicle": {"radius": 0.2, "wheelbase": 0.44, "max_steer_deg": 35},
           "obstacles": [{"type": "circle", "center": [x, y], "radius": r} for x, y, r in discs
                         if math.hypot(x - 0.5, y - 0.5) > r + 0.3
                         and math.hypot(x - 9.5, y - 9.5) > r + 0.3]}
    result = planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=800,
                           steering=steering, seed=seed)
    if result.solved:
        chords_valid(scn, result)


def test_polyline_clearance_is_the_clearance_of_the_chords_not_of_the_arc():
    """Rows every 5 cm on a circle of radius 2 about a disc: the chords' midpoints come nearer
    to it by the sagitta, and so does the reported clearance."""
    scn = {"name": "ring", "bounds": [-5, -5, 5, 5], "start": [2.0, 0.0, math.pi / 2],
           "goal": [-2.0, 0.0, -math.pi / 2], "vehicle": {"radius": 0.1},
           "obstacles": [{"type": "circle", "center": [0, 0], "radius": 1.5}]}
    problem = planner.compile_problem(planner.parse_scenario(scn))
    step = 0.05 / 2.0  # rad: 5 cm of arc
    th = np.arange(0.0, math.pi + 1e-9, step)
    rows = np.column_stack([2 * np.cos(th), 2 * np.sin(th), th + math.pi / 2,
                            np.full_like(th, 0.5), np.ones_like(th), th])
    sag = 2.0 * (1.0 - math.cos(step / 2))
    assert sag <= chord_sag(2.0) < 1.001 * sag
    assert polyline_clearance(problem.world, rows, False) == pytest.approx(0.4 - sag, abs=1e-9)
    fine = polyline(rows, step=0.005)
    assert np.hypot(*np.diff(fine[:, :2], axis=0).T).max() <= 0.005 + 1e-12
    assert fine[-1].tolist() == rows[-1].tolist()


@settings(max_examples=25, deadline=None)
@given(obstacles=st.lists(st.tuples(st.floats(0.5, 9.5), st.floats(0.5, 9.5), st.floats(0.05, 1.0),
                                    st.booleans()), min_size=1, max_size=12),
       length=st.floats(0.0, 2.0), walk=st.lists(st.tuples(st.floats(-0.1, 0.1),
                                                           st.floats(-0.1, 0.1),
                                                           st.floats(-1.0, 1.0)),
                                                 min_size=1, max_size=60))
def test_the_least_clearance_measures_few_rows_and_is_every_rows_least(obstacles, length, walk):
    """`least_clearance` skips rows by how far the footprint moves (a rectangle's corners move
    with its heading too): it is exactly the least of measuring every row."""
    from planner._world import least_clearance, path_clearances

    vehicle = ({"footprint": {"type": "rectangle", "length": length, "width": 0.2}}
               if length > 0.3 else {"radius": 0.1})
    scn = {"name": "walk", "bounds": [0, 0, 10, 10], "start": [5, 5, 0], "goal": [9, 9, 0],
           "vehicle": vehicle, "obstacles": [
               {"type": "circle", "center": [x, y], "radius": r} if round_ else
               {"type": "polygon", "points": [[x - r, y - r], [x + r, y - r], [x, y + r]]}
               for x, y, r, round_ in obstacles]}
    try:
        world = planner.compile_problem(planner.parse_scenario(scn)).world
    except ScenarioError:  # the start or goal inside an obstacle
        assume(False)
    rows = np.vstack([[5.0, 5.0, 0.0], np.array(walk)]).cumsum(axis=0)
    rows = np.column_stack([rows, np.zeros((len(rows), 3))])
    assert least_clearance(world, rows, False) == path_clearances(world, rows, False).min()


@settings(max_examples=60, deadline=None)
@given(st.floats(-1.1, 1.1), st.floats(-20.0, 20.0), st.floats(0.01, 0.05), st.floats(0.0, 1.0))
def test_a_clothoids_chord_and_interpolated_heading_stay_within_the_two_sags(k0, sigma, length,
                                                                             reach):
    """Between two rows on a clothoid a footprint point ``reach`` m ahead of the pose, moved
    along the chord with the heading interpolated linearly, is within chord_sag + heading_sag of
    where it is on the curve."""
    from planner._clothoid import clothoid_pose
    from planner._rows import heading_sag

    assume(abs(k0 + sigma * length) <= 1.1)
    u = np.linspace(0.0, 1.0, 41)
    exact = np.array([clothoid_pose(0.0, 0.0, 0.0, k0, sigma, v * length) for v in u])
    end = exact[-1]
    chord = np.column_stack([u * end[0], u * end[1], u * end[2]])

    def ahead(p):
        return p[:, :2] + reach * np.column_stack([np.cos(p[:, 2]), np.sin(p[:, 2])])

    gap = np.hypot(*(ahead(exact) - ahead(chord)).T).max()
    assert gap <= chord_sag(1 / 1.1, length) + heading_sag(abs(sigma), reach, length) + 1e-12
