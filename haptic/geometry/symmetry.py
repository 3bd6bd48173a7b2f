"""Rigid congruences between polyhedra, and the symmetry group of a model.

The symmetry group is the set of proper rotations (about the centroid) that map a model onto itself. Two
interpretations of one model whose poses differ by such a rotation cannot be told apart by any touch data,
so they form one pose class.

Tolerances follow the models (:meth:`~haptic.geometry.Tolerances.for_model`): a candidate map is fitted to
all its vertex correspondences by least squares and kept when every vertex lands within the models' match
tolerance, so a model read from a rounded file keeps the symmetries of the solid it was written from.
"""

from __future__ import annotations

import numpy as np

from haptic.errors import ModelError
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3, frame_from_edge


def congruences(a: Polyhedron, b: Polyhedron, eps: float | None = None) -> list[SE3]:
    """All proper rigid transforms ``T`` with ``T(a) = b`` as solids (vertices, faces and adjacency).

    A proper rotation preserves the left/right sense of every edge, so one reference edge of ``a`` with its
    left face can only go to an edge of ``b`` of the same length (taken in either direction) with the face
    then on its left. Each such choice fixes a candidate transform; its vertex correspondence (nearest
    vertices) is refined by a least-squares fit, and the map is kept when every vertex lands within ``eps``
    (default: the larger of the two models' match tolerances) of its partner and every face onto a face.
    Mirror images are therefore never congruent unless the solid is itself mirror-symmetric.
    """
    return [t for t, _ in _congruences(a, b, eps)]


def _congruences(a: Polyhedron, b: Polyhedron, eps: float | None) -> list[tuple[SE3, tuple[int, ...]]]:
    from scipy.spatial import cKDTree

    if (a.n_vertices, a.n_edges, a.n_faces) != (b.n_vertices, b.n_edges, b.n_faces):
        return []
    eps = max(a.tolerances.match, b.tolerances.match) if eps is None else eps
    area = float(a.face_areas.sum() + b.face_areas.sum())
    if abs(a.volume - b.volume) > area * eps + 1e-6 * max(abs(a.volume), 1e-12):
        return []
    # the reference edge of a: the one whose length fewest edges of b share (fewest candidates to try)
    order = np.argsort(b.edge_lengths)
    lb = b.edge_lengths[order]
    lo = np.searchsorted(lb, a.edge_lengths - 2 * eps, side="left")
    hi = np.searchsorted(lb, a.edge_lengths + 2 * eps, side="right")
    ref = int(np.argmin(hi - lo))
    candidates = order[lo[ref] : hi[ref]]
    src = frame_from_edge(a.edge_directions[ref], a.face_normals[a.edge_left_face[ref]])
    pa = a.edge_points[ref]
    # a first correspondence is unambiguous while the candidate's error stays under half the closest vertex pair
    loose = max(eps, 0.3 * float(b.edge_lengths.min()))
    tree = cKDTree(b.vertices)
    b_faces = {frozenset(f) for f in b.faces}
    found: dict[tuple[int, ...], SE3] = {}
    for e in candidates:
        for forward in (True, False):
            if forward:
                dirn, left, p = b.edge_directions[e], b.edge_left_face[e], b.edge_points[e]
            else:
                dirn, left, p = -b.edge_directions[e], b.edge_right_face[e], b.vertices[b.edges[e, 1]]
            r = frame_from_edge(dirn, b.face_normals[left]) @ src.T
            t = p - r @ pa
            dist, nearest = tree.query(a.vertices @ r.T + t, distance_upper_bound=loose)
            if not np.isfinite(dist).all() or len(np.unique(nearest)) != a.n_vertices:
                continue
            perm = tuple(int(i) for i in nearest)
            if perm in found:
                continue
            r, t = _fit_rotation(a.vertices, b.vertices[nearest])
            if np.linalg.norm(a.vertices @ r.T + t - b.vertices[nearest], axis=1).max() > eps:
                continue
            if all(frozenset(perm[i] for i in f) in b_faces for f in a.faces):
                found[perm] = SE3(r, t)
    return [(t, perm) for perm, t in found.items()]


def _fit_rotation(src: np.ndarray, dst: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The proper rigid motion ``(R, t)`` taking ``src`` closest to ``dst`` in least squares (Kabsch)."""
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    u, _, vt = np.linalg.svd((src - cs).T @ (dst - cd))
    d = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    return r, cd - r @ cs


def symmetry_group(poly: Polyhedron) -> list[SE3]:
    """The proper rigid motions mapping the model onto itself (identity first).

    Every symmetry fixes the centroid, so each is a rotation about it: ``R (w − c) + c``. The result is checked
    to be a group: it holds the identity and the composition of any two of its members (as vertex
    permutations, which is exact); :class:`ModelError` says so when the model's precision leaves it not closed.
    """
    pairs = _congruences(poly, poly, None)
    perms = {perm for _, perm in pairs}
    identity = tuple(range(poly.n_vertices))
    where = poly.source or poly.name
    if identity not in perms:
        raise ModelError(f"{where}: the symmetry search did not find the identity (a bug, or a degenerate model)")
    for _, g in pairs:
        for _, h in pairs:
            if tuple(g[i] for i in h) not in perms:
                raise ModelError(
                    f"{where}: the {len(pairs)} rotations found mapping the model onto itself are not closed under "
                    f"composition, so they are not its symmetry group; its vertices are not placed precisely "
                    f"enough (tolerance {poly.tolerances.match * 1e3:.3g} mm) to tell — write the file with "
                    "more decimals"
                )
    pairs.sort(key=lambda tp: (tp[1] != identity, -float(np.trace(tp[0].rotation))))
    return [t for t, _ in pairs]


def are_congruent(a: Polyhedron, b: Polyhedron) -> bool:
    """True when a proper rigid motion maps one solid onto the other (mirror images are not congruent)."""
    return bool(_congruences(a, b, None))
