"""Run metrics from the per-tick record: collisions, clearance, timing shares, percentiles."""

from __future__ import annotations

import numpy as np

__all__ = ["AT_REST", "MOVING", "collision_runs", "contacts", "cycle_stats"]

MOVING, AT_REST = 1, 2  # whose contact: the car drove into it, or the car stood when it began


def collision_runs(clearances: np.ndarray) -> int:
    """Contacts: maximal runs of consecutive ticks in collision (clearance ≤ 0, touching counts)."""
    hit = np.asarray(clearances) <= 0.0
    return int(np.count_nonzero(hit[1:] & ~hit[:-1]) + (1 if len(hit) and hit[0] else 0))


def contacts(clearances: np.ndarray, speeds: np.ndarray) -> np.ndarray:
    """Per tick 0 (clear), `MOVING` or `AT_REST`: each contact (a run of ticks in collision)
    takes the state of its first tick — at rest when the car stood still over the tick that
    led into it (the speed held over the tick before; the car starts at rest)."""
    hit = np.asarray(clearances) <= 0.0
    held = np.concatenate([[0.0], np.abs(np.asarray(speeds, dtype=float))[:-1]])
    first = hit & ~np.concatenate([[False], hit[:-1]])
    kind = np.where(held < 1e-9, AT_REST, MOVING)
    run = np.cumsum(first)  # contact number of each tick (0 before the first)
    start_kind = np.concatenate([[0], kind[first]])
    return np.where(hit, start_kind[run], 0).astype(np.int64)


def cycle_stats(wall_s: list[float]) -> dict:
    """Cycle-time percentiles (ms) and the shares of cycles within 1/30 s and 1/4 s."""
    if not wall_s:
        return {"cycle_ms": {"p50": None, "p95": None, "p99": None, "max": None},
                "share_30hz": None, "share_4hz": None}
    ms = np.asarray(wall_s) * 1000.0
    p = {f"p{q}": float(np.percentile(ms, q)) for q in (50, 95, 99)}
    p["max"] = float(ms.max())
    return {"cycle_ms": p, "share_30hz": float(np.mean(ms <= 1000.0 / 30.0)),
            "share_4hz": float(np.mean(ms <= 250.0))}
