"""`trackstar plan` and `trackstar scenario` through the installed console script."""

import json
import subprocess
import time

import pytest
from conftest import scenario_dict

import planner
from app.animate import check_animation_path


def run(*args, timeout=120):
    return subprocess.run(["trackstar", *args], capture_output=True, text=True, timeout=timeout)


def test_plan_prints_one_json_object_with_the_contract_keys():
    out = run("plan", "slalom", "--json", "--time", "0.5")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    for key in ("solved", "cost", "time_to_first_solution_s", "iterations", "nodes",
                "collision_checks", "min_clearance_m", "path", "parameters"):
        assert key in data
    assert data["solved"] and all(len(p) == 3 for p in data["path"])
    assert data["parameters"]["planner"] == "rrtstar" and data["parameters"]["time"] == 0.5
    assert data["parameters"]["seed"] == 0 and data["parameters"]["eps"] > 0


def test_plan_with_iterations_is_reproducible_and_echoes_options():
    args = ("plan", "open_field", "--json", "--iterations", "800",
            "--seed", "3", "--planner", "rrt", "--steering", "dubins")
    a, b = json.loads(run(*args).stdout), json.loads(run(*args).stdout)
    assert a["path"] == b["path"] and a["iterations"] == b["iterations"]
    assert a["parameters"]["planner"] == "rrt" and a["parameters"]["iterations"] == 800
    assert a["parameters"]["time"] is None


def test_moving_obstacles_give_timed_paths():
    data = json.loads(run("plan", "crossing", "--json",
                          "--iterations", "2000").stdout)
    assert data["solved"] and all(len(p) == 4 for p in data["path"])
    assert data["arrival_time_s"] == pytest.approx(data["path"][-1][3])


def test_human_summary_without_json():
    out = run("plan", "slalom", "--iterations", "1500")
    assert out.returncode == 0 and "cost" in out.stdout and "iterations" in out.stdout


def test_unsolved_is_exit_0_with_solved_false(tmp_path):
    scn = scenario_dict("open_field")
    scn["obstacles"].append({"type": "polygon", "points": [[0, 10], [20, 10], [20, 10.5],
                                                           [0, 10.5]]})
    path = tmp_path / "walled.json"
    path.write_text(json.dumps(scn))
    out = run("plan", str(path), "--json", "--iterations", "500")
    assert out.returncode == 0
    data = json.loads(out.stdout)
    assert data["solved"] is False and data["path"] == [] and data["cost"] is None


@pytest.mark.parametrize("content, message", [
    (None, "no such scenario file or bundled scenario"),
    ("{not json", "not valid JSON"),
    ('{"name": "x", "bounds": [0, 0, 1, 1], "start": [0.5, 0.5, 0], "goal": [0.6, 0.6, 0], '
     '"obstacles": [], "vehicel": {}}', "did you mean 'vehicle'"),
    ('{"name": "x", "bounds": [0, 0, 1, 1], "start": [0.5, 0.5, 0], "goal": [0.6, 0.6, 0], '
     '"obstacles": [{"type": "circle", "center": [0.5, 0.5], "radius": 0.2}]}', "start"),
    ('{"name": "x", "bounds": [0, 0, 1, 1], "start": [NaN, 0.5, 0], "goal": [0.6, 0.6, 0], '
     '"obstacles": []}', "NaN"),
    ('[1, 2]', "JSON object"),
])
def test_bad_input_exits_2_with_one_line_quickly(tmp_path, content, message):
    path = tmp_path / "bad.json"
    if content is not None:
        path.write_text(content)
    started = time.perf_counter()
    out = run("plan", str(path), "--json")
    assert time.perf_counter() - started < 10
    assert out.returncode == 2
    assert out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0]


