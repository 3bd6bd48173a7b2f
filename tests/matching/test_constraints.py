"""The §2.4/§2.6 constraint functions: formulas against brute force, and invariance under rigid motions."""

import numpy as np
import pytest

from haptic.geometry import SE3, load_library
from haptic.matching import constraints as C


def _rng(seed=0):
    return np.random.default_rng(seed)


def _unit(v):
    return v / np.linalg.norm(v)


def test_closest_approach_matches_brute_force():
    rng = _rng(1)
    for _ in range(50):
        p1, p2 = rng.normal(size=3), rng.normal(size=3)
        b1, b2 = _unit(rng.normal(size=3)), _unit(rng.normal(size=3))
        s1, s2 = C.closest_approach(p1, b1, p2, b2)
        # the connecting segment is perpendicular to both lines
        d = (p2 + s2 * b2) - (p1 + s1 * b1)
        assert abs(d @ b1) < 1e-9 and abs(d @ b2) < 1e-9
        assert abs(abs(C.skew_distance(p1, b1, p2, b2)) - np.linalg.norm(d)) < 1e-9


def test_closest_approach_is_nan_for_parallel_lines():
    s1, s2 = C.closest_approach(np.zeros(3), np.array([1.0, 0, 0]), np.ones(3), np.array([1.0, 0, 0]))
    assert np.isnan(s1) and np.isnan(s2)


def test_force_clockwise_reverses_and_moves_p_for_a_left_face():
    p, b = C.force_clockwise(np.zeros(3), np.array([1.0, 0, 0]), 2.0, True)
    assert np.allclose(p, [2, 0, 0]) and np.allclose(b, [-1, 0, 0])
    p, b = C.force_clockwise(np.zeros(3), np.array([1.0, 0, 0]), 2.0, False)
    assert np.allclose(p, 0) and np.allclose(b, [1, 0, 0])


def test_face_side_agrees_with_the_model_left_face():
    box = load_library()["BOX01"]
    for e in range(box.n_edges):
        for f, expect in ((box.edge_left_face[e], 1), (box.edge_right_face[e], -1)):
            q = box.vertices[list(box.faces[f])].mean(axis=0)
            assert C.face_side(box.face_normals[f], box.edge_directions[e], box.edge_points[e], q) == expect


def test_edge_length_test():
    eps = C.edge_length_epsilon(0.001)
    assert C.edge_length_test(0.1015, 0.1, eps)
    assert not C.edge_length_test(0.1025, 0.1, eps)


def test_face_pair_test_uses_the_sum_of_bounds():
    n1 = np.array([0, 0, 1.0])
    n2 = np.array([np.sin(0.02), 0, np.cos(0.02)])
    assert C.face_pair_test(n1, n2, n1, n1, C.face_pair_epsilon(0.011, 0.011))
    assert not C.face_pair_test(n1, n2, n1, n1, C.face_pair_epsilon(0.009, 0.009))


def test_edge_position_test_contains_the_interval():
    # model edge of length 10 starting 2 before the meeting point; data interval inside / outside
    assert C.edge_position_test(s_d=1.5, l_d=3.0, s_m=2.0, l_m=10.0, eps=0.01)
    assert not C.edge_position_test(s_d=2.5, l_d=1.0, s_m=2.0, l_m=10.0, eps=0.01)  # starts before the model
    assert not C.edge_position_test(s_d=1.0, l_d=9.5, s_m=2.0, l_m=10.0, eps=0.01)  # runs past the end
    # a vertex at p: tight
    assert C.edge_position_test(2.0, 1.0, 2.0, 10.0, 0.01, start_at_vertex=True)
    assert not C.edge_position_test(1.5, 1.0, 2.0, 10.0, 0.01, start_at_vertex=True)


def test_edge_position_epsilon_bounds_the_closest_approach_of_skew_lines():
    """Errors at their bounds (each line offset by ρ and tilted by β about its p) move the closest approach along
    line 1 by no more than ε − λ; for skew lines the tilt out of the plane of the two directions moves it by
    ``h β / sin² θ``, more than the terms without the skew distance allow."""
    rng = _rng(7)
    rho, beta, h, theta = 0.6e-3, np.deg2rad(0.9), 0.08, np.deg2rad(31.5)
    b1, b2 = np.array([1.0, 0, 0]), np.array([np.cos(theta), np.sin(theta), 0])
    p1, p2 = np.array([-0.004, 0, 0]), np.array([0, 0, h]) - 0.01 * b2
    s1, s2 = C.closest_approach(p1, b1, p2, b2)
    sin_min = C.min_sine(theta, beta, beta)
    eps = C.edge_position_epsilon(s1, s2, sin_min, 0.0, rho, rho, beta, beta, h)
    without_skew = C.edge_position_epsilon(s1, s2, sin_min, 0.0, rho, rho, beta, beta)
    worst = 0.0
    for _ in range(300):
        q = []
        for p, b in ((p1, b1), (p2, b2)):
            tilt = _unit(np.cross(b, rng.normal(size=3)))
            off = _unit(np.cross(b, rng.normal(size=3)))
            q += [p + rho * off, np.cos(beta) * b + np.sin(beta) * tilt]
        worst = max(worst, abs(C.closest_approach(*q)[0] - s1))
    assert worst < eps
    assert worst > without_skew


