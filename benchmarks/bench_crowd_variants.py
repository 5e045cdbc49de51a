"""Safety among crowd scenes that are not bundled (issue 30: "the same will be checked on crowd
scenes that are not in the repository").

Makes fresh scenes of the issue's kinds, each checked fair against the true motions by the
independent checker (tests/checker.py): waiting at the start touches nothing for 60 s, and a
space-time plan to the goal exists.

* variants of the five bundled crowd scenes: every mover's timetable stretched × 0.75–1.3 and
  started 0–3 s late, every constant-velocity mover's speed × 0.8–1.3 and its start moved up
  to 1 m along its way;
* pedestrian crossings of 6–8 walkers at 0.7–1.5 m/s that cross, pause on the zebra, turn back
  halfway, or turn back at once 0.8–2.5 m in;
* open squares of 8–10 walkers on six random legs at 0.6–1.3 m/s, pausing between some;
* warehouses of random aisles, each cross aisle a dead end at the wall with a shuttle that
  reverses and dwells (`warehouse`);
* merges into, and overtakes against, streams of movers at random speeds and gaps.

Then drives each through `trackstar simulate FILE --rate R --timing T --seed K --fixed-latency
20 --json` (R 10 and 30 Hz, both timings, K = 0..seeds−1) and writes, per scene, the runs with a
collision while moving, at rest, and the goals reached, to benchmarks/results/crowd_variants.md.

    python benchmarks/bench_crowd_variants.py [--seed 33] [--count 2] [--seeds 3] [--jobs 2]

About 25 minutes with the defaults (20 scenes, 240 runs) on a 2-core machine.
"""

from __future__ import annotations

import argparse
import copy
import itertools
import json
import math
import random
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import _harness
import numpy as np
from tqdm import tqdm

import planner

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from checker import first_collision, pose_valid  # the independent checker

CROWDS = ("crowd_crossing", "crowd_warehouse", "crowd_merge", "crowd_square", "crowd_overtake")
CAR = {"vehicle": {"wheelbase": 0.44, "max_steer_deg": 26, "radius": 0.2, "speed": 1.0,
                   "max_speed": 1.5, "max_accel": 1.0},
       "goal_tolerance": {"position": 0.25, "heading_deg": 20}}


def varied(scene: dict, rng: random.Random) -> dict:
    """A bundled scene with its movers' timing changed (see the module's docstring)."""
    scene = copy.deepcopy(scene)
    for ob in scene["obstacles"]:
        motion = ob.get("motion") or {}
        if "waypoints" in motion:
            f, late = rng.uniform(0.75, 1.3), rng.uniform(0.0, 3.0)
            motion["waypoints"] = [[0.0, 0.0, 0.0]] + [
                [round(t * f + late, 3), dx, dy] for t, dx, dy in motion["waypoints"]]
        elif "velocity" in motion:
            (vx, vy), f, along = motion["velocity"], rng.uniform(0.8, 1.3), rng.uniform(-1, 1)
            motion["velocity"] = [round(vx * f, 3), round(vy * f, 3)]
            norm = max(math.hypot(vx, vy), 1e-9)
            ob["center"] = [round(ob["center"][0] + along * vx / norm, 2),
                            round(ob["center"][1] + along * vy / norm, 2)]
    return scene


def crossing(rng: random.Random) -> dict:
    """Walkers cross a 10 m street on the zebra at x 10–14; each crosses, pauses on it, turns
    back halfway or turns back at once soon after stepping on it."""
    walkers = []
    for _ in range(rng.randint(6, 8)):
        sign = rng.choice((1, -1))
        v, start = rng.uniform(0.7, 1.5), rng.uniform(1.0, 30.0)
        kind = rng.choice(("across", "pause", "back", "back at once", "pause and back"))
        d = (rng.uniform(0.8, 2.5) if kind == "back at once"
             else rng.uniform(3.0, 8.0) if kind == "back" else rng.uniform(2.0, 9.0))
        stops = {"across": [11.2], "pause": [d, d, 11.2], "back": [d, 0.0],
                 "back at once": [d, 0.0], "pause and back": [d, d, 0.0]}[kind]
        t, at, way = start, 0.0, [[0.0, 0.0, 0.0], [round(start, 3), 0.0, 0.0]]
        for stop in stops:  # walk there, or (the same stop again) pause
            t += abs(stop - at) / v if stop != at else rng.uniform(0.5, 3.0)
            at = stop
            way.append([round(t, 3), 0.0, round(sign * stop, 2)])
        walkers.append({"type": "circle", "center": [round(rng.uniform(10.2, 13.8), 2),
                                                     -0.6 if sign > 0 else 10.6],
                        "radius": 0.3, "motion": {"waypoints": way}})
    return {"bounds": [0, 0, 24, 10], **CAR, "start": [1.0, 5.0, 0.0],
            "goal": [23.0, 5.0, 0.0], "obstacles": walkers}