@pytest.mark.parametrize("args, words", [
    (("plan", "slalom", "--planner", "prm"), "'--planner'"),
    (("plan", "slalom", "--steering", "foo"), "'foo' is not one of"),
    (("plan", "slalom", "--time", "-1"), "--time: Input should be greater than 0"),
    (("plan", "slalom", "--goal-bias", "1.5"), "--goal-bias: Input should be less than 1"),
    (("plan", "slalom", "--iterations", "0"), "--iterations: Input should be greater than or equal to 1"),
    (("plan", "slalom", "--timing", "fast"), "'fast' is not one of 'constant', 'optimal'"),
    (("plan", "train", "--timing", "optimal", "--speed", "3"),
     "speed: 3 m/s is above vehicle.max_speed (2 m/s)"),
    (("plan",), "Missing argument"),
    (("plan", "slalom", "--bogus"), "No such option: --bogus"),
    (("nonsense",), "No such command"),
])
def test_usage_errors_exit_2_with_one_line(args, words):
    out = run(*args)
    assert out.returncode == 2 and out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], out.stderr


def test_help_keeps_bracketed_defaults_and_units():
    plan = run("plan", "--help").stdout
    assert "[default: 1.0, or none when an iteration budget is given]" in " ".join(plan.split())
    sample = " ".join(run("track", "sample", "--help").stdout.split())
    assert "[m]" in sample and "Wheelbase L [m]" in sample


