"""Perturbed variants of library models (objects close to a model but not in the library)."""

import numpy as np
import pytest

from haptic.errors import ModelError
from haptic.geometry import load_library
from haptic.geometry.perturb import chamfer_edge, move_vertex, scale_dimension, vertex_normal
from haptic.geometry.shapes import box

LIB = load_library()


def test_scale_dimension_changes_one_extent():
    b = LIB["BOX01"]
    s = scale_dimension(b, 0, 1.03)
    assert np.allclose(s.extents, b.extents * [1.03, 1, 1])
    assert s.n_faces == b.n_faces and np.isclose(s.volume, 1.03 * b.volume)
    with pytest.raises(ModelError, match="axis 0, 1 or 2"):
        scale_dimension(b, 3, 1.0)


@pytest.mark.parametrize("name", sorted(LIB))
def test_move_vertex_moves_only_that_vertex(name):
    p = LIB[name]
    for v in range(p.n_vertices):
        try:
            q = move_vertex(p, v, 0.004)
        except ModelError:
            continue  # a vertex the move would make invalid (the benchmark takes another)
        target = p.vertices[v] + 0.004 * vertex_normal(p, v)
        assert np.linalg.norm(q.vertices - target, axis=1).min() < 1e-12
        others = [x for i, x in enumerate(p.vertices) if i != v]
        assert all(np.linalg.norm(q.vertices - x, axis=1).min() < 1e-12 for x in others)
        assert q.n_faces >= p.n_faces
        return
    pytest.fail(f"no vertex of {name} could be moved")


def test_move_box_corner_splits_its_three_faces():
    b = box(0.1, 0.08, 0.06)
    q = move_vertex(b, 0, 0.004)
    assert q.n_faces == 9 and q.volume > b.volume


def test_chamfer_removes_the_edge_and_adds_a_face():
    b = box(0.1, 0.08, 0.06)
    e = int(np.argmax(b.edge_lengths))
    q = chamfer_edge(b, e, 0.004)
    assert q.n_faces == 7 and q.n_vertices == 10
    assert np.isclose(b.volume - q.volume, 0.5 * 0.004 * 0.004 * b.edge_lengths[e])


def test_chamfer_too_large_is_refused():
    b = box(0.1, 0.08, 0.006)
    with pytest.raises(ModelError, match="chamfer"):
        chamfer_edge(b, int(np.argmax(b.edge_lengths)), 0.01)


def test_a_corner_whose_triangle_holds_another_vertex_is_refused():
    """LBLOCK01's corner 0 lies on the L-shaped bottom: its corner triangle (1, 0, 5) spans the L's notch and holds
    vertex 3, so cutting it off would leave the rest of the bottom crossing itself. The move is refused (the
    benchmarks take another vertex); a corner whose triangle stays inside its faces moves."""
    lblock = LIB["LBLOCK01"]
    with pytest.raises(ModelError, match=r"corner triangle \(1, 0, 5\) off face 0, which holds vertex 3"):
        move_vertex(lblock, 0, 0.004)
    q = move_vertex(lblock, 2, 0.004)
    assert q.n_faces == lblock.n_faces + 3 and q.volume > lblock.volume
