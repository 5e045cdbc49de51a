"""Batch jobs over HTTP: progress, results, CSV export, cancellation, failures, responsiveness."""

from __future__ import annotations

import csv
import io
import time

import httpx
import pytest
from _server import Server
from conftest import scenario_dict


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    srv = Server(tmp_path_factory.mktemp("data"))
    yield srv
    srv.stop()


def test_job_runs_every_combination(server):
    stored = server.client.post("/scenarios", json=scenario_dict("slalom")).json()["id"]
    body = {"scenarios": [stored, scenario_dict("open_field")],
            "parameters": [{"iterations": 300}, {"iterations": 300, "planner": "rrt"}],
            "seeds": [0, 1]}
    created = server.client.post("/jobs", json=body)
    assert created.status_code == 202 and created.json()["total"] == 8
    job = server.wait_job(created.json()["id"])
    assert job["status"] == "done" and job["done"] == job["total"] == 8
    runs = {(r["scenario"], r["parameters"]["planner"], r["seed"]) for r in job["results"]}
    assert runs == {(s, a, seed) for s in ("slalom", "open_field") for a in ("rrtstar", "rrt")
                    for seed in (0, 1)}
    assert all("path" not in r and r["iterations"] >= 1 for r in job["results"])
    # A job's run is the same plan as POST /plan with those options.
    single = server.client.post("/plan", json={"scenario_id": stored, "iterations": 300,
                                               "seed": 1}).json()
    twin = next(r for r in job["results"] if r["scenario"] == "slalom" and r["seed"] == 1
                and r["parameters"]["planner"] == "rrtstar")
    assert twin["cost"] == single["cost"] and twin["nodes"] == single["nodes"]

    table = server.client.get(f"/jobs/{job['id']}/results.csv")
    assert table.headers["content-type"].startswith("text/csv")
    rows = list(csv.DictReader(io.StringIO(table.text)))
    assert len(rows) == 8
    assert {"scenario", "seed", "cost", "solved", "parameters.planner"} <= rows[0].keys()
    assert {r["parameters.planner"] for r in rows} == {"rrt", "rrtstar"}


def test_cancel_keeps_finished_results_and_stays_cancelled(server):
    body = {"scenarios": [scenario_dict("slalom")], "parameters": [{"time": 0.5}],
            "seeds": list(range(40))}
    job_id = server.client.post("/jobs", json=body).json()["id"]
    time.sleep(1.2)
    cancelled = server.client.delete(f"/jobs/{job_id}").json()
    assert cancelled["status"] == "cancelled" and cancelled["done"] < 40
    time.sleep(0.8)  # runs that were in the pool finish; they are not counted in
    job = server.client.get(f"/jobs/{job_id}").json()
    assert job["status"] == "cancelled" and job["done"] <= cancelled["done"] + 2
    done = server.wait_job(server.client.post("/jobs", json={
        "scenarios": [scenario_dict("slalom")], "parameters": [{"iterations": 50}]}).json()["id"])
    assert server.client.delete(f"/jobs/{done['id']}").json()["status"] == "done"


def test_unplannable_run_fails_the_job_with_the_reason(server):
    walled = scenario_dict("open_field")
    walled["start"] = [*walled["obstacles"][0]["center"], 0]
    job = server.wait_job(server.client.post("/jobs", json={"scenarios": [walled]}).json()["id"])
    assert job["status"] == "failed" and "in collision" in job["error"]


@pytest.mark.parametrize("body, status, words", [
    ({"scenarios": []}, 422, "at least 1"),
    ({"scenarios": ["nope"]}, 404, "nope"),
    ({"scenarios": [{"name": "x"}]}, 422, "scenarios[0]: invalid scenario: start"),
    ({"scenarios": [scenario_dict("slalom")], "parameters": [{"seed": 3}]}, 422, "seeds"),
    ({"scenarios": [scenario_dict("slalom")], "parameters": [{"time": 1e9}]}, 422, "limit"),
    ({"scenarios": [scenario_dict("slalom")], "seeds": list(range(10_001))}, 422, "at most"),
    # A list's length is refused before its items are validated (8 s on the event loop before).
    ({"scenarios": ["slalom"], "parameters": [{}] * 1_000_000}, 422,
     "at most 10000 items, not 1000000"),
])
def test_bad_jobs_are_refused(server, body, status, words):
    resp = server.client.post("/jobs", json=body)
    assert resp.status_code == status and words in str(resp.json()["detail"]), resp.text


