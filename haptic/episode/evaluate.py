"""Scoring of data components against ground truth -- evaluation code, OUTSIDE the executor.

Given the true model and its pose (``Simulation.ground_truth()``), each data component is matched to the nearest
true component of its kind: a face by normal and plane distance, an edge by the distance of its explored interval
from the true edge segment and its direction, a vertex by position. Errors: face normal [deg], edge direction
[deg], edge position [mm] (largest distance of the interval's ends from the true edge line), vertex position
[mm]. A component farther than the tolerances from every true component of its kind is *spurious*. A move whose
reported edge (vertex) is not the first true edge (vertex) the pad must feel on the ideal path from where the
move started (:func:`first_felt_edge`) -- it crossed a true edge without reporting it; a path meeting the
boundary within the position tolerance of a vertex is not checked --, an edge move whose vertex is not an end
of the true edge it followed, and a vertex move whose new edge does not leave the circled vertex on the face
circled across each count one *missed* component.

Every component is also scored **in units of its own error bounds** (:func:`bound_ratios`): each quantity the
pose check of verification tests (:func:`haptic.matching.acceptance.residual_ratios`: a face's normal and
touched points, an edge's direction, line and extent, a vertex's position) at the true pose, against the true
feature of its kind that explains the component best. A ratio above 1 is a component outside its bounds: the
true object itself does not fit it, and a matcher that trusts the bounds may prune the truth or keep a wrong
model.

The executor and the segmenter never import this module.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from haptic.geometry import tracing
from haptic.geometry.distance import point_triangle_distance, surface_distance
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3, cross, plane_basis
from haptic.matching.acceptance import ROUND_OFF, residual_ratios
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex
from haptic.matching.trace import PHASES
from haptic.matching.tree import Interpretation
from haptic.planning.hypothesis import Hypothesis
from haptic.sim.scene import PAD_RADIUS


@dataclass(frozen=True)
class EvaluationTolerances:
    """Beyond these a data component matches no true component (spurious)."""

    normal: float = math.radians(5.0)
    """Face normal [rad]."""
    plane: float = 0.003
    """Mean distance of a face's points from the true plane [m]."""
    direction: float = math.radians(5.0)
    """Edge direction [rad]."""
    position: float = 0.003
    """Edge interval from the true edge segment; vertex from the true vertex [m]."""


@dataclass(frozen=True)
class ComponentScore:
    """One data component against its nearest true component."""

    id: int
    """Data id."""
    kind: str
    """``face`` | ``edge`` | ``vertex``."""
    true_id: int | None
    """Index of the matched true component in the model, None when spurious."""
    angle_deg: float
    """Normal / direction error [deg] (NaN for a vertex)."""
    position_mm: float
    """Plane / line / point distance [mm]."""


