"""A model learned from its traced boundary (any convexity): exact from exact components, an episode that learns
a non-convex object to closure, and the matcher's bounds widened for a learned model."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import SE3, load_library, load_model, save_model
from haptic.geometry.perturb import move_vertex, scale_dimension
from haptic.geometry.polyhedron import LearnedBounds, Polyhedron
from haptic.geometry.se3 import quat_to_matrix
from haptic.geometry.shapes import l_bracket, slotted_block, stepped_block
from haptic.learning.boundary import boundary_estimate, boundary_model
from haptic.matching.components import DataEdge, DataFace, DataVertex
from haptic.matching.tree import InterpretationTree

NON_CONVEX = {
    "LBLOCK01": lambda: load_library()["LBLOCK01"],
    "FRAME01": lambda: load_library()["FRAME01"],
    "BOX01N": lambda: load_library()["BOX01N"],
    "l_bracket": lambda: l_bracket(0.06, 0.05, 0.015, 0.04),
    "stepped": lambda: stepped_block(0.08, 0.05, 0.06, steps=3),
    "slotted": lambda: slotted_block(0.08, 0.05, 0.04, 0.02, 0.02),
}


def exact_boundary(poly, pose: SE3, inset: float = 1e-3) -> dict:
    """Every face, edge and vertex of ``poly`` (posed) as noiseless data components with their adjacency: each
    edge traced from vertex to vertex with a point beside it on either face, each face touched at those points."""
    nf, ne = poly.n_faces, poly.n_edges
    side: dict[int, list[tuple[int, np.ndarray]]] = {}
    for e in range(ne):
        mid = poly.vertices[poly.edges[e]].mean(axis=0)
        for f in (int(poly.edge_left_face[e]), int(poly.edge_right_face[e])):
            w = np.cross(poly.face_normals[f], poly.edge_directions[e])
            side.setdefault(f, []).append((e, mid + inset * (w if int(poly.edge_left_face[e]) == f else -w)))
    comps = {}
    for f in range(nf):
        pts = pose.apply(np.array([q for _, q in side[f]]))
        comps[f] = DataFace(f, pose.rotate(poly.face_normals[f]), pts, 0.0, 0.0)
    for e in range(ne):
        s, d = (int(x) for x in poly.edges[e])
        fs = (int(poly.edge_left_face[e]), int(poly.edge_right_face[e]))
        sp = tuple((f, pose.apply(q)) for f in fs for ee, q in side[f] if ee == e)
        comps[nf + e] = DataEdge(nf + e, pose.rotate(poly.edge_directions[e]), pose.apply(poly.vertices[s]),
                                 float(poly.edge_lengths[e]), 0.0, 0.0, 0.0, start_vertex=nf + ne + s,
                                 end_vertex=nf + ne + d, adjacent=fs, side_points=sp)  # fmt: skip
    for v in range(poly.n_vertices):
        comps[nf + ne + v] = DataVertex(nf + ne + v, pose.apply(poly.vertices[v]), 0.0)
    return comps


def nearest(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2).min(axis=1)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(sorted(NON_CONVEX)))
def test_a_non_convex_model_from_its_exact_boundary_is_the_model(seed, name):
    model = NON_CONVEX[name]()
    assert not model.is_convex
    pose = SE3.random(np.random.default_rng(seed), translation_scale=0.1)
    est = boundary_estimate(exact_boundary(model, pose))
    assert est.closed, est.counts()
    learned = boundary_model(est, name)
    assert (learned.n_vertices, learned.n_edges, learned.n_faces) == (model.n_vertices, model.n_edges, model.n_faces)
    truth = pose.apply(model.vertices)
    assert nearest(learned.vertices, truth).max() < 1e-7 and nearest(truth, learned.vertices).max() < 1e-7
    assert learned.volume == pytest.approx(model.volume, rel=1e-6)


def test_an_edge_left_out_leaves_the_boundary_open():
    model = load_library()["LBLOCK01"]
    comps = exact_boundary(model, SE3.identity())
    e = model.n_faces + 3
    edge = comps[e]
    comps[e] = DataEdge(e, edge.direction, edge.point, 0.5 * edge.length, 0.0, 0.0, 0.0, start_vertex=edge.start_vertex,
                        adjacent=edge.adjacent, side_points=edge.side_points)  # fmt: skip
    est = boundary_estimate(comps)
    assert est.open_edges() and not est.closed


def test_a_vertex_fan_left_open_leaves_the_boundary_open():
    model = load_library()["LBLOCK01"]
    comps = exact_boundary(model, SE3.identity())
    del comps[model.n_faces + 5]  # one edge not measured: its two vertices' fans are open
    est = boundary_estimate(comps)
    assert est.unbalanced and not est.closed


@pytest.mark.parametrize("make", [
    lambda lib: scale_dimension(lib["LBLOCK01"], 0, 1.05, name="L_WIDE"),
    lambda lib: move_vertex(lib["FRAME01"], 15, 0.004, name="FRAME_MOVED"),
])  # fmt: skip
def test_an_episode_learns_a_non_convex_object_to_closure(make, tmp_path):
    """Geometric executor, noise 1: explored on after no-match until the boundary is closed; the learned model has
    the object's counts and lies within a millimetre of it."""
    truth = make(load_library())
    path = tmp_path / f"{truth.name}.json"
    save_model(truth, path)
    rec = run_episode(EpisodeSpec(model=str(path), seed=3, learn=str(tmp_path / "lib"), learn_name="LEARNED"))
    assert rec.outcome == "no-match"
    learned = rec.learned
    assert learned["status"] == "closed" and not learned["convex"], learned
    model = load_model(learned["path"])
    assert (model.n_vertices, model.n_edges, model.n_faces) == (truth.n_vertices, truth.n_edges, truth.n_faces)
    posed = truth.transformed(quat_to_matrix(np.array(rec.pose["quat_wxyz"])), np.array(rec.pose["translation_m"]))
    assert nearest(model.vertices, posed.vertices).max() < 1e-3
    assert model.volume == pytest.approx(truth.volume, rel=0.02)


