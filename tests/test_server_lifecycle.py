"""`trackstar serve` as a process: ports, environment, restarts, shutdown, the Docker CMD."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import httpx
import pytest
from _server import Server, free_port
from conftest import scenario_dict

ROOT = Path(__file__).resolve().parents[1]


def test_data_survive_a_restart_and_an_interrupted_job_is_marked(tmp_path):
    first = Server(tmp_path)
    track = first.client.post("/tracks", files={"file": ("ring.svg", (ROOT / "tracks" / "library"
                                                                       / "thesis.svg").read_bytes())})
    scenario = first.client.post("/scenarios", json=scenario_dict("slalom")).json()
    finished = first.wait_job(first.client.post("/jobs", json={
        "scenarios": [scenario["id"]], "parameters": [{"iterations": 100}]}).json()["id"])
    running = first.client.post("/jobs", json={"scenarios": [scenario["id"]],
                                               "parameters": [{"time": 3}],
                                               "seeds": list(range(10))}).json()
    time.sleep(1.0)
    assert first.client.get(f"/jobs/{running['id']}").json()["status"] == "running"
    took = first.stop(signal.SIGTERM)
    assert first.proc.returncode == 0 and took < 5, (took, first.err)

    second = Server(tmp_path)
    try:
        assert track.json() in second.client.get("/tracks").json()
        assert second.client.get(f"/scenarios/{scenario['id']}").json() == scenario
        assert second.client.get(f"/jobs/{finished['id']}").json() == finished
        interrupted = second.client.get(f"/jobs/{running['id']}").json()
        assert interrupted["status"] == "failed" and "shutdown" in interrupted["error"]
        assert interrupted["done"] < interrupted["total"]
    finally:
        assert second.stop(signal.SIGINT) < 5


STOP_MID_WRITE = """
import time
from concurrent.futures import ProcessPoolExecutor
import multiprocessing
from app.pool import stop_pool

pool = ProcessPoolExecutor(2, multiprocessing.get_context("spawn"))
futures = [pool.submit(bytes, 20_000_000) for _ in range(400)]
futures[0].result()
time.sleep(0.3)  # both workers keep writing results now
stop_pool(pool)
"""


def test_a_pool_stopped_while_its_workers_write_results_lets_the_process_exit():
    """SIGTERM once hung the server: a worker terminated mid-write left half a result in the
    pipe, and the interpreter's exit waited for the rest for ever."""
    r = subprocess.run([sys.executable, "-c", STOP_MID_WRITE], capture_output=True, text=True,
                       timeout=30, cwd=ROOT, check=False)
    assert r.returncode == 0, r.stderr


def _alive(pid: int) -> bool:
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return False
    return "State:\tZ" not in status


