"""The compiled kernels of the matcher (:mod:`haptic.matching.kernels`) give the numpy forms' results: the same poses
to the rounding, the same pose classes, and episodes that decide the same; ``HAPTIC_COMPILED=0`` selects the numpy
forms."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

import haptic.matching.kernels as kernels
from haptic.env import ExploreEnv, PolicyAgent
from haptic.matching.recognition import PoseTolerance, _same_pose_pairs, model_symmetries, recognize

pytestmark = pytest.mark.skipif(not kernels.COMPILED, reason="numba not installed, or HAPTIC_COMPILED=0")


def _trees(library: str, seeds=range(1, 40)):
    """The interpretation trees of the first decisions of some episodes (posed or not)."""
    env = ExploreEnv(models=library, verify="none")
    agent = PolicyAgent("planner")
    for seed in seeds:
        env.reset(seed=seed)
        for _ in range(3):
            ctx = env.context
            if ctx is None:
                break
            if ctx.tree is not None and ctx.tree.count:
                yield ctx.tree
            _, _, terminated, truncated, _ = env.step(agent.act(env))
            if terminated or truncated:
                break


def _both(monkeypatch, fn, *args):
    """``fn(*args)`` with the kernels, then with the numpy forms."""
    compiled = fn(*args)
    monkeypatch.setattr(kernels, "COMPILED", False)
    try:
        return compiled, fn(*args)
    finally:
        monkeypatch.setattr(kernels, "COMPILED", True)


def test_closed_form_and_refined_poses_are_the_numpy_forms(small_library, monkeypatch):
    posed = refined = 0
    for tree in _trees(small_library):
        prob = tree._build_stacked(np.arange(tree.count))
        (r1, t1, ok1), (r0, t0, ok0) = _both(monkeypatch, prob.initial)
        np.testing.assert_array_equal(ok1, ok0)
        np.testing.assert_allclose(r1[ok1], r0[ok0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(t1[ok1], t0[ok0], rtol=0, atol=1e-12)
        posed += int(ok1.sum())
        idx = np.flatnonzero(ok0)
        if not len(idx):
            continue
        sub = prob.subset(idx)
        (rr1, tr1), (rr0, tr0) = _both(monkeypatch, sub.refine, r0[idx], t0[idx])
        np.testing.assert_allclose(rr1, rr0, rtol=0, atol=1e-12)
        np.testing.assert_allclose(tr1, tr0, rtol=0, atol=1e-12)
        moved = np.abs(tr0 - t0[idx]).max(axis=1) > 1e-9  # the refinement did move these poses
        refined += int(moved.sum())
    assert posed > 100 and refined > 20


def _class_leaves(tree) -> list[tuple[int, ...]]:
    return [c.leaves for c in recognize(tree, max_interpretations=4000).classes]


def test_pose_classes_are_the_numpy_forms(small_library, monkeypatch):
    compared = joined = 0
    for tree in _trees(small_library):
        rot, trans, ok = tree.initial_poses()
        if not ok.all():
            continue
        tol = PoseTolerance.from_data(tree.data)
        for m in np.unique(tree.model_indices):
            rows = np.flatnonzero(tree.model_indices == m)
            model = tree.library.models[int(m)]
            placed = trans[rows] + rot[rows] @ model.centroid
            a, b = _both(monkeypatch, _same_pose_pairs, rot[rows], trans[rows], placed, model, tol)
            np.testing.assert_array_equal(a, b)
            compared += a.size
            joined += int(a.sum() - len(rows))  # pairs of distinct poses in one class
        a, b = _both(monkeypatch, _class_leaves, tree)
        assert a == b
    assert compared > 1000 and joined > 0


def test_pose_pairs_of_a_symmetric_model_with_near_poses(monkeypatch):
    """Random poses, some an earlier pose composed with a symmetry and turned a little (across the tolerance)."""
    from haptic.geometry import load_library
    from haptic.geometry.se3 import random_rotation
    from haptic.matching.batch_poses import exp_so3

    poly = load_library()["BOX01"]
    sym = model_symmetries(poly)
    rng = np.random.default_rng(3)
    rot, trans = [], []
    for i in range(60):
        if i and rng.random() < 0.5:
            j = int(rng.integers(i))
            s = sym[int(rng.integers(len(sym)))]
            turn = exp_so3(rng.normal(size=3) * float(rng.choice([1e-4, 0.03, 0.06])))
            rot.append(turn @ rot[j] @ s.rotation)
            trans.append(turn @ (rot[j] @ s.translation + trans[j]) + rng.normal(size=3) * 1e-3)
        else:
            rot.append(random_rotation(rng))
            trans.append(rng.normal(size=3) * 0.02)
    rot, trans = np.array(rot), np.array(trans)
    placed = trans + rot @ poly.centroid
    tol = PoseTolerance(np.deg2rad(3.0), 0.003)
    a, b = _both(monkeypatch, _same_pose_pairs, rot, trans, placed, poly, tol)
    np.testing.assert_array_equal(a, b)
    assert 60 < a.sum() < 60 * 60 / 2


def _records(library: str, seeds, verify: str) -> list[dict]:
    env = ExploreEnv(models=library, verify=verify)
    agent = PolicyAgent("planner")
    out = []
    for seed in seeds:
        env.reset(seed=seed)
        while True:
            _, _, terminated, truncated, info = env.step(agent.act(env))
            if terminated or truncated:
                rec = info["record"]
                out.append({k: rec[k] for k in ("outcome", "moves", "path_cost", "interpretations", "classes")})
                break
    return out


@pytest.mark.parametrize("verify", ["none", "full"])
def test_episodes_decide_the_same_with_the_kernels_or_without(small_library, monkeypatch, verify):
    seeds = range(1, 9) if verify == "full" else range(1, 21)
    a, b = _both(monkeypatch, _records, small_library, seeds, verify)
    assert a == b
    assert sum(r["moves"] for r in a) > 2 * len(a)


def test_haptic_compiled_0_selects_the_numpy_forms():
    env = {**os.environ, "HAPTIC_COMPILED": "0"}
    code = "import haptic.matching.kernels as k; print(k.COMPILED)"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
