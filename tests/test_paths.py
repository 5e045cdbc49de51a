"""The segment-path integrator: exact arcs, continuity, sampling spacing."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planner._paths import path_end, path_length, pose_at, sample_path

lengths = st.floats(-5, 5, allow_nan=False)
kinds_st = st.lists(st.sampled_from([-1, 0, 1]), min_size=5, max_size=5)


def test_quarter_circle_left_ends_where_geometry_says():
    kinds = np.array([1, 0, 0, 0, 0], dtype=np.int8)
    lens = np.array([math.pi / 2, 0, 0, 0, 0])
    x, y, th = path_end(0.0, 0.0, 0.0, kinds, lens, 1.0)
    assert (x, y, th) == pytest.approx((1.0, 1.0, math.pi / 2), abs=1e-12)


@settings(max_examples=200, deadline=None)
@given(kinds_st, st.lists(lengths, min_size=5, max_size=5), st.floats(0.3, 3))
def test_samples_are_continuous_and_end_at_the_end(kinds, lens, rho):
    kinds = np.array(kinds, dtype=np.int8)
    lens = np.array(lens)
    pts = sample_path(0.5, -0.2, 0.3, kinds, lens, rho, 0.02)
    end = path_end(0.5, -0.2, 0.3, kinds, lens, rho)
    assert np.allclose(pts[-1, :3], end, atol=1e-9)
    assert np.all(np.hypot(*np.diff(pts[:, :2], axis=0).T) <= 0.02 + 1e-9)
    mid = pose_at(0.5, -0.2, 0.3, kinds, lens, rho, path_length(kinds, lens))
    assert np.allclose(mid[:3], end, atol=1e-9)
