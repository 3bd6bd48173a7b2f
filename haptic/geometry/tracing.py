"""Exact outcomes of the seed's tracing primitives on a model (§3.1, §4), in the model frame.

The geometric executor runs these on the true model to produce data; the planner runs them on each
interpretation's model to predict a move's outcome. Pure geometry: no noise, no costs.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from haptic.geometry import kernels
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import cross, plane_basis


@dataclass(frozen=True, eq=False)
class FaceHit:
    """Where a straight trace across a face meets the face's boundary."""

    edge: int
    """Edge met."""
    distance: float
    """Distance travelled from the start [m]."""
    point: np.ndarray
    """Point met on the edge, shape (3,) [m]."""
    next_face: int
    """The face on the other side of the edge."""


@dataclass(frozen=True)
class EdgeHit:
    """Where a trace along an edge meets a vertex."""

    vertex: int
    """Vertex met."""
    distance: float
    """Distance travelled from the start [m]."""


@dataclass(frozen=True)
class VertexHit:
    """Where a circular trace around a vertex meets the next edge."""

    edge: int
    """Edge met."""
    next_face: int
    """The face beyond that edge."""
    angle: float
    """Angle swept at the vertex, in the crossed face, between the two edges [rad]."""
    arc_length: float
    """Length of the circular path, ``radius · angle`` [m]."""




def trace_face(
    poly: Polyhedron, face: int, start: np.ndarray, direction: np.ndarray, vertex_margin: float = 1e-6
) -> FaceHit | None:
    """Trace from ``start`` (on the face) straight along ``direction`` to the first edge of the face.

    ``direction`` is projected into the face plane. Returns None when it has no component in the plane, when
    nothing is met, or when the ray meets the boundary within ``vertex_margin`` of a vertex (no single edge).
    Works for non-convex faces: the first boundary crossing ahead is taken.
    """
    n = poly.face_normals[face]
    d = np.asarray(direction, dtype=float)
    d = d - (d @ n) * n
    norm = np.linalg.norm(d)
    if norm < 1e-9:
        return None
    d /= norm
    start = np.asarray(start, dtype=float)
    # the start and the face's corners on its plane: a model read from a rounded file has its corners off the
    # plane by up to its precision, and a point stepped over from a neighbouring face is off by as much
    start = start - (start @ n - poly.face_offsets[face]) * n
    corners, sides = _plane_corners(poly, face)
    if kernels.COMPILED:
        k, t, u, seg_len = kernels.face_crossing(corners, sides, n, start, d, _STEADY, _MARGIN)
        best = None if k < 0 else (t, poly.face_edges[face][k], u, seg_len)
    else:
        best = _crossing(poly, face, corners, sides, n, start, d)
    if best is None:
        return None
    t, e, u, seg_len = best
    if min(u, 1 - u) * seg_len < vertex_margin:
        return None
    other = poly.edge_right_face[e] if poly.edge_left_face[e] == face else poly.edge_left_face[e]
    return FaceHit(edge=int(e), distance=float(t), point=start + t * d, next_face=int(other))


def _crossing(poly: Polyhedron, face: int, corners, sides, n, start, d) -> tuple[float, int, float, float] | None:
    """The first side of ``face`` that the trace from ``start`` along unit ``d`` meets, as ``(t, edge, u, side
    length)``, or None (:func:`trace_face`; :func:`~haptic.geometry.kernels.face_crossing` is its compiled form)."""
    best = None
    # which sides the trace can meet, from the crossing solved for every side at once; only those are solved
    # exactly one by one below (a side it misses by a margin far above the arithmetic's error is not: the same sides
    # are then met, with the same numbers)
    rel = corners - start
    den = _in_plane_cross(d, sides, n)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_all = _in_plane_cross(rel, sides, n) / den
        u_all = _in_plane_cross(rel, d, n) / den
    steady = np.abs(den) > _STEADY * np.sqrt(np.einsum("ki,ki->k", sides, sides))
    skip = steady & ((t_all < -_MARGIN) | (u_all < -_MARGIN) | (u_all > 1 + _MARGIN))
    dx, dy, dz = d.tolist()
    sx, sy, sz = start.tolist()
    for k, e in enumerate(poly.face_edges[face]):
        if skip[k]:
            continue
        ax, ay, az = corners[k].tolist()
        gx, gy, gz = sides[k].tolist()
        # solve start + t d = a + u seg in the plane: least squares in 3-D (exact when coplanar) by the 2 × 2
        # normal equations, in scalars (d is a unit vector)
        rx, ry, rz = ax - sx, ay - sy, az - sz
        dg, gg = dx * gx + dy * gy + dz * gz, gx * gx + gy * gy + gz * gz
        dr, gr = dx * rx + dy * ry + dz * rz, gx * rx + gy * ry + gz * rz
        det = gg - dg * dg
        if det <= 1e-24 * gg:
            continue  # parallel
        t = (gg * dr - dg * gr) / det
        u = (dg * dr - gr) / det
        if t <= 1e-12 or u < -1e-12 or u > 1 + 1e-12:
            continue
        ex, ey, ez = sx + t * dx - (ax + u * gx), sy + t * dy - (ay + u * gy), sz + t * dz - (az + u * gz)
        if math.sqrt(ex * ex + ey * ey + ez * ez) > 1e-7:
            continue  # off-plane
        if best is None or t < best[0]:
            best = (t, e, u, math.sqrt(gg))
    return best


