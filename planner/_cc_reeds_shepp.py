"""Continuous-curvature Reeds-Shepp paths (Fraichard & Scheuer 2004), in the segment form of
`_paths`: CC turns (`planner._cc_dubins`) and straights, driven forward or in reverse, with
every cusp where κ = 0.

A turn driven in gear g (+1 forward, −1 reverse) with steering direction d (+1 left) leaves a
pose q on the CC circle centred q + R(θ)·(g·r·sin μ, d·r·cos μ) and arrives at q on the circle
q + R(θ)·(−g·r·sin μ, d·r·cos μ) (`_centre`). So where one turn hands over to the next of
the opposite direction, their circles' centres are 2r apart if the gear stays and 2r·cos μ
apart at a cusp, and the pose between them follows from the centres alone (`_joint`); a
straight between two turns is a tangent to both circles (`_tangent`). A path is a chain of
poses and the elements between them (``poses``, the poses where its elements start and end, and ``elems``, each
element's turn or line, gear and direction), and the families are those of
steering_functions' CC00-Reeds-Shepp (Banzhaf et al. 2017), each in every gear and direction:

- T, a single turn, and a straight;
- TST with a cusp or none on either side of the straight (TST, TcST, TScT, TcScT);
- TTT, its middle circle tangent to both (TTT, TcTT, TTcT, TcTcT);
- TTcTT and TcTTcT, two middle circles placed symmetrically (mirrored or point-symmetric);
- TcTST, TSTcT and TcTSTcT, the middle circles where steering_functions puts them.

As σ → ∞ these become Reeds and Shepp's 48 words (tests/test_steering.py checks the lengths
tend to theirs). Like CC-Dubins, the paths are within a few percent of the shortest CC path,
not always the shortest, so the triangle inequality may fail.
"""

from __future__ import annotations

import math

import numpy as np

from planner._cc_dubins import cc_turn, write_cc_turn
from planner._jit import njit
from planner._paths import STRAIGHT, wrap_angle

_TINY = 1e-12
_TURN, _LINE = 1.0, 0.0
_MAX_ELEMENTS = 5  # TcTSTcT: four turns and a straight


@njit(cache=True, inline="always")
def _offset(cx, cy, c, s, u, v):
    """(cx, cy) + R·(u, v), R the rotation by the angle of cosine c and sine s."""
    return cx + c * u - s * v, cy + s * u + c * v


@njit(cache=True, inline="always")
def _centre(g, x, y, c, s, gear, d):
    """Centre of the circle a turn of ``gear`` and direction ``d`` leaves the pose at (x, y),
    heading (c, s) = (cos θ, sin θ), on (with −gear: the circle such a turn arrives on)."""
    return _offset(x, y, c, s, gear * g[3] * g[4], d * g[3] * g[5])


@njit(cache=True, inline="always")
def _arrival(g, cx, cy, c, s, gear, d):
    """Where a turn of ``gear`` and direction ``d`` on the circle centred (cx, cy) ends
    heading (c, s)."""
    return _offset(cx, cy, c, s, gear * g[3] * g[4], -d * g[3] * g[5])


@njit(cache=True, inline="always")
def _joint(g, ax, ay, ga, da, bx, by, gb):
    """The pose where a turn (ga, da) on circle a hands over to a turn of gear gb and the
    opposite direction on circle b, 2r (gb = ga) or 2r·cos μ (a cusp) away: its heading is
    the direction from a to b turned by da·(π/2 − μ·(ga + gb)/2), rotated here without trig."""
    ex, ey = bx - ax, by - ay
    big_d = math.hypot(ex, ey)
    cb = 0.5 * (ga + gb) * g[4]  # cos and sin of the turn
    sb = da * (g[5] if ga == gb else 1.0)
    c, s = (ex * cb - ey * sb) / big_d, (ey * cb + ex * sb) / big_d
    x, y = _arrival(g, ax, ay, c, s, ga, da)
    return x, y, math.atan2(s, c)


@njit(cache=True, inline="always")
def _link(g, ga, gb):
    """How far apart the centres of two tangent circles are: 2r, or 2r·cos μ at a cusp."""
    return 2.0 * g[3] * (1.0 if ga == gb else g[5])


