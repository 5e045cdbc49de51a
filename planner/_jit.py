"""numba as the kernels use it: loaded without SciPy's BLAS, cached kernels without compiling's
registries, the modules of numba's own functions or parsing their bitcode.

* numba's array-math registry, which a compile loads, imports scipy.linalg (0.4 s) only to
  learn whether np.dot and np.linalg may be compiled. The kernels use neither, so before a
  compile the registry is loaded with that import answered "no"; the rest of the process may
  still import SciPy. A cache load needs no array math at all (0.05 s): no kernel calls it.
* Before it loads a function from its on-disk cache, numba refreshes its target context:
  imports and installs every lowering and typing registry (0.4 s), which only compiling reads.
  A cached kernel needs the runtime (NRT) alone, so a cache load initialises that and nothing
  else; numba's compiler still refreshes the context before any real compile.
* Each cached function carries an environment whose globals numba rebuilds from its module,
  importing it: for numba's own np.empty, np.zeros and argsort that is its array library and,
  through it, its string library (0.05 s). Only object-mode code reads those globals and the
  kernels are nopython, so a module not yet imported gives its name and not its contents.
* A cached function is its object code plus its LLVM bitcode, which numba parses as it loads
  (0.06 s for the kernels), to learn the symbols the code defines and to link the function into
  later compiles. The object code's own symbol table tells the symbols, so the bitcode is
  parsed only when a compile links the function.
"""

from __future__ import annotations

import struct
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


def _cache_loads_without_registries() -> bool:
    from numba.core import caching, entrypoints
    from numba.core.runtime import rtsys

    def load_overload(self, sig, target_context):
        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            loaded = self._load_overload(sig, target_context)
        if loaded is None:  # not cached: a compile follows, and loads the registries
            entrypoints.init_all()
            _array_math_without_blas()
        return loaded

    if hasattr(caching.Cache, "_load_overload"):
        caching.Cache.load_overload = load_overload
        return True
    _array_math_without_blas()  # a numba we do not know: leave its loads be, keep SciPy out
    return False


def _environments_without_imports() -> None:
    from numba.core import environment

    if not hasattr(environment, "lookup_environment"):
        return  # a numba we do not know: leave it be

    def rebuild_env(modname, consts, env_name):
        env = environment.lookup_environment(env_name)
        if env is not None:
            return env
        module = sys.modules.get(modname)
        env = environment.Environment(
            module.__dict__ if module is not None else {"__name__": modname})
        env.consts[:] = consts
        env.env_name = env_name
        environment.Environment._memo[env_name] = env
        return env

    environment._rebuild_env = rebuild_env  # what a cache file's pickled environment calls


def _elf_symbols(code: bytes) -> set[str] | None:
    """The names of the symbols an object file defines, if it is 64-bit little-endian ELF."""
    if code[:6] != b"\x7fELF\x02\x01":
        return None
    (table,), (entry, count) = struct.unpack_from("<Q", code, 0x28), struct.unpack_from(
        "<HH", code, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", code, table + i * entry) for i in range(count)]
    names = set()
    for _, kind, _, _, start, size, link, _, _, step in sections:
        if kind != 2:  # SHT_SYMTAB
            continue
        strings = sections[link][4]
        for at in range(start + step, start + size, step):  # entry 0 is the null symbol
            name, info, _, section = struct.unpack_from("<IBBH", code, at)
            if section and info & 0xF not in (3, 4):  # defined; not a section's or file's name
                end = code.index(b"\0", strings + name)
                names.add(code[strings + name:end].decode())
    return names


def _object_code_without_bitcode() -> None:
    import llvmlite.binding as ll
    from numba.core import codegen

    library = codegen.CPUCodeLibrary
    if not (hasattr(library, "_get_module_for_linking")
            and hasattr(codegen.JitEngine, "_load_defined_symbols")):
        return  # a numba we do not know: leave it be
    unserialize, for_linking = library._unserialize.__func__, library._get_module_for_linking

    def _unserialize(cls, codegen_, state):
        name, kind, data = state
        symbols = _elf_symbols(data[0]) if kind == "object" else None
        if symbols is None:
            return unserialize(cls, codegen_, state)
        self = codegen_.create_library(name)
        self.enable_object_caching()
        self._set_compiled_object(data[0])
        self._trackstar_bitcode = data[1]
        self._finalize_final_module()
        codegen_._engine._defined_symbols |= symbols
        return self

    def _get_module_for_linking(self):
        if self._shared_module is None and getattr(self, "_trackstar_bitcode", None):
            self._shared_module = ll.parse_bitcode(self._trackstar_bitcode)
            self._trackstar_bitcode = None
        return for_linking(self)

    library._unserialize = classmethod(_unserialize)
    library._get_module_for_linking = _get_module_for_linking


_LOADS_OWN_EXTENSIONS = _cache_loads_without_registries()
_environments_without_imports()
_object_code_without_bitcode()

import numba  # noqa: E402
from numba import float64, typeof, uint64  # noqa: E402

__all__ = ["float64", "njit", "typeof", "uint64"]


def njit(**options):
    """numba's njit for a kernel. With ``cache=True`` its first call looks for numba's
    extensions (an entry-point scan of every installed package) only when it compiles; a cache
    load needs none."""

    def decorate(function):
        kernel = numba.njit(**options)(function)
        if options.get("cache") and _LOADS_OWN_EXTENSIONS:
            kernel._compilation_chain_init_hook = _no_extensions_before_the_cache
        return kernel

    return decorate


def _no_extensions_before_the_cache() -> None:
    """A kernel's hook before it compiles or loads: nothing, for a cache miss scans numba's
    extensions (`load_overload`)."""
