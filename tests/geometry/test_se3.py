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


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), scale=st.sampled_from([1e-9, 1.0, 1e6]))
def test_angle_is_the_matmul_forms_bit_for_bit(seed, scale):
    """The angle of two vectors (arrays, views, a list) is the arccosine of their clipped ``@`` product to the last
    bit: its array path takes the product with ``dot``, the same numpy routine at less overhead."""
    import math

    from haptic.geometry.se3 import angle

    rng = np.random.default_rng(seed)
    m = rng.normal(size=(4, 3))
    a, b = scale * rng.normal(size=3), rng.normal(size=3)
    for x, y in ((a, b), (m[1], m[2]), (m[:, 0][:3], b), (a, list(b)), (list(a), b)):
        x = x / np.linalg.norm(x)
        y = np.asarray(y) / np.linalg.norm(y) if not isinstance(y, list) else list(np.asarray(y) / np.linalg.norm(y))
        assert angle(x, y) == math.acos(max(-1.0, min(1.0, float(np.asarray(x) @ np.asarray(y)))))
