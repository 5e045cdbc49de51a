"""Load test of `trackstar serve` (issue 19): honest plans alone, then the same honest plans
while hostile clients attack; honest plans must keep their latency within a bound.

    python benchmarks/load_test.py [--duration 20] [--max-p95-ratio 8] [--json]

Beside them, while under attack: 100 idle studio tabs, 20 slow-header (slowloris) connections
on each port and a /health watch (every 0.25 s, each answer within 1 s). At the end the server
gets SIGTERM, and it and all its children must be gone within 10 s.

Hostile work that holds a planning worker (a plan over 10 000 circles whose client gives up
after 1 s, jobs of 20 s runs and 600 s simulations that are deleted) must be stopped by the
server's deadlines and cancellation within a second or two; without that, the honest plans
would wait behind it for tens of seconds. The cheap attacks (bodies above 5 MB, chunked too,
malformed JSON, NaN and 1e308, a deeply nested SVG, a cross-origin write, a wrong Host) must
be refused with a 4xx, never a 5xx. Prints a table (or --json) and writes it to
results/load.md; exits 1 on any 5xx or unexpected answer, a worker left busy, /health or a
plain plan failing afterwards, or an honest p95 above --max-p95-ratio × its p95 alone.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

import _harness
import httpx
import numpy as np

MB = 1024 * 1024
IDLE_TABS = 100  # studio websockets held open, reading nothing, while under attack
SLOW_CLIENTS = 20  # slow-header connections to each port
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")


# -- the server: a real subprocess, its process tree's memory and its workers' CPU

def start_server(data_dir: str) -> tuple[subprocess.Popen, str, int]:
    """`trackstar serve` on free loopback ports; returns the process, the API's base URL and
    the studio's port."""
    proc = subprocess.Popen(["trackstar", "serve", "--port", "0", "--ui-port", "0",
                             "--data-dir", data_dir], stdout=subprocess.PIPE, text=True)
    url = None
    for line in proc.stdout:  # bounded: the process prints its start lines or exits
        if m := re.fullmatch(r"API: (http://.+:\d+)/docs\n", line):
            url = m[1]
        if (m := re.fullmatch(r"UI: http://.+:(\d+)/\n", line)) and url:
            threading.Thread(target=proc.stdout.read, daemon=True).start()  # never blocks it
            return proc, url.replace("://localhost:", "://127.0.0.1:"), int(m[1])
    raise RuntimeError("the server did not start")


def _procs() -> dict[int, list[str]]:
    """Every process's /proc/<pid>/stat fields after its name (field 3 onwards)."""
    procs = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            procs[int(stat.parent.name)] = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:  # ended meanwhile
            continue
    return procs


def process_tree(root: int) -> list[int]:
    """``root`` and all its descendants (the server spawns its planning workers)."""
    children: dict[int, list[int]] = {}
    for pid, fields in _procs().items():
        children.setdefault(int(fields[1]), []).append(pid)
    tree, todo = [], [root]
    while todo:
        pid = todo.pop()
        tree.append(pid)
        todo.extend(children.get(pid, []))
    return tree


def tree_rss_mb(root: int) -> float:
    """Resident memory of the whole tree: the sum of VmRSS (shared pages count in each)."""
    total_kb = 0
    for pid in process_tree(root):
        try:
            status = Path(f"/proc/{pid}/status").read_text()
        except OSError:
            continue
        if m := re.search(r"^VmRSS:\s+(\d+) kB", status, re.MULTILINE):
            total_kb += int(m[1])
    return total_kb / 1024


def workers_cpu_s(root: int) -> float:
    """CPU seconds used so far by the server's descendants (its planning workers)."""
    procs = _procs()
    tree = set(process_tree(root)) - {root}
    return sum(int(procs[p][11]) + int(procs[p][12]) for p in tree if p in procs) / CLOCK_TICKS


class RssSampler(threading.Thread):
    """Samples the tree's RSS every 0.5 s; ``peak(t0, t1)`` is the largest in a window."""

    def __init__(self, root: int) -> None:
        super().__init__(daemon=True)
        self.root, self.samples, self.stopped = root, [], threading.Event()

    def run(self) -> None:
        while not self.stopped.wait(0.5):
            self.samples.append((time.monotonic(), tree_rss_mb(self.root)))

    def peak(self, t0: float = 0, t1: float = float("inf")) -> float:
        return max((mb for t, mb in self.samples if t0 <= t <= t1), default=float("nan"))


