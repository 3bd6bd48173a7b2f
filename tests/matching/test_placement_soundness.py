"""Soundness of several components from one move (property): the true interpretation survives a placement's
faces -- each finger's contact point and normal, perturbed to their error bounds -- added at once after a random
exploration, with the free space of the fingers' closings."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from haptic.errors import MatchError
from haptic.executor.geometric import GeometricExecutor, GeometricSettings, random_walk
from haptic.geometry import SE3, load_library
from haptic.matching.components import SensorNoise
from haptic.matching.free_space import apply_probes
from haptic.matching.library import LibraryArrays
from haptic.matching.tree import InterpretationTree
from haptic.planning.moves import FingerApproach, PlacementMove
from haptic.planning.placements import HAND_FINGERS

from .helpers import true_leaves

LIB = load_library()
NAMES = sorted(LIB)
ARRAYS = LibraryArrays.build(LIB)
BACK = 0.003
"""A finger's line starts this far out from its face (a slot's face too has room for it) [m]."""


def aimed_placement(ex: GeometricExecutor, faces, rng: np.random.Generator) -> PlacementMove:
    """Fingers closing on ``faces`` of the executor's posed model: each head-on at a random point of the face's
    largest triangle, from :data:`BACK` out."""
    m, pose = ex.model, ex.world_from_model
    fingers = []
    for name, f in zip(HAND_FINGERS, faces, strict=False):
        tris = [t for t, g in zip(m.triangles, m.triangle_faces, strict=True) if g == f]
        tri = m.vertices[max(tris, key=lambda t: np.linalg.norm(np.cross(*(m.vertices[t[1:]] - m.vertices[t[0]]))))]
        w = rng.dirichlet(np.ones(3)) * 0.8 + 0.2 / 3  # inside, clear of the triangle's sides
        n = pose.rotate(m.face_normals[f])
        target = pose.apply(w @ tri)
        fingers.append(FingerApproach(name, target + BACK * n, -n, 2 * BACK))
    return PlacementMove(tuple(fingers))


def placed(ex: GeometricExecutor, move: PlacementMove):
    """The placement's faces and free space, carried out by the executor."""
    result = ex.execute(move)
    assert result.ok and all(f["status"] == "touched" for f in result.info["fingers"]), result.info
    return list(result.components), list(result.free_space)


def _check(name: str, seed: int, n_moves: int, fingers: int, at_bounds: bool) -> None:
    rng = np.random.default_rng(seed)
    ex = GeometricExecutor(LIB[name], SE3.random(rng, 0.2), SensorNoise(), rng,
                           settings=GeometricSettings(at_bounds=at_bounds))  # fmt: skip
    random_walk(ex, n_moves, rng)
    tree = InterpretationTree(ARRAYS)
    tree.add_all(ex.components)
    assert len(true_leaves(tree, ex)) >= 1
    faces = rng.choice(ex.model.n_faces, size=min(fingers, ex.model.n_faces), replace=False)
    comps, free = placed(ex, aimed_placement(ex, faces, rng))
    tree.add_move(comps)
    assert len(true_leaves(tree, ex)) >= 1, (name, seed, "components")
    apply_probes(tree, free, [c.id for c in comps])
    assert len(true_leaves(tree, ex)) >= 1, (name, seed, "free space")


_common = settings(deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)


@settings(_common, max_examples=60)
@given(name=st.sampled_from(NAMES), seed=st.integers(0, 2**31), n_moves=st.integers(1, 5),
       fingers=st.sampled_from([2, 3, 4]))  # fmt: skip
def test_the_true_interpretation_survives_a_placement_at_its_bounds(name, seed, n_moves, fingers):
    _check(name, seed, n_moves, fingers, at_bounds=True)


@settings(_common, max_examples=30)
@given(name=st.sampled_from(NAMES), seed=st.integers(0, 2**31), fingers=st.sampled_from([2, 4]))
def test_the_true_interpretation_survives_a_placement_inside_its_bounds(name, seed, fingers):
    _check(name, seed, 3, fingers, at_bounds=False)


def test_a_move_s_new_components_come_in_order():
    rng = np.random.default_rng(0)
    ex = GeometricExecutor(LIB["BOX01"], SE3.random(rng, 0.1), SensorNoise(), rng)
    random_walk(ex, 2, rng)
    tree = InterpretationTree(ARRAYS)
    tree.add_all(ex.components)
    comps, _ = placed(ex, aimed_placement(ex, [0, 1], rng))
    before = tree.count
    with pytest.raises(MatchError, match="next ids in order"):
        tree.add_move(comps[::-1])
    assert tree.count == before and len(tree.data) == len(ex.components) - len(comps)