def test_parallel_order_for_two_intervals_on_one_edge():
    # same model edge (x_m = 0, lengths 10): two data intervals of length 2 at most 8 apart either way
    assert C.parallel_order_test(7.9, 2.0, 2.0, 0.0, 10.0, 10.0, 0.01)
    assert not C.parallel_order_test(8.2, 2.0, 2.0, 0.0, 10.0, 10.0, 0.01)
    assert not C.parallel_order_test(-8.2, 2.0, 2.0, 0.0, 10.0, 10.0, 0.01)


def _edge_pair(box, e1, e2, sense1, sense2, s1, s2, l1, l2):
    """Model edges aligned by sense, and exact data intervals at parameters s along them."""
    out = []
    for e, sense, s, length in ((e1, sense1, s1, l1), (e2, sense2, s2, l2)):
        p = box.edge_points[e] if sense > 0 else box.vertices[box.edges[e, 1]]
        b = sense * box.edge_directions[e]
        out.append((p, b, box.edge_lengths[e], p + s * b, length))
    return out


@pytest.mark.parametrize("seed", range(5))
def test_edge_pair_tests_pass_for_true_data_under_any_rigid_motion(seed):
    rng = _rng(seed)
    model = load_library()["WEDGE01"]
    pose = SE3.random(rng, 0.2)
    for _ in range(30):
        e1, e2 = rng.choice(model.n_edges, 2, replace=False)
        s1 = rng.uniform(0, 0.5) * model.edge_lengths[e1]
        s2 = rng.uniform(0, 0.5) * model.edge_lengths[e2]
        sense1, sense2 = rng.choice([-1, 1], 2)
        (pm1, bm1, lm1, pd1, ld1), (pm2, bm2, lm2, pd2, ld2) = _edge_pair(
            model, e1, e2, sense1, sense2, s1, s2, 0.3 * model.edge_lengths[e1], 0.3 * model.edge_lengths[e2]
        )
        ok = C.edge_pair_tests(
            pose.apply(pd1), pose.rotate(bm1), ld1, pose.apply(pd2), pose.rotate(bm2), ld2,
            pm1, bm1, lm1, pm2, bm2, lm2, 1e-6, 1e-6, 1e-7, 1e-7, 1e-7, 1e-7,
        )  # fmt: skip
        assert ok


def test_edge_pair_tests_reject_a_shifted_interval():
    model = load_library()["BOX01"]
    (pm1, bm1, lm1, pd1, ld1), (pm2, bm2, lm2, pd2, ld2) = _edge_pair(model, 0, 1, 1, 1, 0.01, 0.01, 0.005, 0.005)
    args = (1e-4, 1e-4, 1e-5, 1e-5, 1e-5, 1e-5)
    assert C.edge_pair_tests(pd1, bm1, ld1, pd2, bm2, ld2, pm1, bm1, lm1, pm2, bm2, lm2, *args)
    # slide data edge 1 beyond its model edge's end
    far = pd1 + 0.2 * bm1
    assert not C.edge_pair_tests(far, bm1, ld1, pd2, bm2, ld2, pm1, bm1, lm1, pm2, bm2, lm2, *args)


def test_skew_distance_changes_sign_under_reflection():
    p1, b1 = np.zeros(3), np.array([1.0, 0, 0])
    p2, b2 = np.array([0, 0, 1.0]), np.array([0, 1.0, 0])
    d = C.skew_distance(p1, b1, p2, b2)
    m = np.array([-1.0, 1, 1])
    assert d * C.skew_distance(p1 * m, b1 * m, p2 * m, b2 * m) < 0
    assert C.skew_distance_test(d, d + 0.001, 0.002) and not C.skew_distance_test(d, -d, 0.002)


def test_vertex_edge_test_fixes_the_end():
    # edge along x from the vertex at the origin, model length 10; data interval [2, 3]
    v = np.zeros(3)
    p, b = np.array([2.0, 0, 0]), np.array([1.0, 0, 0])
    t_start, h_start = 0.0, 0.0
    assert C.vertex_edge_test(v, 0.01, p, b, 1.0, 0.01, 0.01, 0.001, t_start, h_start, 10.0)
    # if the vertex were the model edge's end, the interval would lie beyond it
    assert not C.vertex_edge_test(v, 0.01, p, b, 1.0, 0.01, 0.01, 0.001, 10.0, 0.0, 10.0)


def test_vertex_pair_and_face_tests():
    assert C.vertex_pair_test(np.zeros(3), np.array([1.0, 0, 0]), 0.01, 0.01, np.zeros(3), np.array([0, 1.005, 0]))
    assert not C.vertex_pair_test(np.zeros(3), np.array([1.0, 0, 0]), 0.001, 0.001, np.zeros(3), np.array([0, 1.1, 0]))
    n = np.array([0, 0, 1.0])
    assert C.vertex_face_test(np.array([0, 0, 2.0]), 0.01, n, np.zeros(3), 0.01, 0.001, n, 1.0, np.array([5, 5, 3.0]))
    assert not C.vertex_face_test(
        np.array([0, 0, 2.5]), 0.01, n, np.zeros(3), 0.01, 0.001, n, 1.0, np.array([0, 0, 3.0])
    )