@dataclass(frozen=True)
class PerceptionScore:
    """All component scores of an exploration and the counts of spurious and missed components."""

    components: tuple[ComponentScore, ...]
    """Latest report of every data id."""
    spurious: int
    """Data components with no true counterpart within tolerance."""
    missed: int
    """True edges / vertices crossed without being reported (see module doc)."""
    concave_edges_found: int = 0
    """Data edges matched to concave true edges."""
    details: dict = field(default_factory=dict)
    """Per-move checks."""
    ratios: tuple[BoundRatio, ...] = ()
    """Every measured quantity of every component in units of its bound (:func:`bound_ratios`)."""
    hand: dict = field(default_factory=dict)
    """Contacts of links other than the pad (:func:`score_hand`)."""
    wrist: dict = field(default_factory=dict)
    """The wrist force sensor's watch over the moves (:func:`wrist_watch`)."""

    @property
    def outside_bounds(self) -> tuple[int, ...]:
        """Ids of the components with a quantity more than its bound from the best true feature."""
        return tuple(sorted({r.id for r in self.ratios if r.ratio > 1.0}))

    def errors(self, kind: str, what: str) -> np.ndarray:
        """Errors of matched components of ``kind``: ``what`` is ``angle`` or ``position``."""
        vals = [c.angle_deg if what == "angle" else c.position_mm for c in self.components
                if c.kind == kind and c.true_id is not None]  # fmt: skip
        return np.array(vals, dtype=float)

    def summary(self) -> dict:
        """Median and max of each error (JSON-friendly; NaN when there is none)."""

        def stats(a: np.ndarray) -> dict:
            return {
                "median": float(np.median(a)) if len(a) else math.nan,
                "max": float(a.max()) if len(a) else math.nan,
            }

        return {
            "face_normal_deg": stats(self.errors("face", "angle")),
            "edge_direction_deg": stats(self.errors("edge", "angle")),
            "edge_position_mm": stats(self.errors("edge", "position")),
            "vertex_position_mm": stats(self.errors("vertex", "position")),
            "spurious": self.spurious,
            "missed": self.missed,
            "concave_edges_found": self.concave_edges_found,
            "bound_ratio": {
                what: stats(np.array([r.ratio for r in self.ratios if r.what == what])) for what in BOUND_QUANTITIES
            },
            "outside_bounds": len(self.outside_bounds),
            "ratios": [[r.id, r.what, round(r.ratio, 4), r.true_id] for r in self.ratios],
            "hand": self.hand,
            "wrist": self.wrist,
        }


BOUND_QUANTITIES = (
    "face normal", "face point", "edge direction", "edge line", "edge extent", "edge vertex", "vertex"
)  # fmt: skip
"""What :func:`bound_ratios` scores, as the pose check names it, and an edge's ends at its vertices
(:func:`vertex_end_ratios`), which the pose check leaves to the interpretation tree."""


@dataclass(frozen=True)
class BoundRatio:
    """One measured quantity of a data component against the truth, in units of its bound."""

    id: int
    """Data id."""
    what: str
    """One of :data:`BOUND_QUANTITIES`."""
    ratio: float
    """Residual at the true pose over the component's bound (≤ 1: the bound holds)."""
    true_id: int
    """The true feature (model face, edge or vertex index) the component was scored against."""


def bound_ratios(components, model: Polyhedron, world_from_model: SE3) -> list[BoundRatio]:
    """Every quantity of every data component (the latest report of each id) in units of its own bound, at the
    true pose, against the true feature of its kind (and, for an edge, the sense) whose largest ratio is the
    smallest: the feature that explains the component best. The quantities and their residuals are those of
    verification's pose check (:func:`~haptic.matching.acceptance.residual_ratios`), so a ratio above 1 is
    a component that the true object at its true pose does not explain within its bounds."""
    data = {c.id: c for c in _latest(components)}
    out: list[BoundRatio] = []
    for c in data.values():
        if isinstance(c, DataFace):
            options = [({c.id: f}, {}, {}, {}) for f in range(model.n_faces)]
        elif isinstance(c, DataEdge):
            options = [({}, {c.id: e}, {}, {c.id: s}) for e in range(model.n_edges) for s in (1, -1)]
        else:
            near = int(np.argmin(np.linalg.norm(world_from_model.apply(model.vertices) - c.position, axis=1)))
            options = [({}, {}, {c.id: near}, {})]
        best = None
        for faces, edges, vertices, senses in options:
            it = Interpretation(model, 0, faces, edges, vertices, senses, world_from_model, 0)
            rows = residual_ratios(model, data, it, world_from_model)
            if isinstance(c, DataEdge):
                rows += vertex_end_ratios(c, model, edges[c.id], senses[c.id], world_from_model)
            worst = max(r for r, _, _ in rows)
            if best is None or worst < best[0]:
                true_id = next(iter((faces or edges or vertices).values()))
                best = (worst, rows, true_id)
        # one ratio per quantity: the largest (an edge's line is tested at both ends)
        per: dict[str, float] = {}
        for r, _, what in best[1]:
            per[what] = max(per.get(what, 0.0), float(r))
        out += [BoundRatio(c.id, what, r, best[2]) for what, r in per.items()]
    return out


