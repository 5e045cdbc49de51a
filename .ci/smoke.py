"""CI smoke stage: the app as a user meets it after `pip install -e .` (no extras).

Run with the fresh venv's Python. Starts `trackstar serve` on free loopback ports with a
temporary data dir, probes /health, the studio page, /docs (with its assets served locally),
the bundled scenarios and one plan over REST, then stops it with SIGTERM and checks that it and
its workers are gone within 10 s. Then, in an empty directory, `trackstar scenario list`,
`trackstar plan slalom` and a one-run `trackstar study`. Only the standard library is used here, so a module missing from the
runtime dependencies fails in the app, not in this script.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

BIN = Path(sys.executable).parent
REFERENCE = {"open_field", "hallway", "slalom", "parking", "oval_track", "crossing"}
START_TIMEOUT_S = 420  # the first start compiles the planner's kernels


def get(url: str, data: dict | None = None) -> tuple[int, bytes]:
    body = json.dumps(data).encode() if data is not None else None
    request = urllib.request.Request(url, body, {"content-type": "application/json"})
    with urllib.request.urlopen(request, timeout=60) as r:
        return r.status, r.read()


def check(condition: bool, what: str) -> None:
    if not condition:
        sys.exit(f"smoke: FAILED: {what}")
    print(f"smoke: ok: {what}", flush=True)


def children(pid: int) -> list[int]:
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout
    return [int(p) for p in out.split()]


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return Path(f"/proc/{pid}").exists() and "zombie" not in Path(
        f"/proc/{pid}/status").read_text().lower()


def serve(workdir: Path) -> None:
    server = subprocess.Popen(
        [BIN / "trackstar", "serve", "--port", "0", "--ui-port", "0", "--data-dir",
         workdir / "data"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        cwd=workdir)
    urls: dict[str, str] = {}
    started = time.monotonic()
    deadline = started + START_TIMEOUT_S
    for line in server.stdout:
        print(f"  serve: {line.rstrip()}", flush=True)
        if m := re.match(r"(API|UI): (http://\S+)", line):
            urls[m[1]] = m[2]
        if "UI" in urls or time.monotonic() > deadline:
            break
    check("UI" in urls, f"trackstar serve prints its URLs ({time.monotonic() - started:.1f} s)")
    api = urls["API"].removesuffix("/docs")
    try:
        while True:  # the kernels load in the background: a first start compiles them
            status, body = get(f"{api}/health")
            if json.loads(body)["status"] != "warming" or time.monotonic() > deadline:
                break
            time.sleep(0.5)
        check(status == 200 and json.loads(body)["status"] == "ok",
              f"GET /health says ok ({time.monotonic() - started:.1f} s after the start)")
        status, body = get(urls["UI"])
        check(status == 200 and b"<html" in body.lower(), "the studio page")
        status, body = get(f"{api}/docs")
        asset = re.search(rb'src="(/[^"]*swagger-ui-bundle\.js)"', body)
        check(status == 200 and asset is not None, "/docs names a local Swagger UI script")
        check(get(api + asset[1].decode())[0] == 200, "/docs' script is served by the app")
        status, body = get(f"{api}/api/v1/scenarios")
        names = {r["id"] for r in json.loads(body) if r["source"] == "library"}
        check(REFERENCE <= names, "GET /api/v1/scenarios lists the bundled scenarios")
        status, body = get(f"{api}/api/v1/plan", {"scenario_id": "slalom", "time": 0.3})
        check(status == 200 and json.loads(body)["solved"], "POST /api/v1/plan solves slalom")
    finally:
        workers = children(server.pid)
        server.send_signal(signal.SIGTERM)
        try:
            code = server.wait(timeout=10)
        except subprocess.TimeoutExpired:
            server.kill()
            code = None
        print(server.stdout.read(), end="", flush=True)
    check(code == 0, f"SIGTERM ends the server within 10 s (exit {code})")
    time.sleep(1)
    check(not [p for p in workers if alive(p)], "no worker process outlives the server")


def cli(workdir: Path) -> None:
    empty = workdir / "empty"
    empty.mkdir()
    run = subprocess.run([BIN / "trackstar", "scenario", "list", "--json"], cwd=empty,
                         capture_output=True, text=True, timeout=120)
    names = {r["name"] for r in json.loads(run.stdout)} if run.returncode == 0 else set()
    check(REFERENCE <= names, "trackstar scenario list names the bundled scenarios")
    run = subprocess.run([BIN / "trackstar", "plan", "slalom", "--time", "0.3", "--json"],
                         cwd=empty, capture_output=True, text=True, timeout=600)
    check(run.returncode == 0 and json.loads(run.stdout)["solved"],
          f"trackstar plan slalom solves in an empty directory {run.stderr.strip()}")
    (empty / "tiny.yaml").write_text("name: tiny\nscenarios: [slalom]\nplanners: [rrt]\n"
                                     "budget: {iterations: 200}\n")
    run = subprocess.run([BIN / "trackstar", "study", "tiny.yaml", "--json"], cwd=empty,
                         capture_output=True, text=True, timeout=600)
    report = empty / "studies" / "tiny" / "report.html"
    check(run.returncode == 0 and json.loads(run.stdout)["done"] == 1 and report.is_file(),
          f"trackstar study runs a study and writes its report {run.stderr.strip()[-300:]}")


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        serve(Path(tmp))
        cli(Path(tmp))