def test_the_matcher_widens_the_data_bounds_by_a_learned_models():
    lib = load_library()
    tree = InterpretationTree(lib)
    assert tree.widen is None
    box = lib["BOX01"]
    learned = Polyhedron.from_faces(box.vertices, box.faces, name="LEARNED_BOX",
                                    learned_bounds=LearnedBounds(0.01, 0.0006, 0.01))  # fmt: skip
    tree = InterpretationTree({**lib, "LEARNED_BOX": learned})
    face = DataFace(0, np.array([0.0, 0.0, 1.0]), np.array([[0.0, 0.0, 0.0]]), 0.01, 0.0008)
    tree.add(face)
    assert tree.widen is not None
    assert tree.data[0] is face  # the data as reported
    assert tree._data.items[0].normal_bound == pytest.approx(np.hypot(0.01, 0.01))
    assert tree._data.items[0].position_bound == pytest.approx(0.001)


def test_points_touched_on_an_edge_do_not_outvote_the_one_beside_it():
    """An edge traced twice more, each time with its points beside it touched on the edge itself and off it the
    wrong way by less than the data's bound: the face is on the side of the one point touched clear of the
    edge, and the boundary closes (by the points' signs alone it had the face on the wrong side of the edge,
    and the fans of the edge's vertices open)."""
    model = load_library()["LBLOCK01"]
    comps = exact_boundary(model, SE3.identity())
    nf, ne = model.n_faces, model.n_edges
    e = comps[nf + 2]
    nid = nf + ne + model.n_vertices
    for k in range(2):
        wrong = []
        for f, q in e.side_points:
            mid = e.point + 0.5 * e.length * e.direction
            off = q - mid - ((q - mid) @ e.direction) * e.direction
            wrong.append((f, mid - 0.5e-6 * off / np.linalg.norm(off)))
        comps[nid + k] = DataEdge(nid + k, e.direction, e.point, e.length, 0.0, 0.0, 0.0, start_vertex=e.start_vertex,
                                  end_vertex=e.end_vertex, adjacent=e.adjacent, side_points=tuple(wrong))  # fmt: skip
    est = boundary_estimate(comps)
    assert est.closed, (est.counts(), est.problems, est.unbalanced)
