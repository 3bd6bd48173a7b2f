"""The fold check: a measured face of four or more vertices may be two faces folded along a diagonal.

A vertex moved by a few millimetres folds its faces along a diagonal by a degree or less. No data edge divides
the two halves until a move crosses the fold: a face move that crosses it stops there and measures the edge, and
the two halves become two planes (:func:`~haptic.learning.reconstruct.face_planes`). Until then one plane fitted
across both holds every point touched on them within its bounds, and the learned model has a face and an edge
too few (an inward fold: a non-convex object learned convex).

So before the surface is called closed, every diagonal of every measured face with at least
:data:`MIN_FOLD_VERTICES` vertices is *crossed*: a face move's path on that face (a :class:`Stroke`, from where it
started to the edge where it stopped) crosses the diagonal clear of its ends (:func:`crosses`). A move from the
middle of an edge of a quadrilateral to the middle of the opposite one crosses both its diagonals.

Pure numpy.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from haptic.geometry.se3 import plane_basis

MIN_FOLD_VERTICES = 4
"""Faces with at least this many vertices have diagonals a fold may run along."""
END_MARGIN = 0.05
"""A crossing within this fraction of a diagonal's length from its ends does not count [-]: there the estimate's
diagonal and the object's are closest, but a path that near a vertex runs along the faces' edges."""
STROKE_SLACK = 0.02
"""A crossing counts this fraction of the path's length beyond its ends [-]: the path ends on the edge where it
stopped, which a diagonal ends on too."""


@dataclass(frozen=True, eq=False)
class Stroke:
    """A face move's path: the data face it started on, where it started and where it stopped (world) [m]."""

    face: int
    """Id of the data face the move crossed."""
    start: np.ndarray
    """Where the move started, shape (3,) [m]."""
    end: np.ndarray
    """Where it stopped (on an edge), shape (3,) [m]."""


def diagonals(loop: Sequence[int]) -> list[tuple[int, int]]:
    """The diagonals of a face with vertex loop ``loop``: pairs of its vertices not next to each other (none
    for a face of fewer than :data:`MIN_FOLD_VERTICES`)."""
    n = len(loop)
    if n < MIN_FOLD_VERTICES:
        return []
    return [(int(loop[i]), int(loop[j])) for i in range(n) for j in range(i + 2, n) if not (i == 0 and j == n - 1)]


def crosses(start: np.ndarray, end: np.ndarray, a: np.ndarray, b: np.ndarray, normal: np.ndarray) -> bool:
    """Whether the path ``start``→``end`` crosses the diagonal ``a``–``b`` of a face with unit ``normal``,
    clear of the diagonal's ends (:data:`END_MARGIN`): both projected on the face's plane."""
    x, y = plane_basis(np.asarray(normal, float))

    def flat(p: np.ndarray) -> np.ndarray:
        return np.array([p @ x, p @ y])

    p, r = flat(start), flat(end) - flat(start)
    q, s = flat(a), flat(b) - flat(a)
    denom = float(r[0] * s[1] - r[1] * s[0])
    if abs(denom) < 1e-12 * max(float(np.linalg.norm(r) * np.linalg.norm(s)), 1e-30):
        return False  # parallel
    w = q - p
    t = float(w[0] * s[1] - w[1] * s[0]) / denom  # along the path
    u = float(w[0] * r[1] - w[1] * r[0]) / denom  # along the diagonal
    return -STROKE_SLACK <= t <= 1 + STROKE_SLACK and END_MARGIN <= u <= 1 - END_MARGIN


def _flat(points: np.ndarray, normal: np.ndarray) -> np.ndarray:
    x, y = plane_basis(np.asarray(normal, float))
    return np.stack([np.asarray(points, float) @ x, np.asarray(points, float) @ y], axis=-1)


def _proper_cross(p: np.ndarray, r: np.ndarray, q: np.ndarray, s: np.ndarray) -> bool:
    """Whether 2-D segments ``p + t r`` and ``q + u s`` cross inside both (0 < t, u < 1)."""
    denom = float(r[0] * s[1] - r[1] * s[0])
    if abs(denom) < 1e-15:
        return False
    w = q - p
    t = float(w[0] * s[1] - w[1] * s[0]) / denom
    u = float(w[0] * r[1] - w[1] * r[0]) / denom
    return 1e-9 < t < 1 - 1e-9 and 1e-9 < u < 1 - 1e-9


def _inside(point: np.ndarray, polygon: np.ndarray) -> bool:
    """Whether 2-D ``point`` lies inside ``polygon`` (even-odd rule)."""
    x, y = point
    inside = False
    for (x1, y1), (x2, y2) in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


def inner_diagonals(vertices: np.ndarray, loop: Sequence[int], normal: np.ndarray) -> list[tuple[int, int]]:
    """The :func:`diagonals` of the face ``loop`` that run inside it (all of a convex face's; a fold cannot
    run outside its face)."""
    out = []
    poly = _flat(vertices[list(loop)], normal)
    for i, j in diagonals(loop):
        a, b = _flat(vertices[[i, j]], normal)
        if not _inside(0.5 * (a + b), poly):
            continue
        if any(_proper_cross(a, b - a, poly[k], poly[(k + 1) % len(poly)] - poly[k]) for k in range(len(poly))):
            continue
        out.append((i, j))
    return out


def unchecked_diagonals(
    vertices: np.ndarray, faces: Sequence[tuple[int, Sequence[int]]], normals: Mapping[int, np.ndarray],
    plane_of: Mapping[int, int], strokes: Iterable[Stroke],
) -> dict[int, list[tuple[int, int]]]:
    """Face → the inner diagonals of face ``faces[face]`` (``(plane, vertex loop)``, loops of indices into
    ``vertices``) that no stroke on its plane crosses; faces with none left out. ``normals``: plane → unit
    normal; ``plane_of``: data face id → plane, for the strokes."""
    on: dict[int, list[Stroke]] = {}
    for s in strokes:
        k = plane_of.get(s.face)
        if k is not None:
            on.setdefault(k, []).append(s)
    out: dict[int, list[tuple[int, int]]] = {}
    for f, (k, loop) in enumerate(faces):
        left = [(i, j) for i, j in inner_diagonals(vertices, loop, normals[k])
                if not any(crosses(s.start, s.end, vertices[i], vertices[j], normals[k]) for s in on.get(k, ()))]
        if left:
            out[f] = left
    return out
