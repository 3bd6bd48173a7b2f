"""The compiled kernels of the matcher, the tracer and the planner (:mod:`haptic.matching.kernels`,
:mod:`haptic.geometry.kernels`, :mod:`haptic.planning.kernels`) give the numpy forms' results: the same poses to the
rounding, the same pose classes, the same face crossings and predictions, and episodes that decide the same;
``HAPTIC_COMPILED=0`` selects the numpy forms."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

import haptic.geometry.kernels as geometry_kernels
import haptic.matching.kernels as kernels
import haptic.planning.kernels as planning_kernels
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
    for module in (kernels, geometry_kernels, planning_kernels):
        monkeypatch.setattr(module, "COMPILED", False)
    try:
        return compiled, fn(*args)
    finally:
        for module in (kernels, geometry_kernels, planning_kernels):
            monkeypatch.setattr(module, "COMPILED", True)


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
    code = "import haptic.matching.kernels as k, haptic.geometry.kernels as g; print(k.COMPILED, g.COMPILED)"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


def test_edge_pair_tests_are_the_numpy_forms():
    """Random pairs of data and model edges, near and far, some model edges (anti-)parallel, some interval ends at
    known vertices: the kernel's verdicts are those of :func:`~haptic.matching.constraints.edge_pair_tests`."""
    from haptic.matching import constraints as C

    rng = np.random.default_rng(4)

    def unit(*shape):
        v = rng.normal(size=(*shape, 3))
        return v / np.linalg.norm(v, axis=-1, keepdims=True)

    passed = total = 0
    for _ in range(200):
        n_c, n_e = int(rng.integers(1, 30)), int(rng.integers(1, 5))
        p_d1, b_d1, l_d1 = rng.normal(size=3) * 0.05, unit(), float(rng.uniform(0.001, 0.1))
        p_d2, b_d2, l_d2 = rng.normal(size=(n_e, 3)) * 0.05, unit(n_e), rng.uniform(0.001, 0.1, n_e)
        # model edges: the data edges turned a little and moved a little, or at random; some (anti-)parallel
        turn = 10.0 ** rng.uniform(-4, -1)
        p_m1 = p_d1 + rng.normal(size=(n_c, 3)) * turn * 0.05
        b_m1 = b_d1 + rng.normal(size=(n_c, 3)) * turn
        b_m1 /= np.linalg.norm(b_m1, axis=-1, keepdims=True)
        p_m2 = p_d2 + rng.normal(size=(n_c, n_e, 3)) * turn * 0.05
        b_m2 = b_d2 + rng.normal(size=(n_c, n_e, 3)) * turn
        b_m2 /= np.linalg.norm(b_m2, axis=-1, keepdims=True)
        wild = rng.random((n_c, n_e)) < 0.2
        b_m2[wild] = unit(int(wild.sum()))
        par = rng.random((n_c, n_e)) < 0.2
        b_m2[par] = (b_m1[:, None] * rng.choice([-1.0, 1.0], size=(n_c, n_e, 1)))[par]
        if rng.random() < 0.2:  # data edges parallel as well
            b_d2[:] = b_d1 * rng.choice([-1.0, 1.0])
        l_m1, l_m2 = l_d1 + rng.uniform(-0.01, 0.05, n_c), l_d2 + rng.uniform(-0.01, 0.05, (n_c, n_e))
        beta_1, beta_2 = 10.0 ** rng.uniform(-3, -1), 10.0 ** rng.uniform(-3, -1, n_e)
        rho_1, rho_2 = 10.0 ** rng.uniform(-4, -2), 10.0 ** rng.uniform(-4, -2, n_e)
        lam_1, lam_2 = 10.0 ** rng.uniform(-4, -2), 10.0 ** rng.uniform(-4, -2, n_e)
        start_1, end_1 = bool(rng.random() < 0.3), bool(rng.random() < 0.3)
        start_2, end_2 = rng.random(n_e) < 0.3, rng.random(n_e) < 0.3
        want = C.edge_pair_tests(
            p_d1, b_d1, l_d1, p_d2, b_d2, l_d2, p_m1[:, None], b_m1[:, None], l_m1[:, None], p_m2, b_m2, l_m2,
            beta_1, beta_2, rho_1, rho_2, lam_1, lam_2, start_1, end_1, start_2, end_2,
        )  # fmt: skip
        got = kernels.edge_pair_tests(
            p_d1, b_d1, l_d1, p_d2, b_d2, l_d2, p_m1, b_m1, l_m1, p_m2, b_m2, l_m2,
            beta_1, beta_2, rho_1, rho_2, lam_1, lam_2, start_1, end_1, start_2, end_2,
            C.SAFETY, C.ANGLE_FLOOR, C.LENGTH_FLOOR, C.MIN_SIN, float(np.cos(C.PARALLEL_MODEL)),
        )  # fmt: skip
        np.testing.assert_array_equal(got, want)
        passed, total = passed + int(want.sum()), total + want.size
    assert 0.1 < passed / total < 0.9  # both verdicts common


