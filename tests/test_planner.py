"""RRT and RRT* on the reference scenarios, validated by the independent checker."""

import math

import numpy as np
import pytest
from checker import arc_mismatch, clothoid_mismatch, first_collision
from conftest import STATIC, scenario_dict

import planner


def plan(name, iterations=3000, **kw):
    scn = planner.parse_scenario(scenario_dict(name))
    return planner.solve(scn, time_limit=None, iterations=iterations, **kw)


@pytest.mark.parametrize("name", STATIC)
@pytest.mark.parametrize("steering", list(planner.STEERINGS))
def test_paths_are_valid_continuous_and_feasible(name, steering):
    result = plan(name, iterations=4000, steering=steering)
    assert result.solved, f"{name} not solved in 4000 iterations"
    scn = scenario_dict(name)
    path = result.path
    rho = 0.44 / math.tan(math.radians(26))
    assert path[0, :3] == pytest.approx(scn["start"], abs=1e-12)
    gx, gy, gth = scn["goal"]
    assert math.hypot(path[-1, 0] - gx, path[-1, 1] - gy) <= 0.25 + 1e-9
    if not planner.STEERINGS[steering].heading_free:  # else the goal is reached by position
        assert abs(math.remainder(path[-1, 2] - gth, 2 * math.pi)) <= math.radians(20) + 1e-9
    assert np.all(np.hypot(*np.diff(path[:, :2], axis=0).T) <= 0.05 + 1e-9)
    assert np.all(np.abs(path[:, 3]) <= 1 / rho + 1e-9)
    if steering == "straight":
        assert np.all(path[:, 3] == 0.0)
    if planner.STEERINGS[steering].continuous:  # κ ramps within the servo's rate (180°/s)
        assert clothoid_mismatch(path) < 1e-9
        sigma = math.radians(180) / (result.options.speed * 0.44)
        steps = np.hypot(*np.diff(path[:, :2], axis=0).T)
        assert np.all(np.abs(np.diff(path[:, 3])) <= sigma * steps + 1e-12)
    else:
        assert arc_mismatch(path[:, :3]) < 1e-6
    assert first_collision(scn, path[:, :3]) is None
    # The reported cost is the driven length of the returned path.
    steps = np.hypot(*np.diff(path[:, :2], axis=0).T)
    assert result.cost == pytest.approx(steps.sum(), rel=2e-3)
    assert result.min_clearance_m > 0


def test_reeds_shepp_reverses_into_the_parking_slot_and_is_never_longer():
    dub = plan("parking", iterations=6000, steering="dubins")
    rs = plan("parking", iterations=6000, steering="reeds-shepp")
    assert rs.solved and dub.solved
    assert np.any(rs.path[:, 4] < 0), "Reeds-Shepp should use reverse somewhere"
    assert np.all(dub.path[:, 4] > 0)


def test_same_seed_same_tree_other_seed_other_tree():
    a = plan("slalom", iterations=1500, seed=7)
    b = plan("slalom", iterations=1500, seed=7)
    c = plan("slalom", iterations=1500, seed=8)
    assert a.cost == b.cost and a.nodes == b.nodes and np.array_equal(a.path, b.path)
    assert (c.cost, c.nodes) != (a.cost, a.nodes)


def test_rrtstar_cost_never_increases():
    result = plan("open_field", iterations=6000)
    costs = [c for _, c, _ in result.cost_over_time]
    assert len(costs) > 3
    assert all(b < a for a, b in zip(costs, costs[1:]))
    assert costs[-1] == result.cost
    iterations = [i for _, _, i in result.cost_over_time]
    assert iterations == sorted(iterations) and iterations[-1] <= result.iterations


def test_rrtstar_beats_rrt_on_average_over_seeds():
    star = [plan("slalom", iterations=3000, seed=s).cost for s in range(4)]
    rrt = [plan("slalom", iterations=3000, seed=s, planner="rrt").cost for s in range(4)]
    assert np.mean(star) < np.mean(rrt)


