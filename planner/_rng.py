"""A small counter-free PRNG (xoshiro256+) whose whole state is one uint64[4] array.

numba's ``np.random`` keeps one global stream per thread, so two planners in one process (the
studio runs one per browser tab) would disturb each other's sequences. Keeping the state in the
planner's own array makes "same seed, same tree" hold regardless of what else runs.
"""

from __future__ import annotations

import numpy as np

from planner._jit import njit, uint64

_MASK = (1 << 64) - 1


def seed_state(seed: int) -> np.ndarray:
    """Expand an integer seed into a xoshiro state with splitmix64 (the authors' recommendation)."""
    z = seed & _MASK
    state = np.empty(4, dtype=np.uint64)
    for i in range(4):
        z = (z + 0x9E3779B97F4A7C15) & _MASK
        x = z
        x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
        x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & _MASK
        state[i] = x ^ (x >> 31)
    return state


@njit(cache=True, inline="always")
def _rotl(x, k):
    return (x << uint64(k)) | (x >> uint64(64 - k))


@njit(cache=True)
def uniform(state: np.ndarray) -> float:
    """Next double in [0, 1); advances ``state`` in place."""
    result = state[0] + state[3]
    t = state[1] << uint64(17)
    state[2] ^= state[0]
    state[3] ^= state[1]
    state[1] ^= state[2]
    state[0] ^= state[3]
    state[2] ^= t
    state[3] = _rotl(state[3], 45)
    return (result >> uint64(11)) * (1.0 / 9007199254740992.0)
