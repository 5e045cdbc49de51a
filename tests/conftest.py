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


def scenario_dict(name: str) -> dict:
    """A bundled scenario's JSON object, to modify in a test."""
    import planner

    return json.loads(planner.bundled_scenario_path(name).read_text())


@pytest.fixture(scope="session", autouse=True)
def compiled_planner():
    """Compile the planner's kernels once, in this process, into numba's on-disk cache, so the
    CLI subprocesses the tests start load them in about a second."""
    from planner.rrt import warm_up

    warm_up()