def test_distinguishable_is_the_numpy_form(monkeypatch):
    from haptic.planning.efficiency import distinguishable

    rng = np.random.default_rng(5)
    told = 0
    for _ in range(300):
        n, a = int(rng.integers(1, 40)), int(rng.integers(1, 4))
        o = rng.normal(size=(n, a)) * 0.01
        o[rng.random((n, a)) < 0.2] = np.nan
        o[rng.random((n, a)) < 0.2] = o[0, 0]  # ties
        b = rng.uniform(0, 0.01, a)
        got, want = _both(monkeypatch, distinguishable, o, b)
        np.testing.assert_array_equal(got, want)
        told += int(want.sum())
    assert told > 1000


def test_without_numba_the_numpy_forms_pose_an_interpretation():
    """With numba not importable, the kernels module says so and the matcher works on the numpy forms alone."""
    code = (
        "import sys; sys.modules['numba'] = None\n"
        "import haptic.matching.kernels as k\n"
        "from haptic.geometry import load_library\n"
        "from haptic.matching.pose import estimate_pose\n"
        "from haptic.matching.components import DataFace\n"
        "import numpy as np\n"
        "box = load_library()['BOX01']\n"
        "pick = []\n"
        "for f in range(box.n_faces):\n"
        "    if all(abs(box.face_normals[f] @ box.face_normals[g]) < 0.5 for g in pick):\n"
        "        pick.append(f)\n"
        "faces = [DataFace(i, box.face_normals[f], box.vertices[list(box.faces[f])][:3].mean(axis=0)[None], 1e-3, 1e-4,"
        " ()) for i, f in enumerate(pick[:3])]\n"
        "pose = estimate_pose(box, faces, dict(enumerate(pick[:3])), {}, {}, {})\n"
        "print(k.COMPILED, np.allclose(pose.rotation, np.eye(3)), np.allclose(pose.translation, 0, atol=1e-9))\n"
    )
    env = {**os.environ, "HAPTIC_COMPILED": "1"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "True", "True"]


def test_point_triangle_distances_are_the_numpy_forms():
    """Points near and far from the triangles of a model (inside a triangle's prism, beyond a side, past a corner):
    the kernels' distances are :mod:`haptic.geometry.distance`'s to the rounding."""
    from haptic.geometry import load_library
    from haptic.geometry.distance import paired_point_triangle_distance, surface_distance

    poly = load_library()["LBLOCK01"]
    tri = np.ascontiguousarray(poly.vertices[poly.triangles])
    rng = np.random.default_rng(6)
    scale = rng.choice([1e-4, 1e-2, 0.1], size=(400, 1))
    pts = poly.vertices[rng.integers(0, len(poly.vertices), 400)] + rng.normal(size=(400, 3)) * scale
    np.testing.assert_allclose(kernels.surface_distance(pts, tri), surface_distance(poly, pts), rtol=1e-12, atol=1e-15)
    own = rng.integers(0, len(tri), 400)
    got = kernels.paired_point_triangle_distance(pts, np.ascontiguousarray(tri[own]))
    np.testing.assert_allclose(got, paired_point_triangle_distance(pts, tri[own]), rtol=1e-12, atol=1e-15)


def test_face_crossings_are_the_python_loops(monkeypatch):
    """Traces across every face of some models, from points inside and on the boundary, in every direction (some
    along a side, some at a corner): the compiled crossing gives the Python loop's hit, the same bits."""
    from haptic.geometry import load_library
    from haptic.geometry.tracing import trace_face

    lib = load_library()
    rng = np.random.default_rng(7)
    hits = misses = 0
    for name in ("BOX01", "LBLOCK01", "TETRA01L", "WEDGE01"):
        poly = lib[name]
        for f in range(poly.n_faces):
            loop = poly.vertices[list(poly.faces[f])]
            for _ in range(40):
                w = rng.dirichlet(np.ones(len(loop)) * rng.choice([0.2, 1.0]))
                start = w @ loop
                if rng.random() < 0.3:  # along a side, or towards a corner
                    k = int(rng.integers(len(loop)))
                    direction = loop[(k + 1) % len(loop)] - loop[k] if rng.random() < 0.5 else loop[k] - start
                else:
                    direction = rng.normal(size=3)
                a, b = _both(monkeypatch, trace_face, poly, f, start, direction)
                assert (a is None) == (b is None)
                if a is None:
                    misses += 1
                    continue
                hits += 1
                assert (a.edge, a.next_face, a.distance) == (b.edge, b.next_face, b.distance)
                np.testing.assert_array_equal(a.point, b.point)
    assert hits > 500 and misses > 10


