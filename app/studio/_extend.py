"""The teaching view's text: EXTEND with the line one iteration ended on highlighted, RRT*'s or
RRT's (which has no Near, argmin or Rewire to show).

The line is chosen from the kernel's event record of that iteration, so the panel explains what
the planner really did (rejected sample, blocked steer, new node, rewires), not a replay.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass

import planner

__all__ = ["FIRST_NOTE", "StepInfo", "explain", "lines", "near_note", "render", "until_note"]

_GROW = (
    "x_rand ← SampleFree()",
    "x_nearest ← Nearest(T, x_rand)",
    "x_new ← Steer(x_nearest, x_rand)   ▹ at most ε",
    "if blocked after f: x_new ← Steer's point at f/2   ▹ if f/2 ≥ ρ",
    "if ObstacleFree(x_nearest, x_new):",
)
RRT_LINES = (*_GROW, "    T.add(x_new, parent = x_nearest)", "return T")
STAR_LINES = (
    *_GROW,
    "    X_near ← Near(T, x_new, r)",
    "    x_min ← argmin Cost(x) + c(x, x_new) over free x ∈ X_near",
    "    T.add(x_new, parent = x_min)",
    "    for x ∈ X_near cheaper through x_new: Rewire(x → x_new)",
    "return T",
)
FIRST_NOTE = "Press Step to run one iteration."  # the panel's note before the first step


@dataclass(frozen=True)
class StepInfo:
    """One iteration as the kernel recorded it (-1: did not happen)."""

    iteration: int
    nearest: int
    new: int
    parent: int
    n_near: int
    n_rewired: int
    radius: float
    free: float = math.nan  # how far a blocked Steer was free (NaN: not blocked)

    @classmethod
    def from_events(cls, ev: planner.TreeEvents, i: int, n_rewired: int) -> StepInfo:
        """The batch's i-th iteration."""
        return cls(int(ev.iteration[i]), int(ev.nearest[i]), int(ev.new[i]), int(ev.parent[i]),
                   len(ev.near_of(i)), n_rewired, float(ev.radius[i]), float(ev.free[i]))

    @property
    def blocked(self) -> bool:
        """Steer's motion hit an obstacle (x_new then moved back, or was dropped)."""
        return self.nearest >= 0 and (self.new < 0 or not math.isnan(self.free))


def lines(star: bool) -> tuple[str, ...]:
    """The pseudocode of RRT* (``star``) or of RRT."""
    return STAR_LINES if star else RRT_LINES


def explain(info: StepInfo, star: bool) -> tuple[int, str]:
    """(index into `lines` of the line the iteration ended on, a one-line explanation)."""
    if info.nearest < 0:
        return 0, "x_rand fell inside an obstacle: SampleFree rejects it (the iteration counts)."
    if info.new < 0:
        short = "" if math.isnan(info.free) else f" after {info.free:.2f} m, too short to keep"
        return 4, (f"The path from x_nearest (#{info.nearest}) to x_new is blocked{short}: "
                   "no node added.")
    cut = ("" if math.isnan(info.free) else f"Steer was blocked after {info.free:.2f} m, so "
           f"x_new is its point at {info.free / 2:.2f} m. ")
    if not star:
        return 5, f"{cut}x_new (#{info.new}) added with parent x_nearest (#{info.parent})."
    if info.n_rewired:
        most = " (the scene labels those that gained most)" if info.n_rewired > 2 else ""
        return 8, (f"{cut}x_new (#{info.new}) joined via x_min (#{info.parent}); "
                   f"{info.n_rewired} of {info.n_near} near nodes got cheaper through it and "
                   f"were rewired{most}.")
    return 7, (f"{cut}x_new (#{info.new}) joined via x_min (#{info.parent}), the cheapest of "
               f"{info.n_near} near nodes (r = {info.radius:.2f} m); none got cheaper.")


def near_note(info: StepInfo, options) -> str:
    """The near set's size rule with this iteration's numbers filled in, so that the shrinking
    ball of RRT* — and whether γ's term or ε bounds it — can be read off; "" when the
    iteration formed no near set (no node added, or RRT). ``options``: the run's resolved
    `PlanOptions`."""
    if info.new < 0 or options.planner != "rrtstar":
        return ""
    n = info.new + 1  # the tree's size with x_new, as the kernel counts it
    if options.k_rrt:
        return (f"Near set: the k(n) = ⌈k·log n⌉ = ⌈{options.k_rrt:g}·log {n}⌉ = "
                f"{math.ceil(options.k_rrt * math.log(n))} nearest nodes.")
    g, d, eps = options.gamma, options.dimensions, options.eps
    term = g * (math.log(n) / n) ** (1 / d)
    return (f"Near radius r(n) = min(γ·(log n / n)^(1/d), ε) = min({g:.2f}·(log {n} / {n})"
            f"^(1/{d}), {eps:.2f}) = min({term:.2f}, {eps:.2f}) = {min(term, eps):.2f} m "
            f"(n = {n} nodes, d = {d}: x, y{', θ' if d == 3 else ''}).")


def until_note(until: str | None, count: int, outcome: str) -> str:
    """What a "step until" did (`PlannerWorker.step`): ``outcome`` "found", "done" (the run
    ended first) or "cap" (it gave up)."""
    if until is None:
        return ""
    if outcome == "found":
        event = "a node was added" if until == "node" else "a rewire"
        return f"Stepped {count} iteration{'s' * (count > 1)} until {event}."
    why = "the run is done" if outcome == "done" else "the most one press steps"
    return (f"{count:,} iterations without {'a new node' if until == 'node' else 'a rewire'}: "
            f"stopped ({why}).")


def render(line: int | None, *notes: str, star: bool = True) -> str:
    """The panel's HTML: numbered pseudocode (RRT*'s, or RRT's), the current line in a <mark>,
    the notes below (empty ones left out)."""
    rows = []
    for i, text in enumerate(lines(star)):
        code = f"{i + 1:>2}  {html.escape(text)}"
        rows.append(f"<mark>{code}</mark>" if i == line else code)
    return ("<pre style='font-size:11px;line-height:1.5;margin:0;white-space:pre-wrap'>"
            + "\n".join(rows) + "</pre>"
            + "".join(f"<p style='font-size:12px'>{html.escape(n)}</p>" for n in notes if n))
