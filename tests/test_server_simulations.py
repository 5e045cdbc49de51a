"""Simulations over HTTP (a real `trackstar serve` process): progress, summary, log, bad input.

A run with a fixed latency is reproducible byte for byte, so the API's summary and log are
compared with what `trackstar simulate` prints for the same options.
"""

from __future__ import annotations

import json
import subprocess
import time

import pytest
from _server import Server
from conftest import scenario_dict

THESIS = {"name": "thesis-plain", "track": {"name": "thesis"},
          "vehicle": {"wheelbase": 0.44, "max_steer_deg": 26, "radius": 0.1, "speed": 1.0},
          "start": [2.373, -0.264, 3.14], "goal": [2.353, -4.33, 0.0]}


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    srv = Server(data := tmp_path_factory.mktemp("data"))
    srv.data_dir = data
    yield srv
    srv.stop()


def _wait(server: Server, sim_id: str, timeout: float = 600.0) -> tuple[dict, list[dict]]:
    """The finished simulation, and every status seen while polling."""
    seen = []
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        sim = server.client.get(f"/simulations/{sim_id}").json()
        seen.append(sim)
        if sim["status"] not in ("queued", "running"):
            return sim, seen
        time.sleep(0.2)
    raise TimeoutError(f"simulation {sim_id} still {seen[-1]['status']} after {timeout} s")


def test_summary_and_log_are_those_of_the_cli(server, tmp_path):
    options = {"duration": 3, "seed": 5, "fixed_latency_ms": 20, "controller": "stanley"}
    created = server.client.post("/simulations",
                                 json={"scenario": scenario_dict("crossing"), **options})
    assert created.status_code == 202, created.text
    sim, _ = _wait(server, created.json()["id"])
    assert sim["status"] == "done" and sim["progress"] == 1.0 and sim["error"] is None
    assert sim["scenario"] == "crossing" and sim["settings"]["controller"] == "stanley"
    cli = subprocess.run(["trackstar", "simulate", "crossing", "--duration", "3",
                          "--seed", "5", "--fixed-latency", "20", "--controller", "stanley",
                          "--json", "--log", tmp_path / "cli.csv"],
                         capture_output=True, text=True, check=True, timeout=120)
    assert sim["summary"] == json.loads(cli.stdout)
    log = server.client.get(f"/simulations/{sim['id']}/log")
    assert log.status_code == 200 and log.headers["content-type"].startswith("text/csv")
    assert log.content == (tmp_path / "cli.csv").read_bytes()


def test_laps_of_a_stored_scenario_with_progress(server):
    stored = server.client.post("/scenarios", json=THESIS)
    assert stored.status_code == 201, stored.text
    created = server.client.post("/simulations", json={
        "scenario_id": stored.json()["id"], "laps": 1, "fixed_latency_ms": 100, "seed": 2})
    assert created.status_code == 202, created.text
    sim_id = created.json()["id"]
    early = server.client.get(f"/simulations/{sim_id}/log")
    assert early.status_code == 409 and "once it is done" in early.json()["detail"]
    sim, seen = _wait(server, sim_id)
    assert sim["status"] == "done", sim
    s = sim["summary"]
    assert s["laps"] == 1 and len(s["lap_times_s"]) == 1 and s["reached_goal"]
    assert 0.85 * 14.0 < s["lap_times_s"][0] < 1.25 * 14.0
    # Progress was reported while it ran: simulated time rising, short of the duration.
    running = [x for x in seen if x["status"] == "running" and 0.0 < x["progress"] < 1.0]
    assert running, [(x["status"], x["progress"]) for x in seen]
    times = [x["sim_time_s"] for x in running]
    assert times == sorted(times) and times[-1] <= s["duration_s"]
    rows = server.client.get(f"/simulations/{sim_id}/log").text.splitlines()
    assert rows[0].startswith("t,x,y,theta,v,steer")
    assert len(rows) - 1 == round(s["duration_s"] * 100) + 1


@pytest.mark.parametrize("body, status, words", [
    ({"scenario": scenario_dict("crossing"), "laps": 2}, 422, "laps needs a scenario"),
    ({"scenario": THESIS, "laps": 0}, 422, "greater than or equal to 1"),
    ({"scenario": THESIS, "duration": 0}, 422, "greater than 0"),
    ({"scenario": THESIS, "duration": 1e6}, 422, "less than or equal to 600"),
    ({"scenario": THESIS, "control_rate": 1e12}, 422, "less than or equal to 1000"),
    ({"scenario": THESIS, "controller": "lqr"}, 422, "pure-pursuit"),
    ({"scenario": THESIS, "steering": "straight"}, 422, "cc-dubins"),
    ({"scenario": THESIS, "seeds": [1]}, 422, "unknown key 'seeds' (did you mean 'seed'?)"),
    ({"scenario": THESIS, "scenario_id": "x"}, 422, "exactly one of"),
    ({}, 422, "exactly one of"),
    ({"scenario_id": "nope"}, 404, "nope"),
    ({"scenario": {**THESIS, "start": [0, 0, 0]}}, 422, "in collision"),
    ({"scenario": {**THESIS, "track": {"name": "nowhere"}}}, 422, "nowhere"),
])
def test_bad_simulations_are_refused(server, body, status, words):
    resp = server.client.post("/simulations", json=body)
    assert resp.status_code == status, resp.text
    assert words in json.dumps(resp.json()["detail"])


def test_unknown_simulation_is_404(server):
    assert server.client.get("/simulations/nope").status_code == 404
    assert server.client.get("/simulations/nope/log").status_code == 404


def test_delete_stops_a_running_simulation(server):
    created = server.client.post("/simulations", json={
        "scenario": THESIS, "laps": 20, "duration": 600, "fixed_latency_ms": 100})
    sim_id = created.json()["id"]
    deadline = time.monotonic() + 60
    while server.client.get(f"/simulations/{sim_id}").json()["sim_time_s"] == 0:
        assert time.monotonic() < deadline, "the simulation did not start"
        time.sleep(0.1)
    stopped = server.client.delete(f"/simulations/{sim_id}")
    assert stopped.status_code == 200 and stopped.json()["status"] == "cancelled"
    time.sleep(1.0)  # the run stops within a quarter second of wall time and one tick
    busy = server.workers_cpu_s()
    time.sleep(0.5)
    assert server.workers_cpu_s() - busy < 0.05, "a worker still simulates"
    left = [*(server.data_dir / "stop").iterdir(), *(server.data_dir / "simulations").glob(
        f"{sim_id}.*")]
    assert not left, left
    assert server.client.get(f"/simulations/{sim_id}").json()["status"] == "cancelled"
    assert server.client.get(f"/simulations/{sim_id}/log").status_code == 409
    assert server.client.delete("/simulations/nope").status_code == 404
