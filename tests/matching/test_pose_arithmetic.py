"""The matcher's faster pose arithmetic gives the poses of the plain formulas: the closed-form Jacobian is the
finite-difference one, the one residual form has the sum of squares of the seed's residuals, the refinement reaches
the least-squares pose that Gauss–Newton on those residuals reaches, the translation from the normal equations is
the SVD least squares of the explicit rows (and is refused exactly where that is ill-conditioned), the pose classes
taken as bit sets are those of the array loop, and the unrefined poses kept as arrays are the poses."""

from __future__ import annotations

import numpy as np
import pytest

import haptic.matching.batch_poses as bp
from haptic.env import ExploreEnv
from haptic.geometry.se3 import random_rotation
from haptic.matching.recognition import _first_classes


def _problems(small_library, seeds=range(1, 25), most=12):
    """Stacked pose problems of the leaves of real trees (posed leaves only) with their closed-form poses."""
    env = ExploreEnv(models=small_library, verify="none")
    rng = np.random.default_rng(0)
    out = []
    for seed in seeds:
        env.reset(seed=seed)
        for _ in range(4):
            ctx = env.context
            if ctx is None:
                break
            tree = ctx.tree
            if tree.count:
                prob = tree._build_stacked(np.arange(tree.count))
                r, t, ok = prob.initial()
                idx = np.flatnonzero(ok)
                if len(idx):
                    out.append((prob.subset(idx), r[idx], t[idx]))
            _, _, terminated, truncated, _ = env.step(int(rng.choice(np.flatnonzero(env.action_masks()))))
            if terminated or truncated:
                break
        if len(out) >= most:
            break
    assert out, "no posed leaves"
    return out


@pytest.fixture(scope="module")
def problems(small_library):
    return _problems(small_library)


def _reference_refine(prob, r, t, iterations=12):
    """Gauss–Newton on :meth:`StackedPoses.residuals` with a finite-difference Jacobian and the exact exponential
    (the plain formulas), run to convergence."""
    r, t = r.copy(), t.copy()
    h = 1e-7
    for _ in range(iterations):
        f0 = prob.residuals(r, t)
        jac = np.empty((*f0.shape, 6))
        for k in range(6):
            xi = np.zeros(6)
            xi[k] = h
            e = bp.exp_so3(xi[:3])
            jac[..., k] = (prob.residuals(e @ r, (e @ t[..., None])[..., 0] + xi[3:]) - f0) / h
        step = np.linalg.lstsq(jac[0], -f0[0], rcond=None)[0][None] if len(r) == 1 else np.stack(
            [np.linalg.lstsq(jac[i], -f0[i], rcond=None)[0] for i in range(len(r))]
        )
        dr = bp.exp_so3(step[:, :3])
        r, t = dr @ r, (dr @ t[..., None])[..., 0] + step[:, 3:]
    return r, t


def test_the_closed_form_jacobian_is_the_finite_difference_one(problems):
    rng = np.random.default_rng(1)
    for prob, r, t in problems:
        f, jac = prob._residuals_and_jacobian(r, t)
        assert f.shape == jac.shape[:2] and jac.shape[2] == 6
        h = 1e-6
        for k in range(6):
            xi = np.zeros(6)
            xi[k] = h
            e = bp.exp_so3(xi[:3])
            plus, _ = prob._residuals_and_jacobian(e @ r, (e @ t[..., None])[..., 0] + xi[3:])
            e = bp.exp_so3(-xi[:3])
            minus, _ = prob._residuals_and_jacobian(e @ r, (e @ t[..., None])[..., 0] - xi[3:])
            fd = (plus - minus) / (2 * h)
            scale = np.abs(jac[..., k]).max() + 1.0
            assert np.abs(fd - jac[..., k]).max() <= 1e-5 * scale
        # anywhere, not only at the closed-form poses
        r2 = np.stack([random_rotation(rng) for _ in range(len(r))])
        f2, _ = prob._residuals_and_jacobian(r2, t + rng.normal(size=t.shape) * 0.01)
        assert np.isfinite(f2).all()


def test_one_residual_form_has_the_sum_of_squares_of_the_seeds_residuals(problems):
    rng = np.random.default_rng(2)
    for prob, r, t in problems:
        turned = np.stack([random_rotation(rng) for _ in range(len(r))])
        for rot, tr in ((r, t), (turned, t + rng.normal(size=t.shape))):
            plain = (prob.residuals(rot, tr) ** 2).sum(axis=-1)
            fused = (prob._residuals_and_jacobian(rot, tr)[0] ** 2).sum(axis=-1)
            np.testing.assert_allclose(fused, plain, rtol=1e-9, atol=1e-18)


