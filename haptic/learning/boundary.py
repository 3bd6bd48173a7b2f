"""Any object's model from its traced boundary: planes, edges between them and vertices, stitched by adjacency.

A non-convex object is not the intersection of its planes' half-spaces, so its model is built from the traced
boundary itself (:func:`boundary_estimate`):

- the **planes** are the data faces grouped by agreement (:func:`~haptic.learning.reconstruct.face_planes`);
- the **vertices** are the data vertices grouped by position (two data vertices within their summed bounds are
  one vertex), each placed where the planes of its edges meet (least squares, held to the measured position
  where the planes leave it free);
- the **edges** are the data edges grouped by the pair of planes of their faces and their place on the pair's
  line (intervals that overlap are one edge), each bounded by the vertices its data edges reach; an edge whose
  two faces lie on one plane is *flat* (coplanar faces);
- the **faces** are traced on each plane: every edge on it is a half-edge with the face on its left (the side
  its data put the face on: the points touched beside the edge), a flat edge one each way, and the loops are
  followed turning as far right as the plane's half-edges allow at each vertex.

The boundary is *closed* when every edge reaches a vertex at both ends, every vertex has as many half-edges in as
out on each of its planes (the fan of faces round it is complete), every plane's loops are traced and none is a
hole (a face with a hole lacks the edges that join its loops). :func:`boundary_model` then makes the model,
validated like an imported file (:func:`~haptic.learning.reconstruct.validated_model`).

Tolerances come from the data's error bounds (:class:`~haptic.learning.reconstruct.LearnBounds`). Pure numpy.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import plane_basis
from haptic.learning.reconstruct import (
    BOUND_FLOOR,
    LearnBounds,
    LearnError,
    Plane,
    anchored,
    edge_faces,
    face_planes,
    validated_model,
    vertex_edges,
)
from haptic.matching.components import DataComponent, DataEdge, DataVertex

PRIOR_WEIGHT = 1e-3
"""Weight of a vertex's measured position against its planes when placing it, relative to a plane's [-]: enough
to fix it along the directions its planes leave free, too little to move it off them."""
OVERLAP_FACTOR = 2.0
"""Two data edges on one pair of planes are one edge when their intervals overlap by more than this many times
their length bound [-] (collinear edges that meet at a vertex only touch)."""


@dataclass(eq=False)
class BoundaryEdge:
    """An edge of the object: data edges on one pair of planes, on one stretch of their line."""

    planes: tuple[int, int]
    """The planes of its two faces (one plane twice for a flat edge), lower first."""
    data: list[int]
    """Ids of its data edges."""
    vertices: set[int] = field(default_factory=set)
    """The vertices (groups) its data edges reach."""
    sides: dict[int, list[np.ndarray]] = field(default_factory=dict)
    """Plane → points measured on that plane's face beside the edge [m]."""
    beside: dict[int, tuple[np.ndarray, ...]] = field(default_factory=dict)
    """Plane → the points touched on that plane's faces: those of its data edges' faces, then of every face on the
    plane, shape (P, 3) each [m]. Which side of the edge the face lies on is taken from them where no point of
    :attr:`sides` lies clear of the edge (:func:`_side_from_faces`)."""

    @property
    def flat(self) -> bool:
        return self.planes[0] == self.planes[1]

    @property
    def closed(self) -> bool:
        return len(self.vertices) == 2