def test_line_crossings_and_inside_tests_are_the_numpy_forms():
    """Lines through a non-convex model (some through its vertices and along its faces) and points inside, outside
    and near its surface: the compiled crossings and inside tests of the free-space test are
    :func:`~haptic.geometry.raycast.line_hits`'s and :meth:`~haptic.geometry.polyhedron.Polyhedron.contains`'s."""
    from haptic.geometry import load_library
    from haptic.geometry.raycast import BARYCENTRIC_SLACK, line_hits

    poly = load_library()["LBLOCK01"]
    tri = np.ascontiguousarray(poly.vertices[poly.triangles])
    rng = np.random.default_rng(8)
    centre, size = poly.vertices.mean(axis=0), float(np.ptp(poly.vertices, axis=0).max())
    starts = centre + rng.normal(size=(300, 3)) * size
    aims = poly.vertices[rng.integers(0, len(poly.vertices), 300)]
    aims[::2] += rng.normal(size=(150, 3)) * size * 0.2
    dirs = aims - starts
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    got, want = geometry_kernels.line_params(starts, dirs, tri, BARYCENTRIC_SLACK), line_hits(poly, starts, dirs).params
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    assert np.isfinite(want).sum() > 300
    pts = centre + rng.normal(size=(500, 3)) * size * 0.5
    inside = poly.contains(pts)
    np.testing.assert_array_equal(geometry_kernels.contains(pts, tri), inside)
    assert 20 < inside.sum() < 480  # both verdicts


def test_inside_samples_are_the_numpy_forms(monkeypatch):
    """Segments through a non-convex model (some ending inside it, some through its vertices, some of length 0): the
    compiled samples of the free-space test, with their depth bounds, are
    :func:`~haptic.geometry.raycast.sample_inside_many`'s numpy form's, bit for bit, and so is the verdict of
    :func:`~haptic.matching.free_space.free_segments_consistent` on a posed model."""
    from haptic.geometry import load_library
    from haptic.geometry.raycast import BARYCENTRIC_SLACK, CROSSING_SLACK, DEPTH_SAMPLES, sample_inside_many
    from haptic.geometry.se3 import SE3
    from haptic.matching import free_space
    from haptic.matching.free_space import FreeSegment, free_segments_consistent

    poly = load_library()["LBLOCK01"]
    tri = np.ascontiguousarray(poly.vertices[poly.triangles])
    rng = np.random.default_rng(9)
    centre, size = poly.vertices.mean(axis=0), float(np.ptp(poly.vertices, axis=0).max())
    starts = centre + rng.normal(size=(200, 3)) * size
    aims = poly.vertices[rng.integers(0, len(poly.vertices), 200)]
    aims[::2] += rng.normal(size=(100, 3)) * size * 0.2
    dirs = aims - starts
    lengths = np.linalg.norm(dirs, axis=1) * rng.uniform(0.5, 2.0, 200)
    lengths[::17] = 0.0
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    pts, upper, owner = geometry_kernels.inside_samples(starts, dirs, lengths, tri, BARYCENTRIC_SLACK, DEPTH_SAMPLES,
                                                        CROSSING_SLACK)  # fmt: skip
    for compiled in (True, False):  # the crossings compiled (the same bits), or numpy's (the same to the rounding)
        monkeypatch.setattr(geometry_kernels, "COMPILED", compiled)
        want = sample_inside_many(poly, starts, dirs, lengths)
        monkeypatch.undo()
        np.testing.assert_array_equal(owner, np.repeat(np.arange(200), [len(p) for p, _ in want]))
        check = np.testing.assert_array_equal if compiled else np.testing.assert_allclose
        check(pts, np.concatenate([p for p, _ in want]), **({} if compiled else {"rtol": 1e-9, "atol": 1e-12}))
        check(upper, np.concatenate([u for _, u in want]), **({} if compiled else {"rtol": 1e-9, "atol": 1e-12}))
    assert len(pts) > 300 and np.isfinite(upper).sum() > 100
    pose = SE3.random(rng, 0.1)
    tol = PoseTolerance(np.deg2rad(3.0), 3e-3)
    verdicts = []
    for k in range(0, 200, 5):
        segs = [FreeSegment(pose.apply(starts[j]), pose.rotate(dirs[j]), lengths[j], 1e-3) for j in range(k, k + 5)]
        monkeypatch.setattr(free_space.kernels, "COMPILED", False)
        reference = free_segments_consistent(poly, pose, segs, tol)
        monkeypatch.undo()
        assert free_segments_consistent(poly, pose, segs, tol) == reference
        verdicts.append(reference)
    assert 0 < sum(verdicts) < len(verdicts)  # both verdicts


