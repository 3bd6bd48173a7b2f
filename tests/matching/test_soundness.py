"""Soundness (property): with noise inside the error bounds, the true interpretation is never pruned.

Random model from the library, random pose, random exploration walk, random noise level; once with noise
drawn inside the bounds and once with every draw exactly at its bound (the worst case).
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from haptic.executor.geometric import GeometricExecutor, GeometricSettings, random_walk
from haptic.geometry import SE3, load_library
from haptic.geometry.shapes import box
from haptic.matching.components import SensorNoise
from haptic.matching.library import LibraryArrays
from haptic.matching.tree import InterpretationTree

from .helpers import true_leaves

LIB = load_library()
NAMES = sorted(LIB)
ARRAYS = LibraryArrays.build(LIB)


def _check(name: str, seed: int, n_moves: int, level: float, at_bounds: bool) -> None:
    rng = np.random.default_rng(seed)
    ex = GeometricExecutor(
        LIB[name],
        SE3.random(rng, 0.2),
        SensorNoise().scaled(level),
        rng,
        settings=GeometricSettings(at_bounds=at_bounds),
    )
    random_walk(ex, n_moves, rng)
    tree = InterpretationTree(ARRAYS)
    for c in ex.components:
        tree.add(c)
        assert len(true_leaves(tree, ex)) >= 1, (name, seed, c)


_common = settings(deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)


@pytest.mark.slow  # a property over many random episodes: make test, not make check
@settings(_common, max_examples=700)
@given(
    name=st.sampled_from(NAMES),
    seed=st.integers(0, 2**31),
    n_moves=st.integers(1, 8),
    level=st.sampled_from([0.0, 0.3, 1.0, 2.0, 4.0]),
)
def test_true_interpretation_survives_noise_inside_bounds(name, seed, n_moves, level):
    _check(name, seed, n_moves, level, at_bounds=False)


@pytest.mark.slow  # a property over many random episodes: make test, not make check
@settings(_common, max_examples=400)
@given(name=st.sampled_from(NAMES), seed=st.integers(0, 2**31), n_moves=st.integers(1, 8))
# skew (non-adjacent) edge pair: the closest approach moves with the tilt of either line times the skew distance
@example(name="WEDGE01", seed=123, n_moves=6)
def test_true_interpretation_survives_noise_at_the_bounds(name, seed, n_moves):
    _check(name, seed, n_moves, 1.0, at_bounds=True)


def test_soundness_for_a_model_outside_the_library_set():
    """The same holds for any valid solid (here a thin plate): the matcher has no library-specific fudge."""
    plate = box(0.12, 0.05, 0.012, name="PLATE")
    for seed in range(20):
        rng = np.random.default_rng(seed)
        ex = GeometricExecutor(plate, SE3.random(rng, 0.1), SensorNoise(), rng)
        random_walk(ex, 8, rng)
        tree = InterpretationTree({"PLATE": plate, **LIB})
        for c in ex.components:
            tree.add(c)
        assert len(true_leaves(tree, ex)) >= 1
