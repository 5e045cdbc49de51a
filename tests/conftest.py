"""Shared fixtures: the reference scenarios of ../shared/scenarios and a scenario loader."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from hypothesis import settings

# CI replays the same examples every run (a red CI must mean a regression); locally hypothesis
# keeps exploring new ones.
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

# shared/ sits beside the repository, here and in CI.
SCENARIOS = Path(__file__).resolve().parents[2] / "shared" / "scenarios"
STATIC = ["open_field", "hallway", "slalom", "parking", "oval_track"]


def scenario_dict(name: str) -> dict:
    return json.loads((SCENARIOS / f"{name}.json").read_text())


@pytest.fixture(scope="session", autouse=True)
def compiled_planner():
    """Compile the planner's kernels once, in this process, into numba's on-disk cache, so the
    CLI subprocesses the tests start load them in about a second."""
    from planner.rrt import warm_up

    warm_up()
