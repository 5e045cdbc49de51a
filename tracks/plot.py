"""A figure of a track and its driving profile; kept out of the core so matplotlib loads only here."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tracks._errors import TrackError
from tracks._profile import Profile
from tracks._raceline import Limits, raceline_rows
from tracks._track import Track

FORMATS = (".png", ".svg", ".pdf")


def figure_path(output: str | Path) -> Path:
    """``output`` as a Path if matplotlib can write its format, else a TrackError."""
    output = Path(output)
    if output.suffix.lower() not in FORMATS:
        raise TrackError(f"output must end in {', '.join(FORMATS)}, got {output.name!r}")
    return output


def plot_profile(
    track: Track, profile: Profile, output: str | Path, max_steer_deg: float, limits: Limits
) -> Path:
    """Write the track with its boundaries, and curvature, steering angle (±δmax shaded) and the
    raceline's speed (below its limit min(V, √(A_lat/|κ|)), shaded) over s."""
    from matplotlib.figure import Figure

    output = figure_path(output)
    spacing = profile.s[1] - profile.s[0] if len(profile.s) > 1 else 0.02
    left, right = track.boundaries(spacing)
    bad = ~profile.feasible
    rows = raceline_rows(profile, limits)
    fig = Figure(figsize=(9, 12), layout="constrained")
    plan, curv, steer, speed = fig.subplots(4, 1, height_ratios=[2.2, 1, 1, 1])
    plan.plot(*left.T, color="0.45", lw=0.8, label="boundaries")
    plan.plot(*right.T, color="0.45", lw=0.8)
    plan.plot(profile.x, profile.y, color="C0", lw=1.2, label="centreline")
    plan.plot(
        profile.x[bad], profile.y[bad], "o", color="C3", ms=2, label=f"|δ| > {max_steer_deg}°"
    )
    plan.plot(profile.x[0], profile.y[0], ">", color="C2", ms=9, label="start")
    plan.set(
        aspect="equal",
        xlabel="x [m]",
        ylabel="y [m]",
        title=f"{track.name}: {track.length_m:.3f} m",
    )
    plan.legend(loc="best", fontsize="small")
    curv.plot(profile.s, profile.curvature, color="C0")
    curv.set(ylabel="curvature κ [1/m]")
    steer.axhspan(-max_steer_deg, max_steer_deg, color="C2", alpha=0.15, label="±δmax")
    steer.plot(profile.s, profile.steering_deg, color="C1")
    steer.plot(profile.s[bad], profile.steering_deg[bad], ".", color="C3", ms=3)
    steer.set(ylabel="steering δ [°]")
    steer.legend(loc="best", fontsize="small")
    cap = np.minimum(limits.v_max, np.sqrt(limits.a_lat / np.maximum(np.abs(rows[:, 4]), 1e-300)))
    speed.fill_between(rows[:, 0], 0, cap, color="C2", alpha=0.15,
                       label=f"v ≤ {limits.v_max:g} m/s, |a_lat| ≤ {limits.a_lat:g} m/s²")
    speed.plot(rows[:, 0], rows[:, 5], color="C4", label=f"v(s), |a_long| ≤ {limits.a_long:g} m/s²")
    speed.set(xlabel="s [m]", ylabel="speed v [m/s]", ylim=(0, limits.v_max * 1.1))
    speed.legend(loc="best", fontsize="small")
    for ax in (curv, steer, speed):
        ax.grid(alpha=0.3)
        ax.set_xlim(0, max(profile.length_m, np.finfo(float).eps))
    fig.savefig(output)
    return output
