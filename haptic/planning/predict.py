"""Candidate moves and their predicted outcomes under each hypothesis (seed §4.1).

Through its pose, each hypothesis (:class:`~haptic.planning.hypothesis.Hypothesis`: one pose class of one
model) predicts what a candidate move would yield "in its world": the distance travelled, the new edge's angle,
the new face's angle; and what the move would cost there. The planner compares these predictions
(:mod:`haptic.planning.efficiency`).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import cross, plane_basis
from haptic.geometry.tracing import FaceHit, circle_vertex, trace_edge
from haptic.matching.components import DataComponent, DataEdge, DataFace, SensorNoise
from haptic.planning import kernels
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import FaceTrace, Hypothesis, trace_in
from haptic.planning.moves import EdgeMove, FaceMove, Move, SensorState, VertexMove, start_state
from haptic.planning.table import data_table_conflict, hand_trace, table_prediction


@dataclass(frozen=True, eq=False)
class Prediction:
    """A candidate move with every hypothesis's predicted outcome and cost."""

    move: Move
    """The candidate move."""
    outcomes: np.ndarray
    """Predicted outcome attributes per hypothesis, shape (N, A); NaN where a hypothesis cannot predict."""
    bounds: np.ndarray
    """Error bound of each attribute, shape (A,)."""
    costs: np.ndarray
    """Predicted cost per hypothesis, shape (N,) [units]."""
    clearance: np.ndarray
    """For face moves, the predicted distance of the edge crossing from the nearest vertex, per hypothesis
    (NaN otherwise), shape (N,) [m]."""
    table: np.ndarray | None = None
    """Per hypothesis: 1 when the move is predicted to bring the pad onto the table, 0 when not, NaN when the
    hypothesis cannot say; None without a table (``PlannerConfig.table_z``)."""
    reach: np.ndarray | None = None
    """For face moves with a table, per hypothesis: how far along the face the trace touches it, to the edge
    or to where the pad would come too close to the table and stop, whether or not the move then succeeds
    (NaN: cannot say) [m]."""
    edge_only: np.ndarray | None = None
    """For face moves with ``config.max_undercut``, per hypothesis: 1 when the move is predicted to end at its
    edge, the next face leaning under out of the pad's reach (the executor then reports the edge alone:
    its distance and direction are measured, the next face's angle is not), 0 when not, NaN when the
    hypothesis cannot say."""

    @property
    def table_risk(self) -> float:
        """Fraction of the hypotheses that can say which predict the move to run into the table (0 without
        a table or a prediction)."""
        if self.table is None or np.isnan(self.table).all():
            return 0.0
        return float(np.nanmean(self.table))

    def reliable(self, config: PlannerConfig) -> bool:
        """False for a face move predicted to be too short, or to cross its edge too near a vertex."""
        if self.move.kind != "face" or np.isnan(self.outcomes[:, 0]).all():
            return True
        return bool(
            nan_median(self.outcomes[:, 0]) >= config.min_face_travel
            and nan_median(self.clearance) >= config.min_vertex_clearance
        )


