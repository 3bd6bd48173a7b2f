"""Exact convex decomposition of a polyhedral solid.

A simulator collides each mesh geom as its convex hull, so a non-convex object must be given as convex
pieces. Every face lies in one of the solid's face planes, so each cell of the arrangement of those planes
(inside the bounding box) lies wholly inside or wholly outside the solid: the inside cells are an exact
decomposition. Neighbouring cells whose union is convex are then merged greedily to keep the count small.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from haptic.geometry.polyhedron import Polyhedron


def convex_decomposition(poly: Polyhedron) -> list[np.ndarray]:
    """Vertex sets (n_i, 3) of convex pieces whose union is exactly the solid (one piece if it is convex)."""
    if poly.is_convex:
        return [np.array(poly.vertices)]
    lo, hi = poly.vertices.min(axis=0), poly.vertices.max(axis=0)
    box = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    planes = _unique_planes(poly.face_normals, poly.face_offsets)
    scale = float(np.max(hi - lo))
    eps = 1e-9 * scale
    cells = [box]
    for n, d in planes:
        nxt = []
        for cell in cells:
            s = cell @ n - d
            if (s > eps).any() and (s < -eps).any():
                nxt.extend(_split(cell, s, eps))
            else:
                nxt.append(cell)
        cells = nxt
    cells = [c for c in cells if _volume(c) > 1e-12 * scale**3]
    inside = poly.contains(np.array([c.mean(axis=0) for c in cells]))
    pieces = [c for c, keep in zip(cells, inside, strict=True) if keep]
    return _merge(pieces)


def _unique_planes(normals: np.ndarray, offsets: np.ndarray) -> list[tuple[np.ndarray, float]]:
    out: list[tuple[np.ndarray, float]] = []
    for n, d in zip(normals, offsets, strict=True):
        if not any(
            (abs(n @ m - 1) < 1e-9 and abs(d - e) < 1e-9) or (abs(n @ m + 1) < 1e-9 and abs(d + e) < 1e-9)
            for m, e in out
        ):
            out.append((n, float(d)))
    return out


def _split(cell: np.ndarray, s: np.ndarray, eps: float) -> list[np.ndarray]:
    pos, neg, on = cell[s > eps], cell[s < -eps], cell[np.abs(s) <= eps]
    cuts = []
    for i in np.flatnonzero(s > eps):
        for j in np.flatnonzero(s < -eps):
            t = s[i] / (s[i] - s[j])
            cuts.append(cell[i] + t * (cell[j] - cell[i]))
    cuts = np.array(cuts).reshape(-1, 3)
    return [_hull_vertices(np.vstack([pos, on, cuts])), _hull_vertices(np.vstack([neg, on, cuts]))]


def _hull_vertices(points: np.ndarray) -> np.ndarray:
    try:
        return points[ConvexHull(points).vertices]
    except QhullError:
        return points


def _volume(points: np.ndarray) -> float:
    try:
        return float(ConvexHull(points).volume)
    except QhullError:
        return 0.0


def _merge(pieces: list[np.ndarray]) -> list[np.ndarray]:
    """Greedy merging: the first pair (in list order) whose union is convex (its hull's volume is the sum of
    theirs) becomes one piece, until no pair merges. A pair's hull volume is computed once: a pair of pieces that
    did not merge is not tried again until one of them changes (each piece carries a token, new when it does)."""
    pieces = list(pieces)
    vols = [_volume(p) for p in pieces]
    tokens = list(range(len(pieces)))
    fresh = len(pieces)
    apart: set[tuple[int, int]] = set()  # pairs of tokens whose union is not convex
    merged = True
    while merged:
        merged = False
        for i in range(len(pieces)):
            for j in range(i + 1, len(pieces)):
                if (tokens[i], tokens[j]) in apart:
                    continue
                union = np.vstack([pieces[i], pieces[j]])
                hv = _volume(union)
                if abs(hv - vols[i] - vols[j]) <= 1e-9 * max(hv, 1e-12):
                    pieces[i] = _hull_vertices(union)
                    vols[i] = hv
                    tokens[i], fresh = fresh, fresh + 1
                    del pieces[j], vols[j], tokens[j]
                    merged = True
                    break
                apart.add((tokens[i], tokens[j]))
            if merged:
                break
    return pieces
