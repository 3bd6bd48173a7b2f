"""A convex object's model from the data components alone: planes from the faces, a solid from the planes.

The executor reports every face it meets under a new id (it cannot tell that it touches a face again), so the
data faces are first grouped into the planes of the object (:func:`face_planes`): two data faces are one plane
when their normals and points agree within their error bounds. Each plane is fitted to every point known to lie
on it -- the touched points of its faces, the explored ends of the edges between its faces and the data vertices
on those edges -- with the measured normals as a prior (:func:`fit_plane`).

The solid is the intersection of the planes' inner half-spaces (:func:`convex_estimate`, with
``scipy.spatial.HalfspaceIntersection``), bounded by a box well outside the data where the data do not bound it
yet: the box's faces are the object's unmeasured boundary. Its vertices are then checked against the data
vertices (:class:`ConvexEstimate`): the surface is *closed* when every face is a measured plane and every vertex
was met by the sensor, for a face that the data miss would cut off at least one vertex of the estimate.

Where noisy planes meet at a vertex of more than three faces they do not meet in one point but along an edge
too short for the data to tell from a point; such edges (shorter than :meth:`LearnBounds.merge_length`, and not
split by two data vertices farther apart than their bounds) are contracted (:func:`learned_model`). The result
passes the validation of an imported model file, at the precision the data support.

Each plane's fit holds the measured vertices of the estimate's vertices on it (:func:`anchored`), not only those
its data edges reach. On the table (the simulated hand), the table's top is the plane of the face the object rests
on, which the pad never touches (:meth:`Plane.table_top`); a vertex on it is placed by the planes through it.

Tolerances come from the data's own error bounds (:class:`LearnBounds`). Pure numpy and scipy.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from haptic.errors import ModelError
from haptic.geometry.polyhedron import LearnedBounds, Polyhedron
from haptic.geometry.se3 import plane_basis
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex

BOX_MARGIN = 0.1
"""How far outside the data the box that bounds an open estimate lies [m]."""
BOUND_FLOOR = 1e-6
"""Smallest error bound used for a noiseless component: positions [m], angles [rad]."""
MERGE_FACTOR = 2.0
"""An edge of the estimate shorter than this many times the error of a vertex placed by planes is noise (two
noisy planes where one vertex of more than three faces is) [-]."""
REGROUP_ROUNDS = 3
"""Rounds of regrouping the data faces once every plane is fitted (:func:`face_planes`)."""
NUMERIC = 1e-9
"""Vertices of the half-space intersection closer than this, relative to the size, are one point [-]."""


class LearnError(ModelError):
    """The data do not make a model: no bounded solid, an object that is not convex, an estimate not closed."""


@dataclass(frozen=True)
class LearnBounds:
    """The error bounds of the data a model is learned from: the largest of each kind over the components."""

    normal: float
    """Face normal direction [rad]."""
    position: float
    """Position perpendicular to a face, an edge, or of a vertex [m]."""
    direction: float
    """Edge direction [rad]: the data edges', and at least what a model edge where two fitted planes meet square is
    off by, each plane tilted toward it by up to :attr:`normal` (``√2 normal``; the learned FRAME01 with a vertex
    moved 2 mm had an edge 0.65° off, which with a data edge at its bound turned a face-edge angle beyond the
    data's 0.9° and a declared 0.9° in quadrature). Where two planes meet at a smaller angle, the measured
    vertices at the edge's ends hold it."""
    size: float
    """Size of the data: the diagonal of the box round every measured point [m]."""

    @classmethod
    def of(cls, components: Iterable[DataComponent]) -> LearnBounds:
        nb, pb, db = BOUND_FLOOR, BOUND_FLOOR, BOUND_FLOOR
        for c in components:
            if isinstance(c, DataFace):
                nb, pb = max(nb, c.normal_bound), max(pb, c.position_bound)
            elif isinstance(c, DataEdge):
                db, pb = max(db, c.direction_bound), max(pb, c.position_bound)
            else:
                pb = max(pb, c.position_bound)
        pts = data_points(components)
        size = float(np.linalg.norm(np.ptp(pts, axis=0))) if len(pts) else 0.0
        return cls(nb, pb, max(db, float(np.sqrt(2.0)) * nb), size)

    @property
    def vertex(self) -> float:
        """How far a vertex placed by three fitted planes may lie from the true one [m]: a plane's offset, and
        its tilt over the size of the data."""
        return self.position + self.size * np.sin(self.normal)

    @property
    def merge_length(self) -> float:
        """Edges of an estimate shorter than this are contracted into one vertex [m]."""
        return MERGE_FACTOR * self.vertex

    def to_json(self) -> dict:
        return {"normal_rad": self.normal, "position_m": self.position, "direction_rad": self.direction,
                "size_m": self.size}  # fmt: skip


def data_points(components: Iterable[DataComponent]) -> np.ndarray:
    """Every measured point: touched points, explored edge ends, vertices, shape (P, 3) [m]."""
    pts: list[np.ndarray] = []
    for c in components:
        if isinstance(c, DataFace):
            pts.extend(c.points)
        elif isinstance(c, DataEdge):
            pts.extend((c.point, c.end_point))
        else:
            pts.append(c.position)
    return np.array(pts, dtype=float).reshape(-1, 3)


# ------------------------------------------------------------------------------------------------- planes


@dataclass(frozen=True, eq=False)
class Plane:
    """One plane of the object: the data faces on it, fitted."""

    normal: np.ndarray
    """Outward unit normal, shape (3,)."""
    offset: float
    """``d`` with ``n·w − d = 0`` [m]."""
    faces: tuple[int, ...]
    """Ids of the data faces on it."""
    normal_bound: float
    """The largest error bound of its faces' normals [rad]."""
    position_bound: float
    """The largest error bound of its faces' points [m]."""
    points: np.ndarray | None = None
    """The points it is fitted to: its faces' touched points, the edge ends and vertices on it, shape (P, 3) [m]."""
    fold_line: tuple[np.ndarray, np.ndarray] | None = None
    """The measured edge's line it is fitted through, a point and a unit direction (a fold, :func:`face_planes`);
    None when free."""
    table: bool = False
    """Whether it is the table's top, which the object rests on (:meth:`table_top`): no data face on it."""

    @classmethod
    def table_top(cls, table_z: float) -> Plane:
        """The table's top at height ``table_z`` [m] as a plane of an object resting on it (outward normal down).
        The pad cannot touch within a few millimetres of the table, so the face the object rests on is never
        measured; it is where the table is."""
        return cls(np.array([0.0, 0.0, -1.0]), -float(table_z), (), BOUND_FLOOR, BOUND_FLOOR, table=True)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance of ``points`` from the plane (positive outside) [m]."""
        return np.asarray(points) @ self.normal - self.offset


def edge_faces(components: Mapping[int, DataComponent]) -> dict[int, set[int]]:
    """The data faces on either side of each data edge: those it names (its side points, its adjacency) and
    those that name it."""
    out: dict[int, set[int]] = {}
    for c in components.values():
        if isinstance(c, DataEdge):
            s = out.setdefault(c.id, set())
            s.update(f for f, _ in c.side_points if isinstance(components.get(f), DataFace))
            s.update(a for a in c.adjacent if isinstance(components.get(a), DataFace))
    for c in components.values():
        if isinstance(c, DataFace):
            for a in c.adjacent:
                if a in out:
                    out[a].add(c.id)
    return out


def vertex_edges(components: Mapping[int, DataComponent]) -> dict[int, set[int]]:
    """The data edges at each data vertex (those that start or end there, those it names)."""
    out: dict[int, set[int]] = {c.id: set() for c in components.values() if isinstance(c, DataVertex)}
    for c in components.values():
        if isinstance(c, DataEdge):
            for v in (c.start_vertex, c.end_vertex, *c.adjacent):
                if v in out:
                    out[v].add(c.id)
        elif isinstance(c, DataVertex):
            out[c.id].update(a for a in c.adjacent if isinstance(components.get(a), DataEdge))
    return out


def _same_plane(a: DataFace, n: np.ndarray, d: float, pts: np.ndarray, nb: float, pb: float) -> bool:
    """Whether data face ``a`` lies on the plane ``(n, d)`` fitted to ``pts`` within both error bounds."""
    angle = float(np.arccos(np.clip(a.normal @ n, -1.0, 1.0)))
    if angle > a.normal_bound + nb + BOUND_FLOOR:
        return False
    centre = pts.mean(axis=0)
    lever = np.linalg.norm(a.points - centre, axis=1)
    off = np.abs(a.points @ n - d)
    return bool((off <= a.position_bound + pb + lever * np.sin(nb) + BOUND_FLOOR).all())


def _misfit(a: DataFace, n: np.ndarray, d: float, nb: float, pb: float) -> float:
    """How far data face ``a`` is from the plane ``(n, d)``: its normal's angle and its points' mean distance,
    each over its bound [-]."""
    angle = float(np.arccos(np.clip(a.normal @ n, -1.0, 1.0)))
    off = float(np.mean(np.abs(a.points @ n - d)))
    return angle / (a.normal_bound + nb + BOUND_FLOOR) + off / (a.position_bound + pb + BOUND_FLOOR)


def fit_plane(points: np.ndarray, normals: np.ndarray, position_bound: float, normal_bound: float):
    """The plane ``(n, d)`` nearest to ``points`` (each within ``position_bound`` of it) and to the measured
    ``normals`` (each within ``normal_bound``): the smallest eigenvector of
    ``Σ (p − p̄)(p − p̄)ᵀ / σp² + Σ (I − n_j n_jᵀ) / σn²``, turned to agree with the normals."""
    pb, nb = max(position_bound, BOUND_FLOOR), max(normal_bound, BOUND_FLOOR)
    centre = points.mean(axis=0)
    q = points - centre
    a = q.T @ q / pb**2 + (len(normals) * np.eye(3) - normals.T @ normals) / nb**2
    w, v = np.linalg.eigh(a)
    n = v[:, 0]
    mean = normals.sum(axis=0)
    if n @ mean < 0:
        n = -n
    return n / np.linalg.norm(n), float(centre @ n)


SIDE_MISFIT = 1.0
"""A face the side of a fold's edge sends to the other half's group stays where its misfit there (:func:`_misfit`)
is this much more than in its own group [-]."""
FOLD_NEAR = 2.0
"""A data face whose every touched point lies within this many times its and a shallow data edge's position bounds
of that edge (:func:`at_shallow_folds`) is grouped after the others [-]."""


def _segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each of ``points`` from the segment ``a``-``b`` [m]."""
    ab = b - a
    t = np.clip((points - a) @ ab / max(float(ab @ ab), BOUND_FLOOR**2), 0.0, 1.0)
    return np.linalg.norm(points - a - t[:, None] * ab[None], axis=1)


def at_shallow_folds(components: Mapping[int, DataComponent], faces: Iterable[DataFace],
                     ef: Mapping[int, set[int]]) -> set[int]:
    """Ids of the data ``faces`` touched only at a shallow fold: every point within :data:`FOLD_NEAR` times the
    bounds of a data edge between two data faces whose normals agree within their bounds (``ef``:
    :func:`edge_faces`). A vertex moved a few millimetres folds its faces by under a degree: near the fold a
    point lies on both halves' planes within its bound, and the normal there agrees with both, so nothing but
    the edges that divide the face from others says which half it is on (at the moved corner, no point
    can)."""
    shallow = []
    for eid, fs in ef.items():
        side = [components[f] for f in fs if isinstance(components.get(f), DataFace)]
        if any(float(np.arccos(np.clip(a.normal @ b.normal, -1.0, 1.0))) <= a.normal_bound + b.normal_bound
               for i, a in enumerate(side) for b in side[i + 1:]):  # fmt: skip
            shallow.append(components[eid])
    out = set()
    for f in faces:
        pts = np.asarray(f.points, float).reshape(-1, 3)
        for e in shallow:
            tol = FOLD_NEAR * (f.position_bound + e.position_bound)
            if len(pts) and (_segment_distance(pts, e.point, e.end_point) <= tol).all():
                out.add(f.id)
                break
    return out


def _group_fit(g: list[DataFace]) -> tuple[np.ndarray, float, float]:
    """The plane ``(n, d)`` of a group of data faces (:func:`fit_plane`) and its normals' bound [rad]."""
    nb = max(x.normal_bound for x in g)
    n, d = fit_plane(np.concatenate([x.points for x in g]), np.array([x.normal for x in g]),
                     max(x.position_bound for x in g), nb)  # fmt: skip
    return n, d, nb


def _fold_sides(groups: list[list[DataFace]], components: Mapping[int, DataComponent],
                ef: Mapping[int, set[int]], apart: Mapping[int, set[int]]) -> list[list[DataFace]]:
    """``groups`` with the faces of each shallow fold's two groups regrouped by the side of the fold they lie on.

    Two groups divided by data edges whose planes meet at less than :data:`FOLD_FACTOR` times their normals'
    bounds are the halves of a face folded by under a degree or so (a vertex moved almost in its faces' planes):
    there a touched point lies on both planes within its bound, so agreement grouped the faces by the order they
    came in, each half's group holding faces of both. The data edges between them measure the fold's line; each
    group keeps the side most of its faces lie on, and every face of either group whose points all lie on one side,
    clear of the line by
    :data:`FOLD_NEAR` times the bounds and within the fold's measured extent, goes to that side's group where it
    agrees with that group's plane and fits it not clearly worse than its own (:data:`SIDE_MISFIT`), unless a data
    edge divides it from a face there; a face on the line, to the side opposite the faces its data edges divide it
    from, or the side of its point beside the fold's edge (a point touched on it beside the edge). A fold the sides
    would leave with two faces in one group that a data edge divides is left as it is. Groups left empty are
    dropped."""
    groups = [list(g) for g in groups]
    plane_of = {f.id: k for k, g in enumerate(groups) for f in g}
    between: dict[tuple[int, int], list[DataEdge]] = {}
    for eid, fs in ef.items():
        ks = sorted({plane_of[f] for f in fs if f in plane_of})
        if len(ks) == 2:
            between.setdefault((ks[0], ks[1]), []).append(components[eid])
    fits = {k: _group_fit(g) for k, g in enumerate(groups)}
    order = sorted(between.items(), key=lambda kv: -sum(e.length for e in kv[1]))
    for (a, b), edges in order:
        (na, _, ba), (nb_, _, bb) = fits[a], fits[b]
        if float(np.arccos(np.clip(na @ nb_, -1.0, 1.0))) >= FOLD_FACTOR * (ba + bb):
            continue
        ends = np.array([p for e in edges for p in (e.point, e.end_point)])
        centre = ends.mean(axis=0)
        _, sv, vt = np.linalg.svd(ends - centre)
        if sv[0] < BOUND_FLOOR:
            continue
        u = vt[0]
        n = na + nb_
        w = np.cross(n / np.linalg.norm(n), u)
        span = (ends - centre) @ u
        lo, hi = float(span.min()), float(span.max())
        bound = max(e.position_bound for e in edges)
        side: dict[int, float] = {}  # face id -> the side of the line its points lie on (+1, -1)
        for f in [*groups[a], *groups[b]]:
            q = np.asarray(f.points, float).reshape(-1, 3) - centre
            s, t = q @ w, q @ u
            tol = FOLD_NEAR * (f.position_bound + bound)
            if len(q) and (t >= lo).all() and (t <= hi).all() and ((s > tol).all() or (s < -tol).all()):
                side[f.id] = float(np.sign(s[0]))
        for e in edges:  # a face touched on the line itself: the side its point beside the edge is on
            for f, q in e.side_points:
                if plane_of.get(f) in (a, b) and f not in side:
                    s = float((np.asarray(q) - centre) @ w)
                    if abs(s) > FOLD_NEAR * (components[f].position_bound + bound):
                        side[f] = float(np.sign(s))
        both = [*groups[a], *groups[b]]
        # the side each group keeps: the one most of its faces are on (the fewest faces move; either on a tie)
        votes = sum(side.get(f.id, 0.0) for f in groups[a]) - sum(side.get(f.id, 0.0) for f in groups[b])
        to = {(1.0 if votes >= 0 else -1.0): a, (-1.0 if votes >= 0 else 1.0): b}
        # a face goes to the other group only where it agrees with that group's plane, and fits it not clearly worse
        # than its own (by :data:`SIDE_MISFIT`): a face that is not convex (an L's side) can reach across the fold's
        # line beyond the fold, where the planes are far apart
        agree = {}
        for k in (a, b):
            pts = np.concatenate([x.points for x in groups[k]])
            pb_k = max(x.position_bound for x in groups[k])
            agree[k] = (fits[k][0], fits[k][1], pts, fits[k][2], pb_k)
        for f in both:
            here = plane_of[f.id]
            if f.id not in side or to[side[f.id]] == here:
                continue
            n_k, d_k, pts, nb_k, pb_k = agree[to[side[f.id]]]
            n_h, d_h, _, nb_h, pb_h = agree[here]
            if not _same_plane(f, n_k, d_k, pts, nb_k, pb_k) or (
                    _misfit(f, n_k, d_k, nb_k, pb_k) > _misfit(f, n_h, d_h, nb_h, pb_h) + SIDE_MISFIT):
                del side[f.id]
        # a face near the line whose data edge divides it from a face on one side is on the other
        grown = True
        while grown:
            grown = False
            for f in both:
                if f.id in side:
                    continue
                across = {side[x] for x in apart.get(f.id, ()) if x in side}
                if len(across) == 1:
                    side[f.id] = -next(iter(across))
                    grown = True
        new_a = [f for f in both if to.get(side.get(f.id), plane_of[f.id]) == a]
        new_b = [f for f in both if to.get(side.get(f.id), plane_of[f.id]) == b]
        ids_a, ids_b = {f.id for f in new_a}, {f.id for f in new_b}
        if not new_a or not new_b or any(apart.get(f, set()) & ids for ids in (ids_a, ids_b) for f in ids):
            continue  # a face the sides leave with one a data edge divides it from: the fold is left as it was
        groups[a], groups[b] = new_a, new_b
        plane_of.update({f: a for f in ids_a} | {f: b for f in ids_b})
        for k in (a, b):
            if groups[k]:
                fits[k] = _group_fit(groups[k])
    return [g for g in groups if g]


def _merge_agreeing(groups: list[list[DataFace]], apart: Mapping[int, set[int]]) -> list[list[DataFace]]:
    """``groups`` with every two that are one plane merged: no data edge divides a face of one from a face of the
    other, and every face of both agrees with the plane fitted to them all (:func:`_same_plane`), the closest pair
    first. Regrouping moves faces one at a time: where agreement grouped a shallow fold's faces by the order they
    came in (each half's group holding faces of both), moving each to the plane it fits best can leave one half's
    faces in two groups, the one a data edge divides from a face of the other half and the one none does (FRAME01
    with a corner moved 2 mm: a face move that crossed the fold's line split its far half's plane in two, and the
    boundary could not close)."""
    groups = [list(g) for g in groups]
    while True:
        best: tuple[float, int, int] | None = None
        fits = [_group_fit(g) for g in groups]
        for i, gi in enumerate(groups):
            ids_i = {f.id for f in gi}
            for j in range(i + 1, len(groups)):
                gj = groups[j]
                (ni, _, bi), (nj, _, bj) = fits[i], fits[j]
                if float(np.arccos(np.clip(ni @ nj, -1.0, 1.0))) > bi + bj + BOUND_FLOOR:
                    continue
                if any(apart.get(f.id, set()) & ids_i for f in gj):
                    continue
                union = gi + gj
                n, d, nb = _group_fit(union)
                pts = np.concatenate([x.points for x in union])
                pb = max(x.position_bound for x in union)
                if not all(_same_plane(f, n, d, pts, nb, pb) for f in union):
                    continue
                worst = max(_misfit(f, n, d, nb, pb) for f in union)
                if best is None or worst < best[0]:
                    best = (worst, i, j)
        if best is None:
            return groups
        _, i, j = best
        groups[i] = groups[i] + groups.pop(j)


def face_planes(components: Mapping[int, DataComponent], fold_vertices: bool = False) -> list[Plane]:
    """The object's planes: the data faces grouped by agreement (in order of acquisition, those touched only at a
    shallow fold last (:func:`at_shallow_folds`), each joining the plane it agrees with best, by normal, but never
    one that holds a face a data edge divides it from: two faces that meet at an edge are two planes, however small
    the angle between them; a shallow fold's two groups then regrouped by the side of its edge each face lies on,
    :func:`_fold_sides`), each group fitted to its points, edge ends and vertices (:func:`fit_plane`). A fold's two
    planes are fitted through the line of the edge between them, and with ``fold_vertices`` through the vertices
    measured at that edge's ends too (:func:`_fold_vertices`)."""
    faces = [c for c in components.values() if isinstance(c, DataFace)]
    faces.sort(key=lambda c: c.id)
    ef = edge_faces(components)
    apart: dict[int, set[int]] = {}
    for fs in ef.values():
        for a in fs:
            apart.setdefault(a, set()).update(b for b in fs if b != a)
    groups: list[list[DataFace]] = []
    fitted: list[tuple[np.ndarray, float, np.ndarray, float, float]] = []
    # a face touched only at a shallow fold agrees with both halves' planes: grouped after every other face, where
    # the data edges that divide it from faces of one half leave it the other
    late = at_shallow_folds(components, faces, ef)
    for f in [x for x in faces if x.id not in late] + [x for x in faces if x.id in late]:
        agree = [
            (_misfit(f, n, d, nb, pb), k)
            for k, (n, d, pts, nb, pb) in enumerate(fitted)
            if not apart.get(f.id, set()) & {x.id for x in groups[k]} and _same_plane(f, n, d, pts, nb, pb)
        ]  # fmt: skip
        if not agree:
            groups.append([f])
            fitted.append((f.normal.copy(), f.offset, np.array(f.points), f.normal_bound, f.position_bound))
            continue
        k = min(agree)[1]
        _, _, _, nb, pb = fitted[k]
        g = groups[k]
        g.append(f)
        allp = np.concatenate([x.points for x in g])
        nn, dd = fit_plane(allp, np.array([x.normal for x in g]), max(x.position_bound for x in g),
                           max(x.normal_bound for x in g))  # fmt: skip
        fitted[k] = (nn, dd, allp, max(nb, f.normal_bound), max(pb, f.position_bound))
    # every face again to the plane it agrees with best, now that the planes are fitted to all their faces (a face
    # grouped early, by a touch or two, may fit another plane better)
    for _ in range(REGROUP_ROUNDS):
        moved = False
        for f in faces:
            here = next(k for k, g in enumerate(groups) if f in g)
            if len(groups[here]) == 1:
                continue
            agree = [
                (_misfit(f, n, d, nb, pb), k)
                for k, (n, d, pts, nb, pb) in enumerate(fitted)
                if not apart.get(f.id, set()) & {x.id for x in groups[k] if x is not f}
                and _same_plane(f, n, d, pts, nb, pb)
            ]  # fmt: skip
            if not agree or min(agree)[1] == here:
                continue
            k = min(agree)[1]
            groups[here].remove(f)
            groups[k].append(f)
            for j in (here, k):
                g = groups[j]
                allp = np.concatenate([x.points for x in g])
                nn, dd = fit_plane(allp, np.array([x.normal for x in g]), max(x.position_bound for x in g),
                                   max(x.normal_bound for x in g))  # fmt: skip
                fitted[j] = (nn, dd, allp, max(x.normal_bound for x in g), max(x.position_bound for x in g))
            moved = True
        if not moved:
            break
    groups = _fold_sides(_merge_agreeing(groups, apart), components, ef, apart)
    # the edges and vertices on each plane join its fit
    plane_of = {f.id: k for k, g in enumerate(groups) for f in g}
    extra: list[list[np.ndarray]] = [[] for _ in groups]
    ef = edge_faces(components)
    for eid, fs in ef.items():
        e = components[eid]
        for k in {plane_of[f] for f in fs if f in plane_of}:
            extra[k].extend((e.point, e.end_point))
    for vid, es in vertex_edges(components).items():
        v = components[vid]
        ks = {plane_of[f] for e in es for f in ef.get(e, ()) if f in plane_of}
        for k in ks:
            extra[k].append(v.position)
    planes = []
    fits = []
    for k, g in enumerate(groups):
        pts = np.concatenate([np.concatenate([x.points for x in g]), np.array(extra[k]).reshape(-1, 3)])
        nb = max(x.normal_bound for x in g)
        pb = max(x.position_bound for x in g)
        n, d = fit_plane(pts, np.array([x.normal for x in g]), pb, nb)
        planes.append(Plane(n, d, tuple(x.id for x in g), nb, pb, pts))
        fits.append((pts, np.array([x.normal for x in g])))
    # a fold: two planes a data edge divides at an angle their normals' bounds hardly tell apart (a vertex moved
    # almost in its face's plane) meet, fitted each on its own, wherever their small errors put the line, far from
    # the edge the data measured; each is fitted again through the measured edge's line
    folds: dict[tuple[int, int], list[np.ndarray]] = {}
    for eid, fs in ef.items():
        ks = sorted({plane_of[f] for f in fs if f in plane_of})
        if len(ks) == 2:
            e = components[eid]
            folds.setdefault((ks[0], ks[1]), []).extend((e.point, e.end_point))
    if fold_vertices:
        _fold_vertices(folds, components, ef, plane_of)
    held: set[int] = set()
    for (a, b), ends in sorted(folds.items(), key=lambda kv: -float(np.ptp(np.array(kv[1]), axis=0).max())):
        pa, pb_ = planes[a], planes[b]
        angle = float(np.arccos(np.clip(pa.normal @ pb_.normal, -1.0, 1.0)))
        if angle >= FOLD_FACTOR * (pa.normal_bound + pb_.normal_bound) or a in held or b in held:
            continue
        line = np.array(ends)
        centre = line.mean(axis=0)
        _, sv, vt = np.linalg.svd(line - centre)
        if sv[0] < BOUND_FLOOR:
            continue
        for k in (a, b):
            n = _plane_through_line(fits[k][0], fits[k][1], centre, vt[0], planes[k].position_bound,
                                    planes[k].normal_bound)  # fmt: skip
            planes[k] = replace(planes[k], normal=n, offset=float(centre @ n), fold_line=(centre, vt[0]))
            held.add(k)
    return planes


def _fold_vertices(folds: dict[tuple[int, int], list[np.ndarray]], components: Mapping[int, DataComponent],
                   ef: Mapping[int, set[int]], plane_of: Mapping[int, int]) -> None:
    """Each fold's line points (``folds``: plane pair → its data edges' ends) joined by the data vertices at those
    edges that lie on the edges' own line within the bounds: the vertices span the edge end to end, where its
    data edges, measured over a few centimetres, tilt it by their direction's error over the edge's length."""
    at_edge: dict[int, list[DataVertex]] = {}
    for vid, es in vertex_edges(components).items():
        for e in es:
            at_edge.setdefault(e, []).append(components[vid])
    fold_edges: dict[tuple[int, int], list[DataEdge]] = {}
    for eid, fs in ef.items():
        ks = sorted({plane_of[f] for f in fs if f in plane_of})
        if len(ks) == 2:
            fold_edges.setdefault((ks[0], ks[1]), []).append(components[eid])
    for pair, es in fold_edges.items():
        ends = folds[pair]
        line = np.array(ends)
        centre = line.mean(axis=0)
        u = np.linalg.svd(line - centre)[2][0]
        for e in es:
            for v in at_edge.get(e.id, ()):
                r = v.position - centre
                off = float(np.linalg.norm(r - (r @ u) * u))
                if off <= v.position_bound + e.position_bound + abs(float(r @ u)) * np.sin(e.direction_bound):
                    ends.append(v.position)


FOLD_FACTOR = 2.0
"""Two planes a data edge divides meet at a fold (:func:`face_planes`) when the angle between them is below this
many times the sum of their normals' bounds [-]: their fitted lines of intersection are then off by the planes'
offset errors over the angle's sine, more than the measured edge's own bound."""


def _plane_through_line(points: np.ndarray, normals: np.ndarray, centre: np.ndarray, direction: np.ndarray,
                        position_bound: float, normal_bound: float) -> np.ndarray:
    """The unit normal of the plane through the line ``centre + s direction`` nearest to ``points`` and to the
    measured ``normals`` (:func:`fit_plane`'s criterion, the normal kept perpendicular to the line)."""
    pb, nb = max(position_bound, BOUND_FLOOR), max(normal_bound, BOUND_FLOOR)
    q = points - centre
    a = q.T @ q / pb**2 + (len(normals) * np.eye(3) - normals.T @ normals) / nb**2
    u = np.cross(direction, np.eye(3)[int(np.argmin(np.abs(direction)))])
    u /= np.linalg.norm(u)
    basis = np.stack([u, np.cross(direction, u)], axis=1)
    _, v = np.linalg.eigh(basis.T @ a @ basis)
    n = basis @ v[:, 0]
    if n @ normals.sum(axis=0) < 0:
        n = -n
    return n / np.linalg.norm(n)


def anchored(planes: list[Plane], components: Mapping[int, DataComponent],
             anchors: Mapping[int, Iterable[np.ndarray]]) -> list[Plane]:
    """The planes fitted again with the measured vertices found on them (``anchors``: plane index → vertex
    positions). A data vertex joins the fit of the planes its data edges lie between only (:func:`face_planes`);
    a plane touched near one corner, and met at its far corners by vertices reached along other faces' edges, is
    otherwise held there by its measured normals alone, whose error over the face's size puts its far vertices
    further off than the bounds the learned model carries. A plane fitted through a fold's edge stays through
    it."""
    out = list(planes)
    for k, extra in anchors.items():
        extra = [np.asarray(x, float) for x in extra]
        p = planes[k]
        if not extra or p.points is None:
            continue
        pts = np.vstack([p.points, np.array(extra)])
        normals = np.array([components[f].normal for f in p.faces])
        if p.fold_line is None:
            n, d = fit_plane(pts, normals, p.position_bound, p.normal_bound)
        else:
            centre, direction = p.fold_line
            n = _plane_through_line(pts, normals, centre, direction, p.position_bound, p.normal_bound)
            d = float(centre @ n)
        out[k] = replace(p, normal=n, offset=d, points=pts)
    return out


def convexity_violation(components: Mapping[int, DataComponent], planes: list[Plane], bounds: LearnBounds):
    """A measured point outside a plane beyond what the bounds allow (the object is not convex), as
    ``(plane index, distance [m])``, or None."""
    pts = data_points(components.values())
    if not len(pts) or not planes:
        return None
    tol = 2 * bounds.position + bounds.size * np.sin(bounds.normal)
    for k, p in enumerate(planes):
        dist = p.distance(pts)
        if dist.max() > tol:
            return k, float(dist.max())
    return None


# ------------------------------------------------------------------------------------------------- solid


@dataclass(frozen=True, eq=False)
class Polytope:
    """The intersection of half-spaces: vertices, and per plane its face's vertex loop (CCW from outside)."""

    vertices: np.ndarray
    """Vertex positions, shape (V, 3) [m]."""
    normals: np.ndarray
    """Outward unit normals of the planes, shape (P, 3)."""
    offsets: np.ndarray
    """Plane offsets, shape (P,) [m]."""
    loops: dict[int, tuple[int, ...]]
    """Plane index → its face's vertex loop, for the planes that bound the solid."""
    vertex_planes: tuple[frozenset[int], ...]
    """The planes through each vertex."""


def _interior_point(normals: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """The centre of the largest ball inside every half-space ``n·w ≤ d`` (a linear programme)."""
    from scipy.optimize import linprog

    a = np.hstack([normals, np.ones((len(normals), 1))])
    res = linprog(c=[0, 0, 0, -1], A_ub=a, b_ub=offsets, bounds=[(None, None)] * 3 + [(0, None)], method="highs")
    if res.status != 0 or res.x[3] <= 0:
        raise LearnError("the measured faces bound no solid (their half-spaces do not overlap)")
    return res.x[:3]


def intersect(normals: np.ndarray, offsets: np.ndarray) -> Polytope:
    """The solid ``{w : n_i·w ≤ d_i for every i}`` (bounded by the planes given) with its faces."""
    from scipy.spatial import HalfspaceIntersection, QhullError

    normals, offsets = np.asarray(normals, float), np.asarray(offsets, float)
    inside = _interior_point(normals, offsets)
    try:
        hs = HalfspaceIntersection(np.hstack([normals, -offsets[:, None]]), inside)
    except QhullError as exc:
        raise LearnError(f"the half-space intersection failed ({str(exc).splitlines()[0]})") from None
    pts = hs.intersections
    size = float(np.linalg.norm(np.ptp(pts, axis=0)))
    # points of one vertex (qhull reports a vertex of more than three planes once per three of them)
    tol = NUMERIC * max(size, 1.0) * 1e3
    owner = np.arange(len(pts))
    for i in range(len(pts)):
        if owner[i] != i:
            continue
        near = np.flatnonzero(np.linalg.norm(pts - pts[i], axis=1) < tol)
        owner[near[near > i]] = i
    keep = np.unique(owner)
    index = {int(o): k for k, o in enumerate(keep)}
    verts = pts[keep]
    vplanes: list[set[int]] = [set() for _ in keep]
    for i, facet in enumerate(hs.dual_facets):
        vplanes[index[int(owner[i])]].update(int(j) for j in facet)
    # every plane through a vertex within round-off counts (a vertex of more than three planes)
    dist = verts @ normals.T - offsets[None, :]
    for k in range(len(verts)):
        vplanes[k].update(int(j) for j in np.flatnonzero(np.abs(dist[k]) < tol))
    loops: dict[int, tuple[int, ...]] = {}
    for j in range(len(normals)):
        ids = [k for k in range(len(verts)) if j in vplanes[k]]
        if len(ids) < 3:
            continue
        u, w = plane_basis(normals[j])
        c = verts[ids].mean(axis=0)
        ang = [np.arctan2((verts[k] - c) @ w, (verts[k] - c) @ u) for k in ids]
        loops[j] = tuple(ids[i] for i in np.argsort(ang))
    return Polytope(verts, normals, offsets, loops, tuple(frozenset(s) for s in vplanes))


def box_planes(points: np.ndarray, margin: float = BOX_MARGIN) -> tuple[np.ndarray, np.ndarray]:
    """The six planes of the axis-aligned box ``margin`` outside ``points``."""
    lo, hi = points.min(axis=0) - margin, points.max(axis=0) + margin
    normals = np.vstack([np.eye(3), -np.eye(3)])
    return normals, np.concatenate([hi, -lo])


@dataclass(eq=False)
class ConvexEstimate:
    """The object as the data so far bound it: the measured planes cut from a box round the data, with which
    of its faces, edges and vertices the data measured."""

    planes: list[Plane]
    """The object's planes found so far (:func:`face_planes`)."""
    polytope: Polytope
    """Their solid, bounded by :func:`box_planes` where they leave it open (planes ``len(planes)`` and on)."""
    bounds: LearnBounds
    """The data's error bounds."""
    vertex_data: dict[int, int]
    """Data vertex → the vertex of the polytope nearest to it, when within :attr:`LearnBounds.vertex` plus the
    data vertex's bound."""
    groups: list[list[int]] = field(default_factory=list)
    """The polytope's vertices grouped into the object's vertices (edges too short to be real contracted)."""
    measured: set[int] = field(default_factory=set)
    """Vertices of the polytope within the bounds of a data vertex."""

    @property
    def n_planes(self) -> int:
        return len(self.planes)

    def is_box_plane(self, j: int) -> bool:
        """Whether plane ``j`` of the polytope is the bounding box's (unmeasured boundary)."""
        return j >= self.n_planes

    def open_faces(self) -> list[int]:
        """Box planes that bound the polytope: where the object's surface is not measured yet."""
        return [j for j in self.polytope.loops if self.is_box_plane(j)]

    def group_of(self) -> dict[int, int]:
        return {k: g for g, ks in enumerate(self.groups) for k in ks}

    def unmeasured_vertices(self) -> list[int]:
        """Groups (object vertices) no data vertex was measured at (box corners included)."""
        measured = {self.group_of()[k] for k in self.measured}
        return [g for g in range(len(self.groups)) if g not in measured]

    @property
    def closed(self) -> bool:
        """Every face a measured plane and every vertex measured."""
        return not self.open_faces() and not self.unmeasured_vertices()

    def counts(self) -> dict:
        """What is measured of the estimate: planes, open (box) faces, vertices measured of all."""
        return {"planes": self.n_planes, "open_faces": len(self.open_faces()), "vertices": len(self.groups),
                "vertices_measured": len(self.groups) - len(self.unmeasured_vertices())}  # fmt: skip


def _polytope_edges(poly: Polytope) -> set[tuple[int, int]]:
    out = set()
    for loop in poly.loops.values():
        for a, b in zip(loop, loop[1:] + loop[:1], strict=True):
            out.add((min(a, b), max(a, b)))
    return out


def convex_estimate(components: Mapping[int, DataComponent], bounds: LearnBounds | None = None,
                    table_z: float | None = None) -> ConvexEstimate:
    """The :class:`ConvexEstimate` of the data so far (a :class:`LearnError` when they bound no solid). With a
    table (``table_z``, its top's height [m]) the object rests on it: the table's top is one of its planes, and a
    vertex on it is measured when the other planes through it are (:meth:`Plane.table_top`)."""
    bounds = bounds or LearnBounds.of(components.values())
    planes = face_planes(components)
    if not planes:
        raise LearnError("no face measured")
    if table_z is not None:
        planes.append(Plane.table_top(table_z))
    est = _estimate(planes, components, bounds)
    # every measured vertex joins the fit of each plane through the estimate's vertex it measures
    anchors: dict[int, list[np.ndarray]] = {}
    gof = est.group_of()
    for vid, k in est.vertex_data.items():
        pos = components[vid].position
        through = set().union(*(est.polytope.vertex_planes[m] for m in est.groups[gof[k]]))
        for j in through:
            if j < len(planes) and planes[j].points is not None and not (planes[j].points == pos).all(axis=1).any():
                anchors.setdefault(j, []).append(pos)
    if not anchors:
        return est
    return _estimate(anchored(planes, components, anchors), components, bounds)


def _estimate(planes: list[Plane], components: Mapping[int, DataComponent], bounds: LearnBounds) -> ConvexEstimate:
    """The :class:`ConvexEstimate` of ``planes``: their solid in the box round the data, its vertices matched to
    the data vertices and grouped."""
    pts = data_points(components.values())
    bn, bd = box_planes(pts)
    normals = np.vstack([np.array([p.normal for p in planes]), bn])
    offsets = np.concatenate([np.array([p.offset for p in planes]), bd])
    poly = intersect(normals, offsets)
    est = ConvexEstimate(planes, poly, bounds, {})
    verts = [c for c in components.values() if isinstance(c, DataVertex)]
    real = [k for k in range(len(poly.vertices)) if not any(est.is_box_plane(j) for j in poly.vertex_planes[k])]
    near: dict[int, set[int]] = {k: set() for k in range(len(poly.vertices))}
    for v in verts:
        d = np.linalg.norm(poly.vertices[real] - v.position, axis=1)
        for i in np.flatnonzero(d <= bounds.vertex + v.position_bound):
            near[real[int(i)]].add(v.id)
        if len(d) and d.min() <= bounds.vertex + v.position_bound:
            est.vertex_data[v.id] = real[int(np.argmin(d))]
    # contract the edges that one data vertex measures both ends of and no two data vertices tell apart
    parent = list(range(len(poly.vertices)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    def length(ab: tuple[int, int]) -> float:
        return float(np.linalg.norm(poly.vertices[ab[0]] - poly.vertices[ab[1]]))

    # a vertex on the table, where the pad cannot reach, placed by the table and measured planes alone
    table = {j for j, p in enumerate(planes) if p.table}
    on_table = {k for k in real if poly.vertex_planes[k] & table}

    def apart(x: int, y: int) -> bool:
        """Whether data vertices ``x`` and ``y`` are farther apart than their bounds: two vertices."""
        vx, vy = components[x], components[y]
        return float(np.linalg.norm(vx.position - vy.position)) > vx.position_bound + vy.position_bound

    for a, b in sorted(_polytope_edges(poly), key=length):
        if length((a, b)) >= bounds.merge_length:
            continue
        only_a, only_b = near[a] - near[b], near[b] - near[a]
        if any(apart(x, y) for x in only_a for y in only_b):
            continue  # a data vertex at each end alone, apart: two vertices
        if not (near[a] & near[b]) and not any(not apart(x, y) for x in only_a for y in only_b) \
                and not ({a, b} & on_table and not (only_a and only_b)):
            continue  # no data vertex measures both ends, nor the table one end with no data vertex at the other
        parent[find(a)] = find(b)
    groups: dict[int, list[int]] = {}
    for k in range(len(poly.vertices)):
        groups.setdefault(find(k), []).append(k)
    est.groups = list(groups.values())
    est.measured = {k for k in range(len(poly.vertices)) if near[k] or k in on_table}
    return est


def _lsq_point(normals: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """The point nearest to every plane (least squares)."""
    x, *_ = np.linalg.lstsq(normals, offsets, rcond=None)
    return x


PRECISIONS = (0.0, 5e-7, 5e-6)
"""Precisions a learned model is tried at, finest first [m]: the finest at which its faces are planar. A model
file written with 6 or 5 decimals of metres is read back at the last two (:func:`haptic.geometry.io.text_quantum`)."""
PLANAR_ROUNDS = 200
"""Rounds of :func:`planarize` when a learned model's faces are not planar at any of :data:`PRECISIONS`."""


def learned_model(est: ConvexEstimate, name: str = "learned") -> Polyhedron:
    """The validated model of a closed estimate: each group of the polytope's vertices one vertex, placed where
    its planes meet (least squares), each measured plane one face. Its precision is the finest of
    :data:`PRECISIONS` at which the faces are planar within the model's tolerance (a vertex of more than three
    noisy planes lies on none of them exactly)."""
    if est.open_faces():
        raise LearnError(f"{name}: the surface is not closed: {len(est.open_faces())} faces not measured")
    poly = est.polytope
    gof = est.group_of()
    planes_of = [set().union(*(poly.vertex_planes[k] for k in ks)) for ks in est.groups]
    verts = np.array([_lsq_point(poly.normals[sorted(p)], poly.offsets[sorted(p)]) for p in planes_of])
    faces = []
    for j in sorted(poly.loops):
        loop = []
        for k in poly.loops[j]:
            g = gof[k]
            if not loop or loop[-1] != g:
                loop.append(g)
        while len(loop) > 1 and loop[0] == loop[-1]:
            loop.pop()
        if len(loop) >= 3:
            faces.append(loop)
    used = sorted({g for f in faces for g in f})
    index = {g: i for i, g in enumerate(used)}
    return validated_model(verts[used], [[index[g] for g in f] for f in faces], est.bounds, name)


def validated_model(verts: np.ndarray, faces: list[list[int]], b: LearnBounds, name: str) -> Polyhedron:
    """The model of ``verts`` and ``faces`` (CCW loops) validated like an imported file at the finest of
    :data:`PRECISIONS` its faces are planar at (moved toward planar faces when none: :func:`planarize`), then
    made exactly symmetric under the motions that map it onto itself within the data's bounds
    (:func:`symmetrized`)."""
    last: ModelError | None = None
    learned = LearnedBounds(b.normal, b.position, b.direction)
    model = None
    for attempt in (verts, planarize(verts, faces, PLANAR_ROUNDS)):
        for q in PRECISIONS:
            try:
                model = Polyhedron.from_faces(rounded(attempt, q), faces, name=name, precision=q,
                                              learned_bounds=learned)  # fmt: skip
                break
            except ModelError as exc:
                last = exc
        if model is not None:
            break
    if model is None:
        raise LearnError(f"{name}: the learned solid is not a valid model ({last})")
    sym = symmetrized(model, SYMMETRY_FACTOR * b.position)
    for q in PRECISIONS:
        try:
            return Polyhedron.from_faces(rounded(sym, q), faces, name=name, precision=q, learned_bounds=learned)
        except ModelError:
            continue
    return model


SYMMETRY_FACTOR = 1.3
"""Rigid motions that map a learned model onto itself within this many times the data's position bound are
taken for symmetries of the object (:func:`symmetrized`) [-]. Between what noise and what an object's shape
leave: on the seed library's dimension variants learned at noise 1 (bound 0.6 mm) the true symmetries mapped the
learned vertices onto each other within 0.58 mm at worst (FRAME01 5 % taller), while HEXPRISM01 3 % narrower,
symmetric only under its half turns, came within 0.96 mm under the sixth turns it lost; at twice the bound those
were taken for symmetries and the model made a regular hexagon again (its source, not the object)."""
SYMMETRY_ROUNDS = 50
"""Most rounds of :func:`symmetrized`."""


def symmetrized(model: Polyhedron, eps: float) -> np.ndarray:
    """The vertices of ``model`` made exactly symmetric under the rigid motions that map it onto itself within
    ``eps`` [m]: each vertex the mean of its images under them, the motions fitted again, until they map the
    vertices onto each other to round-off. A model learned from noisy data is symmetric only within its
    bounds; the matcher groups the poses of a model by its exact symmetry group, so an object's symmetric poses
    would otherwise stay apart, never to be told from each other."""
    from haptic.geometry.symmetry import congruence_pairs, fit_rotation

    pairs = congruence_pairs(model, model, eps)
    v = np.array(model.vertices, dtype=float)
    if len(pairs) <= 1:
        return v
    perms = [perm for _, perm in pairs]
    for _ in range(SYMMETRY_ROUNDS):
        acc = np.zeros_like(v)
        worst = 0.0
        for perm in perms:  # the motion carries vertex i to vertex perm[i]
            r, t = fit_rotation(v, v[perm])
            moved = v @ r.T + t
            worst = max(worst, float(np.linalg.norm(moved - v[perm], axis=1).max()))
            acc[perm] += moved
        v = acc / len(perms)
        if worst < NUMERIC * max(float(np.ptp(v)), 1.0):
            break
    return v


def planarize(vertices: np.ndarray, faces: list[list[int]], rounds: int) -> np.ndarray:
    """Vertices moved toward planar faces: in turn, each face's plane fitted to its vertices and each vertex
    placed nearest to its faces' planes (least squares; each round lowers the sum of squared distances)."""
    v = np.array(vertices, dtype=float)
    vfaces: list[list[int]] = [[] for _ in range(len(v))]
    for i, f in enumerate(faces):
        for k in f:
            vfaces[k].append(i)
    for _ in range(rounds):
        normals, offsets = [], []
        for f in faces:
            p = v[f]
            c = p.mean(axis=0)
            _, _, vt = np.linalg.svd(p - c)
            n = vt[2] if vt[2] @ np.cross(p[1] - p[0], p[2] - p[0]) >= 0 else -vt[2]
            normals.append(n)
            offsets.append(float(c @ n))
        normals, offsets = np.array(normals), np.array(offsets)
        v = np.array([_lsq_point(normals[fs], offsets[fs]) for fs in vfaces])
    return v


def rounded(vertices: np.ndarray, precision: float) -> np.ndarray:
    """Coordinates rounded as a file written at ``precision`` (half a unit of its last decimal) holds them."""
    if precision <= 0:
        return np.asarray(vertices, float)
    decimals = decimals_for(precision)
    return np.round(np.asarray(vertices, float), decimals)


def decimals_for(precision: float) -> int:
    """Decimals of metres whose half unit is ``precision`` (5e-6 → 5)."""
    return int(round(-np.log10(2 * precision)))
