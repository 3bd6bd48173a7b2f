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
    return [t for t, _ in congruence_pairs(a, b, eps)]


def congruence_pairs(a: Polyhedron, b: Polyhedron, eps: float | None) -> list[tuple[SE3, np.ndarray]]:
    """Each congruence with its vertex correspondence (``perm[i]``: the vertex of ``b`` that vertex ``i`` of
    ``a`` goes to)."""
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
    n = b.n_vertices
    weights = np.random.default_rng(0).integers(1, 2**63, size=n, dtype=np.uint64)
    a_flat, a_owner = _face_index(a)
    b_flat, b_owner = _face_index(b)
    b_faces = _keys(weights[b_flat], b_owner, b.n_faces)  # a face's key: the sum of its vertices' weights
    b_edges = np.sort(b.edges, axis=1)
    b_edges = b_edges[:, 0] * n + b_edges[:, 1]
    found: dict[bytes, tuple[SE3, np.ndarray]] = {}
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
            key = nearest.tobytes()
            if key in found:
                continue
            r, t = fit_rotation(a.vertices, b.vertices[nearest])
            if np.linalg.norm(a.vertices @ r.T + t - b.vertices[nearest], axis=1).max() > eps:
                continue
            mapped = np.sort(nearest[a.edges], axis=1)
            if not np.isin(mapped[:, 0] * n + mapped[:, 1], b_edges).all():
                continue
            if np.isin(_keys(weights[nearest[a_flat]], a_owner, a.n_faces), b_faces).all():
                found[key] = (SE3(r, t), nearest)
    return list(found.values())


def _face_index(poly: Polyhedron) -> tuple[np.ndarray, np.ndarray]:
    """The faces' vertex loops end to end, and the face each entry belongs to."""
    flat = np.concatenate([np.asarray(f) for f in poly.faces])
    return flat, np.repeat(np.arange(poly.n_faces), [len(f) for f in poly.faces])


def _keys(values: np.ndarray, owner: np.ndarray, count: int) -> np.ndarray:
    """Per-group sums of 64-bit weights (wrapping): equal sets of vertices give equal keys; unequal sets of
    random weights collide with odds of about 2^-64."""
    keys = np.zeros(count, dtype=np.uint64)
    np.add.at(keys, owner, values)
    return keys


def fit_rotation(src: np.ndarray, dst: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The proper rigid motion ``(R, t)`` taking ``src`` closest to ``dst`` in least squares (Kabsch)."""
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    u, _, vt = np.linalg.svd((src - cs).T @ (dst - cd))
    d = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    return r, cd - r @ cs


def symmetry_group(poly: Polyhedron) -> list[SE3]:
    """The proper rigid motions mapping the model onto itself (identity first).

    Every symmetry fixes the centroid, so each is a rotation about it: ``R (w − c) + c``. The result is checked
    to be a group: it holds the identity and the composition of any two of its members, compared exactly as
    vertex permutations on a few vertices that fix a rigid motion (three not on one line);
    :class:`ModelError` says so when the model's precision leaves it not closed.
    """
    pairs = congruence_pairs(poly, poly, None)
    where = poly.source or poly.name
    perm = np.array([p for _, p in pairs], dtype=np.int64).reshape(len(pairs), poly.n_vertices)
    probe = _spanning_vertices(poly.vertices)
    known = {row.tobytes() for row in perm[:, probe]}
    if probe.tobytes() not in known:
        raise ModelError(f"{where}: the symmetry search did not find the identity (a bug, or a degenerate model)")
    for g in perm:
        if any(row.tobytes() not in known for row in g[perm[:, probe]]):  # g ∘ h for every h
            raise ModelError(
                f"{where}: the {len(pairs)} rotations found mapping the model onto itself are not closed under "
                f"composition, so they are not its symmetry group; its vertices are not placed precisely "
                f"enough (tolerance {poly.tolerances.match * 1e3:.3g} mm) to tell — write the file with "
                "more decimals"
            )
    identity = np.arange(poly.n_vertices)
    pairs.sort(key=lambda tp: (not np.array_equal(tp[1], identity), -float(np.trace(tp[0].rotation))))
    return [t for t, _ in pairs]


def _spanning_vertices(points: np.ndarray) -> np.ndarray:
    """Three vertices not on one line (vertex 0, the farthest from it, the farthest from their line)."""
    i = int(np.argmax(np.linalg.norm(points - points[0], axis=1)))
    d = points[i] - points[0]
    off = np.linalg.norm(np.cross(points - points[0], d), axis=1)
    return np.array([0, i, int(np.argmax(off))], dtype=np.int64)


def library_twin(model: Polyhedron, library: dict[str, Polyhedron]) -> tuple[str, SE3] | None:
    """The library model congruent to ``model`` (a proper rigid motion maps one onto the other), with the
    map ``T`` taking the library model onto ``model`` (``T(library model) = model``); ``None`` when there is none.

    The same model read from another file, another encoding or another pose is found here whatever its name.
    """
    for name, candidate in library.items():
        if candidate is model:
            return name, SE3.identity()
    for name, candidate in library.items():
        maps = congruences(candidate, model)
        if maps:
            return name, maps[0]
    return None


def are_congruent(a: Polyhedron, b: Polyhedron) -> bool:
    """True when a proper rigid motion maps one solid onto the other (mirror images are not congruent)."""
    return bool(congruence_pairs(a, b, None))


def model_summary(poly: Polyhedron, symmetry: list | None = None) -> dict:
    """Counts and properties of a model for listings (``symmetry``: its group when already found)."""
    return {
        "name": poly.name,
        "V": poly.n_vertices,
        "E": poly.n_edges,
        "F": poly.n_faces,
        "euler": poly.euler_characteristic,
        "genus": poly.genus,
        "convex": poly.is_convex,
        "symmetry": len(symmetry if symmetry is not None else symmetry_group(poly)),
        "extents_mm": [round(float(x) * 1e3, 2) for x in poly.extents],
        "volume_cm3": round(poly.volume * 1e6, 3),
    }