def vertex_end_ratios(
    c: DataEdge, model: Polyhedron, edge: int, sense: int, world_from_model: SE3
) -> list[tuple[float, int, str]]:
    """``(residual / bound, data id, "edge vertex")`` of each end of data edge ``c``'s explored interval that it
    reports at a vertex (``start_vertex`` at ``p``, ``end_vertex`` at ``p + l b``), paired with model ``edge`` in
    ``sense``: how far along the model edge's line that end lies from the model edge's end it claims (its start in
    that sense, or its end), over the edge's length bound λ. The interpretation tree holds such an end to that
    model end within λ and the vertex's bound (:func:`~haptic.matching.constraints.edge_position_test`,
    :func:`~haptic.matching.constraints.vertex_edge_test`, tight at a known vertex); an interval reported starting at
    the vertex it ends at, running on past it, lies a whole edge from the end it claims."""
    out: list[tuple[float, int, str]] = []
    if c.start_vertex is None and c.end_vertex is None:
        return out
    inv = world_from_model.inverse()
    b = model.edge_directions[edge]
    first, last = model.edge_points[edge], model.edge_points[edge] + model.edge_lengths[edge] * b
    start, end = (first, last) if sense > 0 else (last, first)
    for vertex, at, model_end in ((c.start_vertex, c.point, start), (c.end_vertex, c.end_point, end)):
        if vertex is not None:
            along = abs(float((inv.apply(np.asarray(at, float)) - model_end) @ b))
            out.append((along / (c.length_bound + ROUND_OFF), c.id, "edge vertex"))
    return out


def _latest(components) -> list[DataComponent]:
    out: dict[int, DataComponent] = {}
    for c in components:
        out[c.id] = c
    return [out[i] for i in sorted(out)]


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    s = min(max(float((p - a) @ ab / (ab @ ab)), 0.0), 1.0)  # np.clip of one number, without its overhead
    w = p - (a + s * ab)
    return _length(w)


def _length(w: np.ndarray) -> float:
    """``np.linalg.norm`` of a vector (the square root of ``w @ w``, as numpy takes it), without its overhead."""
    return math.sqrt(float(w @ w))


def _outside_distance(model: Polyhedron, face: int, points_m: np.ndarray) -> float:
    """Mean in-plane distance of ``points_m`` (model frame) outside the polygon of ``face`` (0 inside)."""
    u, w = plane_basis(model.face_normals[face])
    loop = model.vertices[list(model.faces[face])]
    uv = np.column_stack([loop @ u, loop @ w])
    q = np.column_stack([points_m @ u, points_m @ w])
    return float(np.mean([0.0 if tracing.inside_polygon(x, uv) else tracing.boundary_distance(x, uv) for x in q]))


def score_face(c: DataFace, model: Polyhedron, rot: np.ndarray, trans: np.ndarray, tol: EvaluationTolerances):
    normals = model.face_normals @ rot.T
    offsets = model.face_offsets + normals @ trans
    ang = np.degrees(np.arccos(np.clip(normals @ c.normal, -1, 1)))
    dist = np.abs(c.points @ normals.T - offsets).mean(axis=0)
    # coplanar faces (BOX01N/P's two top faces) have the same normal and plane: tell them apart by whether the
    # points lie inside the face polygon, else the lower index would always win
    points_m = (np.asarray(c.points, dtype=float) - trans) @ rot
    near = ang / math.degrees(tol.normal) + dist / tol.plane
    # the distance outside a face's polygon only adds (a sum never falls by adding a number >= 0): a face whose
    # angle and plane distance alone cost more than a face's full cost cannot win, and is not measured (the
    # polygon test of every point is most of a component's scoring); ties keep the lowest index as before
    cost = np.full(model.n_faces, math.inf)
    best = math.inf
    for f in np.argsort(near, kind="stable").tolist():
        if near[f] > best:
            break
        cost[f] = near[f] + _outside_distance(model, f, points_m) / tol.plane
        best = min(best, float(cost[f]))
    k = int(np.argmin(cost))
    ok = ang[k] <= math.degrees(tol.normal) and dist[k] <= tol.plane
    return ComponentScore(c.id, "face", k if ok else None, float(ang[k]), float(dist[k] * 1e3))


