"""Plot a behaviour run's logged path over its scene, coloured by the machine's state.

    trackstar simulate hallway --behaviour examples/fsm/hallway.json \\
        --fixed-latency 20 --json --log run.csv > run.json
    python examples/fsm/plot_run.py hallway examples/fsm/hallway.json \\
        run.csv run.json docs/img/fsm_hallway.png

The scenario is a bundled scenario's name or a scenario file.

Approach points are drawn with their tolerance circles, transitions as ticks on the path, the
goal region in green. docs/scenario-format.md scenes (circles, polygons) only; needs matplotlib.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import Circle, Polygon, Rectangle

import planner


def _approach_points(ax, machine: dict, prefix: str = "") -> None:
    for st in machine["states"]:
        if st["type"] == "StateMachine":
            _approach_points(ax, st, f"{prefix}{st['id']}/")
        elif st["type"] == "ApproachPoint":
            p = st["params"]["point"]
            ax.add_patch(Circle(p, st["params"]["tolerance_m"], fill=False, ls="--", color="k"))
            ax.annotate(prefix + st["id"], p, fontsize=7, xytext=(4, 4),
                        textcoords="offset points")


def main(scenario, fsm_path, log_path, summary_path, out) -> None:
    scenario_path = (scenario if Path(scenario).is_file()
                     else planner.bundled_scenario_path(scenario))
    scn, machine, s = (json.loads(Path(p).read_text())
                       for p in (scenario_path, fsm_path, summary_path))
    log = np.genfromtxt(log_path, delimiter=",", names=True)
    fig, ax = plt.subplots(figsize=(11, 8.6))
    x0, y0, x1, y1 = scn["bounds"]
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, lw=1.5))
    for ob in scn["obstacles"]:
        if ob["type"] == "polygon":
            ax.add_patch(Polygon(ob["points"], color="0.6"))
        elif ob["type"] == "circle":
            ax.add_patch(Circle(ob["center"], ob["radius"], color="0.6"))
    state = log["state"].astype(int)
    colours = plt.get_cmap("tab20")
    for i, name in enumerate(s["behaviour"]["states"]):
        if (state == i).any():
            ax.scatter(log["x"][state == i], log["y"][state == i], s=2, color=colours(i % 20),
                       label=name)
    _approach_points(ax, machine)
    dt = log["t"][1] - log["t"][0]
    for tr in s["behaviour"]["transitions"]:
        k = round(tr["t"] / dt)
        ax.plot(log["x"][k], log["y"][k], "k|", ms=8)
    gx, gy, _ = scn["goal"]
    tol = scn.get("goal_tolerance", {}).get("position", 0.1)
    ax.add_patch(Circle((gx, gy), tol, fill=False, color="g", lw=2))
    sx, sy, sth = scn["start"]
    ax.arrow(sx, sy, 0.5 * np.cos(sth), 0.5 * np.sin(sth), width=0.05, color="b")
    ax.set_aspect("equal")
    ax.set_xlim(x0 - 0.2, x1 + 0.2)
    ax.set_ylim(y0 - 0.2, y1 + 0.2)
    goal = (f"goal reached at t = {s['time_to_goal_s']:.2f} s" if s["reached_goal"]
            else "goal not reached")
    ax.set_title(f"{scn['name']} driven by {fsm_path.split('/')[-1]}: {goal}, "
                 f"{s['collisions']} collisions, min clearance {s['min_clearance_m']:.2f} m",
                 fontsize=10)
    ax.legend(loc="center", bbox_to_anchor=(0.62, 0.62), fontsize=7, markerscale=4, ncol=2)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    fig.tight_layout()
    fig.savefig(out, dpi=90)


if __name__ == "__main__":
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    main(*sys.argv[1:])
