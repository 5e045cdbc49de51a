"""The same route planned with a bang-bang and with a continuous-curvature steering, and what a
servo must do.

    python examples/cc_profiles.py thesis_half_lap docs/img/cc_dubins_profiles.png
    python examples/cc_profiles.py parking docs/img/cc_reeds_shepp_profiles.png reeds-shepp

Plans the scenario (a bundled name or a scenario file) with RRT* for 3000 iterations, seed 0,
with the steering named third (default dubins) and its CC kin (cc-dubins), and plots the paths, their curvature κ(s), steering angle δ(s) = atan(Lκ)
against ±δmax and the steering rate dδ/dt at the planned speed against the servo's
±max_steer_rate. Dubins' steps show as spikes of dδ/dt (a jump over one 5 cm row); CC-Dubins
ramps stay within the limit. Needs matplotlib.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import planner

COLOURS = ("#d6336c", "#1c7ed6")  # the bang-bang steering, its CC kin


def main(scenario: str, out: str, kin: str = "dubins") -> None:
    path = Path(scenario) if Path(scenario).is_file() else planner.bundled_scenario_path(scenario)
    scn = planner.parse_scenario(json.loads(path.read_text()))
    vehicle = scn.vehicle
    fig = plt.figure(figsize=(11, 6.5), layout="constrained")
    grid = fig.add_gridspec(3, 2, width_ratios=(1, 1.3))
    plane = fig.add_subplot(grid[:, 0])
    kappa, delta, rate = (fig.add_subplot(grid[i, 1]) for i in range(3))
    for steering, colour in zip((kin, "cc-" + kin), COLOURS):
        result = planner.solve(scn, steering=steering, time_limit=None, iterations=3000, seed=0)
        rows = result.path
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(rows[:, :2], axis=0).T))])
        steer = np.degrees(np.arctan(vehicle.wheelbase * rows[:, 3]))
        speed = result.options.speed
        label = f"{planner.STEERINGS[steering].label} ({result.length_m:.2f} m)"
        plane.plot(rows[:, 0], rows[:, 1], color=colour, label=label)
        kappa.plot(s, rows[:, 3], color=colour)
        delta.plot(s, steer, color=colour)
        rate.plot(s[1:], np.diff(steer) / np.diff(s) * speed, color=colour)
    plane.set_aspect("equal")
    plane.legend(loc="best", fontsize=8)
    plane.set_title(f"{scn.name}: RRT*, 3000 iterations, seed 0")
    for ax, limit, ylabel in ((kappa, 1 / vehicle.turning_radius, "κ (1/m)"),
                              (delta, vehicle.max_steer_deg, "δ (deg)"),
                              (rate, vehicle.max_steer_rate_deg_s, "dδ/dt (deg/s)")):
        for sign in (1, -1):
            ax.axhline(sign * limit, color="#2e9e5b", ls="--", lw=1)
        ax.set_ylabel(ylabel)
    rate.set_ylim(-3 * vehicle.max_steer_rate_deg_s, 3 * vehicle.max_steer_rate_deg_s)
    rate.set_xlabel("arc length s (m)")
    rate.set_title(f"at the planned speed; dashed: the servo's ±{vehicle.max_steer_rate_deg_s:g}°/s"
                   f" ({planner.STEERINGS[kin].label}'s jumps run off the chart)", fontsize=8)
    kappa.set_title(f"dashed: ±κmax = 1/ρ, ρ = {vehicle.turning_radius:.3f} m", fontsize=8)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*sys.argv[1:4])
