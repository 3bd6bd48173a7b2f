"""Perturbed variants of a model: objects close to a library model but not in it.

They are what a user's real part looks like next to the library's nominal model (one dimension off, a corner
dented, an edge broken), and what the verification before recognition must turn away as ``no-match``. Each
function returns a new validated :class:`Polyhedron`; geometry that the change would invalidate (a vertex moved
through a face, a chamfer larger than its faces) raises :class:`~haptic.errors.ModelError`.
"""

from __future__ import annotations

import numpy as np

from haptic.errors import ModelError
from haptic.geometry.polyhedron import Polyhedron, triangulate_polygon


def scale_dimension(poly: Polyhedron, axis: int, factor: float, name: str | None = None) -> Polyhedron:
    """The model stretched by ``factor`` along model axis ``axis`` (0, 1, 2) about its centroid: an affine map,
    so faces stay planar (a box 100 mm long becomes 103 mm long at factor 1.03)."""
    if axis not in (0, 1, 2) or not np.isfinite(factor) or factor <= 0:
        raise ModelError(f"{poly.name}: scale_dimension takes axis 0, 1 or 2 and a factor > 0, got {axis}, {factor}")
    v = np.array(poly.vertices)
    c = poly.centroid
    v[:, axis] = c[axis] + factor * (v[:, axis] - c[axis])
    # the source's rounding is stretched with it: the tolerances follow (:func:`scaled_to`)
    return Polyhedron.from_faces(v, poly.faces, name=name or f"{poly.name}_x{axis}_{factor:g}", source=poly.source,
                                 precision=poly.precision * max(1.0, factor), vertex_labels=poly.vertex_labels)


def scaled_to(poly: Polyhedron, extent: float, name: str | None = None) -> Polyhedron:
    """The model scaled about the origin so that its largest extent (bounding box) is ``extent`` [m]: the
    same solid at another size (a library at the sizes a hand must explore). The source's rounding
    (:attr:`~haptic.geometry.polyhedron.Polyhedron.precision`) is scaled with it, and the tolerances follow: the
    dodecahedron of ``assets/libraries/polyhedra`` (30 mm, coordinates to 0.5 µm, a face 0.3 µm off its plane)
    scaled to 150 mm is the same solid, its face 1.6 µm off, where a tolerance from the unscaled precision refused
    it as not planar."""
    if not np.isfinite(extent) or extent <= 0:
        raise ModelError(f"{poly.name}: scaled_to takes an extent > 0 [m], got {extent}")
    f = extent / float(np.max(poly.extents))
    return Polyhedron.from_faces(np.array(poly.vertices) * f, poly.faces, name=name or poly.name, source=poly.source,
                                 precision=poly.precision * f, vertex_labels=poly.vertex_labels)


def vertex_normal(poly: Polyhedron, vertex: int) -> np.ndarray:
    """Unit mean of the outward normals of the faces at ``vertex`` (weighted equally)."""
    n = poly.face_normals[list(poly.vertex_faces[vertex])].sum(axis=0)
    return n / max(float(np.linalg.norm(n)), 1e-12)


