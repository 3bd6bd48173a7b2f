"""Formula solids: counts, symmetry orders, determinism and validation."""

import numpy as np
import pytest

from haptic.errors import ModelError
from haptic.geometry import symmetry_group
from haptic.geometry.shapes import (
    PLATONIC,
    antiprism,
    bipyramid,
    convex_hull,
    l_bracket,
    platonic,
    random_convex_hull,
    regular_prism,
    slotted_block,
    stepped_block,
    trapezohedron,
)

# kind: (V, E, F, order of the rotation group)
PLATONIC_COUNTS = {
    "tetrahedron": (4, 6, 4, 12),
    "cube": (8, 12, 6, 24),
    "octahedron": (6, 12, 8, 24),
    "dodecahedron": (20, 30, 12, 60),
    "icosahedron": (12, 30, 20, 60),
}


def _counts(m):
    return m.n_vertices, m.n_edges, m.n_faces, len(symmetry_group(m))


@pytest.mark.parametrize("kind", PLATONIC)
def test_platonic_solids(kind):
    m = platonic(kind, 0.05)
    assert _counts(m) == PLATONIC_COUNTS[kind]
    assert np.allclose(np.linalg.norm(m.vertices, axis=1), 0.05)
    assert m.is_convex


@pytest.mark.parametrize("n", [3, 5, 8, 12])
def test_dihedral_families(n):
    # a right prism, antiprism, bipyramid and trapezohedron on an n-gon all have the rotation group D_n
    assert _counts(regular_prism(n, 0.04, 0.03)) == (2 * n, 3 * n, n + 2, 2 * n)
    assert _counts(antiprism(n, 0.04, 0.03)) == (2 * n, 4 * n, 2 * n + 2, 2 * n)
    assert _counts(bipyramid(n, 0.04, 0.03)) == (n + 2, 3 * n, 2 * n, 2 * n)
    assert _counts(trapezohedron(n, 0.04, 0.01)) == (2 * n + 2, 4 * n, 2 * n, 2 * n)


def test_trapezohedron_faces_are_kites():
    m = trapezohedron(5, 0.04, 0.01)
    assert all(len(f) == 4 for f in m.faces)


def test_convex_hull_drops_inner_points_and_merges_coplanar_triangles():
    corners = np.array([(x, y, z) for x in (0, 0.1) for y in (0, 0.08) for z in (0, 0.06)], dtype=float)
    extra = np.array([(0.05, 0.04, 0.03), (0.05, 0.04, 0.0), (0.05, 0.0, 0.0)])  # inside, on a face, on an edge
    m = convex_hull(np.vstack([corners, extra]))
    assert (m.n_vertices, m.n_edges, m.n_faces) == (8, 12, 6)
    assert m.volume == pytest.approx(0.1 * 0.08 * 0.06)


def test_convex_hull_of_flat_points_is_refused():
    with pytest.raises(ModelError, match="span no solid"):
        convex_hull([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)])


def test_random_convex_hull_is_seeded_and_well_shaped():
    a = random_convex_hull(np.random.default_rng(7), 12, 0.04)
    b = random_convex_hull(np.random.default_rng(7), 12, 0.04)
    assert np.array_equal(a.vertices, b.vertices) and a.faces == b.faces
    assert a.n_vertices == 12 and a.edge_lengths.min() >= 0.04 / 5
    cos_turn = np.einsum("ij,ij->i", a.face_normals[a.edge_left_face], a.face_normals[a.edge_right_face])
    assert cos_turn.max() <= np.cos(np.radians(10))
    assert len(symmetry_group(a)) == 1


def test_cad_like_parts():
    assert _counts(stepped_block(0.1, 0.06, 0.06)) == (12, 18, 8, 1)
    assert _counts(stepped_block(0.1, 0.06, 0.06, steps=3)) == (16, 24, 10, 1)
    assert _counts(l_bracket(0.08, 0.08, 0.02, 0.05)) == (12, 18, 8, 2)  # equal legs: a half turn swaps them
    assert _counts(l_bracket(0.08, 0.06, 0.02, 0.05)) == (12, 18, 8, 1)
    assert _counts(slotted_block(0.1, 0.06, 0.05, 0.03, 0.02)) == (16, 24, 10, 2)
    for m in (
        stepped_block(0.1, 0.06, 0.06),
        l_bracket(0.08, 0.06, 0.02, 0.05),
        slotted_block(0.1, 0.06, 0.05, 0.03, 0.02),
    ):
        assert not m.is_convex and m.volume > 0


def test_unknown_platonic_kind_names_the_valid_ones():
    with pytest.raises(ModelError, match="valid: tetrahedron, cube"):
        platonic("cuboctahedron", 0.05)