def test_rrt_stops_at_its_first_solution():
    result = plan("open_field", iterations=20000, planner="rrt")
    assert result.solved and result.iterations < 20000
    assert len(result.cost_over_time) == 1


def test_events_report_every_iteration_and_cost_nothing_without_listener():
    scn = planner.parse_scenario(scenario_dict("slalom"))
    problem = planner.compile_problem(scn)
    seen = []
    watched = planner.Planner(problem)
    watched.add_listener(seen.append)
    for _ in range(200):
        watched.step(1)
    quiet = planner.Planner(problem)
    quiet.step(200)
    # Observing does not change the run.
    assert np.array_equal(watched.snapshot().pose, quiet.snapshot().pose)
    assert [int(i) for e in seen for i in e.iteration] == list(range(1, 201))
    rewires = [r for e in seen for r in e.rewires]
    snap = watched.snapshot()
    added = {int(e.new[0]): int(e.parent[0]) for e in seen if e.new[0] >= 0}
    polished = [int(n) for e in seen for n in e.polished]
    assert len(added) + len(polished) == snap.nodes - 1  # every node but the root, added once
    assert not set(added) & set(polished)
    for e in seen:
        if e.new[0] >= 0:  # x_new's parent is x_min, one of its near nodes or x_nearest
            assert e.parent[0] in set(e.near_of(0)) | {e.nearest[0]}
            assert 0 < e.radius[0] < math.inf
    for r in rewires:
        assert r.old_parent != r.new_parent and added[r.new_parent] >= 0
    assert rewires, "slalom rewires within 200 iterations"
    # The last rewire of each node is its current parent; the others kept their first one.
    last = {**added, **{r.node: r.new_parent for r in rewires}}
    assert all(snap.parent[n] == p for n, p in last.items())


def test_events_name_every_near_node_and_rewire_however_many():
    """A replay draws what the events name. With k = 30·log n nearest (OMPL's default is
    5.5), one iteration's near set outgrows the 64 entries a one-iteration batch was given:
    the kernel stops the batch, the buffers grow, and nothing is dropped."""
    problem = planner.compile_problem(planner.parse_scenario(scenario_dict("slalom")))
    run = planner.Planner(problem, planner.PlanOptions(seed=2, k_rrt=30.0))
    seen = []
    run.add_listener(seen.append)
    for _ in range(300):
        before = run.nodes
        run.step(1)
        e = seen[-1]
        if e.new[0] >= 0:  # exactly the k nearest of the nodes there were
            assert len(e.near_of(0)) == min(before, math.ceil(30.0 * math.log(before + 1)))
    assert max(len(e.near_of(0)) for e in seen) > 64
    assert sum(len(e.rewires) for e in seen) == run.rewires


def test_unsolvable_scenario_reports_unsolved():
    scn = scenario_dict("open_field")
    scn["obstacles"].append({"type": "circle", "center": [19, 19], "radius": 0.1})
    scn["goal"] = [19.0, 17.0, 1.5708]
    # A wall across the field: no way through.
    scn["obstacles"].append({"type": "polygon", "points": [[0, 10], [20, 10], [20, 10.5],
                                                           [0, 10.5]]})
    result = planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=1500)
    assert not result.solved and result.cost is None and len(result.path) == 0


@pytest.mark.parametrize("mutate, message", [
    (lambda s: s.update(start=[5.0, 5.0, 0.0]), "start"),  # inside a circle? checked below
    (lambda s: s.update(goal=[-1.0, 5.0, 0.0]), "goal"),
])
def test_start_or_goal_in_collision_is_rejected(mutate, message):
    scn = scenario_dict("slalom")
    mutate(scn)
    scn["obstacles"].append({"type": "circle", "center": [5.0, 5.0], "radius": 0.5})
    with pytest.raises(planner.ScenarioError, match=message):
        planner.compile_problem(planner.parse_scenario(scn))


def test_k_nearest_variant_finds_valid_paths_and_rewires():
    result = plan("slalom", iterations=3000, k_rrt=5.5)
    assert result.solved and result.rewires > 0
    assert first_collision(scenario_dict("slalom"), result.path[:, :3]) is None
    assert result.options.k_rrt == 5.5


