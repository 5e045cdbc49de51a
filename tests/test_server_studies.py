"""Studies over HTTP: the same validation and rows as `trackstar study`, results downloadable
while they grow, cancellation that keeps finished runs, and a restart that resumes."""

from __future__ import annotations

import csv
import io
import sqlite3
import time
from concurrent.futures import ThreadPoolExecutor

import pytest
from _server import Server
from conftest import scenario_dict

STUDY = {"name": "eps", "scenarios": ["slalom"], "planners": ["rrt", "rrtstar"],
         "parameters": {"eps": [1.0, 2.0]}, "seeds": 2, "budget": {"iterations": 300}}


def wait(server, study_id, until=("done", "failed", "cancelled"), timeout=60):
    deadline = time.monotonic() + timeout
    while True:
        status = server.client.get(f"/studies/{study_id}").json()
        if status["status"] in until or time.monotonic() > deadline:
            return status
        time.sleep(0.2)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    srv = Server(tmp_path_factory.mktemp("data"))
    yield srv
    srv.stop()


def test_a_study_runs_to_the_same_rows_as_the_command_line(server, tmp_path):
    stored = server.client.post("/scenarios", json=scenario_dict("open_field")).json()["id"]
    body = dict(STUDY, scenarios=["slalom", stored, dict(scenario_dict("hallway"),
                                                         name="inline_hallway")])
    created = server.client.post("/studies", json=body)
    assert created.status_code == 202 and created.json()["total"] == 3 * 4 * 2  # scenarios × settings × seeds
    status = wait(server, created.json()["id"])
    assert status["status"] == "done" and status["done"] == status["total"] == 24
    study_id = created.json()["id"]
    table = list(csv.DictReader(io.StringIO(
        server.client.get(f"/studies/{study_id}/results.csv").text)))
    assert {r["scenario"] for r in table} == {"slalom", "open_field", "inline_hallway"}
    # The same study through the command line stores the same numbers.
    import json
    import subprocess

    (tmp_path / "eps.json").write_text(json.dumps(dict(STUDY, scenarios=["slalom"])))
    subprocess.run(["trackstar", "study", str(tmp_path / "eps.json"), "--out",
                    str(tmp_path / "out")], check=True, capture_output=True, timeout=120)
    with sqlite3.connect(tmp_path / "out" / "results.sqlite") as db:
        cli = sorted(db.execute("SELECT planner, parameters, seed, solved, cost, nodes FROM runs"))
    rest = sorted((r["planner"], r["parameters"], int(r["seed"]), int(r["solved"]),
                   float(r["cost"]) if r["cost"] else None, int(r["nodes"]))
                  for r in table if r["scenario"] == "slalom")
    assert rest == cli
    database = server.client.get(f"/studies/{study_id}/results.sqlite")
    assert database.status_code == 200 and database.content.startswith(b"SQLite format 3")
    report = server.client.get(f"/studies/{study_id}/report.html")
    assert report.status_code == 200 and "Best setting per scenario" in report.text
    assert "http://" not in report.text and "data:image/png;base64," in report.text
    assert any(s["id"] == study_id for s in server.client.get("/studies").json())


@pytest.mark.parametrize("body, words", [
    (dict(STUDY, planers=["rrt"]), "unknown key 'planers' (did you mean 'planners'?)"),
    (dict(STUDY, scenarios=["no_such_id"]), "scenarios[0]"),
    (dict(STUDY, parameters={"eps": [-1]}), "eps[0] = -1"),
    (dict(STUDY, budget={"time_s": 1e6}), "above this server's limit"),
    (dict(STUDY, seeds=20000), "expands to 80,000 runs"),
    (dict(STUDY, scenarios=[{"name": "x", "bounds": [0, 0, 1, 1]}]), "scenarios[0]: "),
])
def test_a_bad_study_is_422_naming_the_key(server, body, words):
    answer = server.client.post("/studies", json=body)
    assert answer.status_code == 422 and words in answer.json()["detail"], answer.text


@pytest.mark.parametrize("huge, words", [
    ({"seeds": 1_000_000}, "a count of seeds is 1 to 100000"),
    ({"parameters": {"eps": [1 + i / 1000 for i in range(150)],
                     "gamma": [1 + i / 100 for i in range(150)],
                     "goal_bias": [i / 20 for i in range(10)]}}, "expands to 900,000 runs"),
    ({"parameters": {"eps": {"min": 0.5, "max": 2.0}}, "sample": 300_000}, "sample.n"),
    ({"parameters": {"eps": {"min": 0.5, "max": 2.0}}, "sample": 20_000}, "at most 10,000"),
])
def test_a_study_too_big_is_refused_at_once_and_the_server_answers_meanwhile(server, huge,
                                                                             words):
    """Counted from the sizes of its axes, before anything is built, off the event loop
    (issue 32: a 100-byte body took 25 s and froze /health)."""
    with ThreadPoolExecutor(1) as pool:
        posted = pool.submit(server.client.post, "/studies", json={**STUDY, **huge})
        health = server.get("/health", timeout=1.0)
        answer = posted.result(timeout=2.0)
    assert health.status_code == 200
    assert answer.status_code == 422 and words in answer.json()["detail"], answer.text
    assert answer.elapsed.total_seconds() < 2.0


def test_delete_stops_a_study_and_keeps_its_finished_runs(server):
    body = dict(STUDY, name="long", planners=["rrtstar"], parameters={}, seeds=200,
                budget={"iterations": 20000})
    study_id = server.client.post("/studies", json=body).json()["id"]
    status = wait(server, study_id, until=(), timeout=1.5)
    deadline = time.monotonic() + 30
    while status["done"] < 2 and time.monotonic() < deadline:
        status = server.client.get(f"/studies/{study_id}").json()
    stopped = server.client.delete(f"/studies/{study_id}").json()
    assert stopped["status"] == "cancelled" and 2 <= stopped["done"] < 200
    time.sleep(1.0)
    assert server.client.get(f"/studies/{study_id}").json()["done"] <= stopped["done"] + 2
    assert server.client.get(f"/studies/{study_id}/results.csv").text.count("\n") >= 3


def test_a_restarted_server_resumes_an_interrupted_study(tmp_path):
    srv = Server(tmp_path)
    body = dict(STUDY, name="resumed", planners=["rrtstar"], parameters={}, seeds=40,
                budget={"iterations": 5000})
    study_id = srv.client.post("/studies", json=body).json()["id"]
    deadline = time.monotonic() + 30
    while srv.client.get(f"/studies/{study_id}").json()["done"] < 3:
        assert time.monotonic() < deadline
        time.sleep(0.1)
    srv.stop()
    again = Server(tmp_path)
    try:
        status = wait(again, study_id, timeout=120)
        assert status["status"] == "done" and status["done"] == 40
        assert 3 <= status["skipped"] < 40  # the runs stored before the stop were not redone
        rows = again.client.get(f"/studies/{study_id}/results.csv").text.strip().splitlines()
        assert len(rows) == 41  # a header and each run once
    finally:
        again.stop()
