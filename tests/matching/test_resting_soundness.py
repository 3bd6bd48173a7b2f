"""Soundness of a resting probe (property): the true interpretation survives the face another finger measures while
the exploring pad rests -- its contact point and normal perturbed to their error bounds -- and the free space of its
closing, after a random exploration."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from haptic.executor.geometric import GeometricExecutor, GeometricSettings, random_walk
from haptic.geometry import SE3, load_library
from haptic.matching.components import SensorNoise
from haptic.matching.free_space import apply_probes
from haptic.matching.library import LibraryArrays
from haptic.matching.tree import InterpretationTree
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.resting import RestingConfig, RestingFinger, resting_lines

from .helpers import true_leaves

LIB = load_library()
NAMES = sorted(LIB)
ARRAYS = LibraryArrays.build(LIB)


def _check(name: str, seed: int, n_moves: int, pick: int, at_bounds: bool) -> None:
    rng = np.random.default_rng(seed)
    ex = GeometricExecutor(LIB[name], SE3.random(rng, 0.2), SensorNoise(), rng,
                           settings=GeometricSettings(at_bounds=at_bounds))  # fmt: skip
    random_walk(ex, n_moves, rng)
    tree = InterpretationTree(ARRAYS)
    tree.add_all(ex.components)
    assert len(true_leaves(tree, ex)) >= 1
    # the resting lines onto the object's faces, as the planner makes them (a finger reaching anywhere near)
    h = Hypothesis(model=name, poly=ex.model, world_from_model=ex.world_from_model, faces={}, edges={}, vertices={})
    here = np.asarray(ex.state.position, dtype=float)
    face = next(c for c in ex.components if c.id == ex.state.face)
    finger = RestingFinger("middle", here, here, 1.0)
    lines = resting_lines([h], np.ones(1), [finger], here, face.normal, RestingConfig())
    hits = []
    for move in lines[pick % max(1, len(lines)) :][:6]:
        result = ex.execute(move)
        if result.ok and result.components:
            hits.append(result)
            break
    if not hits:
        return
    result = hits[0]
    tree.add_move(result.components)
    assert len(true_leaves(tree, ex)) >= 1, (name, seed, "component")
    apply_probes(tree, list(result.free_space), [c.id for c in result.components])
    assert len(true_leaves(tree, ex)) >= 1, (name, seed, "free space")


_common = settings(deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)


@settings(_common, max_examples=60)
@given(name=st.sampled_from(NAMES), seed=st.integers(0, 2**31), n_moves=st.integers(1, 5), pick=st.integers(0, 200))
def test_the_true_interpretation_survives_a_resting_probe_at_its_bounds(name, seed, n_moves, pick):
    _check(name, seed, n_moves, pick, at_bounds=True)


@settings(_common, max_examples=20)
@given(name=st.sampled_from(NAMES), seed=st.integers(0, 2**31), pick=st.integers(0, 200))
def test_the_true_interpretation_survives_a_resting_probe_inside_its_bounds(name, seed, pick):
    _check(name, seed, 3, pick, at_bounds=False)
