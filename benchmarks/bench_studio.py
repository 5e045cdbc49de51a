"""What the studio's live view costs: on the wire, and in a real browser.

The wire (issue 7's goals): a headless websocket client (no rendering, so the browser's own CPU
does not blur the numbers) connects to a real studio server; the session plans `open_field`
until the tree has 10 000+ nodes. Reported: the planner's iteration rate without a UI and with
one (goal: < 20 % lower), the updates (websocket frames) per second the client receives (goal:
≥ 20), and bytes per second at growing tree sizes (goal: bounded, not growing with the tree).

The browser (issue 33's goals): `trackstar serve` and Debian's Chromium with software WebGL
(Playwright, 1280 × 800), the lecture run: the thesis track, RRT* Dubins, 30 000 iterations at
max pace (paused for 3 s, 0.3 s after it started), then 5 s of the finished tree, then Run on
(as many iterations again) and 5 s of that tree. Reported twice a second: frames drawn (requestAnimationFrame; goal ≥ 5), the run's
iterations and nodes (read off the panel), websocket bytes received (goal: under
``BYTES_PER_S_GOAL``); and how long the status line takes to answer a click on Run and on
Pause (goal ≤ 1 s).

    python benchmarks/bench_studio.py [--only wire|browser] [--nodes 10000] [--json out.json]

Prints the numbers and writes them to benchmarks/results/studio.md. The browser part needs the
test extras (Playwright) and /usr/bin/chromium.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
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
    ap.add_argument("--only", choices=("wire", "browser"))
    ap.add_argument("--nodes", type=int, default=10000, help="the wire part's tree size")
    ap.add_argument("--iterations", type=int, default=30000, help="the browser part's budget")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    out = {}
    if args.only != "browser":
        out["wire"] = _wire(args.nodes)
    if args.only != "wire":
        out["browser"] = _browser(args.iterations)
    print(json.dumps(out, indent=2))
    if args.json:
        args.json.write_text(json.dumps(out, indent=2) + "\n")
    parts = {"wire": _wire_markdown, "browser": _browser_markdown}
    _harness.write_result("studio", "\n".join(parts[k](v) for k, v in out.items()))


def _wire(n: int) -> dict:
    marks = [n // 8, n // 4, n // 2, 3 * n // 4]
    data = _scenario()
    warm_up()
    problem = planner.compile_problem(planner.parse_scenario(data))
    options = planner.PlanOptions(seed=1)

    alone = PlannerWorker(problem, options, budget=1_000_000)
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
    session.ui.budget.value = 1_000_000  # the most a run may be given
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
    return {
        "scenario": data["name"], "nodes": n,
        "iterations_per_s_alone": round(rate_alone), "iterations_per_s_with_ui": round(rate_ui),
        "ui_cost_percent": round(100 * (1 - rate_ui / rate_alone), 1),
        "wire": rows,
    }


def _wire_markdown(out: dict) -> str:
    lines = [f"# The studio's cost to the planner ({out['scenario']}, {out['nodes']} nodes)", "",
             "Command: `python benchmarks/bench_studio.py --only wire`", "",
             (f"Iterations/s alone {out['iterations_per_s_alone']}, with the live view "
              f"{out['iterations_per_s_with_ui']}: the UI costs {out['ui_cost_percent']} %."), "",
             "| nodes | updates/s | bytes/s |", "|---:|---:|---:|"]
    lines += [f"| {r['nodes']} | {r['updates_per_s']} | {r['bytes_per_s']} |" for r in out["wire"]]
    return "\n".join(lines) + "\n"


CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                 "--use-gl=swiftshader"]
FRAME_COUNTER = """
window.__frames = 0;
const count = () => { window.__frames++; requestAnimationFrame(count); };
requestAnimationFrame(count);
"""
BYTES_PER_S_GOAL = 1_500_000  # the websocket at most, at every tree size


def _serve(data_dir: str) -> tuple[subprocess.Popen, str]:
    """`trackstar serve` on free ports, and its studio's URL."""
    exe = shutil.which("trackstar") or "trackstar"
    proc = subprocess.Popen([exe, "serve", "--port", "0", "--ui-port", "0", "--data-dir",
                             data_dir], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)
    seen = []
    for line in proc.stdout:  # until it prints its UI's address, or ends
        seen.append(line)
        m = re.match(r"UI: (http://\S+)", line)
        if m:
            return proc, m.group(1)
    proc.wait()
    raise RuntimeError("trackstar serve printed no UI line:\n" + "".join(seen[-10:]))


def _panel_count(text: str, row: str) -> int:
    m = re.search(rf"\b{row}\s+(\d+)", text)
    return int(m.group(1)) if m else 0