def nan_median(x: np.ndarray) -> float:
    """``np.nanmedian`` of a short 1-D array (the same value: the middle one, or the mean of the two middle ones, of
    those not NaN; NaN when all are), without its cost on the planner's small arrays."""
    v = np.sort(x[~np.isnan(x)])
    m = len(v)
    if not m:
        return float("nan")
    return float(v[m // 2]) if m % 2 else float((v[m // 2 - 1] + v[m // 2]) / 2)


def outcome_bounds(noise: SensorNoise) -> dict[str, np.ndarray]:
    """Bounds within which two predicted outcomes cannot be told apart by one measurement.

    Two predictions are distinguishable when they differ by more than the measurement's error bound
    (§4.1.1: predicted 2.8 and 3.0 with ±0.2 are not). A distance is measured between two contact events,
    each within ``k σ_len``; an angle between two measured directions, each within ``k σ_n``.
    """
    k = noise.k
    dist = 2 * k * noise.length_sigma + 1e-4
    ang = 2 * k * max(noise.normal_sigma, noise.direction_sigma) + np.deg2rad(0.5)
    return {
        "face": np.array([dist, ang, ang]),
        "edge": np.array([dist]),
        "vertex": np.array([ang, ang]),
    }


# ------------------------------------------------------------------------------------------- candidates


def candidate_moves(
    state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> list[Move]:
    """The admissible moves from the current state (§4.1: near a face / an edge / a vertex)."""
    moves: list[Move] = []
    face = components.get(state.face)
    if isinstance(face, DataFace):
        moves.extend(FaceMove(d) for d in face_directions(state, components, config.n_directions))
    edge = components.get(state.edge) if state.edge is not None else None
    if isinstance(edge, DataEdge):
        toward_vertex = 0  # the sense that points at the vertex the sensor is at, if any
        vertex = components.get(state.vertex) if state.vertex is not None else None
        if vertex is not None:
            mid = edge.point + 0.5 * edge.length * edge.direction
            toward_vertex = 1 if (vertex.position - mid) @ edge.direction > 0 else -1
        for sense in (+1, -1):
            if (edge.end_vertex if sense > 0 else edge.start_vertex) is None and sense != toward_vertex:
                moves.append(EdgeMove(sense))
        if state.vertex is not None:
            moves.extend(VertexMove(f) for f in state.edge_faces if isinstance(components.get(f), DataFace))
    return moves


CONVEX_SIN = math.sin(math.radians(5.0))
"""An edge is convex between its faces when the way from it into the other face heads at least asin of this under
the current face's plane [-]."""
OTHER_FACE_INSET = 0.005
"""A face move across the other face of the edge the sensor is on starts this far from the edge on that face [m]
(:func:`other_face_start`; the hand's touch afresh beside an edge, ``PhysicsSettings.reacquire_inset``)."""


def other_face_start(state: SensorState, components: Mapping[int, DataComponent], face: int
                     ) -> tuple[np.ndarray, np.ndarray] | None:  # fmt: skip
    """Where a face move across data face ``face``, the other face of the edge the sensor is on, starts
    (:attr:`FaceMove.start`): beside the sensor's foot on the edge's explored interval, :data:`OTHER_FACE_INSET`
    into that face (toward the point the edge has on its side, else its points' middle); with the unit direction
    in the face's plane away from the edge. None without the edge or the face, or where the edge is not convex
    between the two: in a concave corner the pad touches both faces (the current face's moves start a pad's radius
    out of the corner)."""
    edge, f = components.get(state.edge) if state.edge is not None else None, components.get(face)
    here = components.get(state.face)
    if not isinstance(edge, DataEdge) or not isinstance(f, DataFace) or not isinstance(here, DataFace):
        return None
    b = np.asarray(edge.direction, float)
    w = cross(f.normal, b)
    norm = float(np.linalg.norm(w))
    if norm < 0.5:  # the face's normal near the edge's line: not a face of it
        return None
    w /= norm
    foot = edge.point + float(np.clip((state.position - edge.point) @ b, 0.0, edge.length)) * b
    side = dict(edge.side_points).get(face)
    ref = side if side is not None else f.points.mean(axis=0)
    if float((ref - foot) @ w) < 0.0:
        w = -w
    if float(w @ here.normal) > -CONVEX_SIN:  # into a convex edge's other face is down from the current face
        return None
    return foot + OTHER_FACE_INSET * w, w


def face_directions(
    state: SensorState, components: Mapping[int, DataComponent], n: int
) -> list[np.ndarray]:
    """Unit directions in the current face's plane: over the half-plane into the face when the sensor is on
    an edge of it, over the full circle otherwise."""
    face = components[state.face]
    normal = face.normal
    edge = components.get(state.edge) if state.edge is not None else None
    if isinstance(edge, DataEdge) and abs(edge.direction @ normal) < 0.5:
        b = edge.direction - (edge.direction @ normal) * normal
        b /= np.linalg.norm(b)
        inward = cross(normal, b)
        side = dict(edge.side_points).get(state.face)
        if side is not None:  # a point on the face beside the edge: the face's side of the edge line
            if (side - edge.point) @ inward < 0:
                inward = -inward
        elif (face.points.mean(axis=0) - state.position) @ inward < 0:
            inward = -inward
        angles = (np.arange(n) + 0.5) * np.pi / n
        return [np.cos(a) * b + np.sin(a) * inward for a in angles]
    u, w = plane_basis(normal, assume_unit=True)
    angles = np.arange(n) * 2 * np.pi / n
    return [np.cos(a) * u + np.sin(a) * w for a in angles]


# ------------------------------------------------------------------------------------------- prediction


def _signed_dihedral(poly: Polyhedron, f_from: int, f_to: int, edge: int) -> float:
    """Angle between the two faces' normals, negative across a concave edge [rad]."""
    ang = math.acos(min(1.0, max(-1.0, float(poly.face_normals[f_from] @ poly.face_normals[f_to]))))
    return ang if poly.edge_convexity[edge] > 0 else -ang


def _line_angle(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two lines (unsigned directions), in [0, π/2] [rad]."""
    c = abs(float(a @ b)) / (math.sqrt(float(a @ a)) * math.sqrt(float(b @ b)))
    return math.acos(min(1.0, max(0.0, c)))


_LOOPS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _face_loop(poly: Polyhedron, face: int) -> tuple[np.ndarray, ...]:
    """A face's sides as arrays (cached per model), in loop order (as :func:`~haptic.geometry.tracing.trace_face`
    walks them): start vertices ``a`` (K, 3), side vectors (K, 3), edge ids and the faces beyond them (K,); then,
    per side, its edge's direction and source point (K, 3) and length (K,), the signed dihedral angle from this
    face to the one beyond (:func:`_signed_dihedral`) and the side's length (K,)."""
    per = _LOOPS.setdefault(poly, {})
    if face not in per:
        loop = poly.faces[face]
        a = poly.vertices[list(loop)]
        seg = np.roll(a, -1, axis=0) - a
        edges = np.asarray(poly.face_edges[face], dtype=np.int64)
        beyond = np.where(poly.edge_left_face[edges] == face, poly.edge_right_face[edges], poly.edge_left_face[edges])
        dihedral = np.array([_signed_dihedral(poly, face, int(g), int(e)) for e, g in zip(edges, beyond, strict=True)])
        side = np.array([math.sqrt(float(s.dot(s))) for s in seg])
        per[face] = (a, seg, edges, beyond, poly.edge_directions[edges], poly.edge_points[edges],
                     poly.edge_lengths[edges], dihedral, side)  # fmt: skip
    return per[face]


def trace_all(hypotheses: Sequence[Hypothesis], move: FaceMove, state: SensorState) -> list[FaceTrace | None]:
    """:func:`trace_in` for every hypothesis at once (:func:`trace_moves` for one move)."""
    return trace_moves(hypotheses, [move], state)[0]


def trace_moves(
    hypotheses: Sequence[Hypothesis], moves: Sequence[FaceMove], state: SensorState
) -> list[list[FaceTrace | None]]:
    """:func:`trace_in` for every face move and every hypothesis: the sides of every hypothesis's current face are
    stacked once (padded to the longest loop), and for each move the crossing of its trace with each side is solved
    in one array operation over the hypotheses (in the face's plane, ``start + t d = a + u (b − a)``); the first side
    met ahead, clear of its ends, is the hit. The same outcome as :func:`~haptic.geometry.tracing.trace_face` for
    each hypothesis and move. Returns one list per move, one entry per hypothesis."""
    out: list[list[FaceTrace | None]] = [[None] * len(hypotheses) for _ in moves]
    rows, starts, rots, normals, loops = [], [], [], [], []
    for i, h in enumerate(hypotheses):
        f_m = h.faces.get(state.face)
        if h.world_from_model is None or f_m is None:
            continue
        model_from_world = h.model_from_world
        poly, p_m = h.poly, model_from_world.apply(state.position)
        n = poly.face_normals[f_m]
        rows.append(i)
        starts.append(p_m - (p_m @ n - poly.face_offsets[f_m]) * n)
        rots.append(h.world_from_model.rotation)  # SE3.rotate of model_from_world multiplies by it
        normals.append(n)
        loops.append(_face_loop(poly, f_m))
    if not rows or not moves:
        return out
    k = max(len(lp[2]) for lp in loops)
    a_all = np.zeros((len(rows), k, 3))
    seg_all = np.zeros((len(rows), k, 3))
    real_all = np.zeros((len(rows), k), dtype=bool)
    for j, lp in enumerate(loops):
        a_all[j, : len(lp[2])], seg_all[j, : len(lp[2])], real_all[j, : len(lp[2])] = lp[0], lp[1], True
    start_all, n_all = np.array(starts), np.array(normals)
    # each move's direction in each hypothesis's model frame (M, m, 3), by the arithmetic of SE3.rotate, and its
    # part in the face's plane, unit length (by batched row products: the same bits as one hypothesis at a time)
    dirs = np.array([mv.direction for mv in moves], dtype=float)
    d_raw = (dirs[:, None, None, :] @ np.array(rots)[None])[:, :, 0]
    d_in = d_raw - (d_raw[..., None, :] @ n_all[None, :, :, None])[..., 0] * n_all[None]
    norm_all = np.linalg.norm(d_in, axis=2)
    for mi in range(len(moves)):
        use = np.flatnonzero(norm_all[mi] >= 1e-9)
        if not len(use):
            continue
        for j, hit in _first_crossings(
            start_all[use], d_in[mi, use] / norm_all[mi, use, None], n_all[use], a_all[use], seg_all[use],
            real_all[use], [loops[j] for j in use], use,
        ):  # fmt: skip
            i = rows[j]
            out[mi][i] = FaceTrace(hypotheses[i].faces[state.face], starts[j], d_raw[mi, j], hit)
    return out


def _first_crossings(start, d, n, a, seg, real, loops, index):
    """The first side each trace ``start + t d`` meets, as ``(index[j], FaceHit)`` for the traces that meet one
    clear of its ends (shapes: start, d, n (m, 3); a, seg (m, k, 3); real (m, k))."""
    k = a.shape[1]
    r = a - start[:, None]
    den = np.einsum("mkc,mc->mk", cross(d[:, None], seg), n)
    safe = np.where(np.abs(den) > 1e-15, den, 1.0)
    t = np.einsum("mkc,mc->mk", cross(r, seg), n) / safe
    u = np.einsum("mkc,mkc->mk", cross(r, d[:, None]), n[:, None].repeat(k, axis=1)) / safe
    miss = start[:, None] + t[..., None] * d[:, None] - (a + u[..., None] * seg)
    ok = real & (np.abs(den) > 1e-15) & (t > 1e-12) & (u >= -1e-12) & (u <= 1 + 1e-12)
    ok &= np.linalg.norm(miss, axis=2) <= 1e-7
    t_ok = np.where(ok, t, np.inf)
    best = np.argmin(t_ok, axis=1)
    for j in range(len(start)):
        b = int(best[j])
        if not np.isfinite(t_ok[j, b]):
            continue
        sj = seg[j, b]
        seg_len = math.sqrt(float(sj.dot(sj)))  # np.linalg.norm's arithmetic (a row: contiguous)
        if min(u[j, b], 1 - u[j, b]) * seg_len < 1e-6:
            continue
        _, _, edges, beyond = loops[j][:4]
        tj = float(t[j, b])
        yield int(index[j]), FaceHit(edge=int(edges[b]), distance=tj, point=start[j] + tj * d[j],
                                     next_face=int(beyond[b]))  # fmt: skip


def predict_one(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> tuple[np.ndarray, float]:
    """One hypothesis's predicted outcome attributes and cost for a move (NaN attributes when it can't say)."""
    out, cost, _ = _predict_one(h, move, state, components, config)
    return out.copy(), cost


_NAN = {kind: np.full(n, np.nan) for kind, n in (("face", 3), ("edge", 1), ("vertex", 2))}
"""No prediction, per kind of move (read only: :func:`predict` stacks the rows into a new array)."""
for _row in _NAN.values():
    _row.flags.writeable = False


def _predict_one(
    h: Hypothesis,
    move: Move,
    state: SensorState,
    components: Mapping[int, DataComponent],
    config: PlannerConfig,
    trace: FaceTrace | None | bool = False,
) -> tuple[np.ndarray, float, float]:
    nan_face, nan_edge, nan_vertex = _NAN["face"], _NAN["edge"], _NAN["vertex"]
    costs = config.costs
    if h.world_from_model is None:
        return _NAN[move.kind], np.nan, np.nan
    poly = h.poly
    if isinstance(move, FaceMove):
        tr = hand_trace(h, move, state, config, trace_in(h, move, state) if trace is False else trace)
        if tr is None:
            return nan_face, np.nan, np.nan
        hit = tr.hit
        out = np.array(
            [
                hit.distance,
                _line_angle(poly.edge_directions[hit.edge], tr.direction),
                _signed_dihedral(poly, tr.face, hit.next_face, hit.edge),
            ]
        )
        return out, costs.face_move(hit.distance), tr.clearance(poly)
    if isinstance(move, EdgeMove):
        e_m = h.edges.get(state.edge) if state.edge is not None else None
        if e_m is None:
            return nan_edge, np.nan, np.nan
        b_world = h.world_from_model.rotate(poly.edge_directions[e_m])
        data_edge = components[state.edge]
        sense_m = move.sense if b_world @ data_edge.direction > 0 else -move.sense
        hit = trace_edge(poly, e_m, h.model_from_world.apply(state.position), sense_m)
        return np.array([hit.distance]), costs.edge_move(hit.distance), np.nan
    if isinstance(move, VertexMove):
        e_m = h.edges.get(state.edge) if state.edge is not None else None
        v_m = h.vertices.get(state.vertex) if state.vertex is not None else None
        a_m = h.faces.get(move.across_face)
        if e_m is None or v_m is None or a_m is None:
            return nan_vertex, np.nan, np.nan
        try:
            hit = circle_vertex(poly, v_m, e_m, a_m, config.vertex_radius)
        except ValueError:
            return nan_vertex, np.nan, np.nan
        out = np.array([hit.angle, _signed_dihedral(poly, a_m, hit.next_face, hit.edge)])
        return out, costs.vertex_move(hit.arc_length), np.nan
    raise TypeError(f"unknown move {move!r}")


def crossed_edge(h: Hypothesis, move: FaceMove, state: SensorState, config: PlannerConfig | None = None) -> int | None:
    """The model edge hypothesis ``h`` predicts face move ``move`` to meet (None when it cannot say); with
    ``config``, as the hand follows it (:func:`~haptic.planning.table.hand_trace`)."""
    tr = trace_in(h, move, state) if config is None else hand_trace(h, move, state, config)
    return None if tr is None else int(tr.hit.edge)


def predict(
    hypotheses: Sequence[Hypothesis],
    move: Move,
    state: SensorState,
    components: Mapping[int, DataComponent],
    noise: SensorNoise,
    config: PlannerConfig,
    traces: Sequence[FaceTrace | None] | None = None,
) -> Prediction:
    """Every hypothesis's predicted outcome and cost for one candidate move (``traces``: a face move's traces in
    every hypothesis, :func:`trace_moves`, when already computed)."""
    state = start_state(move, state)
    rows, costs, clear = [], [], []
    if traces is None:
        traces = trace_all(hypotheses, move, state) if isinstance(move, FaceMove) else [False] * len(hypotheses)
    for h, tr in zip(hypotheses, traces, strict=True):
        o, c, cl = _predict_one(h, move, state, components, config, tr)
        rows.append(o)
        costs.append(c)
        clear.append(cl)
    table = reach = edge_only = None
    if config.table_z is not None:
        if data_table_conflict(move, state, components, config):
            table = np.ones(len(hypotheses))
        else:
            got = np.array([table_prediction(h, move, state, components, config) for h in hypotheses], dtype=float)
            table = got[:, 0]
            if isinstance(move, FaceMove):
                reach = got[:, 1]
                edge_only = got[:, 2] if config.max_undercut is not None else None
    return _prediction(move, np.array(rows), np.array(costs, dtype=float), np.array(clear, dtype=float), table, reach,
                       edge_only, noise)  # fmt: skip


def _prediction(
    move: Move, outcomes: np.ndarray, costs: np.ndarray, clear: np.ndarray, table, reach, edge_only, noise: SensorNoise
) -> Prediction:
    """The :class:`Prediction`, a cost no hypothesis can say replaced by the mean of those that can (1 when none
    can)."""
    nan = np.isnan(costs)
    if nan.all():
        costs = np.ones_like(costs)
    elif nan.any():
        costs = np.where(nan, np.nanmean(costs), costs)
    return Prediction(move, outcomes, outcome_bounds(noise)[move.kind], costs, clear, table, reach, edge_only)


def predict_moves(
    hypotheses: Sequence[Hypothesis],
    moves: Sequence[Move],
    state: SensorState,
    components: Mapping[int, DataComponent],
    noise: SensorNoise,
    config: PlannerConfig,
) -> list[Prediction]:
    """:func:`predict` for each of ``moves``; the face moves' outcomes, costs and clearances in every hypothesis
    at once (:func:`face_outcomes`), their traces (:func:`trace_moves`) only where a table asks for them; a face
    move on another face than the current one (:attr:`~haptic.planning.moves.FaceMove.face`) from there."""
    on: list[Move] = []
    elsewhere: list[Move] = []
    for m in moves:
        (on if start_state(m, state) is state else elsewhere).append(m)
    if elsewhere:
        got = dict(zip(map(id, on), predict_moves(hypotheses, on, state, components, noise, config), strict=True))
        for m in elsewhere:
            got[id(m)] = predict(hypotheses, m, state, components, noise, config)
        return [got[id(m)] for m in moves]
    faces = [m for m in moves if isinstance(m, FaceMove)]
    if config.table_z is not None:
        traced = dict(zip(map(id, faces), trace_moves(hypotheses, faces, state), strict=True))
        return [predict(hypotheses, m, state, components, noise, config, traced.get(id(m))) for m in moves]
    stacked = dict(zip(map(id, faces), face_outcomes(hypotheses, faces, state, config), strict=True))
    edges = [m for m in moves if isinstance(m, EdgeMove)]
    stacked.update(zip(map(id, edges), edge_outcomes(hypotheses, edges, state, components, config), strict=True))
    return [
        _prediction(m, *stacked[id(m)], None, None, None, noise) if id(m) in stacked
        else predict(hypotheses, m, state, components, noise, config)
        for m in moves
    ]  # fmt: skip


def edge_outcomes(
    hypotheses: Sequence[Hypothesis],
    moves: Sequence[EdgeMove],
    state: SensorState,
    components: Mapping[int, DataComponent],
    config: PlannerConfig,
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Every edge move's predicted outcome (the distance to the vertex, (N, 1)), cost (N,) and clearance (NaN, (N,))
    in every hypothesis at once, as :func:`predict` forms them (:func:`~haptic.geometry.tracing.trace_edge` in each
    hypothesis's world along its model edge, in the sense that pairs with the data edge's)."""
    n_h = len(hypotheses)
    out = [(np.full((n_h, 1), np.nan), np.full(n_h, np.nan), np.full(n_h, np.nan)) for _ in moves]
    data_edge = components.get(state.edge) if state.edge is not None else None
    rows, edges, rots, starts = [], [], [], []
    for i, h in enumerate(hypotheses):
        e_m = h.edges.get(state.edge) if state.edge is not None else None
        if h.world_from_model is None or e_m is None:
            continue
        rows.append(i)
        edges.append((h.poly, e_m))
        rots.append(h.world_from_model.rotation)
        starts.append(h.model_from_world.apply(state.position))
    if not rows or not moves:
        return out
    b = np.array([p.edge_directions[e] for p, e in edges])
    p0 = np.array([p.edge_points[e] for p, e in edges])
    length = np.array([p.edge_lengths[e] for p, e in edges])
    b_world = (b[:, None, :] @ np.swapaxes(np.array(rots), -1, -2))[:, 0]  # SE3.rotate's arithmetic
    along = b_world @ data_edge.direction > 0
    s = np.clip(np.einsum("mc,mc->m", np.array(starts) - p0, b), 0.0, length)
    c = config.costs
    for k, move in enumerate(moves):
        forward = along if move.sense > 0 else ~along
        dist = np.where(forward, length - s, s)
        out[k][0][rows, 0] = dist
        out[k][1][rows] = c.c_e * dist + c.c_k
    return out


def face_outcomes(
    hypotheses: Sequence[Hypothesis], moves: Sequence[FaceMove], state: SensorState, config: PlannerConfig
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Every face move's predicted outcome attributes (N, 3), cost (N,) and crossing clearance (N,) in every
    hypothesis (NaN where it cannot say), as :func:`predict` forms them from :func:`trace_moves`: the crossings of
    every move with every side of every hypothesis's current face solved in one array operation over
    (moves, hypotheses, sides), and the attributes gathered from per-side tables of each model face
    (:func:`_face_loop`), with no step per hypothesis."""
    n_h, n_m = len(hypotheses), len(moves)
    outcomes = np.full((n_m, n_h, 3), np.nan)
    costs = np.full((n_m, n_h), np.nan)
    clear = np.full((n_m, n_h), np.nan)
    rows, starts, rots, normals, loops = [], [], [], [], []
    for i, h in enumerate(hypotheses):
        f_m = h.faces.get(state.face)
        if h.world_from_model is None or f_m is None:
            continue
        poly, p_m = h.poly, h.model_from_world.apply(state.position)
        n = poly.face_normals[f_m]
        rows.append(i)
        starts.append(p_m - (p_m @ n - poly.face_offsets[f_m]) * n)
        rots.append(h.world_from_model.rotation)
        normals.append(n)
        loops.append(_face_loop(poly, f_m))
    if rows and n_m:
        k = max(len(lp[2]) for lp in loops)
        m = len(rows)
        a_all, seg_all = np.zeros((m, k, 3)), np.zeros((m, k, 3))
        b_all, p_all = np.zeros((m, k, 3)), np.zeros((m, k, 3))
        len_all, dih_all, seg_len = np.ones((m, k)), np.zeros((m, k)), np.zeros((m, k))
        real = np.zeros((m, k), dtype=bool)
        for j, lp in enumerate(loops):
            s = slice(0, len(lp[2]))
            a_all[j, s], seg_all[j, s], real[j, s] = lp[0], lp[1], True
            b_all[j, s], p_all[j, s], len_all[j, s], dih_all[j, s], seg_len[j, s] = lp[4:9]
        start, n_all = np.array(starts), np.array(normals)
        dirs = np.array([mv.direction for mv in moves], dtype=float)
        if kernels.COMPILED:
            c = config.costs
            hit, tb, angle, dih, cost, near = kernels.face_outcomes(
                dirs, np.array(rots, dtype=float), start, n_all, a_all, seg_all, real, b_all, p_all, len_all, dih_all,
                seg_len, np.array([c.c_f, c.c_j, c.c_b, c.c_n], dtype=float),
            )  # fmt: skip
            mi, hj = np.nonzero(hit)
            cols = np.array(rows)[hj]
            outcomes[mi, cols, 0], outcomes[mi, cols, 1], outcomes[mi, cols, 2] = tb[mi, hj], angle[mi, hj], dih[mi, hj]
            costs[mi, cols], clear[mi, cols] = cost[mi, hj], near[mi, hj]
            return [(outcomes[i], costs[i], clear[i]) for i in range(n_m)]
        d_raw = (dirs[:, None, None, :] @ np.array(rots)[None])[:, :, 0]  # (M, m, 3): SE3.rotate's arithmetic
        d_in = d_raw - (d_raw[..., None, :] @ n_all[None, :, :, None])[..., 0] * n_all[None]
        norm = np.linalg.norm(d_in, axis=2)
        use = norm >= 1e-9
        d = d_in / np.where(use, norm, 1.0)[..., None]
        # start + t d = a + u seg in the face's plane, for every (move, hypothesis, side)
        r = a_all - start[:, None]
        den = np.einsum("Mmkc,mc->Mmk", cross(d[:, :, None], seg_all[None]), n_all)
        safe = np.where(np.abs(den) > 1e-15, den, 1.0)
        t = np.einsum("mkc,mc->mk", cross(r, seg_all), n_all)[None] / safe
        u = np.einsum("Mmkc,mc->Mmk", cross(r[None], d[:, :, None]), n_all) / safe
        miss = start[None, :, None] + t[..., None] * d[:, :, None] - (a_all + u[..., None] * seg_all)
        ok = real[None] & (np.abs(den) > 1e-15) & (t > 1e-12) & (u >= -1e-12) & (u <= 1 + 1e-12)
        ok &= np.linalg.norm(miss, axis=3) <= 1e-7
        t_ok = np.where(ok, t, np.inf)
        best = np.argmin(t_ok, axis=2)[..., None]
        tb = np.take_along_axis(t_ok, best, 2)[..., 0]
        ub = np.take_along_axis(u, best, 2)[..., 0]
        hit = use & np.isfinite(tb)
        hit &= np.minimum(ub, 1 - ub) * np.take_along_axis(np.broadcast_to(seg_len, t.shape), best, 2)[..., 0] >= 1e-6

        def at_best(x: np.ndarray) -> np.ndarray:  # the hit side's entry of a per-side table (m, k[, 3])
            full = np.broadcast_to(x, (n_m, *x.shape))
            idx = best if x.ndim == 2 else best[..., None]
            return np.take_along_axis(full, idx, 2)[:, :, 0]

        b_hit = at_best(b_all)
        dot = np.abs(np.einsum("Mmc,Mmc->Mm", b_hit, d_raw))
        cos = dot / (np.sqrt(np.einsum("Mmc,Mmc->Mm", b_hit, b_hit)) * np.sqrt(np.einsum("Mmc,Mmc->Mm", d_raw, d_raw)))
        point = start[None] + np.where(hit, tb, 0.0)[..., None] * d
        s_hit = np.einsum("Mmc,Mmc->Mm", point - at_best(p_all), b_hit)
        c = config.costs
        mi, hj = np.nonzero(hit)
        cols = np.array(rows)[hj]
        outcomes[mi, cols, 0] = tb[mi, hj]
        outcomes[mi, cols, 1] = np.arccos(np.clip(cos[mi, hj], 0.0, 1.0))
        outcomes[mi, cols, 2] = at_best(dih_all)[mi, hj]
        costs[mi, cols] = c.c_f * tb[mi, hj] + c.c_j + c.c_b + c.c_n
        clear[mi, cols] = np.minimum(s_hit, at_best(len_all) - s_hit)[mi, hj]
    return [(outcomes[i], costs[i], clear[i]) for i in range(n_m)]