def score_edge(c: DataEdge, model: Polyhedron, rot: np.ndarray, trans: np.ndarray, tol: EvaluationTolerances):
    best = None
    ends = (c.point, c.end_point)
    for e in range(model.n_edges):
        a = rot @ model.vertices[model.edges[e, 0]] + trans
        b = rot @ model.vertices[model.edges[e, 1]] + trans
        u = (b - a) / np.linalg.norm(b - a)
        ang = math.degrees(math.acos(min(1.0, abs(float(u @ c.direction)))))
        line = max(_length(cross(q - a, u)) for q in ends)
        seg = max(_segment_distance(q, a, b) for q in ends)
        cost = ang / math.degrees(tol.direction) + seg / tol.position
        if best is None or cost < best[0]:
            best = (cost, e, ang, line, seg)
    _, e, ang, line, seg = best
    ok = ang <= math.degrees(tol.direction) and seg <= tol.position
    return ComponentScore(c.id, "edge", e if ok else None, ang, line * 1e3)


def score_vertex(c: DataVertex, model: Polyhedron, rot: np.ndarray, trans: np.ndarray, tol: EvaluationTolerances):
    v = model.vertices @ rot.T + trans
    d = np.linalg.norm(v - c.position, axis=1)
    k = int(np.argmin(d))
    return ComponentScore(c.id, "vertex", k if d[k] <= tol.position else None, math.nan, float(d[k] * 1e3))


def score_components(
    components,
    model: Polyhedron,
    world_from_model: SE3,
    results=None,
    tolerances: EvaluationTolerances | None = None,
) -> PerceptionScore:
    """Score ``components`` (every report; the latest of each id counts) against ``model`` at
    ``world_from_model``. With the move ``results`` (``MoveResult`` records, start first), also count
    missed components: the first true edge on a face move's ideal straight path, and the true vertex an edge
    move runs to, must be the ones reported."""
    tol = tolerances or EvaluationTolerances()
    rot, trans = world_from_model.rotation, world_from_model.translation
    scores = []
    for c in _latest(components):
        if isinstance(c, DataFace):
            scores.append(score_face(c, model, rot, trans, tol))
        elif isinstance(c, DataEdge):
            scores.append(score_edge(c, model, rot, trans, tol))
        else:
            scores.append(score_vertex(c, model, rot, trans, tol))
    by_id = {s.id: s for s in scores}
    convexity = model.edge_convexity
    concave = sum(1 for s in scores if s.kind == "edge" and s.true_id is not None and convexity[s.true_id] < 0)
    missed, details = 0, {}
    if results:
        missed, details = _missed(results, model, rot, trans, by_id, tol)
    ratios = tuple(bound_ratios(components, model, world_from_model))
    hand = score_hand(results or (), ratios, model, world_from_model)
    return PerceptionScore(tuple(scores), sum(1 for s in scores if s.true_id is None), missed, concave, details,
                           ratios, hand, wrist_watch(results or ()))  # fmt: skip


def wrist_watch(results) -> dict:
    """The wrist force sensor's watch summed over the moves (``MoveResult.info["wrist"]``, the physics executor's
    :meth:`~haptic.executor.primitives.Toucher.take_wrist`): ticks watched with the pad free, those with a link's
    contact and those of them the wrist felt, those with a force nothing else reports (``unexplained``, and the
    moves with one), and the largest force off the hand's weight with nothing touching. Empty without a watch."""
    out = {"watched": 0, "links": 0, "links_felt": 0, "unexplained": 0, "unexplained_moves": 0, "free_max": 0.0}
    seen = False
    for r in results:
        w = (getattr(r, "info", None) or {}).get("wrist")
        if not w:
            continue
        seen = True
        for k in ("watched", "links", "links_felt", "unexplained"):
            out[k] += int(w[k])
        out["unexplained_moves"] += int(w["unexplained"] > 0)
        out["free_max"] = max(out["free_max"], float(w["free_max"]))
    return out if seen else {}


