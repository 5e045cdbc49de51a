"""Load run of `trackstar serve` on loopback: concurrent clients posting short plans while one
client polls /health. Bounded: a fixed duration, then the server is stopped.

    python benchmarks/bench_server.py [--clients 20] [--plan-s 0.2] [--duration 30]

Prints p50/p95/p99 latency and throughput of POST /plan, the /health latencies (the event loop
must stay free while the pool is saturated: p99 < 100 ms), and every error; writes the same
Markdown to results/server.md.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import re
import subprocess
import sys
import tempfile
import time

import _harness
import httpx
import numpy as np


def start_server(data_dir: str) -> tuple[subprocess.Popen, str]:
    proc = subprocess.Popen(["trackstar", "serve", "--port", "0", "--ui-port", "0",
                             "--data-dir", data_dir], stdout=subprocess.PIPE, text=True)
    for line in proc.stdout:  # bounded: the process prints its start lines or exits
        if m := re.fullmatch(r"API: (http://.+:\d+)/docs\n", line):
            url = m[1]
        if line.startswith("UI: "):
            return proc, url
    raise RuntimeError("server did not start")


async def plan_client(client, body, stop_at, latencies, errors) -> None:
    while time.monotonic() < stop_at:
        start = time.monotonic()
        try:
            resp = await client.post("/api/v1/plan", json=body)
            if resp.status_code == 200 and resp.json()["iterations"] > 0:
                latencies.append(time.monotonic() - start)
            else:
                errors.append(f"{resp.status_code}: {resp.text[:100]}")
        except httpx.HTTPError as exc:
            errors.append(repr(exc))


async def health_client(client, stop_at, latencies, errors) -> None:
    while time.monotonic() < stop_at:
        start = time.monotonic()
        try:
            resp = await client.get("/health")
            latencies.append(time.monotonic() - start)
            if resp.status_code != 200:
                errors.append(f"/health {resp.status_code}")
        except httpx.HTTPError as exc:
            errors.append(f"/health {exc!r}")
        await asyncio.sleep(0.05)


def ms(values, q) -> str:
    return f"{1000 * np.percentile(values, q):.1f}" if values else "–"


async def run(url: str, clients: int, plan_s: float, duration: float) -> str:
    body = {"scenario_id": "slalom", "time": plan_s}  # a bundled scenario
    plans, health, errors = [], [], []
    limits = httpx.Limits(max_connections=clients + 1)
    async with httpx.AsyncClient(base_url=url, timeout=60, limits=limits) as client:
        start = time.monotonic()
        stop_at = start + duration
        await asyncio.gather(health_client(client, stop_at, health, errors),
                             *(plan_client(client, body, stop_at, plans, errors)
                               for _ in range(clients)))
        elapsed = time.monotonic() - start
    return "\n".join([
        (f"# Server load: {clients} clients × {plan_s} s plans for {duration:.0f} s "
         f"({os.cpu_count()} CPUs)"),
        "",
        "| requests | count | p50 (ms) | p95 (ms) | p99 (ms) | throughput (/s) |",
        "|---|---|---|---|---|---|",
        (f"| POST /plan | {len(plans)} | {ms(plans, 50)} | {ms(plans, 95)} | {ms(plans, 99)} | "
         f"{len(plans) / elapsed:.2f} |"),
        (f"| GET /health | {len(health)} | {ms(health, 50)} | {ms(health, 95)} | "
         f"{ms(health, 99)} | – |"),
        "",
        f"errors: {len(errors)}" + "".join(f"\n- {e}" for e in errors[:10]),
        "",
    ])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=20)
    parser.add_argument("--plan-s", type=float, default=0.2)
    parser.add_argument("--duration", type=float, default=30.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as data_dir:
        proc, url = start_server(data_dir)
        try:
            report = asyncio.run(run(url, args.clients, args.plan_s, args.duration))
        finally:
            proc.terminate()
            proc.wait(20)
    print(report)
    _harness.write_result("server", report)
    sys.exit(0 if "errors: 0" in report else 1)


if __name__ == "__main__":
    _harness.run(main)
