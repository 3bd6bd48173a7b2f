"""Perturbed variants of library models (objects close to a model but not in the library)."""

import numpy as np
import pytest

from haptic.errors import ModelError
from haptic.geometry import load_library
from haptic.geometry.distance import surface_distance
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


@pytest.mark.parametrize("name", ["BOX01N", "BOX01P"])
def test_a_slot_or_step_corner_moves_tilting_its_end_faces_triangles_at_it(name):
    """The inner corners of BOX01N's slot and BOX01P's step are reflex on the end faces (their corner triangle lies
    off the face). Triangulated whole, an end face left coplanar neighbours and the move was refused at every such
    corner, so the benchmarks never moved one. Now the end face's triangles at the corner tilt, the rest of it
    stays one face per piece in its plane, and the variant differs from the model only on the triangles at the
    corner."""
    p = LIB[name]
    reflex = [v for v in range(p.n_vertices) if any(
        float(np.cross(p.vertices[v] - p.vertices[lp[lp.index(v) - 1]],
                       p.vertices[lp[(lp.index(v) + 1) % len(lp)]] - p.vertices[v]) @ p.face_normals[f]) < 0
        for f, lp in enumerate(p.faces) if v in lp)]  # fmt: skip
    assert len(reflex) == 4
    for v in reflex:
        for mm in (2, 4, 8):
            q = move_vertex(p, v, mm * 1e-3)
            w = int(np.argmin(np.linalg.norm(q.vertices - (p.vertices[v] + mm * 1e-3 * vertex_normal(p, v)), axis=1)))
            assert np.linalg.norm(q.vertices[w] - p.vertices[v]) > 1e-3
            for f, loop in enumerate(q.faces):
                if w in loop:
                    continue
                pts = q.vertices[list(loop)]
                assert np.all(surface_distance(p, np.vstack([pts, pts.mean(axis=0)])) < 1e-9), (v, mm, f)
            assert q.volume > p.volume


def test_a_reflex_corners_fan_and_the_rest_of_its_face_cover_the_face():
    """BOX01N's front face split at its slot's corner: triangles at the corner, and the rest in pieces whose loops
    turn as the face's, the areas adding up to the face's."""
    from haptic.geometry.perturb import reflex_fan

    p = LIB["BOX01N"]
    f = next(f for f, lp in enumerate(p.faces) if len(lp) == 8)
    n = p.face_normals[f]

    def area(loop):
        pts = p.vertices[list(loop)]
        return 0.5 * float(sum(np.cross(pts[k], pts[(k + 1) % len(pts)]) for k in range(len(pts))) @ n)

    for v in p.faces[f]:
        fan, rest = reflex_fan(p.vertices, p.faces[f], n, v)
        assert fan and all(v in t for t in fan) and all(v not in lp for lp in rest)
        assert all(area(x) > 0 for x in (*fan, *rest))
        assert abs(sum(area(x) for x in (*fan, *rest)) - area(p.faces[f])) < 1e-12


@pytest.mark.parametrize("suffix", [".obj", ".json"])
def test_a_model_scaled_up_keeps_its_sources_rounding_and_is_written_so(tmp_path, suffix):
    # the dodecahedron of the public polyhedra, written to 0.5 µm at 30 mm, has a face 0.3 µm off its plane; scaled
    # to 150 mm that face is 1.6 µm off, more than the tolerance of a model as precise as a nanometre: it was
    # refused as not planar when scaled, and so was the file written of it when read back
    from haptic.geometry.io import load_model, save_model
    from haptic.geometry.perturb import scaled_to

    small = load_library("assets/libraries/polyhedra")["dodecahedron"]
    assert small.precision > 0
    big = scaled_to(small, 0.15)
    assert big.precision == pytest.approx(small.precision * 0.15 / float(np.max(small.extents)))
    back = load_model(save_model(big, tmp_path / f"dodecahedron{suffix}"))
    assert back.precision >= big.precision
    assert back.n_faces == small.n_faces and np.max(back.extents) == pytest.approx(0.15, abs=1e-5)
    longer = scale_dimension(small, 2, 5.0)
    assert longer.precision == pytest.approx(5.0 * small.precision)