@njit(cache=True)
def _tangent(g, ax, ay, ga, da, gs, bx, by, gb, db, root):
    """(ok, pose where the turn (ga, da) on circle a ends, pose where the turn (gb, db) on
    circle b starts, straight length) for a straight of gear ``gs`` between them; ``root``
    ±1 picks one of the two tangents. Circle b's centre is, in the straight's frame, at
    (gs·L + (ga + gb)·r·sin μ, (db − da)·r·cos μ) from a's."""
    r, smu, cmu = g[3], g[4], g[5]
    ex, ey = bx - ax, by - ay
    side = (db - da) * r * cmu
    ee = ex * ex + ey * ey
    dd = ee - side * side
    if dd < 0.0 or ee == 0.0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    along = root * math.sqrt(dd)
    length = gs * (along - (ga + gb) * r * smu)
    if length < -_TINY * r:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    length = max(length, 0.0)
    # the straight's heading: the direction a → b turned back by atan2(side, along)
    c, s = (ex * along + ey * side) / ee, (ey * along - ex * side) / ee
    th = math.atan2(s, c)
    qx, qy = _arrival(g, ax, ay, c, s, ga, da)
    return True, qx, qy, th, qx + gs * length * c, qy + gs * length * s, th, length


@njit(cache=True)
def _length(g, poses, elems, n, bound):
    """Driven length of the chain's first ``n`` elements; stops once it reaches ``bound``."""
    total = 0.0
    for i in range(n):
        a, b = poses[i], poses[i + 1]
        if elems[i, 0] == _TURN:
            total += cc_turn(g, a[0], a[1], a[2], b[0], b[1], b[2], elems[i, 1] * elems[i, 2])[0]
        else:
            total += math.hypot(b[0] - a[0], b[1] - a[1])
        if total >= bound:
            return math.inf
    return total


@njit(cache=True, inline="always")
def _set(poses, i, x, y, th):
    poses[i, 0], poses[i, 1], poses[i, 2] = x, y, th


@njit(cache=True, inline="always")
def _set_joint(g, poses, i, ax, ay, ga, da, bx, by, gb):
    x, y, th = _joint(g, ax, ay, ga, da, bx, by, gb)
    _set(poses, i, x, y, th)


@njit(cache=True, inline="always")
def _elem(elems, i, kind, gear, d):
    elems[i, 0], elems[i, 1], elems[i, 2] = kind, gear, d


@njit(cache=True)
def _keep(g, poses, elems, n, best, best_n, best_poses, best_elems):
    """Keep the chain if it is shorter than the best so far; returns (best, best_n)."""
    length = _length(g, poses, elems, n, best)
    if length < best:
        best_poses[:, :] = poses
        best_elems[:, :] = elems
        return length, n
    return best, best_n


@njit(cache=True)
def _search(g, x0, y0, th0, x1, y1, th1, bound, best_poses, best_elems):
    """The shortest chain from pose 0 to pose 1 shorter than ``bound``: (length, elements);
    written into best_poses/best_elems. (math.inf, 0) if none is."""
    r = g[3]
    poses = np.empty((_MAX_ELEMENTS + 1, 3))
    elems = np.zeros((_MAX_ELEMENTS, 3))
    best, best_n = bound, 0
    dx, dy = x1 - x0, y1 - y0
    dist = math.hypot(dx, dy)
    c0, s0 = math.cos(th0), math.sin(th0)
    c1, s1 = math.cos(th1), math.sin(th1)
    _set(poses, 0, x0, y0, th0)
    # Aligned: one straight, ahead or behind
    if abs(wrap_angle(th1 - th0)) < _TINY \
            and abs(c0 * dy - s0 * dx) < _TINY * max(1.0, dist):
        _set(poses, 1, x1, y1, th1)
        _elem(elems, 0, _LINE, 1.0 if c0 * dx + s0 * dy >= 0.0 else -1.0, 0.0)
        best, best_n = _keep(g, poses, elems, 1, best, best_n, best_poses, best_elems)
    for g1 in (1.0, -1.0):
        for d1 in (1.0, -1.0):
            ax, ay = _centre(g, x0, y0, c0, s0, g1, d1)
            for gn in (1.0, -1.0):
                for dn in (1.0, -1.0):
                    bx, by = _centre(g, x1, y1, c1, s1, -gn, dn)
                    ex, ey = bx - ax, by - ay
                    big_d = math.hypot(ex, ey)
                    cp, sp = (ex / big_d, ey / big_d) if big_d > 0.0 else (1.0, 0.0)
                    # T: pose 1 ends a turn on the start circle
                    if g1 == gn and d1 == dn and big_d < _TINY * r:
                        _set(poses, 1, x1, y1, th1)
                        _elem(elems, 0, _TURN, g1, d1)
                        best, best_n = _keep(g, poses, elems, 1, best, best_n, best_poses,
                                             best_elems)
                    # TST, a cusp or none on either side of the straight
                    for gs in (1.0, -1.0):
                        for root in (1.0, -1.0):
                            ok, qax, qay, qath, qbx, qby, qbth, _ = _tangent(
                                g, ax, ay, g1, d1, gs, bx, by, gn, dn, root)
                            if ok:
                                _set(poses, 1, qax, qay, qath)
                                _set(poses, 2, qbx, qby, qbth)
                                _set(poses, 3, x1, y1, th1)
                                _elem(elems, 0, _TURN, g1, d1)
                                _elem(elems, 1, _LINE, gs, 0.0)
                                _elem(elems, 2, _TURN, gn, dn)
                                best, best_n = _keep(g, poses, elems, 3, best, best_n,
                                                     best_poses, best_elems)
                    best, best_n = _three_or_more(g, ax, ay, g1, d1, bx, by, gn, dn, big_d, cp,
                                                  sp, x1, y1, th1, poses, elems, best, best_n,
                                                  best_poses, best_elems)
    return best, best_n


