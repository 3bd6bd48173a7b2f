"""What makes environment steps cheap changes no result: the scores of a decision computed once (the observation and
the planner acting through the environment share them) equal scores computed afresh, and the faster arithmetic of
the planner and the matcher gives numpy's own results to the last bit."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import haptic.planning.move_scores as move_scores
from haptic.env import ExploreEnv, PolicyAgent
from haptic.geometry.se3 import random_rotation
from haptic.matching.acceptance import _angle
from haptic.matching.recognition import PoseTolerance, _same_pose_as
from haptic.planning.config import PlannerConfig
from haptic.planning.move_scores import bounded, score_all
from haptic.planning.predict import nan_median
from haptic.planning.tour import FACE, VERTEX, LegCosts, features, start_costs


def _posed_context(env: ExploreEnv, seeds=range(1, 40)):
    """A decision of some episode at which the data fix the poses of two or more classes."""
    for seed in seeds:
        env.reset(seed=seed)
        ctx = env.context
        if ctx is not None and len(ctx.hypotheses) >= 2:
            return ctx
    pytest.fail("no episode reached a decision with pose classes")


def _same_scores(a, b) -> None:
    assert len(a) == len(b) > 0
    for (pa, *va), (pb, *vb) in zip(a, b, strict=True):
        assert move_scores.same_move(pa.move, pb.move)
        assert va == vb  # efficiency, eliminations, cost, risk: exactly
        np.testing.assert_array_equal(pa.outcomes, pb.outcomes)
        np.testing.assert_array_equal(pa.costs, pb.costs)


def test_cached_scores_equal_fresh_ones(small_library):
    env = ExploreEnv(models=small_library, verify="none")
    ctx = _posed_context(env)
    first = score_all(bounded(ctx))  # the observation computed these at reset: a cache hit
    again = score_all(bounded(ctx))
    assert all(x[0] is y[0] for x, y in zip(first, again, strict=True))
    fresh = score_all(replace(bounded(ctx)))  # a new context: computed afresh
    assert all(x[0] is not y[0] for x, y in zip(first, fresh, strict=True))
    _same_scores(first, fresh)


def test_a_context_whose_data_changed_is_scored_afresh(small_library):
    env = ExploreEnv(models=small_library, verify="none")
    ctx = _posed_context(env)
    own = replace(ctx, components=dict(ctx.components))
    before = score_all(own)
    gone = max(own.components)
    own.components[gone] = replace(own.components[gone])  # the same data, another object: not the scores' data
    after = score_all(own)
    assert all(x[0] is not y[0] for x, y in zip(before, after, strict=True))
    _same_scores(before, after)
    del own.components[gone]  # fewer components: computed again, as a new context with these data would
    shorter, fresh = score_all(own), score_all(replace(own, components=dict(own.components)))
    assert all(x[0] is not y[0] for x, y in zip(after, shorter, strict=False))
    assert [(type(p.move), *v) for p, *v in shorter] == [(type(p.move), *v) for p, *v in fresh]


def test_the_planner_through_the_environment_scores_each_decision_once(small_library, monkeypatch):
    calls = []
    real = move_scores._score_all
    monkeypatch.setattr(move_scores, "_score_all", lambda ctx: calls.append(ctx) or real(ctx))
    env, agent = ExploreEnv(models=small_library, verify="none"), PolicyAgent("planner")
    decisions = 0
    for seed in range(1, 6):
        env.reset(seed=seed)
        while True:
            posed = env.context is not None and len(env.context.hypotheses) > 0
            decisions += posed
            _, _, terminated, truncated, _ = env.step(agent.act(env))
            if terminated or truncated:
                break
    assert decisions > 0
    assert len(calls) == decisions


def test_nan_median_is_numpys():
    rng = np.random.default_rng(5)
    for _ in range(3000):
        x = rng.normal(size=int(rng.integers(1, 30))) * rng.choice([1e-3, 1.0, 1e3]) + rng.choice([0.0, 0.1])
        x[rng.random(len(x)) < 0.3] = np.nan
        if rng.random() < 0.1:
            x[~np.isnan(x)] = 0.02  # ties
        if np.isnan(x).all():
            assert np.isnan(nan_median(x))
            continue
        assert nan_median(x) == np.nanmedian(x)


def test_the_residuals_angle_is_numpys():
    rng = np.random.default_rng(6)
    for _ in range(3000):
        u = rng.normal(size=3)
        v = (u * rng.uniform(0.5, 2.0) + rng.normal(size=3) * rng.choice([0.0, 1e-9, 1e-4, 1.0])) * rng.choice([1, -1])
        want = float(np.arccos(np.clip(u @ v / (np.linalg.norm(u) * np.linalg.norm(v)), -1.0, 1.0)))
        assert _angle(u, v) == want


@pytest.mark.parametrize("moves", ["all", "tracing"])
def test_start_costs_are_the_legs_cost_formula(moves):
    from haptic.geometry import load_library

    legs = LegCosts.of(PlannerConfig(moves=moves))
    rng = np.random.default_rng(7)
    for name in ("BOX01", "LBLOCK01", "TETRA01L"):
        poly = load_library()[name]
        feats = features(poly)
        targets = np.flatnonzero(rng.random(len(feats.kinds)) < 0.6)
        for face, edge in ((0, None), (1, 0), (None, None), (2, poly.n_edges - 1)):
            p = poly.vertices.mean(axis=0) + rng.normal(size=3) * 0.01
            got = start_costs(poly, p, face, edge, targets, legs)
            kinds = feats.kinds[targets]
            d = np.linalg.norm(feats.points[targets] - p, axis=1)
            cof = feats.on_face[targets, face] if face is not None else np.zeros(len(targets), bool)
            want = np.minimum(legs.by_tracing(d, kinds, cof), legs.by_probe(d, kinds))
            if edge is not None:
                ends = feats.kinds.size - poly.n_vertices + poly.edges[edge]
                want = np.where(np.isin(targets, ends), np.minimum(want, legs.edge_rate * d + legs.vertex_event), want)
            np.testing.assert_array_equal(got, want)
            assert (kinds == FACE).any() or (kinds == VERTEX).any()


def test_pose_grouping_with_the_centroids_placed_once_is_the_same():
    from haptic.geometry import load_library

    poly = load_library()["BOX01"]
    rng = np.random.default_rng(8)
    rot = np.stack([random_rotation(rng) for _ in range(40)])
    rot[20:] = rot[:20]  # some poses equal
    trans = rng.normal(size=(40, 3)) * 0.01
    trans[20:] = trans[:20]
    tol = PoseTolerance(np.deg2rad(2.0), 0.002)
    from haptic.geometry.se3 import SE3

    a = SE3(rot[3], trans[3])
    placed = trans + rot @ poly.centroid
    np.testing.assert_array_equal(
        _same_pose_as(a, rot, trans, poly, tol), _same_pose_as(a, rot, trans, poly, tol, placed)
    )
    assert _same_pose_as(a, rot, trans, poly, tol).sum() >= 2


def test_pose_classes_from_all_pairs_at_once_are_those_of_one_class_at_a_time(monkeypatch):
    """The grouping that compares every pair of a model's poses in one array gives the classes that comparing each
    class's first pose with the poses left gives (the same members in the same order), symmetric models, near
    poses and poses equal up to a symmetry included."""
    import haptic.matching.recognition as recognition
    from haptic.geometry import load_library
    from haptic.geometry.se3 import SE3

    lib = load_library()
    models = [lib["BOX01"], lib["WEDGE01"], lib["TETRA01L"]]
    rng = np.random.default_rng(9)
    merged = 0
    for _ in range(20):
        n = int(rng.integers(2, 60))
        index = rng.integers(0, len(models), size=n)
        poses = []
        for i in range(n):
            if i and rng.random() < 0.4:  # a pose of an earlier one, moved a little or by a symmetry
                j = int(rng.integers(i))
                index[i] = index[j]
                sym = recognition.model_symmetries(models[index[i]])
                p = poses[j] @ sym[int(rng.integers(len(sym)))]
                from haptic.matching.batch_poses import exp_so3

                small = exp_so3(rng.normal(size=3) * float(rng.choice([1e-3, 0.05])))
                turn = SE3(small, rng.normal(size=3) * 1e-3)
                poses.append(turn @ p)
            else:
                poses.append(SE3(random_rotation(rng), rng.normal(size=3) * 0.02))
        tol = PoseTolerance(np.deg2rad(3.0), 0.003)
        per_model = [models[k] for k in index]
        pairs = recognition._group(per_model, index, poses, tol)
        monkeypatch.setattr(recognition, "MAX_PAIRS", 0)
        one_by_one = recognition._group(per_model, index, poses, tol)
        monkeypatch.undo()
        assert pairs == one_by_one
        merged += n - len(pairs)
    assert merged > 20  # poses did share classes


def test_poses_from_the_kept_problems_of_every_leaf_equal_poses_built_afresh(small_library):
    """The matcher's verdict poses every leaf and then refines one per class from the problems of every leaf it
    keeps: the same poses, to the last bit, as a tree that builds each request's problems afresh."""
    from haptic.matching.recognition import recognize

    env = ExploreEnv(models=small_library, verify="none")
    checked = 0
    for seed in range(1, 30):
        env.reset(seed=seed)
        ctx = env.context
        if ctx is None or ctx.tree is None or not ctx.tree.count:
            continue
        tree = ctx.tree
        fresh = tree.copy()
        fresh._stacked = fresh._build_stacked  # no problems kept
        rec = recognize(tree, max_interpretations=4000)
        leaves = [c.leaves[0] for c in rec.classes]
        for refine in (False, True):
            kept = tree.poses(range(tree.count) if not refine else leaves, refine=refine)
            new = fresh.poses(range(tree.count) if not refine else leaves, refine=refine)
            for a, b in zip(kept, new, strict=True):
                assert (a is None) == (b is None)
                if a is not None:
                    np.testing.assert_array_equal(a.rotation, b.rotation)
                    np.testing.assert_array_equal(a.translation, b.translation)
                    checked += 1
    assert checked > 50


def test_one_start_cost_table_for_many_sensor_positions_is_start_costs_each_time():
    from haptic.geometry import load_library
    from haptic.planning.tour import StartCosts

    legs = LegCosts.of(PlannerConfig(moves="all"))
    rng = np.random.default_rng(10)
    poly = load_library()["LBLOCK01"]
    targets = np.flatnonzero(rng.random(len(features(poly).kinds)) < 0.5)
    table = StartCosts(poly, targets, legs)
    for face, edge in ((0, None), (1, 0), (None, None), (2, poly.n_edges - 1), (3, 2)):
        p = poly.vertices.mean(axis=0) + rng.normal(size=3) * 0.01
        np.testing.assert_array_equal(table(p, face, edge), start_costs(poly, p, face, edge, targets, legs))
