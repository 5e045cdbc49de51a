"""Shared fixtures: the bundled reference scenarios and the compiled planner."""

from __future__ import annotations

import json
import os

import pytest
from hypothesis import settings

# CI replays the same examples every run (a red CI must mean a regression); locally hypothesis
# keeps exploring new ones.
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

STATIC = ["open_field", "hallway", "slalom", "parking", "oval_track"]
# The modules that drive chromium: one worker runs them all, one after the other, so that two
# software-rendered browsers never share the two cores.
BROWSER_MODULES = {"test_studio_browser.py", "test_studio_sim_browser.py"}


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """The groups of pyproject's ``-n 2 --dist loadgroup``: a module runs on one worker (its
    servers start once) and the browser modules share one."""
    for item in items:
        name = item.path.name
        item.add_marker(pytest.mark.xdist_group("browser" if name in BROWSER_MODULES else name))


def scenario_dict(name: str) -> dict:
    """A bundled scenario's JSON object, to modify in a test."""
    import planner

    return json.loads(planner.bundled_scenario_path(name).read_text())


@pytest.fixture(scope="session", autouse=True)
def compiled_planner():
    """Compile the planner's kernels once, in this process, into numba's on-disk cache, so the
    CLI subprocesses the tests start load them in about a second."""
    from planner.timing import warm_up

    warm_up()
