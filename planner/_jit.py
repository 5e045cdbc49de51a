"""numba as the kernels use it: loaded without SciPy's BLAS, cached kernels without compiling's
registries.

* numba's array-math registry, which a process loads with its first compiled function, imports
  scipy.linalg — 0.4 s, a third of `trackstar plan`'s start-up and of every worker's — only to
  learn whether np.dot and np.linalg may be compiled. The kernels use neither, so the registry is
  loaded with that import answered "no"; the rest of the process may still import SciPy.
* Before it loads a function from its on-disk cache, numba refreshes its target context:
  imports and installs every lowering and typing registry (0.4 s), which only compiling reads.
  A cached kernel needs the runtime (NRT) alone, so a cache load initialises that and nothing
  else; numba's compiler still refreshes the context before any real compile.
"""

from __future__ import annotations

import sys

_BLAS = "scipy.linalg.cython_blas"


def _array_math_without_blas() -> None:
    if "numba.np.arraymath" in sys.modules or _BLAS in sys.modules:
        return  # loaded already, or SciPy is: nothing to save
    sys.modules[_BLAS] = None  # importing it raises ImportError now
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        del sys.modules[_BLAS]


def _cache_loads_without_registries() -> None:
    from numba.core import caching
    from numba.core.runtime import rtsys

    def load_overload(self, sig, target_context):
        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    if hasattr(caching.Cache, "_load_overload"):  # else a numba we do not know: leave it be
        caching.Cache.load_overload = load_overload


_array_math_without_blas()
_cache_loads_without_registries()

from numba import float64, njit, typeof, uint64  # noqa: E402

__all__ = ["float64", "njit", "typeof", "uint64"]
