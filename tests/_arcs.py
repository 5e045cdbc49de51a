"""Paths of arcs and straights, written by hand or by Dubins / Reeds-Shepp, in the segment form."""

from __future__ import annotations

import numpy as np

from planner._paths import arc_curvatures


def arcs(kinds: np.ndarray, rho: float) -> np.ndarray:
    """The ``curv`` of a path whose ``kinds`` turn on arcs of radius ρ (`planner._paths`)."""
    curv = np.zeros((len(kinds), 2))
    arc_curvatures(np.asarray(kinds, np.int8), rho, curv)
    return curv
