"""`trackstar study`: a grid of plans from one file, stored run by run, resumable."""

from __future__ import annotations

import csv
import json
import os
import re
import secrets
import signal
import socket
import sqlite3
import subprocess
import sys
import time
from contextlib import contextmanager

import numpy as np
import pytest
from _server import free_port

STUDY = """\
name: small
description: two scenarios, two planners, two eps, two seeds
scenarios: [open_field, ./my/slalom.json]
planners: [rrt, rrtstar]
parameters:
  eps: [1.0, 2.5]
seeds: 2
budget:
  iterations: 400
"""
DETERMINISTIC = ("scenario", "planner", "steering", "parameters", "budget_iterations", "seed",
                 "solved", "cost", "iterations", "nodes", "collision_checks", "min_clearance_m")


def trackstar(*args, cwd=None, timeout=120):
    return subprocess.run(["trackstar", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=timeout)


@pytest.fixture
def study_file(tmp_path):
    """The study beside a scenario file it names by a relative path."""
    from conftest import scenario_dict

    (tmp_path / "my").mkdir()
    (tmp_path / "my" / "slalom.json").write_text(json.dumps(scenario_dict("slalom")))
    path = tmp_path / "small.yaml"
    path.write_text(STUDY)
    return path


def rows(out, columns=DETERMINISTIC):
    with sqlite3.connect(out / "results.sqlite") as db:
        return sorted(db.execute(f"SELECT {', '.join(columns)} FROM runs"))


def test_a_study_runs_its_grid_and_stores_the_numbers_plan_prints(study_file, tmp_path):
    started = time.perf_counter()
    out = trackstar("study", str(study_file), "--json", cwd=tmp_path / "my")  # a path relative to the file
    assert out.returncode == 0, out.stderr
    summary = json.loads(out.stdout)
    assert time.perf_counter() - started < 60
    # 2 scenarios × (2 planners × 2 eps) × 2 seeds
    assert {k: summary[k] for k in ("study", "total", "done", "skipped", "failed")} == {
        "study": "small", "total": 16, "done": 16, "skipped": 0, "failed": 0}
    default_out = tmp_path / "my" / "studies" / "small"
    assert summary["out"] == "studies/small" and (default_out / "results.csv").is_file()
    table = rows(default_out)
    assert len(table) == 16 and len({r[:6] for r in table}) == 16
    # A row is what `trackstar plan` prints for the same settings.
    for scenario, planner_name, _, params, iterations, seed, *numbers in table[3::8]:
        source = "open_field" if scenario == "open_field" else str(tmp_path / "my/slalom.json")
        plan = json.loads(trackstar(
            "plan", source, "--planner", planner_name, "--eps", str(json.loads(params)["eps"]),
            "--iterations", str(iterations), "--seed", str(seed), "--json").stdout)
        assert numbers == [int(plan["solved"]), plan["cost"], plan["iterations"], plan["nodes"],
                           plan["collision_checks"], plan["min_clearance_m"]]
    # The CSV is the table; the cost curves end at each run's cost and never rise.
    with (default_out / "results.csv").open() as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames)[:3] == ("id", "study", "scenario")
        runs = list(reader)
        assert len(runs) == 16
        assert all(0.0 <= float(r["polish_s"]) < float(r["wall_s"]) for r in runs)
    check_report(default_out, ["open_field", "slalom"])
    with sqlite3.connect(default_out / "results.sqlite") as db:
        assert db.execute("PRAGMA user_version").fetchone() == (3,)
        for run_id, cost in db.execute("SELECT id, cost FROM runs WHERE solved"):
            curve = [c for (c,) in db.execute("SELECT cost FROM cost_over_time WHERE run_id = ? "
                                              "ORDER BY iteration", (run_id,))]
            assert curve[-1] == cost and curve == sorted(curve, reverse=True)