# -- honest clients

def honest_client(url: str, first_seed: int, stop_at: float, out: list) -> None:
    """POST short slalom plans back to back; each (latency s, status, solved) goes to ``out``."""
    seed = first_seed
    with httpx.Client(base_url=url, timeout=120) as client:
        while time.monotonic() < stop_at:
            start = time.monotonic()
            try:
                resp = client.post("/api/v1/plan",
                                   json={"scenario_id": "slalom", "time": 0.2, "seed": seed})
                solved = resp.status_code == 200 and resp.json()["solved"]
                out.append((time.monotonic() - start, resp.status_code, solved))
            except httpx.HTTPError as exc:
                out.append((time.monotonic() - start, type(exc).__name__, False))
            seed += 2  # two clients: even and odd seeds


# -- hostile clients: each returns the answers it got, as short labels ("POST 202")

def crowded_scenario() -> bytes:
    """10 000 circles (the limit) on a 1 m lattice of a 100 m field; start and goal are free."""
    circles = [{"type": "circle", "center": [i + 0.5, j + 0.5], "radius": 0.2}
               for i in range(100) for j in range(100)]
    scenario = {"name": "crowded", "bounds": [0, 0, 100, 100],
                "vehicle": {"wheelbase": 0.44, "max_steer_deg": 26},
                "start": [1.0, 1.0, 0.0], "goal": [99.0, 99.0, 0.0], "obstacles": circles}
    return json.dumps({"scenario": scenario, "time": 30}).encode()  # 30 s: --max-plan-s


CROWDED = crowded_scenario()
BIG = b'{"scenario_id": "slalom", "name": "' + b"x" * (6 * MB) + b'"}'
DEEP_SVG = (b'<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm">'
            + b"<g>" * 2000 + b'<path d="M 0 0 L 50 0 L 50 50 Z"/>' + b"</g>" * 2000
            + b"</svg>")
MALFORMED = [b'{"scenario_id": "slalom", "time": ', b"[1, 2", b'{"scenario_id": "slal\xff"}',
             b"[" * 100_000, b"null"]
_SCENARIO = ('{"bounds": [0, 0, 10, 10], "start": [1, 1, 0], "goal": [9, 9, 0], '
             '"obstacles": [{"type": "circle", "center": [5, 5], "radius": 1}]}')
NUMBERS = [_SCENARIO.replace("[0, 0, 10, 10]", "[0, 0, 1e308, 1e308]"),
           _SCENARIO.replace("[1, 1, 0]", "[NaN, 1, 0]"),
           _SCENARIO.replace('"radius": 1', '"radius": Infinity'),
           _SCENARIO.replace("[9, 9, 0]", "[9, 9, 1e309]")]
JSON = {"content-type": "application/json"}
_STUDY = {"name": "huge", "scenarios": ["slalom"], "planners": ["rrt"],
          "budget": {"iterations": 100}}
HUGE_STUDIES = [{**_STUDY, "seeds": 1_000_000},  # ~100-byte bodies that once froze the API
                {**_STUDY, "parameters": {"eps": [1 + i / 1000 for i in range(150)],
                                          "gamma": [1 + i / 100 for i in range(150)],
                                          "goal_bias": [i / 20 for i in range(10)]}},
                {**_STUDY, "parameters": {"eps": {"min": 0.5, "max": 2.0}}, "sample": 300_000}]
FAN_OUT = (b'<svg xmlns="http://www.w3.org/2000/svg"><defs><g id="l0"/>'  # 2**22 clones
           + b"".join(f'<g id="l{i}"><use href="#l{i - 1}"/><use href="#l{i - 1}"/></g>'.encode()
                      for i in range(1, 22))
           + b'</defs><use href="#l21"/><use href="#l21"/></svg>')
LONG_CSV = b"".join(f"{i * 0.01:.2f},{(i % 7) * 0.01:.2f},1.5,1.5\n".encode()
                    for i in range(180_000))  # 180 000 rows, 4 MB
