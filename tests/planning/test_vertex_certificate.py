"""Why the full verification measures every vertex rather than counting one as given by its faces' planes: a chamfer
of the promised size at a vertex leaves every face's plane where the model has it (README, *What verification
costs*), so that no measurement of the faces' planes, however near the vertex, tells the chamfered object from the
model; the vertex measured does."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from haptic.errors import ModelError
from haptic.geometry import load_library
from haptic.geometry.perturb import chamfer_edge

LIB = load_library()
NAMES = sorted(LIB)


def _planes(poly) -> np.ndarray:
    return np.concatenate([poly.face_normals, poly.face_offsets[:, None]], axis=1)


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(NAMES), st.integers(0, 10**6), st.floats(3e-3, 8e-3))
def test_a_chamfer_at_a_vertex_keeps_every_face_plane_and_moves_the_vertex(name, pick, legs):
    poly = LIB[name]
    convex = [e for e in range(poly.n_edges) if poly.edge_convexity[e] > 0]
    edge = convex[pick % len(convex)]
    try:
        cut = chamfer_edge(poly, edge, legs)
    except ModelError:
        return  # the cut would not stay local on this edge at this size
    before, after = _planes(poly), _planes(cut)
    # every face of the model keeps its plane (one new face, the chamfer's)
    gap = np.abs(before[:, None, :] - after[None, :, :]).max(axis=2).min(axis=1)
    assert gap.max() < 1e-9
    assert cut.n_faces == poly.n_faces + 1
    # while each end vertex of the edge is gone: the nearest vertex of the chamfered object is at least half the
    # legs away (0.6 of them at PYR01's base, the least in the seed library), more than the pose check allows a
    # measured vertex (2 x its bound of 0.6 mm)
    for v in poly.edges[edge]:
        d = np.linalg.norm(cut.vertices - poly.vertices[int(v)], axis=1).min()
        assert d > legs / 2 > 2 * 0.6e-3


POSE_ALLOWANCE = 2 * 0.6e-3
"""What the pose check allows a measured point off its model face at the default noise (2 x its bound) [m]."""


@settings(max_examples=80, deadline=None)
@given(st.sampled_from(NAMES), st.integers(0, 10**6), st.floats(3e-3, 8e-3))
def test_a_vertex_moved_along_an_edge_keeps_the_planes_of_the_faces_along_it(name, pick, shift):
    """Nor is a vertex given by probes on some of its faces near it (docs/planner.md, *Verification as a tour*): the
    vertex moved ``shift`` along one of its edges (the edge lengthened) stays in the planes of both faces along
    that edge, so a probe on either, however near the vertex, lands where the model says, while the moved vertex
    leaves the plane of another face at it by more than the pose check allows. Which edge is unknown, so a check
    by probes must touch every face at the vertex (three or more, each ``c_p`` and its travel) -- dearer than the
    probe, face move and short edge move that measure the vertex."""
    poly = LIB[name]
    v = pick % poly.n_vertices
    edges = poly.vertex_edges[v]
    e = int(edges[(pick // poly.n_vertices) % len(edges)])
    other = int(sum(poly.edges[e])) - v
    u = poly.vertices[v] - poly.vertices[other]
    moved = poly.vertices[v] + shift * u / np.linalg.norm(u)
    along = {int(poly.edge_left_face[e]), int(poly.edge_right_face[e])}
    faces = [int(f) for f in poly.vertex_faces[v]]
    assert len(faces) >= 3 and along <= set(faces)
    off = {f: abs(float(poly.face_normals[f] @ moved - poly.face_offsets[f])) for f in faces}
    assert max(off[f] for f in along) < 1e-12
    assert max(off[f] for f in faces if f not in along) > POSE_ALLOWANCE