@njit(cache=True)
def _three_or_more(g, ax, ay, g1, d1, bx, by, gn, dn, big_d, cp, sp, x1, y1, th1, poses, elems,
                   best, best_n, best_poses, best_elems):
    """The chains of three turns or more from circle a (g1, d1) to circle b (gn, dn)."""
    if dn == d1:
        # TTT: a middle circle of direction −d1 tangent to both
        for g2 in (1.0, -1.0):
            l1, l2 = _link(g, g1, g2), _link(g, g2, gn)
            if big_d > l1 + l2 or big_d < abs(l1 - l2) or big_d == 0.0:
                continue
            u = (big_d * big_d + l1 * l1 - l2 * l2) / (2.0 * big_d)
            v = math.sqrt(max(l1 * l1 - u * u, 0.0))
            for side in (1.0, -1.0):
                mx, my = _offset(ax, ay, cp, sp, u, side * v)
                _set_joint(g, poses, 1, ax, ay, g1, d1, mx, my, g2)
                _set_joint(g, poses, 2, mx, my, g2, -d1, bx, by, gn)
                _set(poses, 3, x1, y1, th1)
                _elem(elems, 0, _TURN, g1, d1)
                _elem(elems, 1, _TURN, g2, -d1)
                _elem(elems, 2, _TURN, gn, dn)
                best, best_n = _keep(g, poses, elems, 3, best, best_n,
                                     best_poses, best_elems)
    else:
        best, best_n = _four_turns(g, ax, ay, g1, d1, bx, by, gn, big_d, cp,
                                   sp, x1, y1, th1, poses, elems, best, best_n,
                                   best_poses, best_elems)
    best, best_n = _with_cusped_turns(g, ax, ay, g1, d1, bx, by, gn, dn, big_d,
                                      cp, sp, x1, y1, th1, poses, elems, best,
                                      best_n, best_poses, best_elems)
    return best, best_n


@njit(cache=True)
def _four_turns(g, ax, ay, g1, d1, bx, by, gn, big_d, cp, sp, x1, y1, th1, poses, elems,
                best, best_n, best_poses, best_elems):
    """TTcTT (gn = −g1) and TcTTcT (gn = g1), their middle circles placed symmetrically in the
    frame along a → b: mirrored, m1 = a + (u, ±v) and m2 = b + (−u, ±v) with 2u − D = l2, for
    TTcTT; point-symmetric, m2 = b − (u, ±v), for TcTTcT. (The other placements never gave a
    shorter path in 20 000 random pairs.)"""
    if big_d == 0.0:
        return best, best_n
    mirrored = gn == -g1
    g2, g3 = (g1, -g1) if mirrored else (-g1, -g1)
    l1, l2 = _link(g, g1, g2), _link(g, g2, g3)
    if mirrored:
        u = 0.5 * (big_d + l2)
    else:  # |m2 − m1| = l2
        u = (big_d * big_d + 4.0 * l1 * l1 - l2 * l2) / (4.0 * big_d)
    if abs(u) > l1:
        return best, best_n
    v = math.sqrt(l1 * l1 - u * u)
    for side in (1.0, -1.0):
        m1x, m1y = _offset(ax, ay, cp, sp, u, side * v)
        m2x, m2y = _offset(bx, by, cp, sp, -u, side * v if mirrored else -side * v)
        _set_joint(g, poses, 1, ax, ay, g1, d1, m1x, m1y, g2)
        _set_joint(g, poses, 2, m1x, m1y, g2, -d1, m2x, m2y, g3)
        _set_joint(g, poses, 3, m2x, m2y, g3, d1, bx, by, gn)
        _set(poses, 4, x1, y1, th1)
        _elem(elems, 0, _TURN, g1, d1)
        _elem(elems, 1, _TURN, g2, -d1)
        _elem(elems, 2, _TURN, g3, d1)
        _elem(elems, 3, _TURN, gn, -d1)
        best, best_n = _keep(g, poses, elems, 4, best, best_n, best_poses, best_elems)
    return best, best_n


