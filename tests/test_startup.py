"""Start-up: commands that do not plan load no numba and no compiled kernel, a plan loads none of
numba's implementation modules (a cached kernel needs none), and a plan without a track loads no
track package (issue 22)."""

import subprocess
import sys
from pathlib import Path

import pytest

THESIS = Path(__file__).resolve().parents[1] / "tracks" / "library" / "thesis.svg"
# The CLI's entry point run as the `trackstar` script runs it; then which heavy modules loaded.
CLI = ("import sys\nfrom app.cli import main\nsys.argv = ['trackstar', *sys.argv[1:]]\n"
       "try:\n    main()\nexcept SystemExit:\n    pass\n"
       "print(sorted(m for m in ('numba', 'planner._kernel', 'planner._world', 'tracks', "
       "'numba.np.arrayobj', 'numba.np.arraymath', 'scipy.linalg') if m in sys.modules), "
       "file=sys.stderr)")


def loaded(*args: str) -> str:
    out = subprocess.run([sys.executable, "-c", CLI, *args], capture_output=True, text=True,
                         timeout=60)
    return out.stderr.strip().splitlines()[-1]


@pytest.mark.parametrize("args", [
    ["--help"], ["plan", "--help"], ["scenario", "list"], ["scenario", "schema"],
    ["track", "inspect", str(THESIS)], ["track", "sample", str(THESIS)],
])
def test_commands_that_do_not_plan_load_no_numba(args):
    modules = loaded(*args)
    assert "numba" not in modules and "planner._" not in modules


def test_a_plan_loads_the_kernels_and_tracks_only_for_a_track():
    kernels = "'numba', 'planner._kernel', 'planner._world'"
    assert loaded("plan", "slalom", "--iterations", "1") == f"[{kernels}]"
    assert loaded("plan", "thesis_static", "--iterations", "1") == f"[{kernels}, 'tracks']"


LINKED = """
import llvmlite.binding as ll
from numba.core import entrypoints
from planner import _kernel, rrt
rrt.warm_up()
assert not entrypoints._already_initialized  # no scan for numba extensions: nothing compiled
library = next(iter(_kernel.iterate.overloads.values())).library
assert library._shared_module is None  # loaded without parsing its bitcode
elf = library._codegen._engine._defined_symbols
module = library._get_module_for_linking()  # a compile that links it parses it now
shared = {g.name for g in [*module.functions, *module.global_variables]
          if not g.is_declaration and g.linkage != ll.Linkage.private}
print(len(shared), sorted(shared - elf))
"""


@pytest.mark.skipif(sys.platform != "linux", reason="the object code is ELF on Linux only")
def test_a_cached_kernel_loads_without_parsing_its_bitcode_or_scanning_for_extensions():
    out = subprocess.run([sys.executable, "-c", LINKED], capture_output=True, text=True,
                         timeout=60, check=True)
    count, missing = out.stdout.split(" ", 1)
    assert int(count) > 100 and missing.strip() == "[]"


def test_the_numba_we_pin_is_one_jit_knows_every_patch_applies():
    """pyproject.toml pins numba below the first version CI has not run; on it, each of
    planner/_jit.py's patches takes (a numba it does not know would get plain caching)."""
    from numba.core import codegen, environment

    from planner import _jit

    assert _jit._LOADS_OWN_EXTENSIONS
    assert environment._rebuild_env.__module__ == "planner._jit"
    assert codegen.CPUCodeLibrary._get_module_for_linking.__module__ == "planner._jit"