def move_vertex(poly: Polyhedron, vertex: int, offset: float, name: str | None = None,
                direction: np.ndarray | None = None) -> Polyhedron:  # fmt: skip
    """The model with one vertex moved ``offset`` [m] along its outward vertex normal (:func:`vertex_normal`), or
    along the unit ``direction`` where given (along a face's normal, along an edge).

    Each face at the vertex keeps its plane away from it: the corner triangle (the vertex and its two
    neighbours in the loop) becomes a face of its own, tilted, and the rest of the face stays (a triangle face
    tilts whole; a face the move runs in the plane of stays whole). Where the corner triangle would leave the
    face (a reflex corner: the inner corners of a slot or a step on its end faces) the face's triangles at the
    vertex (:func:`reflex_fan`) tilt, each a face of its own, and the rest of the face stays, one face per piece
    between them: triangulated whole, the triangles away from the vertex would stay coplanar neighbours, which no
    model may have.
    """
    v = np.array(poly.vertices)
    moved = v.copy()
    along = vertex_normal(poly, vertex) if direction is None else np.asarray(direction, dtype=float)
    moved[vertex] = v[vertex] + offset * along
    faces: list[tuple[int, ...]] = []
    for fi, loop in enumerate(poly.faces):
        if vertex not in loop or len(loop) == 3 or abs(float(poly.face_normals[fi] @ along)) < 1e-9:
            faces.append(loop)
            continue
        k = loop.index(vertex)
        prev, nxt = loop[k - 1], loop[(k + 1) % len(loop)]
        n = poly.face_normals[fi]
        convex_corner = float(np.cross(v[vertex] - v[prev], v[nxt] - v[vertex]) @ n) > 0
        if convex_corner:
            inside = [i for i in loop if i not in (prev, vertex, nxt) and _in_triangle(v, (prev, vertex, nxt), i, n)]
            if inside:
                raise ModelError(
                    f"{poly.name}: moving vertex {vertex} would cut the corner triangle {(prev, vertex, nxt)} off "
                    f"face {fi}, which holds vertex {inside[0]} of that face (another vertex can be moved)"
                )
            faces.append((prev, vertex, nxt))
            faces.append(tuple(i for i in loop if i != vertex))
        else:
            fan, rest = reflex_fan(v, loop, n, vertex)
            faces.extend(fan)
            faces.extend(rest)
    return Polyhedron.from_faces(moved, faces, name=name or f"{poly.name}_v{vertex}_{offset * 1e3:g}mm")