def score_hand(results, ratios, model: Polyhedron, world_from_model: SE3) -> dict:
    """The contacts of links other than the exploring pad (``MoveResult.hand``) against the truth: how many moves
    had them and on which links; each point's distance from the true surface, also in units of its link's bound
    (``point_ratio_max``: above 1, the bound does not hold); and the components those moves reported
    (``component_ratio_max``: their largest quantity in units of its bound, from ``ratios``), which tells whether a
    link's contact spoils what the pad measures at the same time. Empty without such contacts."""
    moves, links, dist, rat, ids = 0, set(), [], [], set()
    inv = world_from_model.inverse()
    for r in results:
        groups = [g for g in getattr(r, "hand", ()) if len(g)]
        if not groups:
            continue
        moves += 1
        ids.update(c.id for c in r.components)
        for g in groups:
            links.add(g.link)
            d = surface_distance(model, inv.apply(g.point_in_world))
            dist.extend(d.tolist())
            rat.extend((d / g.bound).tolist() if g.bound > 0 else [math.inf] * len(d))
    if not moves:
        return {}
    comp = [x.ratio for x in ratios if x.id in ids]
    return {"moves": moves, "links": sorted(links), "points": len(dist),
            "point_mm_max": round(1e3 * max(dist), 3), "point_ratio_max": round(max(rat), 4),
            "components": len(ids), "component_ratio_max": round(max(comp), 4) if comp else None,
            "component_ids": sorted(ids)}


MIN_TILT = math.radians(10.0)
"""The least angle between the two faces of an edge of the library: a pad tilted less than this over the
rim of a face cannot be told from one on a real edge that shallow."""


def first_felt_edge(model: Polyhedron, face: int, start_m: np.ndarray, d_m: np.ndarray, tol: EvaluationTolerances):
    """The first edge a pad sliding from ``start_m`` along ``d_m`` on ``face`` (model frame) must feel: the
    first boundary crossing of the straight path after which the path goes farther off the face's polygon
    than ``PAD_RADIUS · sin(MIN_TILT)`` (≈ 2.1 mm) before coming back onto it -- unless the pad runs into
    another face before (:func:`_pad_blocked`). Across a shorter excursion -- clipping a reflex corner of a
    non-convex face -- the pad, resting on the face around it, tilts less than an edge would turn it. None
    when there is no such edge, or when the path meets the boundary within the position tolerance of a
    vertex (no single first edge: the pad is 24 mm wide)."""
    hit = _first_exit_felt(model, face, start_m, d_m, tol)
    if hit is None:
        return None
    return _pad_blocked(model, face, start_m, d_m, hit, tol)


def _pad_blocked(model: Polyhedron, face: int, start_m: np.ndarray, d_m: np.ndarray, hit, tol: EvaluationTolerances):
    """``hit``, or the concave edge to the face the pad (a ball of ``PAD_RADIUS`` on the face) runs into
    first: a wall 20 mm high above a floor is traced only down to where the pad's underside meets the
    floor, 12 mm above it. None when the pad would first meet a face that does not share an edge with
    ``face`` (no single first edge)."""
    n = model.face_normals[face]
    d = np.asarray(d_m, dtype=float) - (np.asarray(d_m, dtype=float) @ n) * n
    d /= np.linalg.norm(d)
    others = np.flatnonzero(model.triangle_faces != face)
    tri = model.vertices[model.triangles[others]]
    ts = np.arange(0.0, hit.distance, 5e-4)
    centres = np.asarray(start_m, dtype=float) + PAD_RADIUS * n + ts[:, None] * d
    dist = point_triangle_distance(centres, tri)
    near = PAD_RADIUS - tol.plane / 6
    dist[:, dist[0] < near] = np.inf  # faces the pad touches where it starts (it leaves them)
    touching = dist.min(axis=1) < near
    if not touching.any():
        return hit
    k = int(np.argmax(touching))
    g = int(model.triangle_faces[others[int(np.argmin(dist[k]))]])
    shared = [e for e in model.face_edges[face] if g in model.edge_faces(e)]
    if not shared or model.edge_convexity[shared[0]] > 0:
        return None
    return tracing.FaceHit(shared[0], float(ts[k]), centres[k] - PAD_RADIUS * n, g)