FLOOD = {"scenarios": ["slalom"], "parameters": [{"time": 8}], "seeds": list(range(50))}


def hostile_plan(client: httpx.Client, i: int) -> list[str]:
    try:
        resp = client.post("/api/v1/plan", content=CROWDED, headers=JSON, timeout=1.0)
        return [f"POST {resp.status_code}"]
    except httpx.TimeoutException:
        return ["gave up after 1 s"]


def hostile_job(client: httpx.Client, i: int) -> list[str]:
    resp = client.post("/api/v1/jobs", json={"scenarios": ["slalom"], "parameters": [{"time": 20}],
                                             "seeds": [i, i + 1]})
    if resp.status_code != 202:
        return [f"POST {resp.status_code}"]
    time.sleep(1)
    deleted = client.delete(f"/api/v1/jobs/{resp.json()['id']}")
    return ["POST 202", f"DELETE {deleted.status_code} {deleted.json().get('status')}"]


def hostile_simulation(client: httpx.Client, i: int) -> list[str]:
    resp = client.post("/api/v1/simulations", json={"scenario_id": "thesis_laps", "laps": 20,
                                                    "duration": 600, "seed": i})
    if resp.status_code != 202:
        return [f"POST {resp.status_code}"]
    time.sleep(2)
    deleted = client.delete(f"/api/v1/simulations/{resp.json()['id']}")
    return ["POST 202", f"DELETE {deleted.status_code} {deleted.json().get('status')}"]


def _upload(client: httpx.Client, **kw) -> list[str]:
    try:
        return [f"POST {client.post(**kw).status_code}"]
    except httpx.TransportError:  # the server answered 413 and closed while we still sent
        return ["connection closed"]


def hostile_upload(client: httpx.Client, i: int) -> list[str]:
    if i % 2:
        return _upload(client, url="/api/v1/plan", content=BIG, headers=JSON)
    return _upload(client, url="/api/v1/tracks", files={"file": ("big.svg", BIG)})


def hostile_chunked(client: httpx.Client, i: int) -> list[str]:
    def chunks():  # no Content-Length: the server must count what arrives
        for _ in range(96):
            yield b"x" * (64 * 1024)  # 6 MB

    return _upload(client, url="/api/v1/plan", content=chunks(), headers=JSON)


def hostile_malformed(client: httpx.Client, i: int) -> list[str]:
    body = MALFORMED[i % len(MALFORMED)]
    return [f"POST {client.post('/api/v1/plan', content=body, headers=JSON).status_code}"]


def hostile_svg(client: httpx.Client, i: int) -> list[str]:
    resp = client.post("/api/v1/tracks", files={"file": ("deep.svg", DEEP_SVG)})
    return [f"POST {resp.status_code}"]


def hostile_numbers(client: httpx.Client, i: int) -> list[str]:
    body = f'{{"scenario": {NUMBERS[i % len(NUMBERS)]}, "time": 0.5}}'
    if i % 5 == 4:
        body = '{"scenario_id": "slalom", "time": 1e308}'
    return [f"POST {client.post('/api/v1/plan', content=body, headers=JSON).status_code}"]


def hostile_origin(client: httpx.Client, i: int) -> list[str]:
    resp = client.post("/api/v1/plan", json={"scenario_id": "slalom", "time": 0.2},
                       headers={"Origin": "https://evil.example"})
    return [f"POST {resp.status_code}"]


def hostile_host(client: httpx.Client, i: int) -> list[str]:
    if i % 2:
        resp = client.get("/health", headers={"Host": "evil.example"})
        return [f"GET {resp.status_code}"]
    resp = client.post("/api/v1/plan", json={"scenario_id": "slalom", "time": 0.2},
                       headers={"Host": "rebound.example:8000"})
    return [f"POST {resp.status_code}"]


def hostile_study(client: httpx.Client, i: int) -> list[str]:
    resp = client.post("/api/v1/studies", json=HUGE_STUDIES[i % len(HUGE_STUDIES)])
    return [f"POST {resp.status_code}"]


def hostile_fan_out(client: httpx.Client, i: int) -> list[str]:
    resp = client.post("/api/v1/tracks", files={"file": ("clones.svg", FAN_OUT)})
    return [f"POST {resp.status_code}"]