def test_bundled_scenarios_by_name_from_any_directory(tmp_path):
    listed = json.loads(run("scenario", "list", "--json").stdout)
    names = [r["name"] for r in listed]
    assert names == sorted(names)
    for name in ("open_field", "hallway", "slalom", "parking", "oval_track", "crossing"):
        assert name in names
    kinds = {r["name"]: r["moving"] for r in listed}
    assert kinds["crossing"] and not kinds["slalom"] and kinds["thesis_half_lap"]
    assert all(r["description"] for r in listed)
    text = run("scenario", "list").stdout.splitlines()
    assert len(text) == len(listed) and text[0].split()[:2] == [names[0], "moving"
                                                                  if listed[0]["moving"]
                                                                  else "static"]
    out = subprocess.run(["trackstar", "plan", "slalom", "--time", "0.3", "--json"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and json.loads(out.stdout)["solved"], out.stderr
    assert run("scenario", "check", "thesis_static").stdout.strip() == "thesis_static: ok"


def test_a_file_beside_a_bundled_name_wins_and_unknown_names_list_the_bundled(tmp_path):
    scn = scenario_dict("open_field")
    scn["name"] = "my-field"
    (tmp_path / "slalom").write_text(json.dumps(scn))
    out = subprocess.run(["trackstar", "scenario", "check", "slalom"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    assert out.stdout.strip() == "my-field: ok"
    out = run("plan", "slalmo")
    assert out.returncode == 2 and "bundled: back_up, crossing" in out.stderr


def test_rrt_says_it_stops_at_its_first_solution():
    out = run("plan", "slalom", "--planner", "rrt", "--time", "0.5")
    assert out.returncode == 0 and "RRT stops at its first solution" in out.stdout


def test_scenario_schema_and_check():
    schema = json.loads(run("scenario", "schema").stdout)
    assert schema["title"] == "Scenario"
    assert run("scenario", "check", "crossing").returncode == 0


def test_straight_steering_plans_checked_straight_paths_from_the_command_line():
    """`plan SCENARIO --steering straight --json`, exactly checked by the independent checker
    (in space-time where obstacles move), curvature 0. The static reference scenarios are
    planned in-process with straight steering in test_planner."""
    from checker import first_collision

    for name in ("parking", "crossing"):
        out = run("plan", name, "--steering", "straight", "--iterations", "3000", "--json")
        assert out.returncode == 0, out.stderr
        data = json.loads(out.stdout)
        scn = scenario_dict(name)
        assert data["solved"] and data["parameters"]["steering"] == "straight", name
        assert data["max_abs_curvature"] == 0.0
        assert first_collision(scn, data["path"]) is None, name
        (x, y, *_), (gx, gy, _) = data["path"][-1], scn["goal"]
        assert ((x - gx) ** 2 + (y - gy) ** 2) ** 0.5 <= 0.25 + 1e-9


def test_straight_steering_refuses_a_rectangular_footprint(tmp_path):
    scn = dict(scenario_dict("open_field"), vehicle={"footprint": {"type": "rectangle", "length": 0.6, "width": 0.3}})
    path = tmp_path / "box.json"
    path.write_text(json.dumps(scn))
    out = run("plan", str(path), "--steering", "straight", "--json")
    assert out.returncode == 2 and out.stdout == ""
    assert "vehicle.radius" in out.stderr and len(out.stderr.strip().splitlines()) == 1


def test_a_safety_margin_that_leaves_no_room_is_one_line_naming_it():
    out = subprocess.run(["trackstar", "plan", "hallway", "--safety-margin", "9"],
                         capture_output=True, text=True)
    assert out.returncode == 2 and out.stderr.count("\n") == 1
    assert "start [1.2, 1.3, 0.0]" in out.stderr and "safety margin of 9 m" in out.stderr


def test_animate_writes_a_gif_of_the_tree_growing(tmp_path):
    from PIL import Image, ImageChops

    gif = tmp_path / "run.gif"
    out = subprocess.run(["trackstar", "plan", "slalom", "--iterations", "400", "--animate",
                          str(gif)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    with Image.open(gif) as im:
        assert im.n_frames >= 20 and im.size[0] >= 640 and im.size[1] >= 480
        first = im.convert("RGB")
        im.seek(im.n_frames - 1)
        assert ImageChops.difference(first, im.convert("RGB")).getbbox() is not None
    with pytest.raises(ValueError, match="written as a .gif"):
        check_animation_path(tmp_path / "a.avi")


def test_an_animated_run_is_the_run_and_the_studio_gets_it_as_a_gif():
    """Planning in 40 parts (the frames) grows the same tree as in one; the studio's download
    draws the run of its settings."""
    import io

    from PIL import Image

    from app.animate import FRAMES, FrameRecorder, animation_gif
    from app.planning import run_plan

    options = planner.PlanOptions(iterations=300, seed=2)
    slalom = planner.load_scenario("slalom")
    whole = run_plan(slalom, options)
    recorder = FrameRecorder()
    parts = run_plan(slalom, options, observe=recorder, chunks=FRAMES)
    assert (parts.cost, parts.nodes, parts.path) == (whole.cost, whole.nodes, whole.path)
    assert [f.iterations for f in recorder.frames][-1] == 300 and len(recorder.frames) == FRAMES
    gif = animation_gif(planner.compile_problem(slalom), options)
    with Image.open(io.BytesIO(gif)) as im:
        assert im.format == "GIF" and im.n_frames == FRAMES


def test_the_studios_animation_is_the_run_on_screen():
    """Timing optimal among movers (issue 33, item 4): the GIF plans with the studio's planner
    (not the constant-speed one), to the iterations the screen shows, so its last tree frame
    has the panel's nodes and cost; then the car drives the result while the mover moves."""
    import io

    from PIL import Image, ImageChops

    from app.animate import DRIVE_FRAMES, FRAMES, FrameRecorder, animation_gif
    from app.planning import advance_in_parts
    from app.studio._worker import Lane

    problem = planner.compile_problem(planner.load_scenario("crossing"))
    options = planner.PlanOptions(iterations=2000, seed=1, timing="optimal")
    lane = Lane(problem, options)  # the studio's run, stepped in its uneven batches
    for batch in (1, 7, 50, 130, 62):
        lane.advance(batch, stepping=False)
    shown = lane.metrics()
    recorder = FrameRecorder()
    advance_in_parts(planner.planner_for(problem, options), None, lane.stepped, FRAMES, recorder)
    last = recorder.frames[-1]
    assert (last.iterations, last.tree.nodes, last.cost) == (
        shown["iterations"], shown["nodes"], shown["cost"])
    constant = FrameRecorder()  # what the download drew before: another run
    at_constant_speed = options.model_copy(update={"timing": "constant"})
    advance_in_parts(planner.planner_for(problem, at_constant_speed), None, lane.stepped, FRAMES,
                     constant)
    assert constant.frames[-1].tree.nodes != shown["nodes"]

    gif = animation_gif(problem, options, lane.stepped)
    with Image.open(io.BytesIO(gif)) as im:
        assert im.n_frames == FRAMES + DRIVE_FRAMES
        frames = []
        for k in (FRAMES - 1, FRAMES + DRIVE_FRAMES // 2, FRAMES + DRIVE_FRAMES - 1):
            im.seek(k)
            frames.append(im.convert("RGB"))
    for a, b in zip(frames, frames[1:]):  # the car and the disc move
        assert ImageChops.difference(a, b).getbbox() is not None
