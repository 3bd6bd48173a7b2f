"""Lines against polyhedra: first contact, inside intervals and depth, checked against independent geometry."""

import numpy as np
import pytest

from haptic.geometry import SE3, load_library
from haptic.geometry.distance import surface_distance
from haptic.geometry.raycast import inside_intervals, line_hits, segment_depth
from haptic.geometry.shapes import box

LIB = load_library()


def test_box_first_contact_face_and_depth():
    b = box(0.1, 0.06, 0.04)  # [0, 0.1] x [0, 0.06] x [0, 0.04]
    starts = np.array([[0.05, 0.03, 0.2], [0.3, 0.02, 0.01], [0.05, 0.03, 0.2]])
    dirs = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    h = line_hits(b, starts, dirs)
    assert h.first[:2] == pytest.approx([0.16, 0.2])
    assert np.isinf(h.first[2]) and h.face[2] == -1
    assert b.face_normals[h.face[0]] @ [0, 0, 1] == pytest.approx(1.0)
    assert b.face_normals[h.face[1]] @ [1, 0, 0] == pytest.approx(1.0)
    assert inside_intervals(b, starts[0], dirs[0], 0.4) == [pytest.approx((0.16, 0.2))]
    assert segment_depth(b, starts[0], dirs[0], 0.4) == pytest.approx(0.02)  # the box's half height
    assert segment_depth(b, starts[0], dirs[0], 0.17) == pytest.approx(0.01)  # stops 1 cm into the top
    assert segment_depth(b, starts[0], dirs[0], 0.15) == 0.0


def _first_inside_by_bisection(poly, start, u, length, steps=4000):
    """Independent: march the line with the winding-number inside test, then bisect the first crossing."""
    ts = np.linspace(0.0, length, steps)
    inside = poly.contains(start + ts[:, None] * u)
    if not inside.any():
        return np.inf
    k = int(np.argmax(inside))
    lo, hi = ts[max(k - 1, 0)], ts[k]
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if poly.contains((start + mid * u)[None])[0] else (mid, hi)
    return hi


@pytest.mark.parametrize("name", sorted(LIB))
def test_first_contact_matches_marching_on_the_seed_library(name):
    poly = LIB[name]
    rng = np.random.default_rng(7)
    c = poly.centroid
    radius = float(np.linalg.norm(poly.vertices - c, axis=1).max())
    for _ in range(6):
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        aim = c + rng.uniform(-0.6, 0.6, 3) * radius
        start = aim - 2 * radius * u
        h = line_hits(poly, start[None], u[None])
        t_ref = _first_inside_by_bisection(poly, start, u, 4 * radius)
        if np.isinf(t_ref):
            # no inside point found: the line misses, or only grazes within the march step
            assert np.isinf(h.first[0]) or segment_depth(poly, start, u, 4 * radius) < 4 * radius / 4000
            continue
        assert h.first[0] == pytest.approx(t_ref, abs=1e-6)
        # the face reported is the surface at that point: its plane passes through it
        p = start + h.first[0] * u
        f = h.face[0]
        assert abs(poly.face_normals[f] @ p - poly.face_offsets[f]) < 1e-9
        assert surface_distance(poly, p[None])[0] < 1e-9


def test_depth_is_invariant_under_rigid_motion():
    poly = LIB["LBLOCK01"]
    rng = np.random.default_rng(3)
    t = SE3.random(rng, 0.1)
    moved = poly.transformed(t.rotation, t.translation)
    start, u = poly.centroid - np.array([0.2, 0.01, 0.0]), np.array([1.0, 0.0, 0.0])
    a = segment_depth(poly, start, u, 0.4)
    b = segment_depth(moved, t.apply(start), t.rotate(u), 0.4)
    assert a > 0.0 and a == pytest.approx(b, abs=1e-9)


def test_many_segments_at_once_sample_as_one_at_a_time():
    from haptic.geometry.raycast import depth_samples, depth_samples_many

    rng = np.random.default_rng(5)
    for name in ("BOX01", "LBLOCK01", "FRAME01"):
        poly = load_library()[name]
        c = poly.centroid
        starts = c + rng.normal(scale=0.03, size=(12, 3))
        dirs = rng.normal(size=(12, 3))
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        lengths = rng.uniform(0.01, 0.15, size=12)
        many = depth_samples_many(poly, starts, dirs, lengths)
        inside = 0
        for k, (pts, depth) in enumerate(many):
            one_pts, one_depth = depth_samples(poly, starts[k], dirs[k], lengths[k])
            assert np.allclose(pts, one_pts) and np.allclose(depth, one_depth)
            inside += len(depth) > 0
        assert inside >= 2, name


def test_each_samples_depth_is_within_its_bound_from_the_crossings():
    """:func:`sample_inside_many` takes the samples of :func:`depth_samples_many`, and no sample lies deeper than
    its distance along the segment from a crossing of the surface (a bound that is finite wherever an inside
    interval ends at a crossing)."""
    from haptic.geometry.raycast import depth_samples_many, sample_inside_many

    rng = np.random.default_rng(6)
    finite = 0
    for name in ("BOX01", "LBLOCK01", "FRAME01", "WEDGE01"):
        poly = load_library()[name]
        starts = poly.centroid + rng.normal(scale=0.05, size=(40, 3))
        dirs = rng.normal(size=(40, 3))
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        lengths = rng.uniform(0.005, 0.2, size=40)
        for (pts, depth), (pts2, upper) in zip(depth_samples_many(poly, starts, dirs, lengths),
                                               sample_inside_many(poly, starts, dirs, lengths), strict=True):
            np.testing.assert_array_equal(pts, pts2)
            assert (depth <= upper).all()
            finite += int(np.isfinite(upper).sum())
    assert finite > 100
