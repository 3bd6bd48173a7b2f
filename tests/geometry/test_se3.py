"""The vector helpers of haptic.geometry.se3."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from haptic.geometry.se3 import cross

SHAPES = [((3,), (3,)), ((5, 3), (5, 3)), ((1, 7, 3), (4, 1, 3)), ((3,), (6, 3)), ((2, 4, 3), (4, 3))]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), shapes=st.sampled_from(SHAPES), scale=st.sampled_from([1e-9, 1.0, 1e6]))
def test_cross_is_numpys_bit_for_bit(seed, shapes, scale):
    """The planner's cross product gives numpy's result to the last bit, broadcast alike, so that swapping it in
    changes no episode."""
    rng = np.random.default_rng(seed)
    a, b = scale * rng.normal(size=shapes[0]), rng.normal(size=shapes[1])
    got, want = cross(a, b), np.cross(a, b)
    assert got.shape == want.shape and np.array_equal(got, want)
