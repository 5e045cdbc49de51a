"""Start-up: commands that do not plan load no numba and no compiled kernel, and a plan without
a track loads no track package (issue 22)."""

import subprocess
import sys
from pathlib import Path

import pytest

THESIS = Path(__file__).resolve().parents[1] / "tracks" / "library" / "thesis.svg"
# The CLI's entry point run as the `trackstar` script runs it; then which heavy modules loaded.
CLI = ("import sys\nfrom app.cli import main\nsys.argv = ['trackstar', *sys.argv[1:]]\n"
       "try:\n    main()\nexcept SystemExit:\n    pass\n"
       "print(sorted(m for m in ('numba', 'planner._kernel', 'planner._world', 'tracks') "
       "if m in sys.modules), file=sys.stderr)")


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
