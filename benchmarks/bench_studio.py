"""What the studio's live view costs, measured on the wire (issue 7's goals).

A headless websocket client (no rendering, so the browser's own CPU does not blur the numbers)
connects to a real studio server; the session plans `open_field` until the tree has 10 000+
nodes. Reported: the planner's iteration rate without a UI and with one (goal: < 20 % lower),
the updates (websocket frames) per second the client receives (goal: ≥ 20), and bytes per
second at growing tree sizes (goal: bounded, not growing with the tree).

    python benchmarks/bench_studio.py [--nodes 10000] [--json out.json]

Prints the numbers and writes them to benchmarks/results/studio.md.
"""

from __future__ import annotations

import argparse
import json
import threading
import time
from pathlib import Path

import _harness
import msgspec
import viser
import websockets.sync.client

import planner
from app.studio import launch
from app.studio._worker import PlannerWorker
from planner.rrt import warm_up


def _scenario() -> dict:
    return json.loads(planner.bundled_scenario_path("open_field").read_text())


class Wire:
    """A headless viser client: counts the frames and bytes it receives, per second."""

    def __init__(self, port: int) -> None:
        self.frames: list[tuple[float, int]] = []
        self._ws = websockets.sync.client.connect(
            f"ws://127.0.0.1:{port}", subprotocols=[f"viser-v{viser.__version__}"],
            max_size=None)
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()
        # viser counts a client as connected once it reports its camera, as a browser does.
        self._ws.send(msgspec.msgpack.encode({
            "type": "ViewerCameraMessage", "wxyz": [1.0, 0.0, 0.0, 0.0],
            "position": [0.0, 0.0, 30.0], "fov": 0.35, "near": 0.01, "far": 1000.0,
            "image_height": 900, "image_width": 1400, "look_at": [0.0, 0.0, 0.0],
            "up_direction": [0.0, 0.0, 1.0]}))

    def _read(self) -> None:
        try:
            while True:
                msg = self._ws.recv()
                self.frames.append((time.monotonic(), len(msg)))
        except websockets.exceptions.ConnectionClosed:
            pass

    def window(self, t0: float, t1: float) -> tuple[float, float]:
        """(frames/s, bytes/s) received between t0 and t1."""
        got = [n for t, n in list(self.frames) if t0 <= t < t1]
        return len(got) / (t1 - t0), sum(got) / (t1 - t0)

    def close(self) -> None:
        self._ws.close()


def _time_to(worker: PlannerWorker, nodes: int, marks: list[int], on_mark=None) -> dict:
    """Run the worker until ``nodes``; note the wall time at each mark."""
    worker.run()
    t0 = time.monotonic()
    at = {}
    while worker.lanes[0].run.nodes < nodes:
        time.sleep(0.02)
        for m in marks:
            if m not in at and worker.lanes[0].run.nodes >= m:
                at[m] = (time.monotonic(), worker.lanes[0].run.iterations)
                if on_mark:
                    on_mark(m)
        if time.monotonic() - t0 > 300:
            raise RuntimeError("the planner did not reach the node count in 5 minutes")
    at[nodes] = (time.monotonic(), worker.lanes[0].run.iterations)
    worker.pause()
    return {"start": t0, "marks": at}


def _rate(res: dict, lo: int, hi: int) -> float:
    (t_lo, it_lo), (t_hi, it_hi) = res["marks"][lo], res["marks"][hi]
    return (it_hi - it_lo) / (t_hi - t_lo)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--nodes", type=int, default=10000)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    n = args.nodes
    marks = [n // 8, n // 4, n // 2, 3 * n // 4]
    data = _scenario()
    warm_up()
    problem = planner.compile_problem(planner.parse_scenario(data))
    options = planner.PlanOptions(seed=1)

    alone = PlannerWorker(problem, options, budget=10**9)
    base = _time_to(alone, n, marks)
    alone.stop()

    studio = launch("127.0.0.1", 0, "http://127.0.0.1:9")
    wire = Wire(studio.port)
    while not studio.sessions:
        time.sleep(0.05)
    session = next(iter(studio.sessions.values()))
    time.sleep(1.0)
    session.sources.load_scenario(data)
    session.ui.seed.value = 1  # resets the run with the same settings as the baseline
    session.ui.budget.value = 10**9
    session.planning.reset()
    time.sleep(0.5)
    with_ui = _time_to(session.planning.worker, n, marks)
    time.sleep(0.3)
    wire.close()
    studio.stop()

    rows = []
    prev = with_ui["start"]
    for m in [*marks, n]:
        t, _ = with_ui["marks"][m]
        lo = max(prev, t - 1.0)
        fps, bps = wire.window(lo, t)
        rows.append({"nodes": m, "updates_per_s": round(fps, 1), "bytes_per_s": round(bps)})
        prev = t
    rate_alone = _rate(base, marks[-1], n)
    rate_ui = _rate(with_ui, marks[-1], n)
    out = {
        "scenario": data["name"], "nodes": n,
        "iterations_per_s_alone": round(rate_alone), "iterations_per_s_with_ui": round(rate_ui),
        "ui_cost_percent": round(100 * (1 - rate_ui / rate_alone), 1),
        "wire": rows,
    }
    print(json.dumps(out, indent=2))
    if args.json:
        args.json.write_text(json.dumps(out, indent=2) + "\n")
    _harness.write_result("studio", _markdown(out))


def _markdown(out: dict) -> str:
    lines = [f"# The studio's cost to the planner ({out['scenario']}, {out['nodes']} nodes)", "",
             "Command: `python benchmarks/bench_studio.py`", "",
             f"Iterations/s alone {out['iterations_per_s_alone']}, with the live view "
             f"{out['iterations_per_s_with_ui']}: the UI costs {out['ui_cost_percent']} %.", "",
             "| nodes | updates/s | bytes/s |", "|---:|---:|---:|"]
    lines += [f"| {r['nodes']} | {r['updates_per_s']} | {r['bytes_per_s']} |" for r in out["wire"]]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    _harness.run(main)
