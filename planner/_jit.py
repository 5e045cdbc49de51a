"""numba as the kernels use it, loaded without SciPy's BLAS.

numba's array-math registry, which a process loads with its first compiled function, imports
scipy.linalg — 0.4 s, a third of `trackstar plan`'s start-up and of every worker's — only to
learn whether np.dot and np.linalg may be compiled. The kernels use neither, so the registry is
loaded with that import answered "no"; the rest of the process may still import SciPy.
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


_array_math_without_blas()

from numba import float64, njit, typeof, uint64  # noqa: E402

__all__ = ["float64", "njit", "typeof", "uint64"]