def test_live_poses_are_a_read_only_view_and_the_root_edge_is_a_dot():
    problem = planner.compile_problem(planner.parse_scenario(scenario_dict("slalom")))
    run = planner.Planner(problem)
    run.step(300)
    poses = run.poses
    assert np.array_equal(poses, run.snapshot().pose) and not poses.flags.writeable
    assert run.edge_points(0, 4) == pytest.approx(np.repeat(poses[:1, :2], 5, axis=0))


@pytest.mark.parametrize("steering", list(planner.STEERINGS))
@pytest.mark.parametrize("name", ["hallway", "oval_track"])
def test_nearest_is_the_true_nearest_by_steering_length(name, steering):
    """The pruned best-first search returns what a scan of every node returns (OMPL's way)."""
    from planner import Planner, PlanOptions
    from planner import _kernel as K
    from planner._paths import path_buffers
    from planner._steer import steer_path

    problem = planner.compile_problem(planner.parse_scenario(scenario_dict(name)))
    run = Planner(problem, PlanOptions(steering=steering, seed=3))
    run.step(3000)
    tree, n = run._tree, run.nodes
    code = planner.STEERINGS[steering].code
    path = path_buffers(planner.STEERINGS[steering].segments)
    rng = np.random.default_rng(0)
    xmin, ymin, xmax, ymax = problem.bounds
    for _ in range(150):
        q = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        node, found = K.nearest(tree, run._P, K.turning(run._P), *q)
        lengths = [steer_path(code, *tree.pose[j], *q, K.turning(run._P), *path)
                   for j in range(n)]
        assert found == pytest.approx(min(lengths), abs=1e-9)
        assert lengths[node] == pytest.approx(found, abs=1e-9)


def test_first_solution_time_falls_inside_its_batch():
    """One batch of 4000 iterations: the first solution's time is interpolated from the
    iteration the kernel records, not the batch's end."""
    problem = planner.compile_problem(planner.parse_scenario(scenario_dict("open_field")))
    run = planner.Planner(problem, planner.PlanOptions(seed=2))
    run.step(4000)
    result = run.result()
    assert result.solved
    assert 0.0 < result.time_to_first_solution_s < 0.5 * result.planning_time_s
    times = [t for t, _, _ in result.cost_over_time]
    assert times[0] == result.time_to_first_solution_s and times == sorted(times)
    assert times[-1] <= result.planning_time_s


def test_the_cost_curve_is_the_same_for_a_seed_whatever_the_batches():
    """Improvements are recorded by the kernel at their iteration: batch sizes do not matter."""
    problem = planner.compile_problem(planner.parse_scenario(scenario_dict("slalom")))
    one = planner.Planner(problem, planner.PlanOptions(seed=4))
    one.step(3000)
    many = planner.Planner(problem, planner.PlanOptions(seed=4))
    for n in (1, 7, 500, 992, 1500):
        many.step(n)
    curve = [(c, i) for _, c, i in one.result().cost_over_time]
    assert curve == [(c, i) for _, c, i in many.result().cost_over_time] and len(curve) > 3


def test_the_se2_metric_picks_the_se2_nearest_and_still_plans_exact_paths():
    """`metric="se2"`: the nearest node by √(Δx² + Δy² + (ρΔθ)²), as a scan of every node
    finds it; the edges are still the exact steering paths, so the paths check out."""
    from planner import Planner, PlanOptions
    from planner import _kernel as K

    problem = planner.compile_problem(planner.parse_scenario(scenario_dict("slalom")))
    run = Planner(problem, PlanOptions(metric="se2", seed=3))
    run.step(2000)
    tree, rho = run.snapshot(), problem.rho
    rng = np.random.default_rng(1)
    xmin, ymin, xmax, ymax = problem.bounds
    for _ in range(100):
        q = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        node, found = K.nearest(run._tree, run._P, K.turning(run._P), *q)
        d = np.sqrt(((tree.pose[:, :2] - q[:2]) ** 2).sum(axis=1)
                    + (rho * np.remainder(q[2] - tree.pose[:, 2] + math.pi, 2 * math.pi)
                       - rho * math.pi) ** 2)
        assert found == pytest.approx(d.min(), abs=1e-9) and d[node] == pytest.approx(found)
    result = plan("slalom", iterations=4000, metric="se2")
    assert result.solved and first_collision(scenario_dict("slalom"), result.path[:, :3]) is None
    assert arc_mismatch(result.path[:, :3]) < 1e-6
    assert result.cost != plan("slalom", iterations=4000).cost  # another tree