def _browser(iterations: int) -> dict:
    """The lecture run in Chromium: Run at max pace, Pause 0.3 s later, watch the paused tree 3 s,
    Run to the budget and watch 5 s more; Run on (as many iterations again) and watch 5 s."""
    from playwright.sync_api import sync_playwright

    received: list[tuple[float, int]] = []
    samples: list[dict] = []
    with tempfile.TemporaryDirectory() as data_dir, sync_playwright() as pw:
        proc, url = _serve(data_dir)
        try:
            browser = pw.chromium.launch(executable_path=CHROMIUM, headless=True,
                                         args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 1280, "height": 800})
            page.add_init_script(FRAME_COUNTER)
            page.on("websocket", lambda ws: ws.on(
                "framereceived", lambda f: received.append((time.monotonic(), len(f)))))
            page.set_default_timeout(120_000)
            page.goto(url)
            page.get_by_text("Metrics").first.wait_for()
            time.sleep(3.0)  # the view fitted, the first panel sent
            budget = page.get_by_label("Budget (iterations)")
            budget.fill(str(iterations))
            budget.press("Enter")
            t0 = time.monotonic()
            last = [t0, page.evaluate("window.__frames")]

            def sample(phase: str) -> str:
                text = page.evaluate("document.body.innerText")
                now, frames = time.monotonic(), page.evaluate("window.__frames")
                got = sum(n for t, n in received if last[0] <= t < now)
                samples.append({"phase": phase, "t_s": round(now - t0, 1),
                                "iterations": _panel_count(text, "iterations"),
                                "nodes": _panel_count(text, "nodes"),
                                "frames_per_s": round((frames - last[1]) / (now - last[0]), 1),
                                "bytes_per_s": round(got / (now - last[0]))})
                last[:] = now, frames
                print(samples[-1], file=sys.stderr, flush=True)
                return text

            def watch(phase: str, seconds: float, until=lambda text: False) -> None:
                end = time.monotonic() + seconds
                while time.monotonic() < end:
                    time.sleep(0.5)
                    if until(sample(phase)):
                        return

            def click(name: str, *answers: str) -> str:
                """Click a run button; the seconds until the status line shows an answer, and
                which ("3.18 s (done)": the run had ended before a Pause was answered)."""
                clicked = time.monotonic()
                page.get_by_role("button", name=name, exact=True).click(force=True)
                answer = page.wait_for_function(
                    "(answers) => answers.find(a => document.body.innerText"
                    ".includes('Status: ' + a))", arg=list(answers)).json_value()
                return f"{time.monotonic() - clicked:.2f} s ({answer})"

            run_s = click("Run", "running")
            time.sleep(0.3)  # at max pace the run is done in about 2 s: Pause while it grows
            pause_s = click("Pause", "paused", "done")
            watch("after Pause", 3)
            click("Run", "running")
            watch("running", 600, lambda text: "Status: done" in text)
            watch("done", 5)
            run_on_s = click("Run", "running")
            watch("running on", 600, lambda text: "Status: done" in text)
            watch("done", 5)
            browser.close()
        finally:
            proc.terminate()
            proc.wait(timeout=10)
    return {"scenario": "thesis", "iterations": iterations, "samples": samples,
            "run_answered": run_s, "run_on_answered": run_on_s, "pause_answered": pause_s,
            "min_frames_per_s": min(s["frames_per_s"] for s in samples),
            "max_bytes_per_s": max(s["bytes_per_s"] for s in samples),
            "bytes_per_s_goal": BYTES_PER_S_GOAL}


def _browser_markdown(out: dict) -> str:
    lines = [(f"# The studio in Chromium with software WebGL ({out['scenario']}, RRT* Dubins, "
              f"{out['iterations']:,} iterations at max pace, 1280 × 800)"), "",
             "Command: `python benchmarks/bench_studio.py --only browser`", "",
             (f"Frames/s, least: {out['min_frames_per_s']} (goal ≥ 5). The status line "
              f"answered Run in {out['run_answered']}, Run on in "
              f"{out['run_on_answered']}, Pause in {out['pause_answered']} (goal ≤ 1 s). "
              f"Websocket bytes/s, most: {out['max_bytes_per_s']:,} "
              f"(goal < {out['bytes_per_s_goal']:,})."), "",
             "| phase | s | iterations | nodes | frames/s | bytes/s |",
             "|---|---:|---:|---:|---:|---:|"]
    lines += [f"| {s['phase']} | {s['t_s']} | {s['iterations']} | {s['nodes']} | "
              f"{s['frames_per_s']} | {s['bytes_per_s']} |" for s in out["samples"]]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    _harness.run(main)
