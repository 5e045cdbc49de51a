"""The steering functions a planner can use, registered under one name each.

Every edge of the system takes its list from `STEERINGS`: the options model (`PlanOptions`),
`trackstar plan --steering`, the REST schema, the studio's dropdown and docs. The compiled
implementations live one per module (`_dubins.py`, `_reeds_shepp.py`, `_straight.py`,
`_cc_dubins.py`, `_cc_reeds_shepp.py`); the planner's kernel reaches them through `_steer.py` by each entry's integer ``code``, and stores
their paths in the segment form of `_paths.py`, ``segments`` wide. Adding a
steering function is: its module, an entry here, a branch per function in `_steer.py`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

__all__ = ["CAR_STEERINGS", "DEFAULT_STEERING", "STEERINGS", "Steering", "SteeringName"]

# the kernel's codes (`_steer.py` dispatches on them)
DUBINS, REEDS_SHEPP, STRAIGHT, CC_DUBINS, CC_REEDS_SHEPP = range(5)


@dataclass(frozen=True)
class Steering:
    """One registered steering function.

    ``heading_free``: a point or disc robot that turns on the spot — the goal is reached by
    position, a rectangular footprint (whose sweep a turn on the spot would ignore) is refused,
    and RRT*'s near radius shrinks as in the plane (d = 2) instead of in (x, y, θ) (d = 3).
    ``curved``: it drives arcs of curvature up to 1/ρ, so the chords between a path's rows stray
    from it (`planner._rows.chord_sag`). ``curvature``: what its paths' curvature profile looks
    like (the studio's caption). ``ompl_space``: OMPL's state space of the same paths (None: OMPL
    has none). ``segments``: the most segments one of its paths has (the width of its paths'
    arrays in the segment form of `planner._paths`). ``continuous``: its curvature never
    jumps — it ramps at most at the car's sharpness σmax, and its paths start and end at κ = 0.
    ``shortest``: its paths are the shortest ones (the triangle inequality holds).
    """

    name: str
    label: str
    code: int
    reverses: bool
    heading_free: bool
    summary: str
    curvature: str
    ompl_space: str | None = None
    curved: bool = True
    segments: int = 5  # Reeds-Shepp's longest words (C|C(π/2)SC(π/2)|C) have five
    continuous: bool = False
    shortest: bool = True


STEERINGS = {s.name: s for s in (
    Steering("dubins", "Dubins", DUBINS, False, False, "forward only (Dubins 1957)",
             "Dubins paths are arcs at the tightest turn and straights: the path's κ is +1/ρ, "
             "−1/ρ or 0 and jumps between them (bang-bang), never in between; ±κmax = 1/ρ.",
             "DubinsStateSpace"),
    Steering("reeds-shepp", "Reeds-Shepp", REEDS_SHEPP, True, False,
             "forward and reverse (Reeds & Shepp 1990)",
             "Reeds-Shepp paths are arcs at the tightest turn and straights, forward or in "
             "reverse: κ is ±1/ρ or 0 (bang-bang). Shaded: driven in reverse; ◆ on the zero "
             "line: a cusp, where the car stops and changes direction.",
             "ReedsSheppStateSpace"),
    Steering("straight", "Straight line", STRAIGHT, False, True,
             "straight lines for a point or disc robot that turns on the spot, goal by "
             "position (the classic RRT picture, LaValle 1998)",
             "Straight lines: κ = 0 all along; the robot turns on the spot between them.",
             curved=False),
    Steering("cc-dubins", "CC-Dubins", CC_DUBINS, False, False,
             "forward only, continuous curvature: clothoids into and out of every turn "
             "(Fraichard & Scheuer 2004)",
             "CC-Dubins paths ramp κ up to ±1/ρ and back down along clothoids of sharpness "
             "σmax, so κ(s) has ramps where Dubins has steps, and δ(s) is a steering servo's "
             "to follow; dδ/dt stays within vehicle.max_steer_rate_deg_s at the planned speed.",
             segments=9, continuous=True, shortest=False),
    Steering("cc-reeds-shepp", "CC-Reeds-Shepp", CC_REEDS_SHEPP, True, False,
             "forward and reverse, continuous curvature: clothoids into and out of every turn, "
             "cusps where the wheels are straight (Fraichard & Scheuer 2004)",
             "CC-Reeds-Shepp paths ramp κ up to ±1/ρ and back down along clothoids of "
             "sharpness σmax, forward or in reverse, and change direction only where κ = 0: "
             "no step anywhere, a cusp (◆) included. Shaded: driven in reverse.",
             segments=13, continuous=True, shortest=False),
)}
DEFAULT_STEERING = next(iter(STEERINGS))

SteeringName = Literal[tuple(STEERINGS)]  # the names, for pydantic and typer
# The steerings a car can drive (the simulated car cannot turn on the spot).
CAR_STEERINGS = tuple(name for name, s in STEERINGS.items() if not s.heading_free)