def _first_exit_felt(model: Polyhedron, face: int, start_m: np.ndarray, d_m: np.ndarray, tol: EvaluationTolerances):
    u, w = plane_basis(model.face_normals[face])
    loop = model.vertices[list(model.faces[face])]
    uv = np.column_stack([loop @ u, loop @ w])
    depth = PAD_RADIUS * math.sin(MIN_TILT)
    step = 2e-4
    p = np.asarray(start_m, dtype=float)
    for _ in range(model.n_edges):
        try:
            hit = tracing.trace_face(model, face, p, d_m, vertex_margin=tol.position)
        except (ValueError, IndexError):
            return None
        if hit is None:
            return None
        d = hit.point - p
        d /= np.linalg.norm(d)
        for s in np.arange(step, float(np.linalg.norm(model.extents)) + step, step):
            q = hit.point + s * d
            x = np.array([q @ u, q @ w])
            if tracing.inside_polygon(x, uv):
                p = q
                break  # back on the face: a corner the pad bridges; trace on from here
            if tracing.boundary_distance(x, uv) > depth:
                return hit
        else:
            return hit
    return None


def _missed(
    results, model: Polyhedron, rot: np.ndarray, trans: np.ndarray, by_id: dict, tol: EvaluationTolerances
) -> tuple[int, dict]:
    """The successful tracing moves whose new component is not the true feature the move should have met next
    (:data:`_FEATURE_CHECKS`, each from the sensor state before the move), and every check made."""
    checks = []
    prev_state = None
    for r in results:
        if r.ok and prev_state is not None and r.move.kind in _FEATURE_CHECKS:
            check = _FEATURE_CHECKS[r.move.kind](r, prev_state, model, rot, trans, by_id, tol)
            if check is not None:
                checks.append(check)
        if r.ok:
            prev_state = r.state
    return sum(1 for c in checks if not c[-1]), {"checks": checks}


def _face_check(r, prev_state, model: Polyhedron, rot: np.ndarray, trans: np.ndarray, by_id: dict,
                tol: EvaluationTolerances) -> tuple | None:  # fmt: skip
    """A face move: its edge must be the first true edge the pad feels from where the straight trace began; one
    whose slide crossed a face over an edge too shallow to feel (``crossed_face``, reported before the edge) rolled
    off that face, and its edge must bound that face's true face."""
    e_comp = next((c for c in r.components if c.kind == "edge"), None)
    e_score = by_id.get(e_comp.id) if e_comp is not None else None
    crossed = by_id.get(r.info.get("crossed_face"))
    if crossed is not None:
        if e_score is None or None in (crossed.true_id, e_score.true_id):
            return None
        return ("face", e_comp.id, crossed.true_id, e_score.true_id,
                crossed.true_id in model.edge_faces(e_score.true_id))  # fmt: skip
    f_score = by_id.get(prev_state.face)
    trace = r.trace
    if not (f_score and f_score.true_id is not None and e_score and trace is not None):
        return None
    rows = trace.in_contact & (trace.phase == PHASES.index("face"))  # where the straight trace began
    if not rows.any():
        return None
    start = trace.point_in_world[np.flatnonzero(rows)[0]]
    d = np.asarray(r.move.direction, float)
    start_m = rot.T @ (start - trans)
    d_m = rot.T @ d
    n = model.face_normals[f_score.true_id]
    d_m = d_m - (d_m @ n) * n
    start_m = start_m - (start_m @ n - model.face_offsets[f_score.true_id]) * n
    hit = first_felt_edge(model, f_score.true_id, start_m, d_m, tol)
    if hit is None:
        return None
    return ("face", r.components[0].id, hit.edge, e_score.true_id, e_score.true_id == hit.edge)