def square(rng: random.Random) -> dict:
    """An open 20 m square the car crosses diagonally, walkers on six legs each."""
    def away(x: float, y: float, d: float) -> bool:
        return math.hypot(x - 1.5, y - 1.5) > d and math.hypot(x - 18.5, y - 18.5) > d

    walkers = []
    while len(walkers) < rng.randint(8, 10):
        cx, cy = rng.uniform(3, 17), rng.uniform(3, 17)
        if not away(cx, cy, 4.0):
            continue
        t, dx, dy, way = 0.0, 0.0, 0.0, [[0.0, 0.0, 0.0]]
        for _ in range(6):
            x, y = rng.uniform(1, 19), rng.uniform(1, 19)
            while not away(x, y, 2.5):
                x, y = rng.uniform(1, 19), rng.uniform(1, 19)
            t += math.hypot(x - cx - dx, y - cy - dy) / rng.uniform(0.6, 1.3)
            dx, dy = x - cx, y - cy
            way.append([round(t, 3), round(dx, 2), round(dy, 2)])
            if rng.random() < 0.4:
                t += rng.uniform(0.5, 3.0)
                way.append([round(t, 3), round(dx, 2), round(dy, 2)])
        walkers.append({"type": "circle", "center": [round(cx, 2), round(cy, 2)],
                        "radius": 0.3, "motion": {"waypoints": way}})
    return {"bounds": [0, 0, 20, 20], **CAR, "start": [1.5, 1.5, 0.785398],
            "goal": [18.5, 18.5, 0.785398], "obstacles": walkers}


def warehouse(rng: random.Random) -> dict:
    """Shelf rows either side of a 3.6–5 m main aisle, cut by 2–4 cross aisles 2–2.4 m wide that
    end at the walls; in each a shuttle (1 × 0.8 m) runs at 0.7–1.3 m/s to the aisle's other end
    or into the main aisle's middle and back, dwelling 1–3 s at each stop."""
    aisle, depth, length = rng.uniform(3.6, 5.0), rng.uniform(2.5, 4.0), rng.uniform(22.0, 30.0)
    height, n = aisle + 2.0 * depth, rng.randint(2, 4)
    slot = (length - 8.0) / n
    cuts = [(x - w / 2, x + w / 2) for x, w in
            ((6.0 + slot * (i + rng.uniform(0.3, 0.7)), rng.uniform(2.0, 2.4)) for i in range(n))]
    edges = [round(x, 2) for x in [0.0, *(x for cut in cuts for x in cut), length]]
    shelves = [{"type": "polygon", "points": [[a, y0], [b, y0], [b, y1], [a, y1]]}
               for a, b in zip(edges[::2], edges[1::2])
               for y0, y1 in ((0.0, round(depth, 2)), (round(depth + aisle, 2), round(height, 2)))]
    shuttles = []
    for a, b in cuts:
        bottom = rng.random() < 0.5
        y_start = 0.5 if bottom else height - 0.5
        ends = (0.0, (height - 1.0) * (1 if bottom else -1))  # offsets from where it starts
        middle, v = depth + aisle / 2 - y_start, rng.uniform(0.7, 1.3)
        t, at = rng.uniform(0.0, 10.0), 0.0
        way = [[0.0, 0.0, 0.0], [round(t, 3), 0.0, 0.0]]
        while t < 75.0:
            far = ends[1] if at == ends[0] else ends[0]
            stops = [middle, at] if rng.random() < 0.3 else [far]
            for stop in stops:
                t += abs(stop - at) / v
                way.append([round(t, 3), 0.0, round(stop, 2)])
                t += rng.uniform(1.0, 3.0)
                way.append([round(t, 3), 0.0, round(stop, 2)])
                at = stop
        shuttles.append({"type": "box", "center": [round((a + b) / 2, 2), round(y_start, 2)],
                         "size": [1.0, 0.8], "motion": {"waypoints": way}})
    mid = round(depth + aisle / 2, 2)
    return {"bounds": [0, 0, round(length, 2), round(height, 2)], **CAR,
            "start": [1.0, mid, 0.0], "goal": [round(length - 1.0, 2), mid, 0.0],
            "obstacles": shelves + shuttles}


def _bundled(name: str) -> dict:
    return json.loads(planner.bundled_scenario_path(name).read_text())


def merge(rng: random.Random) -> dict:
    """An on-ramp into a 3 m lane (the bundled merge's road) where 6–8 discs drive at one speed
    of 0.8–1.3 m/s, 4.5–9 m apart."""
    road = _bundled("crowd_merge")
    v, x, discs = rng.uniform(0.8, 1.3), rng.uniform(6.0, 12.0), []
    for _ in range(rng.randint(6, 8)):
        discs.append({"type": "circle", "center": [round(x, 2), 6.0], "radius": 0.35,
                      "motion": {"velocity": [round(v, 3), 0.0]}})
        x -= rng.uniform(4.5, 9.0)
    return {**road, "obstacles": [ob for ob in road["obstacles"] if "motion" not in ob] + discs}