def reflex_fan(v: np.ndarray, loop: tuple[int, ...], normal: np.ndarray, vertex: int
               ) -> tuple[list[tuple[int, ...]], list[tuple[int, ...]]]:  # fmt: skip
    """A face's loop (``v`` the vertex positions, ``normal`` its outward normal) split at ``vertex``: the triangles
    of its triangulation (:func:`~haptic.geometry.polyhedron.triangulate_polygon`) that have ``vertex`` as a
    corner, and the rest of the face as loops, one per piece of the face that they leave (the triangles of a piece
    joined across their shared edges; every loop counterclockwise about ``normal``, as the face's). A move of
    ``vertex`` off the face's plane tilts those triangles and no more of the face."""
    tris = triangulate_polygon(v, loop, normal)
    fan = [t for t in tris if vertex in t]
    rest = [t for t in tris if vertex not in t]
    pieces: list[list[tuple[int, int, int]]] = []
    for t in rest:  # join the triangles that share an edge, piece by piece
        sides = {frozenset(e) for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
        joined = [p for p in pieces if any(sides & {frozenset(e) for q in p
                                                    for e in ((q[0], q[1]), (q[1], q[2]), (q[2], q[0]))})]  # fmt: skip
        merged = [t] + [q for p in joined for q in p]
        pieces = [p for p in pieces if p not in joined] + [merged]
    loops = []
    for p in pieces:
        directed = [e for q in p for e in ((q[0], q[1]), (q[1], q[2]), (q[2], q[0]))]
        inner = set(directed) & {(b, a) for a, b in directed}
        nxt = {a: b for a, b in directed if (a, b) not in inner}
        start = next(iter(nxt))
        out, cur = [start], nxt[start]
        while cur != start:
            if len(out) > len(nxt):
                raise ModelError(f"the rest of face {list(loop)} past vertex {vertex} is not one loop per piece")
            out.append(cur)
            cur = nxt[cur]
        if len(out) != len(nxt):
            raise ModelError(f"the rest of face {list(loop)} past vertex {vertex} is not one loop per piece")
        loops.append(tuple(out))
    return fan, loops


def _in_triangle(v: np.ndarray, tri: tuple[int, int, int], i: int, normal: np.ndarray) -> bool:
    """Whether vertex ``i`` lies in triangle ``tri`` of a face with ``normal`` (on its rim included)."""
    a, b, c = (v[k] for k in tri)
    return all(float(np.cross(q - p, v[i] - p) @ normal) >= 0 for p, q in ((a, b), (b, c), (c, a)))


def chamfer_edge(poly: Polyhedron, edge: int, size: float, name: str | None = None) -> Polyhedron:
    """The model with convex edge ``edge`` bevelled: a plane through the two lines ``size`` [m] in from the edge
    on its two faces cuts the edge off. The cut must stay local: only the edge's two end vertices may lie beyond
    the plane (else :class:`ModelError`)."""
    if poly.edge_convexity[edge] <= 0:
        raise ModelError(f"{poly.name}: edge {edge} is concave; only a convex edge can be chamfered")
    v = np.asarray(poly.vertices)
    p, b = poly.edge_points[edge], poly.edge_directions[edge]
    fl, fr = int(poly.edge_left_face[edge]), int(poly.edge_right_face[edge])
    in_l = np.cross(poly.face_normals[fl], b)  # left face lies left of b: n × b points into it
    in_r = -np.cross(poly.face_normals[fr], b)
    a_l, a_r = p + size * in_l, p + size * in_r
    n = np.cross(b, a_l - a_r)
    n /= np.linalg.norm(n)
    if n @ (p - a_l) < 0:
        n = -n  # n points to the side that is cut off (where the edge is)
    side = (v - a_l) @ n
    ends = set(int(i) for i in poly.edges[edge])
    beyond = {int(i) for i in np.flatnonzero(side > 1e-9)}
    if beyond != ends:
        raise ModelError(
            f"{poly.name}: a {size * 1e3:g} mm chamfer of edge {edge} would cut vertices {sorted(beyond - ends)} "
            "too (a smaller chamfer or another edge would stay local)"
        )
    points: list[np.ndarray] = []

    def index_of(q: np.ndarray) -> int:
        for i, x in enumerate(points):
            if np.linalg.norm(x - q) < 1e-9:
                return i
        points.append(q)
        return len(points) - 1

    keep = {int(i): index_of(v[i]) for i in range(len(v)) if int(i) not in ends}
    faces: list[list[int]] = []
    cut: dict[int, int] = {}  # cap: cut point -> next cut point, following the clipped faces
    for loop in poly.faces:
        out: list[int] = []
        for k, a in enumerate(loop):
            c = loop[(k + 1) % len(loop)]
            if a not in ends:
                out.append(keep[a])
            if (a in ends) != (c in ends):
                t = side[a] / (side[a] - side[c])
                out.append(index_of(v[a] + t * (v[c] - v[a])))
        if len(out) < 3:
            raise ModelError(f"{poly.name}: the {size * 1e3:g} mm chamfer of edge {edge} removes a whole face")
        faces.append(out)
        if len(out) != len(loop) or any(i in ends for i in loop):
            # the cut runs along this face between two new points: the cap runs it the other way
            new = [i for i in out if i >= 0 and not any(np.allclose(points[i], v[j]) for j in keep)]
            for k, i in enumerate(out):
                j = out[(k + 1) % len(out)]
                if i in new and j in new:
                    cut[j] = i
    start = next(iter(cut))
    cap, cur = [start], cut[start]
    while cur != start:
        cap.append(cur)
        cur = cut[cur]
        if len(cap) > len(cut):
            raise ModelError(f"{poly.name}: the chamfer of edge {edge} does not close")
    faces.append(cap)
    return Polyhedron.from_faces(np.array(points), faces, name=name or f"{poly.name}_e{edge}_ch{size * 1e3:g}mm")


__all__ = ["chamfer_edge", "move_vertex", "reflex_fan", "scale_dimension", "vertex_normal"]