def test_probe_candidates_computed_together_are_the_line_by_line_ones(small_library, monkeypatch):
    """The probe candidates at the decisions of some episodes: the lines computed a hypothesis at a time are those of
    :func:`~haptic.planning.probe_lines._probe_line` line by line, the same lines in the same order, to rounding."""
    from haptic.planning import probe_lines
    from haptic.planning.probe_lines import candidate_probes

    env = ExploreEnv(models=small_library, verify="none")
    agent = PolicyAgent("planner")
    compared = 0
    for seed in range(1, 6):
        env.reset(seed=seed)
        while env.context is not None:
            hyps = [h for h in env.context.hypotheses if h.world_from_model is not None]
            if hyps:
                got = candidate_probes(hyps)
                monkeypatch.setattr(probe_lines, "BATCHED", False)
                want = candidate_probes(hyps)
                monkeypatch.undo()
                assert len(got) == len(want)
                for a, b in zip(got, want, strict=True):  # the same to a few ulps (vectorised sums may round apart)
                    np.testing.assert_allclose(a.direction, b.direction, rtol=0, atol=1e-14)
                    np.testing.assert_allclose(a.start, b.start, rtol=0, atol=1e-14)
                    assert a.length == pytest.approx(b.length, rel=0, abs=1e-14)
                compared += len(got)
            _, _, terminated, truncated, _ = env.step(agent.act(env))
            if terminated or truncated:
                break
    assert compared > 100


def test_face_move_predictions_are_the_numpy_forms(small_library, monkeypatch):
    """The face moves' predicted outcomes, costs and clearances in every hypothesis of decisions of some episodes:
    the compiled predictions are :func:`~haptic.planning.predict.face_outcomes`'s numpy form's, where each hypothesis
    can say and where it cannot."""
    from haptic.planning.moves import FaceMove
    from haptic.planning.predict import candidate_moves, face_outcomes

    env = ExploreEnv(models=small_library, verify="none")
    agent = PolicyAgent("planner")
    said = unsaid = 0
    for seed in range(1, 25):
        env.reset(seed=seed)
        while env.context is not None:
            ctx = env.context
            faces = [m for m in candidate_moves(ctx.state, ctx.components, ctx.config) if isinstance(m, FaceMove)]
            if ctx.hypotheses and faces:
                h = ctx.hypotheses[0]  # along its face's normal: no move in its world
                f_m = h.faces.get(ctx.state.face)
                if h.world_from_model is not None and f_m is not None:
                    faces.append(FaceMove(h.world_from_model.rotate(h.poly.face_normals[f_m])))
                a, b = _both(monkeypatch, face_outcomes, ctx.hypotheses, faces, ctx.state, ctx.config)
                for x, y in zip(a, b, strict=True):
                    for u, v in zip(x, y, strict=True):
                        np.testing.assert_array_equal(np.isnan(u), np.isnan(v))
                        np.testing.assert_allclose(u, v, rtol=1e-12, atol=1e-15)
                    said, unsaid = said + int((~np.isnan(x[1])).sum()), unsaid + int(np.isnan(x[1]).sum())
            _, _, terminated, truncated, _ = env.step(agent.act(env))
            if terminated or truncated:
                break
    assert said > 500 and unsaid > 10


def test_small_solves_are_numpys_and_a_singular_system_hands_back_to_numpy():
    """The kernels' Gaussian elimination solves what ``np.linalg.solve`` solves, and says so where a pivot is exactly
    zero (numpy raises there); the refinement then returns False, and ``StackedPoses.refine`` takes the numpy form."""
    rng = np.random.default_rng(9)
    for n in (3, 6):
        for _ in range(200):
            a = rng.normal(size=(n, n)) * 10.0 ** rng.uniform(-3, 3, size=n)
            b = rng.normal(size=n)
            x = b.copy()
            assert kernels._solve_in_place(a.copy(), x, n)
            np.testing.assert_allclose(a @ x, b, rtol=1e-9, atol=1e-9 * np.abs(a).max())
        a = rng.normal(size=(n, n))
        a[:, 1] = 0.0  # singular: a zero column
        assert not kernels._solve_in_place(a, rng.normal(size=n), n)
    # no row constrains anything: the normal equations are zero
    r, t = np.eye(3)[None].copy(), np.zeros((1, 3))
    none = np.zeros((0, 3))
    assert not kernels.refine_poses(
        np.ones((1, 3)), np.ones((1, 1, 3)), np.zeros((1, 1)), none, np.zeros((1, 0, 3)), np.zeros((1, 0, 3, 3)),
        r, t, 6, 1e-9,
    )  # fmt: skip