@dataclass(eq=False)
class BoundaryEstimate:
    """The object's boundary as the data trace it so far, and what of it is open."""

    planes: list[Plane]
    """The object's planes (:func:`face_planes`)."""
    plane_of: dict[int, int]
    """Data face id → plane."""
    bounds: LearnBounds
    """The data's error bounds."""
    vertex_of: dict[int, int]
    """Data vertex id → vertex (group)."""
    positions: np.ndarray
    """Each vertex's position, shape (V, 3) [m]."""
    vertex_planes: list[set[int]]
    """The planes of each vertex's edges."""
    edges: list[BoundaryEdge]
    """The object's edges found so far."""
    edge_of: dict[int, int]
    """Data edge id → edge."""
    loops: dict[int, list[list[int]]] = field(default_factory=dict)
    """Plane → its traced loops of vertices (CCW about the plane's normal for a face, CW for a hole)."""
    unbalanced: set[tuple[int, int]] = field(default_factory=set)
    """``(vertex, plane)`` where the plane's half-edges in and out of the vertex differ in number: an edge of
    the vertex on that plane is not measured yet."""
    holes: list[tuple[int, list[int]]] = field(default_factory=list)
    """``(plane, loop)`` of each hole traced: a face whose loops are not joined yet."""
    problems: list[str] = field(default_factory=list)
    """Why the boundary cannot be made a model as it stands (edges reaching more than two vertices, ...)."""

    def open_edges(self) -> list[int]:
        return [k for k, e in enumerate(self.edges) if not e.closed]

    def bare_planes(self) -> list[int]:
        """Planes no edge bounds yet."""
        used = {p for e in self.edges for p in e.planes}
        return [k for k in range(len(self.planes)) if k not in used]

    @property
    def closed(self) -> bool:
        return not (self.open_edges() or self.unbalanced or self.holes or self.bare_planes() or self.problems)

    def counts(self) -> dict:
        """What is measured: planes, edges (open), vertices (with an edge missing)."""
        return {"planes": len(self.planes), "edges": len(self.edges), "open_edges": len(self.open_edges()),
                "vertices": len(self.positions), "vertices_open": len({v for v, _ in self.unbalanced}),
                "holes": len(self.holes)}  # fmt: skip


def _edge_vertices(components: Mapping[int, DataComponent]) -> dict[int, set[int]]:
    """The data vertices at each data edge (:func:`~haptic.learning.reconstruct.vertex_edges` turned round)."""
    out: dict[int, set[int]] = {}
    for v, es in vertex_edges(components).items():
        for e in es:
            out.setdefault(e, set()).add(v)
    return out


