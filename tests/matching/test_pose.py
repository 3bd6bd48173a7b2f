"""Pose recovery: exact from an edge pair, and within 1 mm and 0.5° at the default noise over random poses."""

import numpy as np
import pytest

from haptic.executor.geometric import GeometricExecutor
from haptic.geometry import SE3, load_library, symmetry_group
from haptic.matching.components import SensorNoise
from haptic.matching.pose import pose_error, pose_from_edge_pair
from haptic.matching.recognition import RECOGNIZED, recognize
from haptic.matching.tree import InterpretationTree

LIB = load_library()


def test_pose_from_a_non_parallel_edge_pair_is_exact_and_proper():
    rng = np.random.default_rng(0)
    model = LIB["TETRA01L"]
    for _ in range(20):
        truth = SE3.random(rng, 0.3)
        e1, e2 = 0, 1
        b1, b2 = model.edge_directions[e1], model.edge_directions[e2]
        p1 = model.edge_points[e1] + 0.3 * model.edge_lengths[e1] * b1
        p2 = model.edge_points[e2] + 0.6 * model.edge_lengths[e2] * b2
        est = pose_from_edge_pair(
            truth.apply(p1), truth.rotate(b1), truth.apply(p2), truth.rotate(b2),
            model.edge_points[e1], b1, model.edge_points[e2], b2,
        )  # fmt: skip
        assert np.linalg.det(est.rotation) > 0
        assert np.allclose(est.rotation, truth.rotation, atol=1e-9)
        assert np.allclose(est.translation, truth.translation, atol=1e-9)


@pytest.mark.parametrize("name", ["WEDGE01", "TETRA01R", "PYR01", "HEXPRISM01", "LBLOCK01", "FRAME01"])
def test_pose_within_1mm_and_half_a_degree_at_default_noise(name):
    model = LIB[name]
    sym = symmetry_group(model)
    errors = []
    for seed in range(6):
        rng = np.random.default_rng(seed)
        truth = SE3.random(rng, 0.2)
        ex = GeometricExecutor(model, truth, SensorNoise(), rng)
        ex.start()
        tree = InterpretationTree(LIB)
        for c in ex.components:
            tree.add(c)
        for _ in range(60):
            rec = recognize(tree)
            if rec.status != "exploring":
                break
            moves = ex.admissible_moves(rng, n_directions=1)
            res = ex.execute(moves[int(rng.integers(len(moves)))])
            for c in res.components:
                tree.add(c)
        assert rec.status == RECOGNIZED and rec.model == name
        dp, da = pose_error(rec.world_from_model, truth, model, sym)
        errors.append((dp, da))
    errors = np.array(errors)
    assert errors[:, 0].max() < 1e-3, errors
    assert np.degrees(errors[:, 1]).max() < 0.5, errors


@pytest.mark.parametrize("seed", [0, 1])
def test_poses_of_a_batch_equal_the_poses_of_each_interpretation_alone(seed):
    """The tree poses all its leaves in one stacked problem; each pose is the one the leaf's own problem gives
    (undetermined ones included), unrefined and refined, and does not depend on the other leaves of the batch."""
    from haptic.executor.geometric import random_walk
    from haptic.matching.pose import estimate_pose

    rng = np.random.default_rng(seed)
    ex = GeometricExecutor(LIB["WEDGE01"], SE3.random(rng, 0.1), SensorNoise(), rng)
    random_walk(ex, 2, rng)
    tree = InterpretationTree(LIB)
    determined = 0
    for c in ex.components:
        tree.add(c)
        n = tree.count
        for refine in (False, True):
            batch = tree.poses(range(n), refine=refine)
            for leaf in range(n):
                it = tree.interpretation(leaf, with_pose=False)
                alone = estimate_pose(
                    it.model, tree.data, it.faces, it.edges, it.edge_senses, it.vertices, refine=refine
                )
                assert (batch[leaf] is None) == (alone is None)
                if alone is not None:
                    determined += 1
                    assert np.allclose(batch[leaf].rotation, alone.rotation, atol=1e-8)
                    assert np.allclose(batch[leaf].translation, alone.translation, atol=1e-9)
    assert determined > 0