@njit(cache=True)
def _with_cusped_turns(g, ax, ay, g1, d1, bx, by, gn, dn, big_d, cp, sp, x1, y1, th1, poses,
                       elems, best, best_n, best_poses, best_elems):
    """TcTST, TSTcT and TcTSTcT: a cusp onto a middle turn whose circle is 2r·cos μ from the
    start's (or the end's) circle, placed as steering_functions does: on the line between
    the circles for the outer tangent, and off it by (2r·cos μ)²/D for the inner one."""
    if big_d == 0.0:
        return best, best_n
    near = 2.0 * g[3] * g[5]
    ux, uy = near, 0.0  # the middle circle's offset for an outer tangent
    inner = big_d >= near
    if inner:
        uy = near * near / big_d
        ux = near * math.sqrt(1.0 - uy / big_d)
    for family in range(3):  # TcTST, TSTcT, TcTSTcT
        first = family != 1  # a cusped turn after the start
        last = family != 0  # a cusped turn before the goal
        gm = -g1 if first else g1  # the straight's gear
        if gn != (-gm if last else gm):
            continue
        dm1 = -d1 if first else d1  # the directions at the straight's ends
        dm2 = -dn if last else dn
        for side in (1.0, -1.0):
            if dm1 == dm2:
                u, v = near, 0.0
            elif inner:
                u, v = ux, side * uy
            else:
                continue
            m1x, m1y = _offset(ax, ay, cp, sp, u, v) if first else (ax, ay)
            m2x, m2y = _offset(bx, by, cp, sp, -u, -v if first else v) if last else (bx, by)
            for root in (1.0, -1.0):
                ok, qax, qay, qath, qbx, qby, qbth, _ = _tangent(
                    g, m1x, m1y, gm, dm1, gm, m2x, m2y, gm, dm2, root)
                if not ok:
                    continue
                n = 0
                if first:
                    _set_joint(g, poses, 1, ax, ay, g1, d1, m1x, m1y, gm)
                    _elem(elems, 0, _TURN, g1, d1)
                    n = 1
                _elem(elems, n, _TURN, gm, dm1)
                _set(poses, n + 1, qax, qay, qath)
                _elem(elems, n + 1, _LINE, gm, 0.0)
                _set(poses, n + 2, qbx, qby, qbth)
                _elem(elems, n + 2, _TURN, gm, dm2)
                n += 3
                if last:
                    _set_joint(g, poses, n, m2x, m2y, gm, dm2, bx, by, gn)
                    _elem(elems, n, _TURN, gn, dn)
                    n += 1
                _set(poses, n, x1, y1, th1)
                best, best_n = _keep(g, poses, elems, n, best, best_n, best_poses,
                                     best_elems)
            if dm1 == dm2:
                break
    return best, best_n


@njit(cache=True)
def cc_reeds_shepp_length(x0, y0, th0, x1, y1, th1, g, bound=math.inf) -> float:
    """Length of the CC-Reeds-Shepp path from pose 0 to pose 1 (`cc_constants` ``g``); any
    value ≥ ``bound`` once it cannot beat it."""
    best_poses = np.empty((_MAX_ELEMENTS + 1, 3))
    best_elems = np.empty((_MAX_ELEMENTS, 3))
    return _search(g, x0, y0, th0, x1, y1, th1, bound, best_poses, best_elems)[0]


@njit(cache=True)
def cc_reeds_shepp_path(x0, y0, th0, x1, y1, th1, g, kinds, lens, curv) -> float:
    """The CC-Reeds-Shepp path from pose 0 to pose 1 written into kinds/lens/curv (13 segments:
    up to four turns of up to three and a straight); returns its length."""
    poses = np.empty((_MAX_ELEMENTS + 1, 3))
    elems = np.empty((_MAX_ELEMENTS, 3))
    length, n = _search(g, x0, y0, th0, x1, y1, th1, math.inf, poses, elems)
    kinds[:] = 0
    lens[:] = 0.0
    curv[:, :] = 0.0
    k = 0
    for i in range(n):
        a, b = poses[i], poses[i + 1]
        if elems[i, 0] == _TURN:
            k = write_cc_turn(g, a[0], a[1], a[2], b[0], b[1], b[2], elems[i, 2], elems[i, 1],
                              kinds, lens, curv, k)
        else:
            kinds[k], lens[k] = STRAIGHT, elems[i, 1] * math.hypot(b[0] - a[0], b[1] - a[1])
            k += 1
    return length