def test_a_safety_margin_is_kept_from_every_obstacle_and_wall():
    """vehicle.safety_margin grows the checked footprint: the path of a disc car keeps it, as
    an independent check with the disc grown by the margin confirms."""
    scn = scenario_dict("hallway")
    scn["vehicle"] = {**scn.get("vehicle", {}), "safety_margin": 0.1}
    result = planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=2500)
    assert result.solved and result.min_clearance_m >= 0.1
    grown = {**scn, "vehicle": {**scn["vehicle"], "radius": scn["vehicle"]["radius"] + 0.1}}
    assert first_collision(grown, result.path[:, :3]) is None
    scn["vehicle"]["safety_margin"] = 5.0
    with pytest.raises(planner.ScenarioError, match="with the safety margin of 5 m"):
        planner.compile_problem(planner.parse_scenario(scn))


@pytest.mark.parametrize("seed", [0, 1])
def test_polishing_finds_where_to_enter_the_goal_region(seed):
    """Start (1, 1, 0), goal (11, 1, 0) ± 0.25 m and 20°, nothing in the way: the shortest
    path drives straight on and stops where it enters the goal disc, after 10 − 0.25 m — not
    at whatever goal pose the tree sampled."""
    scn = {"name": "goal entry", "bounds": [0, 0, 12, 3],
           "vehicle": {"wheelbase": 0.44, "max_steer_deg": 26.0, "radius": 0.0},
           "start": [1.0, 1.0, 0.0], "goal": [11.0, 1.0, 0.0],
           "goal_tolerance": {"position": 0.25, "heading_deg": 20.0}, "obstacles": []}
    result = planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=3000,
                           seed=seed)
    assert result.cost == pytest.approx(9.75, rel=1e-3)  # the last step: 1/128 of an edge
    assert math.hypot(result.path[-1, 0] - 11.0, result.path[-1, 1] - 1.0) <= 0.25 + 1e-12
    unpolished = planner.solve(planner.parse_scenario(scn), time_limit=None, iterations=3000,
                               seed=seed, polish=False)
    assert unpolished.cost > result.cost + 0.01


def test_polishing_keeps_to_its_share_of_the_work_and_its_time_is_reported():
    """Issue 31: polishing took over two thirds of a 1 s run on the stadium lap. Its budget is
    counted in clearance evaluations (a seed's run is the same anywhere), and its time is
    measured apart (`polish_s`)."""
    import planner._kernel as K

    problem = planner.compile_problem(planner.load_scenario("oval_track"))
    run = planner.planner_for(problem, planner.PlanOptions(seed=1))
    run.advance(None, 20_000)
    cnt = run._tree.cnt
    search = cnt[K.EVALS] - cnt[K.POLISH_EVALS]
    assert 0 < cnt[K.POLISH_EVALS]
    assert cnt[K.POLISH_EVALS] <= K.POLISH_SHARE / (1 - K.POLISH_SHARE) * search + K.POLISH_FREE
    result = run.result()
    assert 0.0 < result.polish_s < result.planning_time_s
    again = planner.planner_for(problem, planner.PlanOptions(seed=1))
    again.advance(None, 20_000)
    assert again.result().cost == result.cost  # counted, not timed: the same run
    off = planner.solve(problem, time_limit=None, iterations=2000, seed=1, polish=False)
    assert off.polish_s == 0.0