_STEADY = 1e-3
"""A side whose crossing with the trace is solved for all sides at once (:func:`trace_face`) counts when the sine of
the angle between them is above this: the crossing's parameters are then within far less than :data:`_MARGIN` of
the least-squares solution."""
_MARGIN = 1e-6
"""A side whose crossing lies this far behind the start, or beyond either end of the side (in units of its length),
is one the trace does not meet."""
_PLANE_CORNERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _plane_corners(poly: Polyhedron, face: int) -> tuple[np.ndarray, np.ndarray]:
    """A face's corners moved onto its plane (K, 3), in loop order, and its sides from each to the next (K, 3)
    (cached per model)."""
    per = _PLANE_CORNERS.setdefault(poly, {})
    if face not in per:
        n = poly.face_normals[face]
        loop = list(poly.faces[face])
        off = poly.vertices[loop] @ n - poly.face_offsets[face]
        corners = poly.vertices[loop] - off[:, None] * n
        per[face] = (corners, np.roll(corners, -1, axis=0) - corners)
    return per[face]


def _in_plane_cross(a: np.ndarray, b: np.ndarray, n: np.ndarray) -> np.ndarray:
    """``(a × b) · n`` along the last axis (broadcast)."""
    return cross(a, b) @ n


def trace_edge(poly: Polyhedron, edge: int, start: np.ndarray, sense: int) -> EdgeHit:
    """Trace from ``start`` (on the edge) along it, ``sense`` +1 along ``b``, −1 against, to a vertex."""
    src, dst = poly.edges[edge]
    p, b, length = poly.edge_points[edge], poly.edge_directions[edge], poly.edge_lengths[edge]
    s = float(np.clip((np.asarray(start, dtype=float) - p) @ b, 0.0, length))
    if sense > 0:
        return EdgeHit(vertex=int(dst), distance=float(length - s))
    return EdgeHit(vertex=int(src), distance=s)


def other_face(poly: Polyhedron, edge: int, face: int) -> int:
    """The face of ``edge`` that is not ``face``."""
    left, right = int(poly.edge_left_face[edge]), int(poly.edge_right_face[edge])
    if face == left:
        return right
    if face == right:
        return left
    raise ValueError(f"face {face} is not a face of edge {edge} (faces {left}, {right})")


def face_edges_at_vertex(poly: Polyhedron, face: int, vertex: int) -> tuple[int, int]:
    """The two edges of ``face`` that meet at ``vertex`` (incoming, outgoing in loop order)."""
    loop = poly.faces[face]
    k = loop.index(vertex)
    fe = poly.face_edges[face]
    return int(fe[k - 1]), int(fe[k])


_CORNERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def corner_angle(poly: Polyhedron, face: int, vertex: int) -> float:
    """Interior angle of ``face`` at ``vertex`` (may exceed π at a reflex corner) [rad] (cached per model)."""
    per = _CORNERS.setdefault(poly, {})
    if (face, vertex) not in per:
        per[face, vertex] = _corner_angle(poly, face, vertex)
    return per[face, vertex]


def _corner_angle(poly: Polyhedron, face: int, vertex: int) -> float:
    loop = poly.faces[face]
    k = loop.index(vertex)
    v = poly.vertices[vertex]
    a = poly.vertices[loop[k - 1]] - v
    b = poly.vertices[loop[(k + 1) % len(loop)]] - v
    n = poly.face_normals[face]
    ang = np.arctan2(np.cross(b, a) @ n, a @ b)
    return float(ang % (2 * np.pi))


def circle_vertex(poly: Polyhedron, vertex: int, from_edge: int, across_face: int, radius: float) -> VertexHit:
    """Circle ``vertex`` from ``from_edge`` across ``across_face`` to that face's other edge at the vertex."""
    e_in, e_out = face_edges_at_vertex(poly, across_face, vertex)
    if from_edge not in (e_in, e_out):
        raise ValueError(f"edge {from_edge} does not meet vertex {vertex} on face {across_face}")
    nxt = e_out if from_edge == e_in else e_in
    ang = corner_angle(poly, across_face, vertex)
    return VertexHit(
        edge=nxt, next_face=other_face(poly, nxt, across_face), angle=ang, arc_length=float(radius * ang)
    )


def random_face_point(poly: Polyhedron, face: int, rng: np.random.Generator, margin: float = 0.0) -> np.ndarray:
    """A random point inside ``face`` at least ``margin`` from its boundary (rejection sampling)."""
    loop = poly.faces[face]
    pts = poly.vertices[list(loop)]
    u, w = plane_basis(poly.face_normals[face])
    uv = np.column_stack([pts @ u, pts @ w])
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    origin = poly.face_normals[face] * poly.face_offsets[face]
    for _ in range(10_000):
        q = rng.uniform(lo, hi)
        if inside_polygon(q, uv) and boundary_distance(q, uv) >= margin:
            return origin + q[0] * u + q[1] * w
    # a face too small for the margin: its centroid-like interior point
    return pts.mean(axis=0)


def inside_polygon(q: np.ndarray, poly2: np.ndarray) -> bool:
    """Whether the 2-D point ``q`` lies inside the polygon of vertices ``poly2`` (n, 2) (even-odd rule)."""
    x, y = q
    inside = False
    n = len(poly2)
    for i in range(n):
        x0, y0 = poly2[i]
        x1, y1 = poly2[(i + 1) % n]
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def boundary_distance(q: np.ndarray, poly2: np.ndarray) -> float:
    """Distance of the 2-D point ``q`` from the boundary of the polygon of vertices ``poly2`` (n, 2)."""
    a = poly2
    b = np.roll(poly2, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", q - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
    return float(np.min(np.linalg.norm(a + t[:, None] * ab - q, axis=1)))