def _edge_check(r, prev_state, model: Polyhedron, rot: np.ndarray, trans: np.ndarray, by_id: dict,
                tol: EvaluationTolerances) -> tuple | None:  # fmt: skip
    """An edge move: the vertex reached must be an end of the true edge followed (else the trace ran past one)."""
    if prev_state.edge is None:
        return None
    e_score = by_id.get(prev_state.edge)
    v = next((c for c in r.components if c.kind == "vertex"), None)
    v_score = by_id.get(v.id) if v is not None else None
    if not (e_score and e_score.true_id is not None and v_score and v_score.true_id is not None):
        return None
    ok = v_score.true_id in (int(model.edges[e_score.true_id, 0]), int(model.edges[e_score.true_id, 1]))
    return ("edge", v.id, e_score.true_id, v_score.true_id, ok)


def _vertex_check(r, prev_state, model: Polyhedron, rot: np.ndarray, trans: np.ndarray, by_id: dict,
                  tol: EvaluationTolerances) -> tuple | None:  # fmt: skip
    """A vertex move: the new edge must leave the vertex circled and bound the face circled across."""
    if prev_state.vertex is None:
        return None
    v_score = by_id.get(prev_state.vertex)
    # a circle that crossed a face over an edge too shallow to feel rolled off that face (reported before the edge)
    f_score = by_id.get(r.info.get("crossed_face", r.move.across_face))
    e_comp = next((c for c in r.components if c.kind == "edge"), None)
    e_score = by_id.get(e_comp.id) if e_comp is not None else None
    if not (v_score and f_score and e_score and None not in (v_score.true_id, f_score.true_id, e_score.true_id)):
        return None
    e = e_score.true_id
    ok = v_score.true_id in (int(model.edges[e, 0]), int(model.edges[e, 1])) and f_score.true_id in model.edge_faces(e)
    return ("vertex", e_comp.id, v_score.true_id, e, ok)


_FEATURE_CHECKS = {"face": _face_check, "edge": _edge_check, "vertex": _vertex_check}
"""Per kind of tracing move, the check of what it met against the truth: a row (kind, data id of the new
component, the two true ids compared, ok), or None when the truth cannot say."""


__all__ = [
    "BOUND_QUANTITIES",
    "BoundRatio",
    "ComponentScore",
    "EvaluationTolerances",
    "PerceptionScore",
    "bound_ratios",
    "score_components",
    "wrist_watch",
]


def true_hypothesis(
    components, model: Polyhedron, world_from_model: SE3, tolerances: EvaluationTolerances | None = None
) -> Hypothesis:
    """The true interpretation of ``components`` (every report; the latest of each id counts) as the planner's
    :class:`~haptic.planning.hypothesis.Hypothesis`: ``model`` at its true pose, each data component paired with
    the true feature of its kind that scores it (:func:`score_components`; a spurious one left out). Through it the
    planner's predictions are made as the truth would make them (:func:`haptic.planning.table.move_outlook`)."""
    tol = tolerances or EvaluationTolerances()
    rot, trans = world_from_model.rotation, world_from_model.translation
    pairs: dict[str, dict[int, int]] = {"face": {}, "edge": {}, "vertex": {}}
    for c in _latest(components):
        score = score_face if isinstance(c, DataFace) else score_edge if isinstance(c, DataEdge) else score_vertex
        s = score(c, model, rot, trans, tol)
        if s.true_id is not None:
            pairs[s.kind][c.id] = int(s.true_id)
    return Hypothesis(model=model.name, poly=model, world_from_model=world_from_model, faces=pairs["face"],
                      edges=pairs["edge"], vertices=pairs["vertex"])  # fmt: skip