def test_server_answers_while_the_pool_is_busy(server):
    body = {"scenarios": [scenario_dict("slalom")], "parameters": [{"time": 1.0}],
            "seeds": list(range(40))}  # ~20 s of work: still running when checked
    job_id = server.client.post("/jobs", json=body).json()["id"]
    time.sleep(0.3)
    latencies = []
    for _ in range(21):
        start = time.monotonic()
        assert server.get("/health").status_code == 200
        latencies.append(time.monotonic() - start)
        time.sleep(0.05)
    assert server.client.get(f"/jobs/{job_id}").json()["status"] == "running"
    assert sorted(latencies)[10] < 0.1, latencies  # the median: robust to a loaded runner
    server.client.delete(f"/jobs/{job_id}")


def test_delete_and_a_client_that_gives_up_stop_their_plans_in_the_workers(server):
    """Two 20 s runs hold both workers until DELETE; then two 20 s plans whose clients give up
    after a second. Each time the workers are free again at once: a short plan answers."""
    def quick_plan_s() -> float:
        start = time.monotonic()
        plan = server.client.post("/plan", json={"scenario_id": "slalom", "time": 0.1})
        assert plan.status_code == 200, plan.text
        return time.monotonic() - start

    long_runs = {"scenarios": [scenario_dict("slalom")], "parameters": [{"time": 20.0}],
                 "seeds": [0, 1]}
    job_id = server.client.post("/jobs", json=long_runs).json()["id"]
    time.sleep(1.0)
    server.client.delete(f"/jobs/{job_id}")
    start = time.monotonic()  # the batch lane's workers are free: a short job runs at once
    quick = server.client.post("/jobs", json={**long_runs, "parameters": [{"time": 0.1}]})
    assert server.wait_job(quick.json()["id"], timeout=5.0)["status"] == "done"
    assert time.monotonic() - start < 5.0
    for _ in range(3):  # every worker: the two of the batch lane and the interactive one
        with pytest.raises(httpx.ReadTimeout):
            server.client.post("/plan", json={"scenario_id": "slalom", "time": 20.0},
                               timeout=1.0)
    assert quick_plan_s() < 5.0


def test_a_plan_answers_at_once_while_jobs_flood_the_server_from_the_same_address(server):
    """Issue 32: six jobs of 50 runs × 8 s, then a 0.3 s plan timed out at 30 s. Plans have
    their own lane now, and batch work never takes its worker."""
    flood = {"scenarios": [scenario_dict("slalom")], "parameters": [{"time": 8.0}],
             "seeds": list(range(50))}
    jobs = [server.client.post("/jobs", json=flood) for _ in range(6)]
    assert all(job.status_code == 202 for job in jobs)
    time.sleep(1.0)
    for _ in range(3):
        start = time.monotonic()
        plan = server.client.post("/plan", json={"scenario_id": "slalom", "time": 0.3})
        assert plan.status_code == 200 and time.monotonic() - start < 5.0, plan.text
    for job in jobs:
        server.client.delete(f"/jobs/{job.json()['id']}")


def test_too_many_queued_runs_from_one_client_get_429_with_retry_after(server):
    """A client may have 10 000 runs queued or running; beyond, a job waits its turn outside
    (nothing is stored or started), and the client is told when to come back."""
    body = {"scenarios": [scenario_dict("slalom")], "parameters": [{"iterations": 2000}],
            "seeds": list(range(10_000))}  # runs of tens of ms: the job outlasts the test's posts
    first = server.client.post("/jobs", json=body)
    assert first.status_code == 202
    # 1 000 more: refused until 1 000 of the first job's runs (a minute's work) are done.
    again = server.client.post("/jobs", json={**body, "seeds": list(range(1_000))})
    assert again.status_code == 429, again.text
    assert "per client" in again.json()["detail"] and int(again.headers["Retry-After"]) >= 1
    server.client.delete(f"/jobs/{first.json()['id']}")
    later = server.client.post("/jobs", json={**body, "seeds": [0]})
    assert later.status_code == 202  # the cancelled job's runs left the queue
    server.wait_job(later.json()["id"])