def hostile_csv(client: httpx.Client, i: int) -> list[str]:
    resp = client.post("/api/v1/tracks", files={"file": ("long.csv", LONG_CSV)})
    return [f"POST {resp.status_code}"]


def hostile_flood(client: httpx.Client, i: int) -> list[str]:
    """Six jobs of 50 runs × 8 s from one address, deleted after 3 s."""
    posted = [client.post("/api/v1/jobs", json={**FLOOD, "seeds": [i * 50 + k for k in
                                                                   range(50)]})
              for _ in range(6)]
    time.sleep(3)
    answers = [f"POST {resp.status_code}" for resp in posted]
    for resp in posted:
        if resp.status_code == 202:
            deleted = client.delete(f"/api/v1/jobs/{resp.json()['id']}")
            answers.append(f"DELETE {deleted.status_code} {deleted.json().get('status')}")
    return answers


# kind → (attack, the answers it may get)
HOSTILE = {
    "plan 10 000 circles, time 30 s, client gives up after 1 s": (
        hostile_plan, {"gave up after 1 s"}),
    "job 2 runs × 20 s, DELETE after 1 s": (
        hostile_job, {"POST 202", "DELETE 200 cancelled"}),
    "simulation 600 s (20 laps), DELETE after 2 s": (
        hostile_simulation, {"POST 202", "DELETE 200 cancelled"}),
    "6 MB body (plan JSON, track upload)": (hostile_upload, {"POST 413"}),
    "6 MB chunked body": (hostile_chunked, {"POST 413"}),
    "malformed JSON": (hostile_malformed, {"POST 400", "POST 422"}),
    "SVG of 2000 nested <g>": (hostile_svg, {"POST 400"}),
    "NaN, Infinity, 1e308 numbers": (hostile_numbers, {"POST 422"}),
    "cross-origin write (Origin: https://evil.example)": (hostile_origin, {"POST 403"}),
    "wrong Host header": (hostile_host, {"GET 400", "POST 400"}),
    "study of 10⁶ seeds, a 225 000-point grid, 300 000 samples": (hostile_study, {"POST 422"}),
    "SVG of <use> clones of clones (2²² from 1.3 KB)": (hostile_fan_out, {"POST 400"}),
    "centreline CSV of 180 000 rows": (hostile_csv, {"POST 400"}),
    "flood: 6 jobs × 50 runs × 8 s, DELETE after 3 s": (
        hostile_flood, {"POST 202", "POST 429", "DELETE 200 cancelled"}),
}


def hostile_client(url: str, kind: str, stop_at: float, pause: float, out: Counter,
                   slowest: dict) -> None:
    """Repeat one attack until ``stop_at``, ``pause`` s apart; it finishes its last round (a
    DELETE included), so nothing it started is left running."""
    attack = HOSTILE[kind][0]
    i = 0
    with httpx.Client(base_url=url, timeout=30) as client:
        while (start := time.monotonic()) < stop_at:
            try:
                answers = attack(client, i)
            except httpx.HTTPError as exc:
                answers = [type(exc).__name__]
            out.update((kind, answer) for answer in answers)
            slowest[kind] = max(slowest.get(kind, 0.0), time.monotonic() - start)
            i += 1
            time.sleep(pause)


# -- background clients of the attack phase: idle studio tabs, slow headers, a /health watch

def idle_websockets(ui_port: int, n: int, stop_at: float, out: dict) -> None:
    """Open ``n`` studio websockets and hold them, reading nothing, until ``stop_at``."""
    import viser
    from websockets.sync.client import connect

    sockets = []
    for _ in range(n):
        try:
            sockets.append(connect(f"ws://127.0.0.1:{ui_port}/", open_timeout=10,
                                   subprotocols=[f"viser-v{viser.__version__}"],
                                   additional_headers={"Origin": f"http://127.0.0.1:{ui_port}"}))
        except (OSError, TimeoutError) as exc:
            out.setdefault("errors", []).append(type(exc).__name__)
    out["opened"] = len(sockets)
    time.sleep(max(0.0, stop_at - time.monotonic()))
    for ws in sockets:
        ws.close()