def _group_vertices(verts: list[DataVertex]) -> dict[int, int]:
    """Data vertex id → group: data vertices within their summed bounds of each other are one vertex."""
    parent = list(range(len(verts)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(len(verts)):
        for j in range(i):
            d = float(np.linalg.norm(verts[i].position - verts[j].position))
            if d <= verts[i].position_bound + verts[j].position_bound + BOUND_FLOOR:
                parent[find(i)] = find(j)
    roots: dict[int, int] = {}
    return {v.id: roots.setdefault(find(i), len(roots)) for i, v in enumerate(verts)}


def _place(planes: list[Plane], ks: set[int], measured: np.ndarray, bound: float) -> np.ndarray:
    """The point nearest to planes ``ks`` (each weighted by its position bound), held to ``measured`` along the
    directions they leave free."""
    rows, rhs = [], []
    for k in sorted(ks):
        p = planes[k]
        w = 1.0 / max(p.position_bound, BOUND_FLOOR)
        rows.append(w * p.normal)
        rhs.append(w * p.offset)
    w = PRIOR_WEIGHT / max(bound, BOUND_FLOOR)
    rows.extend(w * np.eye(3))
    rhs.extend(w * measured)
    x, *_ = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)
    return x


def _line(planes: list[Plane], pair: tuple[int, int], data: list[DataEdge]) -> tuple[np.ndarray, np.ndarray]:
    """A point and unit direction of the line of an edge on ``pair``: where the planes meet, or for a flat edge
    the data edges' own line."""
    mid = np.mean([0.5 * (e.point + e.end_point) for e in data], axis=0)
    if pair[0] != pair[1]:
        a, b = planes[pair[0]], planes[pair[1]]
        u = np.cross(a.normal, b.normal)
        if np.linalg.norm(u) > 1e-9:
            u = u / np.linalg.norm(u)
            m = np.array([a.normal, b.normal, u])
            return np.linalg.solve(m, [a.offset, b.offset, mid @ u]), u
    u = data[0].direction
    return mid, u / np.linalg.norm(u)


def boundary_estimate(components: Mapping[int, DataComponent], bounds: LearnBounds | None = None) -> BoundaryEstimate:
    """The :class:`BoundaryEstimate` of the data so far (a :class:`LearnError` when no face was measured)."""
    bounds = bounds or LearnBounds.of(components.values())
    planes = face_planes(components, fold_vertices=True)
    if not planes:
        raise LearnError("no face measured")
    plane_of = {f: k for k, p in enumerate(planes) for f in p.faces}
    dverts = sorted((c for c in components.values() if isinstance(c, DataVertex)), key=lambda c: c.id)
    vertex_of = _group_vertices(dverts)
    n_v = len(set(vertex_of.values()))
    ev = _edge_vertices(components)
    ef = edge_faces(components)
    problems: list[str] = []
    # data edges by pair of planes, grouped along the pair's line
    by_pair: dict[tuple[int, int], list[DataEdge]] = {}
    for c in sorted((c for c in components.values() if isinstance(c, DataEdge)), key=lambda c: c.id):
        ps = sorted({plane_of[f] for f in ef.get(c.id, []) if f in plane_of})
        if not ps:
            continue
        pair = (ps[0], ps[-1]) if len(ps) <= 2 else None
        if pair is None:
            problems.append(f"data edge {c.id} lies between {len(ps)} planes")
            continue
        if len(ps) == 1 and len(ef.get(c.id, [])) < 2:
            continue  # one face known: its other side not measured (cannot happen with tracing moves)
        by_pair.setdefault(pair, []).append(c)
    dv_pos = {v.id: v.position for v in dverts}
    edges: list[BoundaryEdge] = []
    edge_of: dict[int, int] = {}
    for pair, data in by_pair.items():
        p0, u = _line(planes, pair, data)
        spans = []
        for e in data:
            ts = [float((e.point - p0) @ u), float((e.end_point - p0) @ u)]
            ts += [float((dv_pos[v] - p0) @ u) for v in ev.get(e.id, ())]
            spans.append((min(ts), max(ts), e))
        spans.sort(key=lambda s: s[0])
        groups: list[list] = []
        for lo, hi, e in spans:
            tol = OVERLAP_FACTOR * e.length_bound + BOUND_FLOOR
            if groups and lo < groups[-1][1] - tol:
                groups[-1][1] = max(groups[-1][1], hi)
                groups[-1][2].append(e)
            else:
                groups.append([lo, hi, [e]])
        for _, _, es in groups:
            be = BoundaryEdge(pair, [e.id for e in es])
            for e in es:
                be.vertices.update(vertex_of[v] for v in ev.get(e.id, ()) if v in vertex_of)
                for f, q in e.side_points:
                    if f in plane_of:
                        be.sides.setdefault(plane_of[f], []).append(np.asarray(q))
                for f in sorted(ef.get(e.id, ())):  # no side point: the face's touched point nearest to the edge
                    k = plane_of.get(f)
                    if k is not None and k not in be.sides and not be.flat:
                        pts = components[f].points
                        off = pts - p0 - np.outer((pts - p0) @ u, u)
                        be.sides[k] = [pts[int(np.argmin(np.linalg.norm(off, axis=1)))]]
                edge_of[e.id] = len(edges)
            for k in set(pair):
                own = sorted({f for e in es for f in ef.get(e.id, ()) if plane_of.get(f) == k})
                be.beside[k] = tuple(np.concatenate([np.atleast_2d(components[f].points) for f in fs]).reshape(-1, 3)
                                     for fs in (own, sorted(planes[k].faces)))  # fmt: skip
            if len(be.vertices) > 2:
                problems.append(f"an edge between planes {pair} reaches {len(be.vertices)} vertices")
            edges.append(be)
    edges, edge_of = _drop_shadowed(edges, edge_of)
    # vertices: the planes of their edges, placed where those meet
    vplanes: list[set[int]] = [set() for _ in range(n_v)]
    for be in edges:
        for v in be.vertices:
            vplanes[v].update(be.planes)
    # every measured vertex joins the fit of each plane of its edges (reconstruct.anchored)
    anchors: dict[int, list[np.ndarray]] = {}
    for v in dverts:
        for k in vplanes[vertex_of[v.id]]:
            if planes[k].points is not None and not (planes[k].points == v.position).all(axis=1).any():
                anchors.setdefault(k, []).append(v.position)
    planes = anchored(planes, components, anchors)
    positions = np.zeros((n_v, 3))
    for g in range(n_v):
        members = [v for v in dverts if vertex_of[v.id] == g]
        measured = np.mean([v.position for v in members], axis=0)
        bound = max(v.position_bound for v in members)
        positions[g] = _place(planes, vplanes[g], measured, bound)
    est = BoundaryEstimate(planes, plane_of, bounds, vertex_of, positions, vplanes, edges, edge_of,
                           problems=problems)  # fmt: skip
    _trace_faces(est)
    return est


def _drop_shadowed(edges: list[BoundaryEdge], edge_of: dict[int, int]) -> tuple[list[BoundaryEdge], dict[int, int]]:
    """``edges`` and ``edge_of`` without the edges another shadows: two edges between the same two vertices on one
    plane are one segment of that plane's boundary, so where their other planes differ one of them took its other
    face from a neighbour within the pad's reach of the edge (a fold's sliver that fans in at the edge's end: LBLOCK01
    with a corner moved 2 mm, a wall folded 2° into two triangles, one edge move along the wall's vertical edge read
    the fold's other half). The edge with fewer data edges gives way; its data edges count as the other's."""
    by_ends: dict[frozenset[int], list[int]] = {}
    for k, be in enumerate(edges):
        if be.closed and not be.flat:
            by_ends.setdefault(frozenset(be.vertices), []).append(k)
    into: dict[int, int] = {}
    for ks in by_ends.values():
        for i in ks:
            for j in ks:
                a, b = edges[i], edges[j]
                if len(set(a.planes) & set(b.planes)) == 1 and len(a.data) < len(b.data):
                    into[i] = j
    if not into:
        return edges, edge_of
    kept = [k for k in range(len(edges)) if k not in into]
    new = {k: n for n, k in enumerate(kept)}

    def target(k: int) -> int:
        while k in into:
            k = into[k]
        return new[k]

    return [edges[k] for k in kept], {e: target(k) for e, k in edge_of.items()}


def _half_edges(est: BoundaryEstimate) -> dict[int, list[tuple[int, int, int]]]:
    """Plane → its half-edges ``(from, to, edge)`` with the plane's face on their left (closed edges only)."""
    out: dict[int, list[tuple[int, int, int]]] = {}
    for k, be in enumerate(est.edges):
        if not be.closed:
            continue
        a, b = sorted(be.vertices)
        if be.flat:
            out.setdefault(be.planes[0], []).extend([(a, b, k), (b, a, k)])
            continue
        d = est.positions[b] - est.positions[a]
        for p in be.planes:
            w = np.cross(est.planes[p].normal, d)
            side = np.array([float((q - est.positions[a]) @ w) for q in be.sides.get(p, [])]) / float(np.linalg.norm(w))
            if not len(side):
                est.problems.append(f"edge {k} has no measured point on the face of plane {p}")
                continue
            if not np.any(np.abs(side) > est.bounds.position):
                side = np.append(
                    side, _side_from_faces(be.beside.get(p, ()), est.positions[a], d, w, est.bounds.position)
                )
            left = _left(side, est.bounds.position)
            out.setdefault(p, []).append((a, b, k) if left else (b, a, k))
    return out


def _side_from_faces(beside: tuple[np.ndarray, ...], a: np.ndarray, d: np.ndarray, w: np.ndarray, bound: float
                     ) -> list[float]:  # fmt: skip
    """The signed distance (along ``w``, the plane's normal crossed with the edge's ``d``) from the edge ``a`` to
    ``a + d`` of the touched point nearest to it among those farther than ``bound`` from its line and beside it
    (between its ends): of the first of ``beside``'s point sets that has one (the plane's faces at the edge, then
    all of them); none when none has. A vertex move's only point beside the edge it meets is where its circle met
    it, on the line within the bound: on a sliver face (LBLOCK01 with a corner moved 4 mm folds a wall into two
    triangles, one of them 4 mm across at its end) the face was taken on the wrong side of its edge, the fans at
    the edge's ends never balanced, and the walk went back and forth across another edge until the learning's
    budget ran out."""
    length = float(np.linalg.norm(d))
    u, w = d / length, w / float(np.linalg.norm(w))
    for pts in beside:
        if not len(pts):
            continue
        t = (pts - a) @ u
        off = np.linalg.norm(pts - a - np.outer(t, u), axis=1)
        ok = (off > bound) & (t >= 0.0) & (t <= length)
        if ok.any():
            i = int(np.flatnonzero(ok)[np.argmin(off[ok])])
            return [float((pts[i] - a) @ w)]
    return []


def _left(side: np.ndarray, bound: float) -> bool:
    """Whether the points beside an edge at signed distances ``side`` from it [m] put its face on the left: by the
    points farther from it than the data's position ``bound``, most of them; by the farthest when none is. A
    point touched on the edge itself (an edge traced again, a move along it) is on either side within its
    bound, and such points outvoted the one touched on the face beside it."""
    clear = side[np.abs(side) > bound]
    if not len(clear) or float(np.sum(np.sign(clear))) == 0.0:
        return float(side[int(np.argmax(np.abs(side)))]) > 0
    return float(np.sum(np.sign(clear))) > 0


def _trace_faces(est: BoundaryEstimate) -> None:
    """The loops of every plane (:attr:`BoundaryEstimate.loops`), the vertices whose fan is open on a plane
    and the holes."""
    for p, hes in _half_edges(est).items():
        n = est.planes[p].normal
        x, y = plane_basis(n)
        out_of: dict[int, list[tuple[int, int, int]]] = {}
        into: dict[int, int] = {}
        for h in hes:
            out_of.setdefault(h[0], []).append(h)
            into[h[1]] = into.get(h[1], 0) + 1
        for v in set(out_of) | set(into):
            if len(out_of.get(v, [])) != into.get(v, 0):
                est.unbalanced.add((v, p))
        if any(v == pl for v, pl in est.unbalanced if pl == p):
            continue

        def angle(a: int, b: int, x: np.ndarray = x, y: np.ndarray = y) -> float:
            d = est.positions[b] - est.positions[a]
            return float(np.arctan2(d @ y, d @ x))

        used: set[tuple[int, int, int]] = set()
        loops: list[list[int]] = []
        for h0 in hes:
            if h0 in used:
                continue
            loop, h = [], h0
            while h not in used:
                used.add(h)
                loop.append(h[0])
                a, b, k = h
                back = angle(b, a)
                cands = [c for c in out_of.get(b, []) if c not in used or c == h0]
                if not cands:
                    break
                turn = [((back - angle(b, c[1])) % (2 * np.pi)) or 2 * np.pi for c in cands]
                h = cands[int(np.argmin(turn))]
                if h == h0:
                    break
            if h != h0:
                est.problems.append(f"a loop on plane {p} does not close")
                continue
            pts = est.positions[loop]
            q = np.stack([pts @ x, pts @ y], axis=1)
            area = 0.5 * float(np.sum(q[:, 0] * np.roll(q[:, 1], -1) - np.roll(q[:, 0], -1) * q[:, 1]))
            if area < 0:
                est.holes.append((p, loop))
            loops.append(loop)
        est.loops[p] = loops


def boundary_model(est: BoundaryEstimate, name: str = "learned") -> Polyhedron:
    """The validated model of a closed boundary estimate: its vertices, each face a traced loop
    (:func:`~haptic.learning.reconstruct.validated_model`)."""
    if not est.closed:
        c = est.counts()
        raise LearnError(f"{name}: the surface is not closed: {c['open_edges']} edges open, {c['vertices_open']} "
                         f"vertices with an edge missing, {c['holes']} holes"
                         + (f" ({est.problems[0]})" if est.problems else ""))  # fmt: skip
    faces = [loop for p in sorted(est.loops) for loop in est.loops[p]]
    used = sorted({v for f in faces for v in f})
    index = {v: i for i, v in enumerate(used)}
    return validated_model(est.positions[used], [[index[v] for v in f] for f in faces], est.bounds, name)