def overtake(rng: random.Random) -> dict:
    """The bundled overtaking road: a cart at 0.3–0.45 m/s in the car's lane, discs coming the
    other way at 0.8–1.2 m/s, 14–26 m apart."""
    road = _bundled("crowd_overtake")
    cart = {"type": "box", "center": [round(rng.uniform(4.0, 7.0), 2), 1.5], "size": [1.2, 0.8],
            "motion": {"velocity": [round(rng.uniform(0.3, 0.45), 3), 0.0]}}
    v, x, discs = rng.uniform(0.8, 1.2), rng.uniform(12.0, 22.0), []
    while x < 100.0:
        discs.append({"type": "circle", "center": [round(x, 2), 4.5], "radius": 0.4,
                      "motion": {"velocity": [-round(v, 3), 0.0]}})
        x += rng.uniform(14.0, 26.0)
    return {**road, "obstacles": [cart, *discs]}


def fair(scene: dict) -> bool:
    """Waiting at the start is free for 60 s, and a space-time plan to the goal exists (one of
    three seeds, 3 s each), both by the independent checker."""
    x, y, th = scene["start"]
    if not all(pose_valid(scene, x, y, t, th) for t in np.arange(0.0, 60.0, 0.01)):
        return False
    for seed in range(3):
        res = planner.solve(planner.parse_scenario(scene), time_limit=3.0, seed=seed)
        if res.solved and first_collision(scene, np.asarray(res.path)[:, [0, 1, 2, 5]]) is None:
            return True
    return False


def scenes(seed: int, count: int) -> dict[str, dict]:
    """``count`` fair scenes of each kind, by name."""
    rng, out = random.Random(seed), {}
    makers = [(f"{name}_v", lambda r, n=name: varied(_bundled(n), r)) for name in CROWDS]
    makers += [("crossing_new", crossing), ("square_new", square), ("warehouse_new", warehouse),
               ("merge_new", merge), ("overtake_new", overtake)]
    for prefix, make in makers:
        made = 0
        while made < count:
            scene = {"name": f"{prefix}{made}", "description": f"a variant (seed {seed})",
                     **{k: v for k, v in make(rng).items() if k not in ("name", "description")}}
            if fair(scene):
                out[scene["name"]] = scene
                made += 1
    return out


def simulate(path: Path, rate: int, timing: str, seed: int) -> dict:
    out = subprocess.run(["trackstar", "simulate", str(path), "--rate", str(rate), "--timing",
                          timing, "--seed", str(seed), "--fixed-latency", "20", "--json"],
                         capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"{path.name} {rate} Hz {timing} seed {seed}: {out.stderr[-300:]}")
    return json.loads(out.stdout)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=33, help="the scenes' random seed")
    ap.add_argument("--count", type=int, default=2, help="scenes of each kind")
    ap.add_argument("--seeds", type=int, default=3, help="simulation seeds per setting")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--keep", type=Path, help="also write the scenes here (JSON files)")
    args = ap.parse_args()
    made = scenes(args.seed, args.count)
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        for name, scene in made.items():
            (folder / f"{name}.json").write_text(json.dumps(scene, indent=1))
        cases = list(itertools.product(made, (10, 30), ("constant", "optimal"),
                                       range(args.seeds)))
        with ThreadPoolExecutor(args.jobs) as pool:
            runs = list(tqdm(pool.map(lambda c: simulate(folder / f"{c[0]}.json", *c[1:]),
                                      cases), total=len(cases), desc="runs"))
    rows, failed = [], []
    for name in made:
        mine = [(c, r) for c, r in zip(cases, runs) if c[0] == name]
        moving = sum(r["collisions_moving"] > 0 for _, r in mine)
        rest = sum(r["collisions_at_rest"] > 0 for _, r in mine)
        goals = sum(bool(r["reached_goal"]) for _, r in mine)
        rows.append((name, str(len(mine)), str(moving), str(rest), f"{goals}/{len(mine)}"))
        failed += [(f"{c[0]} {c[1]} Hz {c[2]} seed {c[3]}: "
                    f"{r['collisions_moving']} moving, {r['collisions_at_rest']} at rest, "
                    f"least clearance {r['min_clearance_m']:.3f} m") for c, r in mine
                   if r["collisions_moving"] or r["collisions_at_rest"]]
    total = (f"In all: {len(runs)} runs, {sum(r['collisions_moving'] > 0 for r in runs)} with "
             f"a collision while moving, {sum(r['collisions_at_rest'] > 0 for r in runs)} at "
             f"rest, the goal in {sum(bool(r['reached_goal']) for r in runs)}.")
    table = _harness.markdown_table(("scene", "runs", "moving", "at rest", "goal"), rows)
    command = (f"python benchmarks/bench_crowd_variants.py --seed {args.seed} "
               f"--count {args.count} --seeds {args.seeds}")
    text = "\n".join([f"# Crowd scenes not in the repository (seed {args.seed})", "",
                      f"Command: `{command}`", "", table, "", total, ""]
                     + [f"- {line}" for line in failed])
    print(text)
    _harness.write_result("crowd_variants", text + "\n")


if __name__ == "__main__":
    _harness.run(main)