def test_a_crash_mid_job_is_marked_after_restart(tmp_path):
    first = Server(tmp_path)
    job = first.client.post("/jobs", json={"scenarios": [scenario_dict("slalom")],
                                           "parameters": [{"time": 3}]}).json()
    time.sleep(0.5)
    workers = [int(p) for p in subprocess.run(["pgrep", "-P", str(first.proc.pid)],
                                              capture_output=True, text=True).stdout.split()]
    assert workers
    first.stop(signal.SIGKILL)
    # Its workers (one mid-run) do not live on as orphans: they follow the server.
    deadline = time.monotonic() + 10
    while any(map(_alive, workers)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(map(_alive, workers)), [p for p in workers if _alive(p)]
    second = Server(tmp_path)
    try:
        job = second.client.get(f"/jobs/{job['id']}").json()
        assert job["status"] == "failed" and "interrupted" in job["error"]
    finally:
        second.stop()


@pytest.mark.parametrize("flag", ["--port", "--ui-port"])
def test_a_busy_port_is_an_error_naming_it(tmp_path, flag):
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        other = "--ui-port" if flag == "--port" else "--port"
        out = subprocess.run(["trackstar", "serve", flag, str(port), other, "0",
                              "--data-dir", str(tmp_path)],
                             capture_output=True, text=True, timeout=60, check=False)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and str(port) in lines[0] and lines[0].startswith("error:")


def test_ports_and_data_dir_from_the_environment(tmp_path):
    port, ui_port = free_port(), free_port()
    srv = Server(tmp_path, command=["trackstar", "serve"],
                 env={"TRACKSTAR_PORT": str(port), "TRACKSTAR_UI_PORT": str(ui_port),
                      "TRACKSTAR_DATA_DIR": str(tmp_path / "env-data")})
    try:
        assert (srv.port, srv.ui_port) == (port, ui_port)
        assert srv.lines[-2:] == [f"API: http://127.0.0.1:{port}/docs",
                                  f"UI: http://127.0.0.1:{ui_port}/"]
        assert (tmp_path / "env-data" / "trackstar.sqlite3").is_file()
        assert httpx.get(f"http://127.0.0.1:{ui_port}/", timeout=10).status_code == 200
    finally:
        srv.stop()


def test_the_dockerfile_cmd_serves_health(tmp_path):
    text = (ROOT / "Dockerfile").read_text()
    cmd = json.loads(re.search(r"^CMD (\[.*\])$", text, re.MULTILINE)[1])
    assert cmd == ["trackstar", "serve", "--host", "0.0.0.0"]
    assert re.search(r"^USER (?!root)", text, re.MULTILINE) and "HEALTHCHECK" in text
    port, ui_port = free_port(), free_port()
    srv = Server(tmp_path, command=cmd, env={"TRACKSTAR_PORT": str(port),
                                             "TRACKSTAR_UI_PORT": str(ui_port),
                                             "TRACKSTAR_DATA_DIR": str(tmp_path)})
    try:
        assert f"UI: http://0.0.0.0:{ui_port}/" in srv.lines
        # Beyond loopback without a token: one is generated and printed, as Jupyter does.
        token = next(line.split()[1] for line in srv.lines if line.startswith("Token: "))
        assert len(token) >= 32
        assert f"Studio with the token: http://0.0.0.0:{port}/studio?token={token}" in srv.lines
        health = srv.get("/health").json()
        assert health["status"] == "ok" and health["ui_port"] == ui_port
        for host in ("localhost", "127.0.0.1", f"127.0.0.1:{port}"):  # no name gets past it
            refused = srv.client.get("/scenarios", headers={"Host": host})
            assert refused.status_code == 401, (host, refused.text)
            refused = srv.client.post("/plan", json={"scenario_id": "slalom", "time": 0.1},
                                      headers={"Host": host})
            assert refused.status_code == 401, (host, refused.text)
        signed = {"Authorization": f"Bearer {token}"}
        assert srv.client.get("/scenarios", headers=signed).status_code == 200
    finally:
        assert srv.stop() < 5


def test_no_token_beyond_loopback_is_an_explicit_choice_with_a_warning(tmp_path):
    srv = Server(tmp_path, "--host", "0.0.0.0", "--no-token")
    try:
        assert not any(line.startswith("Token: ") for line in srv.lines)
        assert any("with --no-token: whoever reaches it may use it" in line for line in srv.err)
        assert srv.client.get("/scenarios").status_code == 200
    finally:
        srv.stop()
    both = subprocess.run(["trackstar", "serve", "--token", "t0k3n", "--no-token"],
                          capture_output=True, text=True, timeout=60)
    assert both.returncode == 2 and "choose one of --token and --no-token" in both.stderr


def test_the_image_holds_what_the_readmes_commands_name():
    """A `trackstar` command in the README that names a file of the repository
    (examples/fsm/hallway.json) works in the image too: the Dockerfile copies its directory."""
    commands = re.findall(r"^trackstar .*$", (ROOT / "README.md").read_text(), re.MULTILINE)
    copied = set(re.findall(r"^COPY (\S+) \./", (ROOT / "Dockerfile").read_text(), re.MULTILINE))
    named = {word.split("/")[0] for line in commands for word in line.split()
             if "/" in word and (ROOT / word).is_file()}
    assert named and named <= copied, named - copied


def pool_workers(srv) -> list[int]:
    """The server's worker processes, oldest first."""
    children = Path(f"/proc/{srv.proc.pid}/task/{srv.proc.pid}/children").read_text().split()
    return sorted(int(pid) for pid in children
                  if b"spawn_main" in Path(f"/proc/{pid}/cmdline").read_bytes())


def test_a_dead_worker_is_replaced_and_only_a_run_that_kills_workers_fails(tmp_path):
    srv = Server(tmp_path)
    try:
        os.kill(pool_workers(srv)[0], signal.SIGKILL)  # an idle worker dies (out of memory)
        body = {"scenario": scenario_dict("slalom"), "iterations": 100}
        statuses = [srv.client.post("/plan", json=body) for _ in range(3)]
        assert [r.status_code for r in statuses] == [200, 200, 200]
        # A run whose worker dies mid-plan runs again alone, in a process of its own; when
        # that one dies too, the run is the cause: 422 for it alone, and the server goes on.
        with ThreadPoolExecutor(1) as background:
            crashing = background.submit(srv.client.post, "/plan", json={
                "scenario": scenario_dict("slalom"), "time": 3.0})
            time.sleep(1.0)
            before = pool_workers(srv)
            os.kill(before[-1] if len(before) == 1 else _busy(before), signal.SIGKILL)
            deadline = time.monotonic() + 20
            # A new pool (a worker per CPU and the interactive one), then the run alone.
            pool = len(os.sched_getaffinity(0)) + 1
            while len(alone := [p for p in pool_workers(srv) if p > max(before)]) < pool + 1:
                assert time.monotonic() < deadline, "no new pool and no run alone"
                time.sleep(0.1)
            os.kill(max(alone), signal.SIGKILL)  # the run alone: started after the new pool
            refused = crashing.result(timeout=30)
        assert refused.status_code == 422, refused.text
        assert "stops the planning worker that runs it" in refused.json()["detail"]
        # The server logs it before it answers, but the test's reader thread may not have read
        # the server's stderr yet (seen once in CI): wait for the line, a little.
        deadline = time.monotonic() + 10
        while not any("died twice running run_plan(scenario 'slalom', {" in line
                      for line in srv.err):
            assert time.monotonic() < deadline, srv.err
            time.sleep(0.1)
        assert srv.client.post("/plan", json=body).status_code == 200
    finally:
        assert srv.stop() < 5


def _busy(pids: list[int]) -> int:
    """The worker that uses the CPU now (the one planning)."""
    def cpu(pid: int) -> int:
        return sum(int(v) for v in Path(f"/proc/{pid}/stat").read_text().split()[13:15])

    first = {pid: cpu(pid) for pid in pids}
    time.sleep(0.3)
    return max(pids, key=lambda pid: cpu(pid) - first[pid])


def test_a_simulation_past_the_wall_time_cap_is_stopped_and_says_why(tmp_path):
    srv = Server(tmp_path, "--max-sim-s", "1")
    try:
        sim_id = srv.client.post("/simulations", json={
            "scenario_id": "thesis_laps", "laps": 20, "duration": 600}).json()["id"]
        deadline = time.monotonic() + 20
        while (sim := srv.client.get(f"/simulations/{sim_id}").json())["status"] in (
                "queued", "running"):
            assert time.monotonic() < deadline, sim
            time.sleep(0.2)
        assert sim["status"] == "failed" and "--max-sim-s" in sim["error"], sim
        flags = tmp_path / "stop"
        while any(flags.iterdir()):  # cleared once the worker's run has returned
            assert time.monotonic() < deadline + 30, "the worker was not stopped"
            time.sleep(0.2)
        busy = srv.workers_cpu_s()
        time.sleep(0.5)
        assert srv.workers_cpu_s() - busy < 0.05, "the worker still simulates"
    finally:
        srv.stop()


def test_a_first_start_answers_at_once_says_warming_and_stops_promptly(tmp_path):
    """An empty numba cache, as after an install: the URLs come at once, /health says
    "warming" while the kernels compile in the background, a plan waits for them rather than
    failing, and SIGTERM ends the server without waiting for the compile."""
    started = time.monotonic()
    srv = Server(tmp_path / "data", env={"NUMBA_CACHE_DIR": str(tmp_path / "cache")},
                 warm=False)
    try:
        took = time.monotonic() - started
        assert took < 10, f"the URLs came after {took:.1f} s"
        assert srv.get("/health").json()["status"] == "warming"
        with pytest.raises(httpx.ReadTimeout):  # waits: neither a failure nor a 5xx
            srv.client.post("/plan", json={"scenario_id": "slalom", "time": 0.1}, timeout=2)
        assert srv.get("/health").status_code == 200  # and the server still answers
    finally:
        assert srv.stop() < 10
