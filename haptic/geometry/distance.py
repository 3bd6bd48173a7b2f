"""Distances from points to a polyhedron's surface and its triangles (model frame)."""

from __future__ import annotations

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import cross


def surface_distance(poly: Polyhedron, points: np.ndarray) -> np.ndarray:
    """Unsigned distance from each point (model frame) to the surface, shape (P,)."""
    p = np.atleast_2d(np.asarray(points, dtype=float))
    tri = poly.vertices[poly.triangles]  # (T, 3, 3)
    best = np.full(len(p), np.inf)
    for start in range(0, len(p), 2048):
        q = p[start : start + 2048]
        d = point_triangle_distance(q, tri)
        best[start : start + 2048] = d.min(axis=1)
    return best


def point_triangle_distance(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Distances (P, T) from points to triangles (closest point by barycentric clamping over the regions)."""
    return _distance(p[:, None, :], tri[None, :, 0], tri[None, :, 1], tri[None, :, 2])


def paired_point_triangle_distance(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Distances (M,) from each point ``p[i]`` (M, 3) to its own triangle ``tri[i]`` (M, 3, 3): the entries of
    :func:`point_triangle_distance` that a caller needs, without the rest of the matrix."""
    return _distance(p, tri[:, 0], tri[:, 1], tri[:, 2])


def _distance(q: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Distances from points ``q`` to triangles ``(a, b, c)``, all (..., 3) and broadcast together."""
    ab, ac = b - a, c - a
    n = cross(ab, ac)
    nn = np.einsum("...k,...k->...", n, n) + 1e-30
    # projection onto the plane and its barycentric coordinates
    w = q - a
    dist_plane = np.einsum("...k,...k->...", w, n) / np.sqrt(nn)
    proj = q - (np.einsum("...k,...k->...", w, n) / nn)[..., None] * n
    v0, v1, v2 = ab, ac, proj - a
    d00 = np.einsum("...k,...k->...", v0, v0)
    d01 = np.einsum("...k,...k->...", v0, v1)
    d11 = np.einsum("...k,...k->...", v1, v1)
    d20 = np.einsum("...k,...k->...", v2, v0)
    d21 = np.einsum("...k,...k->...", v2, v1)
    den = d00 * d11 - d01 * d01 + 1e-30
    s = (d11 * d20 - d01 * d21) / den
    t = (d00 * d21 - d01 * d20) / den
    inside = (s >= 0) & (t >= 0) & (s + t <= 1)
    d_in = np.abs(dist_plane)

    def seg(x, y):
        xy = y - x
        h = np.clip(np.einsum("...k,...k->...", q - x, xy) / (np.einsum("...k,...k->...", xy, xy) + 1e-30), 0.0, 1.0)
        return np.linalg.norm(q - (x + h[..., None] * xy), axis=-1)

    d_edge = np.minimum(np.minimum(seg(a, b), seg(b, c)), seg(c, a))
    return np.where(inside, d_in, d_edge)


def _triangle_grid(a: np.ndarray, b: np.ndarray, c: np.ndarray, spacing: float) -> np.ndarray:
    """A barycentric grid on triangle ``abc`` (corners and edges included) whose rows are at most ``spacing`` apart
    along its longest side, shape (P, 3)."""
    n = max(1, int(np.ceil(max(np.linalg.norm(b - a), np.linalg.norm(c - a), np.linalg.norm(c - b)) / spacing)))
    u, v = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = u + v <= n
    return a + (u[keep] / n)[:, None] * (b - a) + (v[keep] / n)[:, None] * (c - a)


def surface_grid(poly: Polyhedron, spacing: float) -> np.ndarray:
    """Points over every face of ``poly`` about ``spacing`` apart [m], shape (P, 3): its vertices, and on each of its
    triangles a grid whose rows are at most ``spacing`` apart along its longest side (edges included)."""
    out = [np.asarray(poly.vertices, dtype=float)]
    for i, j, k in poly.triangles:
        a, b, c = (np.asarray(poly.vertices[x], dtype=float) for x in (i, j, k))
        out.append(_triangle_grid(a, b, c, spacing))
    return np.concatenate(out)


def surface_samples_on_faces(poly: Polyhedron, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Points over every face of ``poly`` (a barycentric grid per triangle, ``spacing`` apart, corners and edges
    included) and the face each lies on, model frame: shapes (P, 3), (P,)."""
    pts, faces = [], []
    for (i, j, k), f in zip(poly.triangles, poly.triangle_faces, strict=True):
        grid = _triangle_grid(poly.vertices[i], poly.vertices[j], poly.vertices[k], spacing)
        pts.append(grid)
        faces.append(np.full(len(grid), int(f)))
    return np.concatenate(pts), np.concatenate(faces)