def check_report(out, scenarios):
    """One self-contained page: every image inline, nothing fetched; the best-setting table,
    and per scenario the success, box plots and cost curve, also as PNGs in figures/."""
    page = (out / "report.html").read_text()
    sources = re.findall(r"""(?:src|href)\s*=\s*["']?([^"' >]+)""", page)
    assert sources and all(src.startswith("data:image/png;base64,") for src in sources)
    assert "http" not in page.replace("http-equiv", "") and "@import" not in page
    assert "Best setting per scenario" in page
    for scenario in scenarios:
        assert f"<h2>{scenario}</h2>" in page
        for name in ("success", "cost", "time_to_first_solution_s", "cost_over_time",
                     "against_eps"):
            assert (out / "figures" / f"{scenario}_{name}.png").stat().st_size > 1000
    assert len(re.findall("<img", page)) == len(list((out / "figures").glob("*.png")))


def test_same_study_twice_same_rows_and_a_rerun_or_an_extension_redoes_nothing(study_file,
                                                                               tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    study_file.write_text(STUDY.replace(", ./my/slalom.json", ""))
    assert trackstar("study", str(study_file), "--out", str(a), "--workers", "1").returncode == 0
    assert trackstar("study", str(study_file), "--out", str(b), "--workers", "2").returncode == 0
    assert rows(a) == rows(b)
    study_file.write_text(STUDY.replace(", ./my/slalom.json", "").replace("seeds: 2", "seeds: 3"))
    (a / "report.html").unlink()
    more = trackstar("study", str(study_file), "--out", str(a), "--json")
    assert "8 of 12 runs already in" in more.stderr
    assert json.loads(more.stdout)["skipped"] == 8 and json.loads(more.stdout)["done"] == 12
    assert set(rows(b)) < set(rows(a)) and len(rows(a)) == 12
    assert (a / "report.html").is_file()  # rebuilt over all rows


# Ctrl-C for a process, 2 s after a file appears: a process of its own, as a user's terminal
# is. (Sent from the test's process, the signal came after all 64 runs in CI, three times in
# a row, though this process only polled and slept; never when the test ran alone.)
CTRL_C_LATER = """import os, pathlib, signal, sys, time
path, pid = pathlib.Path(sys.argv[1]), int(sys.argv[2])
deadline = time.monotonic() + 90
while not path.exists() and time.monotonic() < deadline:
    time.sleep(0.05)
time.sleep(2.0)
os.kill(pid, signal.SIGINT)
"""


def test_ctrl_c_keeps_finished_runs_and_the_next_invocation_goes_on(study_file, tmp_path):
    study_file.write_text(STUDY.replace("iterations: 400", "iterations: 4000").replace(
        "seeds: 2", "seeds: 8"))
    out = tmp_path / "out"
    # Ctrl-C as a terminal delivers it: a process that ignores SIGINT hands the ignoring on
    # to its children, so the study gets the default disposition back whatever this one has.
    proc = subprocess.Popen(["trackstar", "study", str(study_file), "--out", str(out),
                             "--workers", "1"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    ctrl_c = subprocess.Popen([sys.executable, "-c", CTRL_C_LATER, str(out / "results.sqlite"),
                               str(proc.pid)])
    out_text, err = proc.communicate(timeout=120)
    ctrl_c.wait(timeout=10)
    assert proc.returncode == 130, out_text + err
    assert "run the same command again" in err
    kept = rows(out)
    assert 1 <= len(kept) < 64
    done = trackstar("study", str(study_file), "--out", str(out), "--json", timeout=300)
    summary = json.loads(done.stdout)
    assert summary["skipped"] == len(kept) and summary["done"] == 64
    assert set(kept) <= set(rows(out)) and len(rows(out)) == 64


@pytest.mark.parametrize("body, words", [
    (STUDY.replace("planners:", "planers:"), "unknown key 'planers' (did you mean 'planners'?)"),
    (STUDY.replace("[rrt, rrtstar]", "[rrt, prm]"), "planners[1]: 'prm' is not a planner"),
    (STUDY.replace("[rrt, rrtstar]", "[rrt, rrt_turbo]"),
     "planners[1]: 'rrt_turbo' is not a planner (did you mean 'rrt'?)"),
    (STUDY.replace("eps: [1.0, 2.5]", "eps: [1.0, -1]"), "eps[1] = -1"),
    (STUDY.replace("eps:", "epsilon:"), "unknown parameter 'epsilon' (did you mean 'eps'?)"),
    (STUDY.replace("eps: [1.0, 2.5]", "eps: []"), "parameters.eps"),
    (STUDY.replace("open_field", "no_such_scenario"), "scenarios[0] (no_such_scenario)"),
    (STUDY.replace("seeds: 2", "seeds: 0"), "seeds"),
    (STUDY.replace("[1.0, 2.5]", "{min: 0.5, max: 3}"), "a range needs 'sample'"),
    (STUDY.replace("[1.0, 2.5]", "{min: 3, max: 0.5}") + "sample: 4\n", "min must be below max"),
    (STUDY.replace("[1.0, 2.5]", "{min: -1, max: 2}") + "sample: 4\n", "eps.min = -1.0"),
    (STUDY.replace("  iterations: 400", "  {}"), "budget"),
    (STUDY.replace("name: small", "name: a b"), "name"),
    (STUDY.replace("budget:", "budget: ["), "not valid YAML"),
    ("- just\n- a list\n", "a study is a mapping"),
    (STUDY.replace("[rrt, rrtstar]", "[rrt, ompl:bitstar]") + "steering: [straight]\n",
     "steering: ompl:bitstar plans dubins or reeds-shepp only, not 'straight'"),
    (STUDY.replace("[rrt, rrtstar]", "[ompl:rrtstar]").replace("open_field", "crossing"),
     "scenarios[0] (crossing): has moving obstacles, which OMPL's planners cannot plan"),
])
def test_a_bad_study_file_is_refused_naming_the_key(study_file, body, words):
    from app.study.spec import StudyError, load_study

    study_file.write_text(body)
    with pytest.raises(StudyError) as refused:
        load_study(study_file)
    assert words in str(refused.value) and "\n" not in str(refused.value)


@pytest.mark.parametrize("edit", [lambda s: s.replace("planners:", "planers:"),
                                  lambda s: s.replace("open_field", "no_such_scenario")])
def test_a_bad_study_file_exits_2_with_one_line_and_writes_nothing(study_file, tmp_path, edit):
    study_file.write_text(edit(STUDY))
    started = time.perf_counter()
    out = trackstar("study", str(study_file), "--out", str(tmp_path / "out"), timeout=30)
    assert time.perf_counter() - started < 5
    assert out.returncode == 2 and out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and str(study_file) in lines[0]
    assert not (tmp_path / "out").exists()


def test_a_directory_of_another_study_is_refused(study_file, tmp_path):
    out = tmp_path / "out"
    study_file.write_text(STUDY.replace("seeds: 2", "seeds: 1").replace(", ./my/slalom.json", "")
                          .replace("[rrt, rrtstar]", "[rrt]").replace("400", "50"))
    assert trackstar("study", str(study_file), "--out", str(out)).returncode == 0
    study_file.write_text(STUDY.replace("name: small", "name: other"))
    refused = trackstar("study", str(study_file), "--out", str(out))
    assert refused.returncode == 2 and "'small'" in refused.stderr and "'other'" in refused.stderr


def test_a_sample_draws_the_same_random_points_for_the_same_seed(study_file, tmp_path):
    from app.study.spec import load_study

    study_file.write_text(STUDY.replace("[1.0, 2.5]", "{min: 0.5, max: 4, log: true}\n"
                                        "  goal_bias: [0.05, 0.2]")
                          + "sample: {n: 6, seed: 3}\n")
    first, again = load_study(study_file), load_study(study_file)
    assert [r.key for r in first.runs] == [r.key for r in again.runs]
    points = {r.parameters_json for r in first.runs}
    assert len(points) == 6  # rrt and rrtstar share the points (neither sweeps γ here)
    eps = [json.loads(p)["eps"] for p in points]
    assert all(0.5 <= e <= 4 for e in eps) and len(set(eps)) == 6
    assert len(first.runs) == 2 * 2 * 6 * 2  # scenarios × planners × points × seeds
    study_file.write_text(study_file.read_text().replace("seed: 3", "seed: 4"))
    assert {r.parameters_json for r in load_study(study_file).runs} != points


SIM_STUDY = """\
name: rates
kind: simulate
scenarios: [crossing]
parameters:
  rate: [4, 30]
  fixed_latency_ms: [20]
  duration: [12]
seeds: [1]
"""


def test_a_driven_study_stores_what_simulate_prints(tmp_path):
    study = tmp_path / "rates.yaml"
    study.write_text(SIM_STUDY)
    out = trackstar("study", str(study), "--out", str(tmp_path / "out"), "--json")
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)["done"] == 2
    columns = ("parameters", "reached", "collisions", "collisions_moving", "collisions_at_rest",
               "min_clearance_m", "time_to_goal_s", "cycle_p99_ms", "replans",
               "emergency_stops", "max_lateral_error_m")
    with sqlite3.connect(tmp_path / "out" / "results.sqlite") as db:
        stored = db.execute(f"SELECT {', '.join(columns)} FROM sim_runs").fetchall()
    assert len(stored) == 2
    for params, *numbers in stored[:1]:
        rate = json.loads(params)["rate"]
        s = json.loads(trackstar("simulate", "crossing", "--rate", str(rate), "--fixed-latency",
                                 "20", "--duration", "12", "--seed", "1", "--json").stdout)
        assert numbers == [int(s["reached_goal"]), s["collisions"], s["collisions_moving"],
                           s["collisions_at_rest"], s["min_clearance_m"],
                           s["time_to_goal_s"], s["cycle_ms"]["p99"], s["replans"],
                           s["emergency_stops"], s["cross_track_error_m"]["max"]]
    page = (tmp_path / "out" / "report.html").read_text()
    assert "goal reached" in page and "Against rate" in page
    assert (tmp_path / "out" / "figures" / "crossing_collisions.png").is_file()
    assert (tmp_path / "out" / "figures" / "crossing_collisions_moving.png").is_file()


@pytest.mark.parametrize("edit, words", [
    (lambda s: s + "planners: [rrt]\n", "planners: a simulate study replans"),
    (lambda s: s.replace("rate: [4, 30]", "rates: [4, 30]"), "unknown parameter 'rates'"),
    (lambda s: s.replace("rate: [4, 30]", "rate: [4, -1]"), "rate[1] = -1"),
    (lambda s: s.replace("kind: simulate", "kind: drive"), "kind"),
    (lambda s: s.replace("kind: simulate\n", ""), "add 'kind: simulate'"),
])
def test_a_bad_driven_study_is_refused_naming_the_key(tmp_path, edit, words):
    from app.study.spec import StudyError, load_study

    study = tmp_path / "rates.yaml"
    study.write_text(edit(SIM_STUDY))
    with pytest.raises(StudyError, match=re.escape(words)):
        load_study(study)


def test_ray_stores_the_same_rows_as_the_local_pool_and_leaves_no_process(study_file,
                                                                          tmp_path):
    pytest.importorskip("ray")
    study_file.write_text(STUDY.replace(", ./my/slalom.json", "").replace("seeds: 2", "seeds: 1"))
    local, ray = tmp_path / "local", tmp_path / "ray"
    assert trackstar("study", str(study_file), "--out", str(local)).returncode == 0
    out = trackstar("study", str(study_file), "--out", str(ray), "--backend", "ray",
                    "--workers", "2", "--json", timeout=300)
    assert out.returncode == 0, out.stderr
    assert rows(ray) == rows(local) and len(rows(ray)) == 4
    left = subprocess.run(["pgrep", "-f", "raylet|gcs_server"], capture_output=True, text=True)
    assert left.stdout.strip() == "", "Ray processes outlived the command"


@contextmanager
def ray_head(env: dict):
    """A Ray cluster of our own (`ray start --head`, with token authentication, as Ray 2.59+
    starts one by default) on a free port; stopped, all its processes, on leaving."""
    port = free_port()
    head = subprocess.Popen(["ray", "start", "--head", f"--port={port}", "--num-cpus=2",
                             "--include-dashboard=false", "--block"], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                assert head.poll() is None and time.monotonic() < deadline, "no Ray head"
                time.sleep(0.2)
        yield f"127.0.0.1:{port}"
    finally:
        head.terminate()  # --block: ray start stops the cluster's processes as it ends
        head.wait(timeout=60)


def test_a_ray_cluster_at_ray_address_stores_the_local_pools_rows(study_file, tmp_path):
    """A study on a cluster reached through RAY_ADDRESS (token authentication) stores the
    local pool's rows; with that head running and no RAY_ADDRESS, --backend ray starts a Ray of
    its own; a wrong address fails in one line and leaves no results file."""
    pytest.importorskip("ray")
    study_file.write_text(STUDY.replace(", ./my/slalom.json", "").replace("seeds: 2", "seeds: 1"))
    outs = {name: tmp_path / name for name in ("local", "cluster", "own", "wrong")}
    assert trackstar("study", str(study_file), "--out", str(outs["local"])).returncode == 0
    env = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
    env |= {"RAY_AUTH_MODE": "token", "RAY_AUTH_TOKEN": secrets.token_hex(16)}

    def study(out, **more):
        return subprocess.run(["trackstar", "study", str(study_file), "--out", str(out),
                               "--backend", "ray", "--workers", "2"], check=False,
                              capture_output=True, text=True, env=env | more, timeout=120)

    with ray_head(env) as address:
        cluster = study(outs["cluster"], RAY_ADDRESS=address)
        own = study(outs["own"])
    wrong = study(outs["wrong"], RAY_ADDRESS=f"127.0.0.1:{free_port()}")
    assert cluster.returncode == 0, cluster.stderr
    assert own.returncode == 0, own.stderr
    assert rows(outs["cluster"]) == rows(outs["own"]) == rows(outs["local"])
    assert wrong.returncode == 2 and len(wrong.stderr.strip().splitlines()) == 1
    assert "RAY_ADDRESS=127.0.0.1:" in wrong.stderr and "Connection refused" in wrong.stderr
    assert not (outs["wrong"] / "results.sqlite").exists()


def test_without_ray_the_ray_backend_says_how_to_install_it(study_file, tmp_path):
    fake = tmp_path / "no_ray" / "ray"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('no ray here')\n")
    env = {**__import__("os").environ, "PYTHONPATH": str(fake.parent)}
    out = subprocess.run(["trackstar", "study", str(study_file), "--out", str(tmp_path / "o"),
                          "--backend", "ray"], capture_output=True, text=True, env=env,
                         timeout=60)
    assert out.returncode == 2 and "pip install 'trackstar[ray]'" in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


OMPL_STUDY = """\
name: side-by-side
scenarios: [slalom]
planners: [rrtstar, ompl:rrtstar, ompl:bitstar]
parameters:
  eps: [1.0]
  informed: [false]
seeds: [3]
budget:
  iterations: 600
"""


def test_ompl_planners_run_beside_ours_on_the_same_free_space(tmp_path):
    pytest.importorskip("ompl")
    from conftest import scenario_dict

    from planner.ompl_bridge import plan_isolated

    study = tmp_path / "side.yaml"
    study.write_text(OMPL_STUDY)
    out = trackstar("study", str(study), "--out", str(tmp_path / "out"), "--json")
    assert out.returncode == 0, out.stderr
    columns = ("planner", "parameters", "solved", "cost", "iterations", "nodes",
               "collision_checks", "min_clearance_m", "id")
    by_planner = {r[0]: r for r in rows(tmp_path / "out", columns)}
    # Each planner keeps the parameters it has: OMPL's RRT* its range, BIT* none.
    assert {p: json.loads(r[1]) for p, r in by_planner.items()} == {
        "rrtstar": {"eps": 1.0, "informed": False}, "ompl:rrtstar": {"eps": 1.0}, "ompl:bitstar": {}}
    assert by_planner["ompl:rrtstar"][4] == 600  # OMPL's own iteration count, as budgeted
    _, _, solved, cost, _, nodes, checks, clearance, run_id = by_planner["ompl:bitstar"]
    assert solved == 1 and checks is None  # OMPL counts no exact motion checks of ours
    assert clearance > 0  # its path, re-checked every 5 mm against our world
    straight = np.hypot(*np.subtract(scenario_dict("slalom")["goal"][:2],
                                     scenario_dict("slalom")["start"][:2]))
    assert straight < cost < 2 * straight
    with sqlite3.connect(tmp_path / "out" / "results.sqlite") as db:
        curve = [c for (c,) in db.execute("SELECT cost FROM cost_over_time WHERE run_id = ? "
                                          "ORDER BY iteration", (run_id,))]
    assert curve[-1] == cost and curve == sorted(curve, reverse=True)
    # With an iteration budget OMPL's run is reproducible: the row is a direct run's.
    again = plan_isolated(scenario_dict("slalom"), "BITstar", seed=3, iterations=600)
    assert (again["cost"], again["nodes"]) == (cost, nodes)
    assert "ompl:bitstar" in (tmp_path / "out" / "report.html").read_text()


def test_without_ompl_its_planners_say_how_to_install_it(tmp_path):
    fake = tmp_path / "no_ompl" / "ompl"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('no ompl here')\n")
    study = tmp_path / "side.yaml"
    study.write_text(OMPL_STUDY)
    env = {**__import__("os").environ, "PYTHONPATH": str(fake.parent)}
    out = subprocess.run(["trackstar", "study", str(study), "--out", str(tmp_path / "o")],
                         capture_output=True, text=True, env=env, timeout=60)
    assert out.returncode == 2 and not (tmp_path / "o").exists()
    assert out.stderr.strip().splitlines() == [
        f"error: {study}: planners: ompl:rrtstar needs OMPL: pip install 'trackstar[bench]'"]


def test_a_results_file_of_schema_1_gains_the_collision_split(tmp_path):
    """A study stored before issue 30 (sim_runs without the split) is resumed, not broken."""
    from app.study.results import Results

    with sqlite3.connect(tmp_path / "results.sqlite") as db:
        db.executescript("""
            CREATE TABLE sim_runs (id INTEGER PRIMARY KEY, study TEXT NOT NULL,
                scenario TEXT NOT NULL, parameters TEXT NOT NULL, seed INTEGER NOT NULL,
                reached INTEGER, collisions INTEGER, min_clearance_m REAL,
                time_to_goal_s REAL, cycle_p50_ms REAL, cycle_p99_ms REAL, replans INTEGER,
                emergency_stops INTEGER, max_lateral_error_m REAL, wall_s REAL, error TEXT,
                trackstar_version TEXT NOT NULL, finished_at TEXT NOT NULL,
                UNIQUE (study, scenario, parameters, seed));
            INSERT INTO sim_runs (study, scenario, parameters, seed, reached, collisions,
                trackstar_version, finished_at) VALUES ('old', 'crossing', '{}', 0, 1, 0, '0',
                'then');
            PRAGMA user_version = 1;""")
    Results(tmp_path, "old", "simulate", "name: old").close()
    with sqlite3.connect(tmp_path / "results.sqlite") as db:
        columns = [r[1] for r in db.execute("PRAGMA table_info(sim_runs)")]
        assert {"collisions_moving", "collisions_at_rest"} <= set(columns)
        assert db.execute("SELECT reached, collisions_moving FROM sim_runs").fetchall() == [(1, None)]
        assert db.execute("PRAGMA user_version").fetchone() == (3,)


def test_a_results_file_of_schema_2_gains_polish_s(tmp_path):
    """A planning study stored before polishing was timed is resumed, its rows kept."""
    from app.study.results import _SCHEMA, Results

    with sqlite3.connect(tmp_path / "results.sqlite") as db:
        db.executescript(_SCHEMA.replace("polish_s REAL, ", "").replace(
            "user_version = 3", "user_version = 2"))
        db.execute("INSERT INTO runs (study, scenario, planner, steering, parameters, seed, "
                   "solved, trackstar_version, finished_at) VALUES ('old', 'slalom', 'rrt', "
                   "'dubins', '{}', 0, 1, '0', 'then')")
    Results(tmp_path, "old", "plan", "name: old").close()
    with sqlite3.connect(tmp_path / "results.sqlite") as db:
        assert db.execute("SELECT solved, polish_s FROM runs").fetchall() == [(1, None)]
        assert db.execute("PRAGMA user_version").fetchone() == (3,)


def test_a_terminal_gets_a_progress_bar_even_one_that_reports_no_size(tmp_path):
    """stderr on a real pty: one sized like a terminal window, and one of 0 × 0, as script(1)
    and some CI consoles give (tqdm alone would count -1 rows there and draw nothing)."""
    import fcntl
    import os
    import pty
    import struct
    import termios

    (tmp_path / "tiny.yaml").write_text("name: tiny\nscenarios: [slalom]\nplanners: [rrt]\n"
                                        "budget:\n  iterations: 200\nseeds: 2\n")
    for rows, cols in ((40, 120), (0, 0)):
        master, slave = pty.openpty()
        fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", rows, cols, 0, 0))
        run = subprocess.Popen(["trackstar", "study", "tiny.yaml", "--out", f"out{cols}"],
                               cwd=tmp_path, stdout=subprocess.PIPE, stderr=slave)
        os.close(slave)
        drawn = b""
        while True:
            try:
                chunk = os.read(master, 4096)
            except OSError:  # the child closed the pty
                break
            if not chunk:
                break
            drawn += chunk
        os.close(master)
        assert run.wait(timeout=120) == 0
        assert b"2/2 [" in drawn and b"run/s" in drawn, (rows, cols, drawn)
        assert b"study tiny: 2 of 2 runs done" in run.stdout.read()


def test_the_median_cost_curve_counts_unsolved_seeds_and_never_rises():
    """The case a reader saw as a best cost getting worse: seeds solved late with a worse cost.
    Over all seeds (an unsolved one counting as infinite) the median is drawn once more than
    half are solved, and from there it only falls."""
    from app.study.report import Setting, _curve

    db = sqlite3.connect(":memory:")
    db.execute("CREATE TABLE cost_over_time (run_id INTEGER, iteration INTEGER, t_s REAL, "
               "cost REAL)")
    improvements = {1: [(100, 26.6), (900, 26.0)], 2: [(400, 28.1), (950, 27.0)],
                    3: [(700, 29.5)], 4: []}  # seed 4 never solves
    for run, points in improvements.items():
        db.executemany("INSERT INTO cost_over_time VALUES (?, ?, 0, ?)",
                       [(run, it, cost) for it, cost in points])
    setting = Setting("rrt", [{"id": run} for run in improvements])
    grid = np.arange(0, 1001, 50.0)
    low, mid, high = _curve(db, setting, False, grid)
    drawn = np.isfinite(mid)
    assert not drawn[grid < 700].any() and drawn[grid >= 700].all()  # 3 of 4 solved at 700
    assert np.all(np.diff(mid[drawn]) <= 0)  # the old, per-solved-seed median went 26.6 → 29.5
    assert mid[grid == 700][0] == 29.5 and mid[-1] == 29.5
    assert np.isnan(high).all() and np.isfinite(low[grid >= 400]).all()
