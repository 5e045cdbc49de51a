"""The fastest schedule along a fixed path among moving obstacles (path–velocity decomposition).

The path is fixed; the car may drive it at any speed up to ``vmax`` and may stand still. In the
s–t plane (driven length, time) the schedule is a monotone curve, and the search runs on a grid
of stations s_i = i·ds and instants t_j = j·dt with ds = vmax·dt: from each grid point the car
waits one dt or drives one ds at vmax, so any slower speed is a staircase of both and the
earliest arrival on the grid is within one dt per wait of the continuous optimum. The search is
breadth-first in time, so the first layer that reaches the last station is the earliest arrival.

Each move is certified exactly, like `planner._world.motion_free`: the footprint's clearance
from the movers drops by at most (1 + reach·|κ|max) per metre driven (a disc at offset a from the
pose moves at most that far) plus the movers' top speed per second, so from a clearance c the
move is free for the next c / (that rate) of it; the move is refused once c ≤ ``CONTACT``.
No collision slips between stations or between instants, waits included. The static obstacles
are not looked at: the path is already free of them at any time.
"""

from __future__ import annotations

import numpy as np

from planner._jit import njit
from planner._paths import advance, peak_curvature
from planner._world import CONTACT, REACH, VMAX_OBS, World, moving_clearance

WAITED, DROVE = 1, 2  # how a grid point was first reached


@njit(cache=True)
def pose_on(seg_pose, seg_kind, seg_len, seg_curv, seg_s0, s):
    """Pose at driven length s on a path given as driven segments: each one's start pose,
    kind, signed length, curvatures (`planner._paths`) and the driven length where it
    starts."""
    k = min(max(np.searchsorted(seg_s0, s, side="right") - 1, 0), seg_s0.shape[0] - 1)
    length = seg_len[k]
    d = min(max(s - seg_s0[k], 0.0), abs(length))
    return advance(seg_pose[k, 0], seg_pose[k, 1], seg_pose[k, 2], seg_kind[k],
                   d if length >= 0.0 else -d, seg_curv[k, 0], seg_curv[k, 1])


@njit(cache=True)
def station_poses(seg_pose, seg_kind, seg_len, seg_curv, seg_s0, n, ds) -> np.ndarray:
    """(n + 1, 3) poses at s = i·ds."""
    out = np.empty((n + 1, 3))
    for i in range(n + 1):
        out[i, 0], out[i, 1], out[i, 2] = pose_on(seg_pose, seg_kind, seg_len, seg_curv, seg_s0,
                                                  i * ds)
    return out


@njit(cache=True)
def _move_free(w, seg_pose, seg_kind, seg_len, seg_curv, seg_s0, s, t, ds, dt, rate, c):
    """Is the move from (s, t) to (s + ds, t + dt), at constant pace, free of the movers?
    ``c``: the clearance at its start; ``rate``: the most the clearance drops over the move."""
    u = 0.0
    while c > CONTACT:
        if rate == 0.0:  # a wait among movers that stand still
            return True
        u += c / rate
        if u >= 1.0:
            return True
        x, y, th = pose_on(seg_pose, seg_kind, seg_len, seg_curv, seg_s0, s + u * ds)
        c = moving_clearance(w, x, y, th, t + u * dt)
    return False


@njit(cache=True)
def earliest_arrival(w: World, seg_pose, seg_kind, seg_len, seg_curv, seg_s0, n, ds, dt,
                     layers, waits) -> int:
    """The earliest layer j at which the car, leaving station 0 at t = 0, can be at station n
    (the path's end), or −1 if none up to ``layers``. Fills ``waits[i]``, the instants spent at
    station i, for one such schedule: of the schedules arriving then, one that waits as late as
    it can, so the car drives up to a mover and waits there rather than far before it.

    A clearance c found at station i at layer j certifies both moves from station i for the
    next (c − drive's drop) / (wait's drop) layers too (``sure``): in open space most grid
    points cost no evaluation."""
    kmax = 0.0
    for k in range(seg_kind.shape[0]):
        kmax = max(kmax, peak_curvature(seg_kind[k], seg_len[k], seg_curv[k, 0], seg_curv[k, 1]))
    slope = 1.0 + w.geo[REACH] * kmax
    drive_rate = slope * ds + w.geo[VMAX_OBS] * dt
    wait_rate = w.geo[VMAX_OBS] * dt
    poses = station_poses(seg_pose, seg_kind, seg_len, seg_curv, seg_s0, n, ds)
    sure = np.zeros(n + 1, np.int64)  # moves from station i are free before this layer
    state = np.zeros((layers + 1, n + 1), np.uint8)
    state[0, 0] = WAITED
    lo, hi = 0, 0
    for j in range(layers):
        t = j * dt
        new_lo, new_hi = n + 1, -1
        for i in range(lo, hi + 1):
            if state[j, i] == 0:
                continue
            wait_ok = drive_ok = j < sure[i]
            if not wait_ok:
                c = moving_clearance(w, poses[i, 0], poses[i, 1], poses[i, 2], t)
                spare = c - CONTACT - drive_rate
                if spare > 0.0:
                    wait_ok = drive_ok = True
                    sure[i] = j + 1 + int(min(spare / wait_rate, layers)) if wait_rate > 0.0 \
                        else layers + 1
                else:
                    s = i * ds
                    wait_ok = _move_free(w, seg_pose, seg_kind, seg_len, seg_curv, seg_s0, s,
                                         t, 0.0, dt, wait_rate, c)
                    drive_ok = i < n and _move_free(w, seg_pose, seg_kind, seg_len, seg_curv,
                                                    seg_s0, s, t, ds, dt, drive_rate, c)
            # A wait overrides a drive into the same point (stations run upwards, so the
            # drive from below came first): the backtrack then waits late, not early.
            if wait_ok:
                state[j + 1, i] = WAITED
                new_lo, new_hi = min(new_lo, i), max(new_hi, i)
            if drive_ok and i < n:
                state[j + 1, i + 1] = DROVE
                new_lo, new_hi = min(new_lo, i + 1), max(new_hi, i + 1)
        if new_hi < 0:
            return -1
        if state[j + 1, n] != 0:
            i = n
            for k in range(j + 1, 0, -1):
                if state[k, i] == DROVE:
                    i -= 1
                else:
                    waits[i] += 1
            return j + 1
        lo, hi = new_lo, new_hi
    return -1


def no_wait_needed(world: World) -> bool:
    """Without movers the fastest schedule is the top speed throughout."""
    return world.m_kind.shape[0] == 0