def slow_headers(port: int, n: int, stop_at: float, out: dict) -> None:
    """``n`` connections that send a request's headers a byte every 2 s (slowloris); counts
    how many the server closed before ``stop_at``."""
    conns = []
    for _ in range(n):
        conn = socket.create_connection(("127.0.0.1", port), timeout=5)
        conn.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n")
        conns.append(conn)
    closed = 0
    while time.monotonic() < stop_at and conns:
        time.sleep(2.0)
        for conn in list(conns):
            try:
                conn.sendall(b"X")
            except OSError:
                conns.remove(conn)
                closed += 1
    for conn in conns:
        conn.close()
    out[port] = closed


def watch_health(url: str, stop_at: float, out: dict) -> None:
    """GET /health every 0.25 s with a 1 s timeout: the slowest answer and the misses."""
    slowest, missed = 0.0, 0
    with httpx.Client(base_url=url, timeout=1.0) as client:
        while time.monotonic() < stop_at:
            start = time.monotonic()
            try:
                ok = client.get("/health").status_code == 200
            except httpx.HTTPError:
                ok = False
            slowest = max(slowest, time.monotonic() - start)
            missed += not ok
            time.sleep(0.25)
    out.update(slowest_s=slowest, missed=missed)


# -- phases and the report

def run_phase(url: str, ui_port: int, duration: float, hostile: bool,
              pause: float) -> tuple[list, Counter, dict, dict]:
    """Run the clients for ``duration`` s: honest records, hostile answers, slowest rounds,
    and what the background clients saw (idle tabs, slow headers, /health)."""
    honest: list = []
    answers = {kind: Counter() for kind in HOSTILE}  # one per thread: no shared counter
    slowest: dict[str, float] = {}
    seen: dict = {"websockets": {}, "slow_headers": {}, "health": {}}
    stop_at = time.monotonic() + duration
    threads = [threading.Thread(target=honest_client, args=(url, seed, stop_at, honest))
               for seed in (0, 1)]
    threads.append(threading.Thread(target=watch_health, args=(url, stop_at, seen["health"])))
    if hostile:
        threads += [threading.Thread(target=hostile_client,
                                     args=(url, kind, stop_at, pause, answers[kind], slowest))
                    for kind in HOSTILE]
        api_port = int(url.rsplit(":", 1)[1])
        threads += [threading.Thread(target=idle_websockets,
                                     args=(ui_port, IDLE_TABS, stop_at, seen["websockets"])),
                    *(threading.Thread(target=slow_headers,
                                       args=(port, SLOW_CLIENTS, stop_at, seen["slow_headers"]))
                      for port in (api_port, ui_port))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return honest, sum(answers.values(), Counter()), slowest, seen


def idle_after(root: int, limit: float = 15.0) -> float | None:
    """Seconds until the workers use under 10 % of a CPU over half a second (None: never)."""
    start = time.monotonic()
    while time.monotonic() - start < limit:
        before = workers_cpu_s(root)
        time.sleep(0.5)
        if workers_cpu_s(root) - before < 0.05:
            return time.monotonic() - start
    return None


def honest_stats(records: list) -> dict:
    latencies = [lat for lat, status, _ in records if status == 200]
    q = (lambda p: float(np.percentile(latencies, p))) if latencies else (lambda p: float("nan"))
    return {"plans": len(records), "p50_s": q(50), "p95_s": q(95),
            "max_s": max(latencies, default=float("nan")),
            "ok_share": sum(status == 200 for _, status, _ in records) / max(len(records), 1),
            "solved_share": sum(solved for *_, solved in records) / max(len(records), 1),
            "statuses": dict(Counter(str(status) for _, status, _ in records))}


def table(result: dict) -> str:
    idle = result["workers_idle_after_s"]
    rows = [
        (f"# Load test: honest plans alone and under attack, {result['duration_s']:g} s each "
         f"({os.cpu_count()} CPUs)"),
        "",
        ("| honest POST /plan (slalom, 0.2 s) | plans | p50 (s) | p95 (s) | max (s) | 200 | "
         "solved | peak RSS (MB) |"),
        "|---|---|---|---|---|---|---|---|",
    ]
    for name in ("alone", "under_attack"):
        s = result[name]
        rows.append(f"| {name.replace('_', ' ')} | {s['plans']} | {s['p50_s']:.2f} | "
                    f"{s['p95_s']:.2f} | {s['max_s']:.2f} | {s['ok_share']:.0%} | "
                    f"{s['solved_share']:.0%} | {s['peak_rss_mb']:.0f} |")
    rows += [
        "",
        (f"under attack / alone: p50 × {result['p50_ratio']:.2f}, p95 × "
         f"{result['p95_ratio']:.2f} (limit × {result['max_p95_ratio']:g})"),
        "",
        (f"| hostile client (one each, {result['pause_s']:g} s between rounds) | answers | "
         "slowest round (s) |"),
        "|---|---|---|",
    ]
    for kind, answers in result["hostile"].items():
        listed = ", ".join(f"{a}: {n}" for a, n in answers.items())
        rows.append(f"| {kind} | {listed} | {result['slowest_round_s'][kind]:.2f} |")
    rows += [
        "",
        f"5xx answers: {result['5xx']}; unexpected answers: {len(result['unexpected'])}",
        *(f"- {u}" for u in result["unexpected"]),
        (f"workers idle {'never (15 s)' if idle is None else f'{idle:.1f} s'} after the last "
         f"client stopped; peak RSS of the server's process tree {result['peak_rss_mb']:.0f} MB"),
        (f"/health throughout: slowest {result['health_slowest_s']:.2f} s, missed "
         f"{result['health_missed']}; {result['idle_tabs_opened']} idle studio tabs held open; "
         f"slow-header connections closed by the server (per port): "
         f"{result['slow_headers_closed']}"),
        (f"SIGTERM ended the server and its children in {result['sigterm_s']:.1f} s"
         if result.get("sigterm_s") is not None else
         "SIGTERM: the server or a child was still alive after 10 s"),
        (f"afterwards: /health {result['health_after']}, a plain plan "
         f"{'solved' if result['plan_after_solved'] else 'did NOT solve'} in "
         f"{result['plan_after_s']:.2f} s"),
        *(f"FAIL: {why}" for why in result["failures"]),
        "",
    ]
    return "\n".join(rows)


def measure(proc: subprocess.Popen, url: str, ui_port: int, duration: float, pause: float,
            max_p95_ratio: float) -> dict:
    sampler = RssSampler(proc.pid)
    sampler.start()
    with httpx.Client(base_url=url, timeout=120) as client:  # warm-up, not counted (2.2 s)
        threads = [threading.Thread(target=client.post, args=("/api/v1/plan",),
                                    kwargs={"json": {"scenario_id": "slalom", "time": 0.2}})
                   for _ in range(2)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    t0 = time.monotonic()
    print(f"alone: 2 honest clients for {duration:g} s", file=sys.stderr, flush=True)
    alone, _, _, calm = run_phase(url, ui_port, duration, hostile=False, pause=pause)
    t1 = time.monotonic()
    print(f"under attack: 2 honest + {len(HOSTILE)} hostile clients for {duration:g} s",
          file=sys.stderr, flush=True)
    attack, answers, slowest, seen = run_phase(url, ui_port, duration, hostile=True,
                                               pause=pause)
    t2 = time.monotonic()
    idle = idle_after(proc.pid)
    with httpx.Client(base_url=url, timeout=30) as client:
        try:
            health = client.get("/health")
            health_after = health.status_code if health.status_code != 200 else \
                health.json()["status"]
        except httpx.HTTPError as exc:
            health_after = type(exc).__name__
        start = time.monotonic()
        plan = client.post("/api/v1/plan", json={"scenario_id": "slalom", "time": 0.5})
        plan_after_s = time.monotonic() - start
    sampler.stopped.set()
    hostile = {kind: {a: n for (k, a), n in sorted(answers.items()) if k == kind}
               for kind in HOSTILE if kind in slowest}
    honest_5xx = [s for *_, s in alone + attack if isinstance(s, int) and s >= 500]
    result = {
        "duration_s": duration, "pause_s": pause, "max_p95_ratio": max_p95_ratio,
        "alone": honest_stats(alone) | {"peak_rss_mb": sampler.peak(t0, t1)},
        "under_attack": honest_stats(attack) | {"peak_rss_mb": sampler.peak(t1, t2)},
        "hostile": hostile,
        "slowest_round_s": slowest,
        "5xx": len(honest_5xx) + sum(n for (_, a), n in answers.items()
                                     if re.search(r"\b5\d\d\b", a)),
        "unexpected": [f"{kind}: {a} × {n}" for (kind, a), n in sorted(answers.items())
                       if a not in HOSTILE[kind][1]],
        "workers_idle_after_s": idle,
        "peak_rss_mb": sampler.peak(),
        "health_after": health_after,
        "plan_after_solved": plan.status_code == 200 and plan.json()["solved"],
        "plan_after_s": plan_after_s,
        "health_slowest_s": max(calm["health"]["slowest_s"], seen["health"]["slowest_s"]),
        "health_missed": calm["health"]["missed"] + seen["health"]["missed"],
        "idle_tabs_opened": seen["websockets"].get("opened", 0),
        "slow_headers_closed": seen["slow_headers"],
    }
    result["p50_ratio"] = result["under_attack"]["p50_s"] / result["alone"]["p50_s"]
    result["p95_ratio"] = result["under_attack"]["p95_s"] / result["alone"]["p95_s"]
    return result


def failures(result: dict) -> list[str]:
    """Why the run fails, if it does (an empty list: it passes)."""
    why = []
    if result["5xx"]:
        why.append(f"{result['5xx']} answers 5xx")
    if result["unexpected"]:
        why.append("unexpected answers: " + "; ".join(result["unexpected"]))
    if result["health_after"] != "ok":
        why.append(f"/health afterwards: {result['health_after']}")
    if not result["plan_after_solved"]:
        why.append("a plain plan afterwards did not solve")
    if result["health_missed"] or result["health_slowest_s"] > 1.0:
        why.append(f"/health missed {result['health_missed']} times, slowest "
                   f"{result['health_slowest_s']:.2f} s (limit 1 s)")
    if result["idle_tabs_opened"] < IDLE_TABS:
        why.append(f"only {result['idle_tabs_opened']} of {IDLE_TABS} studio tabs opened")
    if not result.get("sigterm_s", 0.0) <= 10.0:  # None: the tree outlived 10 s
        why.append("SIGTERM did not end the server and all its children within 10 s")
    if result["workers_idle_after_s"] is None:
        why.append("the workers were still busy 15 s after the last client stopped")
    if not result["p95_ratio"] <= result["max_p95_ratio"]:  # NaN (no honest plan) fails too
        why.append(f"honest p95 under attack is {result['p95_ratio']:.2f} × its p95 alone "
                   f"(limit {result['max_p95_ratio']:g})")
    return why


def terminate(proc: subprocess.Popen, limit: float = 10.0) -> float | None:
    """SIGTERM the server; seconds until it and every child have ended (None: not within
    ``limit``, and then they are killed)."""
    tree = process_tree(proc.pid)
    start = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    while time.monotonic() - start < limit:
        if proc.poll() is not None and not any(Path(f"/proc/{pid}").exists()
                                               for pid in tree if pid != proc.pid):
            return time.monotonic() - start
        time.sleep(0.05)
    for pid in tree:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    proc.wait()
    return None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=20.0,
                        help="seconds of each phase, alone and under attack (default 20)")
    parser.add_argument("--pause", type=float, default=1.0,
                        help="seconds each hostile client waits between its attacks")
    parser.add_argument("--max-p95-ratio", type=float, default=8.0,
                        help="fail if the honest p95 under attack exceeds this × its p95 alone")
    parser.add_argument("--json", action="store_true", help="print a JSON object, no table")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as data_dir:
        proc, url, ui_port = start_server(data_dir)
        try:
            result = measure(proc, url, ui_port, args.duration, args.pause, args.max_p95_ratio)
        finally:
            sigterm_s = terminate(proc)
    result["sigterm_s"] = sigterm_s
    result["failures"] = failures(result)
    report = table(result)
    print(json.dumps(result, indent=1) if args.json else report)
    _harness.write_result("load", report)
    if args.json:  # the table, which names them, went to results/load.md only
        for why in result["failures"]:
            print(f"FAIL: {why}", file=sys.stderr)
    sys.exit(1 if result["failures"] else 0)


if __name__ == "__main__":
    _harness.run(main)
