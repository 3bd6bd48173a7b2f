"""Rigid congruences between polyhedra, and the symmetry group of a model.

The symmetry group is the set of proper rotations (about the centroid) that map a model onto itself. Two
interpretations of one model whose poses differ by such a rotation cannot be told apart by any touch data,
so they form one pose class.
"""

from __future__ import annotations

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3, frame_from_edge
from haptic.geometry.tolerances import tol


def congruences(a: Polyhedron, b: Polyhedron, eps: float | None = None) -> list[SE3]:
    """All proper rigid transforms ``T`` with ``T(a) = b`` as solids (vertices, faces and adjacency).

    A proper rotation preserves the left/right sense of every edge, so edge 0 of ``a`` with its left face
    can only go to an edge of ``b`` (taken in either direction) with the face then on its left. Each such
    choice fixes one candidate transform, which is kept when it maps every vertex and face of ``a`` onto one
    of ``b``. Mirror images are therefore never congruent unless the solid is itself mirror-symmetric.
    """
    eps = tol.match * max(1.0, float(np.max(a.extents)) * 10) if eps is None else eps
    if (a.n_vertices, a.n_edges, a.n_faces) != (b.n_vertices, b.n_edges, b.n_faces):
        return []
    if abs(a.volume - b.volume) > 1e-6 * max(abs(a.volume), 1e-12) + 1e-12:
        return []
    la = a.edge_lengths[0]
    src = frame_from_edge(a.edge_directions[0], a.face_normals[a.edge_left_face[0]])
    pa = a.edge_points[0]
    out: list[SE3] = []
    for e in np.flatnonzero(np.abs(b.edge_lengths - la) < eps):
        for forward in (True, False):
            if forward:
                dirn, left, p = b.edge_directions[e], b.edge_left_face[e], b.edge_points[e]
            else:
                dirn = -b.edge_directions[e]
                left = b.edge_right_face[e]
                p = b.vertices[b.edges[e, 1]]
            dst = frame_from_edge(dirn, b.face_normals[left])
            r = dst @ src.T
            t = p - r @ pa
            mapped = a.vertices @ r.T + t
            dist = np.linalg.norm(mapped[:, None, :] - b.vertices[None, :, :], axis=2)
            nearest = dist.argmin(axis=1)
            if dist[np.arange(len(nearest)), nearest].max() > eps or len(set(nearest.tolist())) != a.n_vertices:
                continue
            # faces: same vertex sets after mapping
            b_faces = {frozenset(f) for f in b.faces}
            if all(frozenset(int(nearest[i]) for i in f) in b_faces for f in a.faces):
                out.append(SE3(r, t))
    return _unique(out)


def _unique(transforms: list[SE3]) -> list[SE3]:
    kept: list[SE3] = []
    for t in transforms:
        same = (
            np.allclose(t.rotation, k.rotation, atol=1e-6) and np.allclose(t.translation, k.translation, atol=1e-7)
            for k in kept
        )
        if not any(same):
            kept.append(t)
    return kept


def symmetry_group(poly: Polyhedron) -> list[SE3]:
    """The proper rigid motions mapping the model onto itself (identity first).

    Every symmetry fixes the centroid, so each is a rotation about it: ``R (w − c) + c``.
    """
    group = congruences(poly, poly)
    group.sort(key=lambda s: (not np.allclose(s.rotation, np.eye(3), atol=1e-9), float(np.trace(s.rotation)) * -1))
    return group


def are_congruent(a: Polyhedron, b: Polyhedron) -> bool:
    """True when a proper rigid motion maps one solid onto the other (mirror images are not congruent)."""
    return bool(congruences(a, b))