def test_the_refinement_reaches_the_pose_of_gauss_newton_on_the_seeds_residuals(problems):
    checked = 0
    for prob, r, t in problems:
        r1, t1 = prob.refine(r, t)
        r0, t0 = _reference_refine(prob, r, t)
        assert np.abs(r1 - r0).max() < 1e-8
        assert np.abs(t1 - t0).max() < 1e-8  # [m]: far below any bound of the data (micrometres)
        np.testing.assert_allclose(np.swapaxes(r1, -1, -2) @ r1, np.broadcast_to(np.eye(3), r1.shape), atol=1e-12)
        np.testing.assert_allclose(np.linalg.det(r1), 1.0, atol=1e-12)
        checked += len(r)
    assert checked > 10


def test_the_translation_from_the_normal_equations_is_the_least_squares_of_the_rows(problems, monkeypatch):
    """Against the explicit rows and their SVD least squares (the formulas the normal equations replace)."""
    checked = 0
    for prob, r, _ in problems:
        t, ok = prob.translations(r)
        rt = np.swapaxes(r, -1, -2)
        rows, rhs = [], []
        if len(prob.plane_q):
            nrm = prob.plane_n @ rt
            rows.append(prob.plane_w[:, None] * nrm)
            rhs.append(prob.plane_w * (np.einsum("nij,ij->ni", nrm, prob.plane_q) - prob.plane_d))
        if len(prob.line_x):
            b = prob.line_b @ rt
            perp = np.eye(3) - b[..., :, None] * b[..., None, :]
            rows.append((prob.line_w[:, None, None] * perp).reshape(prob.n, -1, 3))
            rel = prob.line_x - prob.line_p @ rt
            rhs.append((prob.line_w[:, None] * np.einsum("nlij,nlj->nli", perp, rel)).reshape(prob.n, -1))
        if len(prob.pt_d):
            pt_rows = (prob.pt_w[:, None, None] * np.eye(3)).reshape(-1, 3)
            rows.append(np.broadcast_to(pt_rows, (prob.n, *pt_rows.shape)))
            rhs.append((prob.pt_w[:, None] * (prob.pt_d - prob.pt_m @ rt)).reshape(prob.n, -1))
        want, s = bp._lstsq(np.concatenate(rows, axis=1), np.concatenate(rhs, axis=1))
        np.testing.assert_array_equal(ok, s[:, -1] >= bp.MIN_CONDITION * s[:, 0])
        assert np.abs(t[ok] - want[ok]).max(initial=0.0) < 1e-12
        checked += int(ok.sum())
    assert checked > 10


def test_pose_classes_as_bit_sets_are_those_of_the_array_loop():
    rng = np.random.default_rng(4)
    for _ in range(300):
        n = int(rng.integers(1, 90))
        same = rng.random((n, n)) < rng.choice([0.02, 0.2, 0.7])
        same |= same.T
        np.fill_diagonal(same, True)
        names = sorted(rng.choice(1000, size=n, replace=False).tolist())
        want = []
        alive = np.ones(n, dtype=bool)
        while alive.any():
            k = int(np.argmax(alive))
            members = alive & same[k]
            members[k] = False
            want.append([names[k], *np.asarray(names)[members].tolist()])
            alive &= ~members
            alive[k] = False
        assert _first_classes(same, names) == want


def _first_trees(small_library, seeds):
    """The tree at the first decision of each episode that has one with interpretations."""
    env = ExploreEnv(models=small_library, verify="none")
    for seed in seeds:
        env.reset(seed=seed)
        if env.context is not None and env.context.tree is not None and env.context.tree.count:
            yield env.context.tree


def test_the_unrefined_poses_kept_as_arrays_are_the_poses(small_library):
    checked = 0
    for tree in _first_trees(small_library, range(1, 15)):
        fresh = tree.copy()  # no poses kept
        r, t, ok = fresh.initial_poses()
        poses = tree.copy().poses(range(fresh.count), refine=False)
        for i, p in enumerate(poses):
            assert (p is None) == (not ok[i])
            if p is not None:
                np.testing.assert_array_equal(p.rotation, r[i])
                np.testing.assert_array_equal(p.translation, t[i])
                checked += 1
        keep = np.arange(fresh.count) % 2 == 0  # retain renumbers the kept poses
        fresh.retain(keep)
        r2, t2, ok2 = fresh.initial_poses()
        np.testing.assert_array_equal(r2, r[keep])
        np.testing.assert_array_equal(ok2, ok[keep])
    assert checked > 20
