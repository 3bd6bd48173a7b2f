"""Triangulated meshes merge back into polygonal faces; bad input is refused with one clear line."""

import json

import numpy as np
import pytest
import trimesh

from haptic.errors import ModelError
from haptic.geometry import load_library, load_model, polyhedron_from_triangles
from haptic.geometry.shapes import regular_prism


def test_triangulated_icosahedron_has_20_faces(tmp_path):
    mesh = trimesh.creation.icosahedron()
    mesh.apply_scale(0.05)
    path = tmp_path / "ico.stl"
    mesh.export(path)
    m = load_model(path)
    assert (m.n_vertices, m.n_edges, m.n_faces) == (12, 30, 20)
    assert m.is_convex


def test_triangulated_octagonal_prism_has_10_faces(tmp_path):
    prism = regular_prism(8, 0.04, 0.05)
    path = tmp_path / "oct.ply"
    prism.to_trimesh().export(path)
    m = load_model(path)
    assert (m.n_vertices, m.n_faces) == (16, 10)


def test_triangulated_notched_box_keeps_its_faces(tmp_path):
    box_n = load_library()["BOX01N"]
    path = tmp_path / "box01n.stl"
    box_n.to_trimesh().export(path)  # binary STL: no shared vertices, every face triangulated
    m = load_model(path)
    assert (m.n_vertices, m.n_edges, m.n_faces) == (box_n.n_vertices, box_n.n_edges, box_n.n_faces)


def test_polygonal_obj_faces_are_kept(tmp_path):
    path = tmp_path / "cube.obj"
    path.write_text(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
        "f 4 3 2 1\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"
    )
    m = load_model(path)
    assert m.n_faces == 6 and all(len(f) == 4 for f in m.faces)


def _native(tmp_path, vertices, faces, name="bad.json"):
    p = tmp_path / name
    p.write_text(json.dumps({"vertices": vertices, "faces": faces}))
    return p


CUBE_V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
CUBE_F = [[3, 2, 1, 0], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]


def test_valid_cube_loads(tmp_path):
    m = load_model(_native(tmp_path, CUBE_V, CUBE_F, "cube.json"))
    assert m.n_faces == 6 and m.name == "cube"


def _expect(path, *words):
    with pytest.raises(ModelError) as info:
        load_model(path)
    msg = str(info.value)
    assert "\n" not in msg
    assert str(path.name) in msg
    for w in words:
        assert w in msg, msg
    return msg


def test_missing_file(tmp_path):
    _expect(tmp_path / "nope.obj", "no such file")


def test_empty_file(tmp_path):
    p = tmp_path / "empty.stl"
    p.write_text("")
    _expect(p, "empty")


def test_unknown_extension(tmp_path):
    p = tmp_path / "model.xyz"
    p.write_text("1 2 3")
    msg = _expect(p, "unknown model file extension")
    assert ".obj" in msg and ".json" in msg


def test_nan_coordinates(tmp_path):
    v = [list(x) for x in CUBE_V]
    v[5] = [float("nan"), 0, 1]
    p = tmp_path / "nan.json"
    p.write_text(json.dumps({"vertices": v, "faces": CUBE_F}).replace("NaN", "NaN"))
    _expect(p, "vertex 5", "non-finite")


def test_nan_in_mesh_file(tmp_path):
    p = tmp_path / "nan.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n")
    _expect(p, "non-finite")


def test_open_mesh(tmp_path):
    _expect(_native(tmp_path, CUBE_V, CUBE_F[:-1], "open.json"), "open")


def test_open_triangle_mesh(tmp_path):
    mesh = trimesh.creation.box()
    mesh.update_faces(np.arange(len(mesh.faces)) != 0)
    p = tmp_path / "open.stl"
    mesh.export(p)
    _expect(p, "open")


def test_non_planar_quad(tmp_path):
    v = [list(x) for x in CUBE_V]
    v[6] = [1, 1, 1.2]
    _expect(_native(tmp_path, v, CUBE_F, "warped.json"), "not planar")


def test_non_planar_quad_in_obj(tmp_path):
    p = tmp_path / "warped.obj"
    v = [list(x) for x in CUBE_V]
    v[6] = [1, 1, 1.2]
    p.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in v) + "".join(
        "f " + " ".join(str(i + 1) for i in f) + "\n" for f in CUBE_F))
    _expect(p, "not planar")


def test_duplicate_faces(tmp_path):
    _expect(_native(tmp_path, CUBE_V, CUBE_F + [CUBE_F[0]], "dup.json"), "duplicate")


def test_zero_length_edge(tmp_path):
    v = [list(x) for x in CUBE_V] + [[1, 1, 1]]  # vertex 8 coincides with vertex 6
    f = [list(x) for x in CUBE_F]
    f[1] = [4, 5, 6, 8, 7]
    _expect(_native(tmp_path, v, f, "zero.json"), "zero-length edge")


def test_non_manifold_edge(tmp_path):
    # two cubes sharing one edge -> four faces on that edge; a fin face makes three
    v = [list(x) for x in CUBE_V] + [[0.5, 0.5, 2.0]]
    f = [list(x) for x in CUBE_F] + [[6, 7, 8]]
    _expect(_native(tmp_path, v, f, "fin.json"), "non-manifold")


def test_non_manifold_edge_in_mesh(tmp_path):
    a = trimesh.creation.box(extents=(1, 1, 1))
    b = trimesh.creation.box(extents=(1, 1, 1))
    b.apply_translation((1, 1, 0))  # shares one vertical edge with a
    p = tmp_path / "twoboxes.stl"
    trimesh.util.concatenate([a, b]).export(p)
    _expect(p, "non-manifold")


def test_inconsistent_orientation(tmp_path):
    f = [list(x) for x in CUBE_F]
    f[2] = list(reversed(f[2]))
    _expect(_native(tmp_path, CUBE_V, f, "flip.json"), "orientation")


def test_inward_orientation(tmp_path):
    f = [list(reversed(x)) for x in CUBE_F]
    _expect(_native(tmp_path, CUBE_V, f, "inward.json"), "inward")


def test_not_json(tmp_path):
    p = tmp_path / "garbage.json"
    p.write_text("{not json")
    _expect(p, "not valid JSON")


def test_disconnected(tmp_path):
    v = [list(x) for x in CUBE_V] + [[x + 3, y, z] for x, y, z in CUBE_V]
    f = [list(x) for x in CUBE_F] + [[i + 8 for i in x] for x in CUBE_F]
    _expect(_native(tmp_path, v, f, "two.json"), "not connected")


def test_face_with_hole_in_mesh_is_refused():
    # a flat-topped square frame (genus 1): its top and bottom are planar faces with a hole
    corners = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    v = [(3 * x, 3 * y, z) for z in (0, 1) for x, y in corners] + [(x, y, z) for z in (0, 1) for x, y in corners]
    quads = []
    for i in range(4):
        j = (i + 1) % 4
        quads += [(i, j, 4 + j, 4 + i), (8 + j, 8 + i, 12 + i, 12 + j), (4 + i, 4 + j, 12 + j, 12 + i),
                  (j, i, 8 + i, 8 + j)]
    tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    with pytest.raises(ModelError, match="hole"):
        polyhedron_from_triangles(np.array(v, float), np.array(tris), name="flatframe")
