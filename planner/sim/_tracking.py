"""The tracking laws, compiled: the control tick calls them once a tick, and the guard rolls
them out over its horizon (`rollout`), so the car the guard foresees is the car that drives.

A reference is plain arrays here: rows (x, y, θ, κ, direction), their arc length ``s``, the
stretches' first rows ``bounds`` and directions ``signs`` (`planner.sim.control.Reference`).
"""

from __future__ import annotations

import math

import numpy as np

from planner._jit import njit
from planner.sim.vehicle import toward

PURE_PURSUIT, STANLEY, PD = 0, 1, 2  # the laws, in `planner.sim.control.CONTROLLERS` order
_TWO_PI = 2.0 * math.pi


@njit(cache=True, inline="always")
def _wrap(a):
    """a wrapped into [-π, π)."""
    return a - _TWO_PI * math.floor(a / _TWO_PI + 0.5)


@njit(cache=True, inline="always")
def _nearest(rows, lo, hi, x, y):
    """The row in [lo, hi) nearest to (x, y) (the first of equals)."""
    i, best = lo, math.inf
    for j in range(lo, hi):
        d2 = (rows[j, 0] - x) ** 2 + (rows[j, 1] - y) ** 2
        if d2 < best:
            i, best = j, d2
    return i


@njit(cache=True)
def project(rows, bounds, stretch, cursor, x, y):
    """(nearest row from a little behind to well ahead of ``cursor``, within the stretch;
    signed lateral error, left positive), refined towards the stretch's next row."""
    i = _nearest(rows, max(cursor - 20, bounds[stretch]),
                 min(cursor + 400, bounds[stretch + 1] + 1), x, y)
    rx, ry, rth = rows[i, 0], rows[i, 1], rows[i, 2]
    if i < bounds[stretch + 1]:
        nx, ny = rows[i + 1, 0], rows[i + 1, 1]
        den = (nx - rx) ** 2 + (ny - ry) ** 2
        if den > 0.0:
            u = ((x - rx) * (nx - rx) + (y - ry) * (ny - ry)) / den
            if 0.0 < u < 1.0:
                rx, ry = rx + u * (nx - rx), ry + u * (ny - ry)
    return i, -(x - rx) * math.sin(rth) + (y - ry) * math.cos(rth)


@njit(cache=True)
def target(rows, s, bounds, signs, stretch, at):
    """The point at arc ``at`` on the stretch; beyond its end, straight on the way the car
    drives there (a look-ahead near a cusp or the end points along the final heading)."""
    last = bounds[stretch + 1]
    if at <= s[last]:
        k = min(np.searchsorted(s, at), len(s) - 1)
        return rows[k, 0], rows[k, 1]
    d = (at - s[last]) * signs[stretch]
    return rows[last, 0] + d * math.cos(rows[last, 2]), rows[last, 1] + d * math.sin(rows[last, 2])


@njit(cache=True)
def steer(law, rows, s, bounds, signs, stretch, i, e, e_old, x, y, th, v, wheelbase, dt,
          gains):
    """The wanted steering angle of ``law`` at the projection (i, e); ``gains``: look-ahead
    min and gain, Stanley's k and softening, the PD's p and d (`control.Tracking`)."""
    d = signs[stretch]
    if law == PURE_PURSUIT:
        ld = max(gains[0], gains[1] * abs(v))
        tx, ty = target(rows, s, bounds, signs, stretch, s[i] + ld)
        alpha = math.atan2(ty - y, tx - x) - th
        dist = max(math.hypot(tx - x, ty - y), 1e-6)
        return math.atan(2.0 * wheelbase * math.sin(alpha) / dist)
    if law == STANLEY:  # the mirror car's front axle when reversing
        th_m = th if d > 0 else th + math.pi
        fx, fy = x + wheelbase * math.cos(th_m), y + wheelbase * math.sin(th_m)
        j = _nearest(rows, i, min(i + 200, bounds[stretch + 1] + 1), fx, fy)
        ef = -(fx - rows[j, 0]) * math.sin(rows[j, 2]) + (fy - rows[j, 1]) * math.cos(rows[j, 2])
        dth = _wrap(rows[j, 2] - th)
        return d * (dth + math.atan2(-gains[2] * d * ef, gains[3] + abs(v)))
    dth = _wrap(th - rows[i, 2])  # PD: the lateral error's rate is v·sin(heading error)
    de = v * math.sin(dth) if math.isnan(e_old) else (e - e_old) / dt
    return math.atan(wheelbase * rows[i, 3]) - gains[4] * e - gains[5] * de


_toward = njit(cache=True, inline="always")(toward)  # the steering's rate, as the car has it


@njit(cache=True)
def rollout(law, rows, s, bounds, signs, stretches, cursor, x, y, th, steer0, vs, wheelbase,
            max_steer, max_steer_rate, dt, sub, gains):
    """The car's poses at the samples of ``vs`` (speeds, ``sub`` control ticks of ``dt``
    apart) as it tracks the reference on ``stretches`` (per sample) with ``law``: the
    steering within its lock and rate, each tick an exact arc, as `planner.sim.run` drives."""
    n = len(vs)
    poses = np.empty((n, 3))
    st, e_old = steer0, math.nan
    for k in range(n):
        poses[k, 0], poses[k, 1], poses[k, 2] = x, y, th
        if k == n - 1:
            break
        stretch = stretches[k]
        for j in range(sub):
            v_was = vs[k] + (vs[k + 1] - vs[k]) * j / sub
            v = vs[k] + (vs[k + 1] - vs[k]) * (j + 1) / sub
            cursor, e = project(rows, bounds, stretch, cursor, x, y)
            want = steer(law, rows, s, bounds, signs, stretch, cursor, e, e_old, x, y, th,
                         v_was, wheelbase, dt, gains)
            e_old = e
            st = _toward(st, min(max(want, -max_steer), max_steer), max_steer_rate * dt)
            dth = v * dt * math.tan(st) / wheelbase
            chord = v * dt * np.sinc(dth / _TWO_PI)
            mid = th + 0.5 * dth
            x, y, th = x + chord * math.cos(mid), y + chord * math.sin(mid), th + dth
    return poses
