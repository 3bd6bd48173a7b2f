"""The shipped library: counts, Euler characteristic, orientation, symmetry, round trips."""

import numpy as np
import pytest

from haptic.geometry import (
    are_congruent,
    convex_decomposition,
    load_library,
    load_model,
    save_model,
    symmetry_group,
)
from haptic.geometry.se3 import random_rotation

LIB = load_library()

# name: (V, E, F, genus) — counted by hand from the designs in assets/models/README.md
EXPECTED = {
    "BOX01": (8, 12, 6, 0),
    "WEDGE01": (6, 9, 5, 0),
    "BOX01N": (16, 24, 10, 0),
    "BOX01P": (16, 24, 10, 0),
    "PYR01": (5, 8, 5, 0),
    "TETRA01L": (4, 6, 4, 0),
    "TETRA01R": (4, 6, 4, 0),
    "HEXPRISM01": (12, 18, 8, 0),
    "LBLOCK01": (12, 18, 8, 0),
    "FRAME01": (16, 32, 16, 1),
}


def test_library_holds_the_expected_models():
    assert set(LIB) == set(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_counts_and_euler_characteristic(name):
    m = LIB[name]
    v, e, f, g = EXPECTED[name]
    assert (m.n_vertices, m.n_edges, m.n_faces) == (v, e, f)
    assert m.euler_characteristic == 2 - 2 * g
    assert m.genus == g


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_face_normals_point_outward(name):
    m = LIB[name]
    assert m.volume > 0
    # a point just outside each face's centre is outside the solid, just inside is inside
    for f, loop in enumerate(m.faces):
        tri = m.vertices[m.triangles[m.triangle_faces == f][0]]
        c = tri.mean(axis=0)
        n = m.face_normals[f]
        assert not m.contains(c + 1e-4 * n)[0], f"face {f} of {name} points inward"
        assert m.contains(c - 1e-4 * n)[0], f"face {f} of {name} points inward"
        assert np.allclose(m.vertices[list(loop)] @ n, m.face_offsets[f], atol=1e-9)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_winged_edge_adjacency_is_consistent(name):
    m = LIB[name]
    for e, (a, b) in enumerate(m.edges):
        left, right = m.edge_faces(e)
        assert e in m.face_edges[left] and e in m.face_edges[right]
        loop_l, loop_r = m.faces[left], m.faces[right]
        # left face runs source -> dest, right face dest -> source
        assert any(loop_l[k] == a and loop_l[(k + 1) % len(loop_l)] == b for k in range(len(loop_l)))
        assert any(loop_r[k] == b and loop_r[(k + 1) % len(loop_r)] == a for k in range(len(loop_r)))
        assert e in m.vertex_edges[a] and e in m.vertex_edges[b]
    for v, faces in enumerate(m.vertex_faces):
        assert len(faces) == len(m.vertex_edges[v]) >= 3


def test_notched_and_bumped_boxes_differ_in_concave_edges():
    n_concave = {k: int((LIB[k].edge_convexity < 0).sum()) for k in ("BOX01", "BOX01N", "BOX01P")}
    assert n_concave == {"BOX01": 0, "BOX01N": 2, "BOX01P": 2}
    assert not LIB["BOX01N"].is_convex and not LIB["BOX01P"].is_convex and LIB["BOX01"].is_convex
    # the notch's concave edges run along its floor, the bump's along its foot
    zn = LIB["BOX01N"].vertices[LIB["BOX01N"].edges[LIB["BOX01N"].edge_convexity < 0]][:, :, 2]
    zp = LIB["BOX01P"].vertices[LIB["BOX01P"].edges[LIB["BOX01P"].edge_convexity < 0]][:, :, 2]
    assert np.allclose(zn, 0.040) and np.allclose(zp, 0.060)


@pytest.mark.parametrize(
    "name,order",
    [("BOX01", 4), ("TETRA01L", 1), ("TETRA01R", 1), ("HEXPRISM01", 12), ("PYR01", 2), ("WEDGE01", 1),
     ("FRAME01", 8), ("LBLOCK01", 1)],
)
def test_symmetry_group_order(name, order):
    group = symmetry_group(LIB[name])
    assert len(group) == order
    assert np.allclose(group[0].rotation, np.eye(3))
    for s in group:
        assert np.isclose(np.linalg.det(s.rotation), 1.0)
        assert np.allclose(s.apply(LIB[name].centroid), LIB[name].centroid, atol=1e-9)


def test_cube_has_24_symmetries():
    from haptic.geometry.shapes import box

    assert len(symmetry_group(box(0.05, 0.05, 0.05))) == 24


def test_mirror_tetrahedra_are_not_related_by_any_rotation():
    left, right = LIB["TETRA01L"], LIB["TETRA01R"]
    assert not are_congruent(left, right)
    assert not are_congruent(right, left)
    assert np.allclose(sorted(left.edge_lengths), sorted(right.edge_lengths))  # same shape, mirrored
    rng = np.random.default_rng(3)
    r = random_rotation(rng)
    assert are_congruent(left, left.transformed(r, [0.1, -0.2, 0.05]))


@pytest.mark.parametrize("name", sorted(EXPECTED))
@pytest.mark.parametrize("suffix", [".json", ".obj", ".stl", ".ply"])
def test_round_trip_export_import(name, suffix, tmp_path):
    m = LIB[name]
    back = load_model(save_model(m, tmp_path / f"{name}{suffix}"))
    assert (back.n_vertices, back.n_edges, back.n_faces) == (m.n_vertices, m.n_edges, m.n_faces)
    assert np.isclose(back.volume, m.volume, rtol=1e-6)
    assert are_congruent(m, back)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_convex_decomposition_is_exact(name):
    from scipy.spatial import ConvexHull

    m = LIB[name]
    pieces = convex_decomposition(m)
    assert (len(pieces) == 1) == m.is_convex
    total = sum(ConvexHull(p).volume for p in pieces)
    assert np.isclose(total, m.volume, rtol=1e-6)
    # every piece is inside the solid: its centroid and its vertices nudged toward the centroid
    for p in pieces:
        c = p.mean(axis=0)
        assert m.contains(c + 0.98 * (p - c)).all()


def test_lookalike_library_has_30_or_more_pairwise_distinct_models():
    from pathlib import Path

    lib = load_library(Path(__file__).resolve().parents[2] / "assets" / "libraries" / "lookalike")
    assert len(lib) >= 30
    names = sorted(lib)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            assert not are_congruent(lib[a], lib[b]), (a, b)


def test_shipped_files_are_what_the_generator_makes():
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    r = subprocess.run([sys.executable, str(root / "scripts" / "make_models.py"), "--check"], capture_output=True)
    assert r.returncode == 0, r.stderr.decode()


def _merge_every_pair_afresh(pieces):
    """The greedy merge tried over every pair after each merge (what the decomposition's merge must equal)."""
    from haptic.geometry.decompose import _hull_vertices, _volume

    pieces = list(pieces)
    merged = True
    while merged:
        merged = False
        for i in range(len(pieces)):
            for j in range(i + 1, len(pieces)):
                union = np.vstack([pieces[i], pieces[j]])
                hv = _volume(union)
                if abs(hv - _volume(pieces[i]) - _volume(pieces[j])) <= 1e-9 * max(hv, 1e-12):
                    pieces[i] = _hull_vertices(union)
                    del pieces[j]
                    merged = True
                    break
            if merged:
                break
    return pieces


def test_decomposition_merge_tries_a_pair_once_and_still_merges_alike():
    """Merging the unit cubes of a 3 x 2 x 1 block with one cube taken out: the merge that skips the pairs it
    already found apart gives the same pieces, in the same order, as the one that tries every pair again."""
    from haptic.geometry.decompose import _merge

    cube = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    cells = [cube + [i, j, 0.0] for i in range(3) for j in range(2) if (i, j) != (1, 1)]
    fast, slow = _merge(cells), _merge_every_pair_afresh(cells)
    assert 1 < len(fast) < len(cells)
    assert len(fast) == len(slow)
    assert all(np.array_equal(a, b) for a, b in zip(fast, slow, strict=True))


@pytest.mark.parametrize("name", ["FRAME01", "LBLOCK01", "TETRA01L"])
def test_contains_outside_the_box_is_the_winding_numbers_verdict(name):
    """The inside test skips the winding number outside the bounding box: the same verdict on every point."""
    m = LIB[name]
    lo, hi = m.vertices.min(axis=0), m.vertices.max(axis=0)
    pts = (lo + hi) / 2 + (np.random.default_rng(3).random((4000, 3)) - 0.5) * 1.6 * (hi - lo)
    inside = m.contains(pts)
    assert 0 < inside.sum() < len(pts) and not inside[((pts < lo) | (pts > hi)).any(axis=1)].any()
    assert np.array_equal(inside, m._winding_inside(pts))
