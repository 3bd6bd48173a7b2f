"""Candidate moves and their predicted outcomes under each hypothesis (seed §4.1).

A hypothesis is one pose class of one model: a model, its pose ``world_from_model`` and the correspondence of
data components to model components. Through the pose, each hypothesis predicts what a candidate move would
yield "in its world": the distance travelled, the new edge's angle, the new face's angle; and what the move
would cost there. The planner compares these predictions (:mod:`haptic.planning.efficiency`).
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3, plane_basis
from haptic.geometry.tracing import FaceHit, circle_vertex, trace_edge, trace_face
from haptic.matching.components import DataComponent, DataEdge, DataFace, SensorNoise
from haptic.planning.moves import DEFAULT_MOVES, CostModel, EdgeMove, FaceMove, Move, SensorState, VertexMove


@dataclass(frozen=True)
class PlannerConfig:
    """Options of candidate generation and prediction."""

    n_directions: int = 8
    """Face-move directions sampled over the half-plane into the face (§4.1.3: discrete angles)."""
    vertex_radius: float = 0.008
    """Radius of the circular path of a vertex move [m]."""
    costs: CostModel = field(default_factory=CostModel)
    """Cost constants (§3.1)."""
    min_face_travel: float = 0.006
    """Face moves predicted (median over hypotheses) to meet an edge sooner than this are not offered: a
    finger that starts that close to an edge cannot settle on the face first [m]."""
    min_vertex_clearance: float = 0.004
    """Face moves predicted to meet their edge closer than this to a vertex are not offered: a fingertip
    crossing there touches two edges at once [m]."""
    table_z: float | None = None
    """Height of the table top in the world frame, a workspace prior the robot knows (set for the physics
    executor's scene, never from the object) [m]. None: no table (the geometric executor), no table checks."""
    pad_radius: float = 0.012
    """Radius of the fingertip pad (the robot's own geometry), for the table checks [m]."""
    table_clearance: float = 0.004
    """A pad position whose lowest point would come closer than this to the table top counts as on the table:
    the executor's own limit (2 mm) plus a margin for the hypotheses' pose error [m]."""
    steep_descent: float = 0.5
    """A face move whose direction points down more steeply than this (the sine of its descent) is "steep"."""
    steep_descent_risk: float = 0.0
    """Failure risk charged to steep face moves (their efficiency is discounted by it): the physics hand,
    fingers pointing down, often loses the surface rolling down over the edge such a trace meets. 0: none."""
    table_rest_tol: float = 0.003
    """With a table, a pose class whose model would reach more than this below the table top, or whose lowest
    point would float more than this above it, is not a pose the object can rest in [m]."""
    max_undercut: float | None = None
    """With a table, how far a face's outward normal may lean back under, past horizontal, for the pad of the
    downward-pointing fingers to roll onto it over a convex edge (the robot's own reach, set for the physics
    executor) [rad]. A face move predicted to roll over an edge onto a face leaning further ends there and
    reports the edge alone (:attr:`Prediction.edge_only`); a vertex move doing so counts as refused like one
    running into the table. None: no limit."""
    touch_evidence: bool = False
    """Every touched point is checked against each pose class's surface (the episode does so with the
    physics executor's traces), so a face move that cannot step onto its next face still tells how far its
    face reaches; scored so."""
    touch_tol: float = 0.0025
    """A touched point farther than this from every face of a pose class whose normal agrees with the sensed
    one contradicts the class [m]."""
    touch_outliers: int = 3
    """Contradicting points it takes to set a pose class aside (a stray reading is not enough)."""
    touch_spacing: float = 0.001
    """Touched points are thinned to about one per this much of the trace [m]."""
    table_risk: float = 0.5
    """Candidate moves that at least this fraction of the hypotheses predict to bring the pad onto the table
    are not offered (the executor would refuse or abort them); the rest are discounted by their risk."""
    max_hypotheses: int | None = 256
    """Most pose classes a policy scores moves against; above it, a reduced set chosen model by model
    (:mod:`haptic.planning.bound`). None: no bound. 256 is above the most pose classes the shipped libraries
    leave at a planner decision (255, look-alike library, with the loop posing up to
    ``haptic.episode.loop.MAX_POSED`` interpretations), so their decisions are unchanged."""
    moves: str = DEFAULT_MOVES
    """Admissible kinds of move (``MOVE_SETS``): "tracing" (face, edge and vertex moves), "probing" (free-space
    probes) or "all" (both, ranked together by one efficiency, seed §1.1)."""

    @property
    def touch_margin(self) -> float:
        """How far past a pose class's edge a trace must touch its face for the touched points to set the
        class aside (``touch_outliers`` points beyond ``touch_tol``) [m]."""
        return self.touch_tol + self.touch_outliers * self.touch_spacing


@dataclass(frozen=True, eq=False)
class Hypothesis:
    """One pose class of one model, as the planner sees it."""

    model: str
    """Model name."""
    poly: Polyhedron
    """The model."""
    world_from_model: SE3 | None
    """Pose (None until the data fix it)."""
    faces: Mapping[int, int]
    """Data face id → model face id."""
    edges: Mapping[int, int]
    """Data edge id → model edge id."""
    vertices: Mapping[int, int]
    """Data vertex id → model vertex id."""
    size: int = 1
    """Interpretations in this pose class."""
    leaves: tuple[int, ...] = ()
    """The matcher's leaf indices of this pose class's interpretations (when known)."""

    @cached_property
    def model_from_world(self) -> SE3 | None:
        """The inverse pose (computed once)."""
        return None if self.world_from_model is None else self.world_from_model.inverse()


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
            np.nanmedian(self.outcomes[:, 0]) >= config.min_face_travel
            and np.nanmedian(self.clearance) >= config.min_vertex_clearance
        )


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
        inward = np.cross(normal, b)
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
    ang = float(np.arccos(np.clip(poly.face_normals[f_from] @ poly.face_normals[f_to], -1, 1)))
    return ang if poly.edge_convexity[edge] > 0 else -ang


def _line_angle(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two lines (unsigned directions), in [0, π/2] [rad]."""
    return float(np.arccos(np.clip(abs(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b)), 0.0, 1.0)))


@dataclass(frozen=True, eq=False)
class FaceTrace:
    """A face move traced in one hypothesis's world (model frame)."""

    face: int
    """The model face traced."""
    start: np.ndarray
    """The sensor's position projected onto it."""
    direction: np.ndarray
    """The move's direction."""
    hit: FaceHit
    """Where it meets the face's boundary."""

    def clearance(self, poly: Polyhedron) -> float:
        """Distance of the crossing point from the nearer end of the edge met [m]."""
        e = self.hit.edge
        s_hit = float((self.hit.point - poly.edge_points[e]) @ poly.edge_directions[e])
        return min(s_hit, float(poly.edge_lengths[e]) - s_hit)


def trace_in(h: Hypothesis, move: FaceMove, state: SensorState) -> FaceTrace | None:
    """Face move ``move`` from ``state`` traced in hypothesis ``h``'s world; None when ``h`` cannot say (no
    pose, the current face not matched, no single edge met)."""
    f_m = h.faces.get(state.face)
    if h.world_from_model is None or f_m is None:
        return None
    model_from_world = h.model_from_world
    poly, p_m = h.poly, model_from_world.apply(state.position)
    n = poly.face_normals[f_m]
    p_m = p_m - (p_m @ n - poly.face_offsets[f_m]) * n
    d_m = model_from_world.rotate(move.direction)
    hit = trace_face(poly, f_m, p_m, d_m)
    return None if hit is None else FaceTrace(f_m, p_m, d_m, hit)


_LOOPS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _face_loop(poly: Polyhedron, face: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A face's sides as arrays (cached per model): start vertices ``a`` (K, 3), side vectors (K, 3), edge ids
    and the faces beyond them (K,), in loop order (as :func:`~haptic.geometry.tracing.trace_face` walks them)."""
    per = _LOOPS.setdefault(poly, {})
    if face not in per:
        loop = poly.faces[face]
        a = poly.vertices[list(loop)]
        seg = np.roll(a, -1, axis=0) - a
        edges = np.asarray(poly.face_edges[face], dtype=np.int64)
        beyond = np.where(poly.edge_left_face[edges] == face, poly.edge_right_face[edges], poly.edge_left_face[edges])
        per[face] = (a, seg, edges, beyond)
    return per[face]


def trace_all(hypotheses: Sequence[Hypothesis], move: FaceMove, state: SensorState) -> list[FaceTrace | None]:
    """:func:`trace_in` for every hypothesis at once: the sides of every hypothesis's current face are stacked
    (padded to the longest loop) and the crossing of the trace with each side solved in one array operation
    (in the face's plane, ``start + t d = a + u (b − a)``); the first side met ahead, clear of its ends, is the
    hit. The same outcome as :func:`~haptic.geometry.tracing.trace_face` for each hypothesis."""
    out: list[FaceTrace | None] = [None] * len(hypotheses)
    rows, starts, dirs, dirs_raw, normals, loops = [], [], [], [], [], []
    for i, h in enumerate(hypotheses):
        f_m = h.faces.get(state.face)
        if h.world_from_model is None or f_m is None:
            continue
        model_from_world = h.model_from_world
        poly, p_m = h.poly, model_from_world.apply(state.position)
        n = poly.face_normals[f_m]
        p_m = p_m - (p_m @ n - poly.face_offsets[f_m]) * n
        d_m = model_from_world.rotate(move.direction)
        d = d_m - (d_m @ n) * n
        norm = np.linalg.norm(d)
        if norm < 1e-9:
            continue
        rows.append(i)
        starts.append(p_m)
        dirs.append(d / norm)
        dirs_raw.append(d_m)
        normals.append(n)
        loops.append(_face_loop(poly, f_m))
    if not rows:
        return out
    k = max(len(lp[2]) for lp in loops)
    m = len(rows)
    a = np.zeros((m, k, 3))
    seg = np.zeros((m, k, 3))
    real = np.zeros((m, k), dtype=bool)
    for j, lp in enumerate(loops):
        a[j, : len(lp[2])], seg[j, : len(lp[2])], real[j, : len(lp[2])] = lp[0], lp[1], True
    start, d, n = np.array(starts), np.array(dirs), np.array(normals)
    r = a - start[:, None]
    den = np.einsum("mkc,mc->mk", np.cross(d[:, None], seg), n)
    safe = np.where(np.abs(den) > 1e-15, den, 1.0)
    t = np.einsum("mkc,mc->mk", np.cross(r, seg), n) / safe
    u = np.einsum("mkc,mkc->mk", np.cross(r, d[:, None]), n[:, None].repeat(k, axis=1)) / safe
    miss = start[:, None] + t[..., None] * d[:, None] - (a + u[..., None] * seg)
    ok = real & (np.abs(den) > 1e-15) & (t > 1e-12) & (u >= -1e-12) & (u <= 1 + 1e-12)
    ok &= np.linalg.norm(miss, axis=2) <= 1e-7
    t_ok = np.where(ok, t, np.inf)
    best = np.argmin(t_ok, axis=1)
    for j, i in enumerate(rows):
        b = int(best[j])
        if not np.isfinite(t_ok[j, b]):
            continue
        seg_len = float(np.linalg.norm(seg[j, b]))
        if min(u[j, b], 1 - u[j, b]) * seg_len < 1e-6:
            continue
        _, _, edges, beyond = loops[j]
        tj = float(t[j, b])
        hit = FaceHit(edge=int(edges[b]), distance=tj, point=start[j] + tj * d[j], next_face=int(beyond[b]))
        f_m = hypotheses[i].faces[state.face]
        out[i] = FaceTrace(f_m, starts[j], dirs_raw[j], hit)
    return out


def predict_one(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> tuple[np.ndarray, float]:
    """One hypothesis's predicted outcome attributes and cost for a move (NaN attributes when it can't say)."""
    out, cost, _ = _predict_one(h, move, state, components, config)
    return out, cost


def _predict_one(
    h: Hypothesis,
    move: Move,
    state: SensorState,
    components: Mapping[int, DataComponent],
    config: PlannerConfig,
    trace: FaceTrace | None | bool = False,
) -> tuple[np.ndarray, float, float]:
    nan_face, nan_edge, nan_vertex = np.full(3, np.nan), np.full(1, np.nan), np.full(2, np.nan)
    costs = config.costs
    if h.world_from_model is None:
        return {"face": nan_face, "edge": nan_edge, "vertex": nan_vertex}[move.kind], np.nan, np.nan
    model_from_world = h.model_from_world
    p_m = model_from_world.apply(state.position)
    poly = h.poly
    if isinstance(move, FaceMove):
        tr = trace_in(h, move, state) if trace is False else trace
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
        hit = trace_edge(poly, e_m, p_m, sense_m)
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


def crossed_edge(h: Hypothesis, move: FaceMove, state: SensorState) -> int | None:
    """The model edge hypothesis ``h`` predicts face move ``move`` to meet (None when it cannot say)."""
    tr = trace_in(h, move, state)
    return None if tr is None else int(tr.hit.edge)


def predict(
    hypotheses: Sequence[Hypothesis],
    move: Move,
    state: SensorState,
    components: Mapping[int, DataComponent],
    noise: SensorNoise,
    config: PlannerConfig,
) -> Prediction:
    """Every hypothesis's predicted outcome and cost for one candidate move."""
    rows, costs, clear = [], [], []
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
            got = np.array([_table_conflict(h, move, state, components, config) for h in hypotheses], dtype=float)
            table = got[:, 0]
            if isinstance(move, FaceMove):
                reach = got[:, 1]
                edge_only = got[:, 2] if config.max_undercut is not None else None
    costs_arr = np.array(costs, dtype=float)
    if np.isnan(costs_arr).all():
        costs_arr[:] = 1.0
    else:
        costs_arr = np.where(np.isnan(costs_arr), np.nanmean(costs_arr), costs_arr)
    return Prediction(
        move, np.array(rows), outcome_bounds(noise)[move.kind], costs_arr, np.array(clear, dtype=float), table,
        reach, edge_only,
    )


# ------------------------------------------------------------------------------------------- the table

EDGE_ROLL = np.deg2rad(12.0)
"""How far the pad's normal must turn over an edge, before it leans under past ``max_undercut``, for the
executor to measure the edge from the roll alone (its segmenter wants 10°): from a face leaning under
within this of the limit, a move ending at an edge onto a face out of reach tells nothing [rad]."""
EDGE_ONLY_CLEARANCE = 0.008
"""A face move ends at its edge with the next face out of reach, reporting the edge alone, only where it meets
the edge at least this far from both its ends: the pad rolls some 40° over it, its centre as far past the
edge's line as ``pad_radius · sin 40°``, and nearer an end it touches the faces round the vertex [m]."""
TABLE_STEP_ONTO = 0.003
"""How far onto the next face a face or vertex move strokes for its normal (for the table check) [m]."""


def pad_clearance(point: np.ndarray, normal: np.ndarray, config: PlannerConfig) -> float:
    """Height above the table top of the pad's lowest point when it touches ``point`` of a surface of outward
    ``normal`` (the fingers point down) [m]; +inf without a table."""
    if config.table_z is None:
        return float("inf")
    r = config.pad_radius
    return float(point[2] + r * normal[2] - r - config.table_z)


def _inward(poly: Polyhedron, edge: int, face: int) -> np.ndarray:
    """Unit vector in ``face``'s plane, perpendicular to ``edge``, pointing into the face (model frame)."""
    w = np.cross(poly.face_normals[face], poly.edge_directions[edge])
    return w if poly.edge_left_face[edge] == face else -w


def circle_points(
    vertex: np.ndarray, u: np.ndarray, w: np.ndarray, radius: float, start: float, stop: float, step: float
) -> np.ndarray:
    """Points of the circle of a vertex move: ``vertex + radius (−cos θ u + sin θ w)`` for θ from ``start`` to
    ``stop`` (``u`` along the current edge toward the vertex, ``w`` into the crossed face), shape (K, 3)."""
    th = np.arange(start, stop + 1e-9, step) if stop > start else np.array([start])
    return vertex + radius * (-np.cos(th)[:, None] * u + np.sin(th)[:, None] * w)


VERTEX_START_ANGLE = np.deg2rad(25.0)
"""The physics executor's vertex circle starts this far from the current edge [rad]."""


def table_conflict(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> float:
    """Whether hypothesis ``h`` predicts ``move`` to bring the pad onto the table (1.0), not (0.0), or cannot
    say (NaN): a face move sliding down to an edge within the pad's reach of the table or stepping onto a face
    the table hides; a vertex move whose circle, before it meets the next edge, would put the pad on the table,
    or whose next face the table hides. Edge moves are never refused (one running down to the table ends at
    the vertex the table blocks, which the executor finds). A workspace prior (``config.table_z``) with the
    hypothesis's own pose; 0.0 without a table. With ``config.max_undercut``, a vertex move stepping over a
    convex edge onto a face that leans under further than the pad reaches counts too (a face move doing so
    ends at the edge instead: :attr:`Prediction.edge_only`)."""
    return _table_conflict(h, move, state, components, config)[0]


def _table_conflict(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> tuple[float, float]:
    """:func:`table_conflict`; for a face move, how far its trace touches the face (:attr:`Prediction.reach`)
    and whether it ends at its edge, the next face out of reach (:attr:`Prediction.edge_only`); NaN, NaN for
    other moves."""
    if config.table_z is None:
        return 0.0, np.nan, np.nan
    t = h.world_from_model
    if t is None:
        return np.nan, np.nan, np.nan
    poly, lim = h.poly, config.table_clearance

    def leans_under(e_m: int, g_m: int) -> bool:
        """Whether the pad cannot roll over convex edge ``e_m`` onto ``g_m``: it leans under, out of reach."""
        if config.max_undercut is None or poly.edge_convexity[e_m] <= 0:
            return False
        return float(t.rotate(poly.face_normals[g_m])[2]) < -np.sin(config.max_undercut)

    def onto_hidden(e_m: int, g_m: int, at_m: np.ndarray) -> bool:
        q = t.apply(at_m + TABLE_STEP_ONTO * _inward(poly, e_m, g_m))
        return leans_under(e_m, g_m) or pad_clearance(q, t.rotate(poly.face_normals[g_m]), config) < lim

    if isinstance(move, FaceMove):
        tr = trace_in(h, move, state)
        if tr is None:
            return np.nan, np.nan, np.nan
        hit = tr.hit
        n_w = t.rotate(poly.face_normals[tr.face])
        d_z = float(np.asarray(move.direction)[2])
        if d_z < 0.0 and pad_clearance(t.apply(hit.point), n_w, config) < lim:
            # the slide stops where the pad comes too close to the table
            start = pad_clearance(t.apply(tr.start), n_w, config)
            return 1.0, float(np.clip((start - lim) / -d_z, 0.0, hit.distance)), 0.0
        if leans_under(hit.edge, hit.next_face):
            near_end = tr.clearance(poly) < EDGE_ONLY_CLEARANCE
            if near_end or float(n_w[2]) < -np.sin(config.max_undercut - EDGE_ROLL):
                return 1.0, float(hit.distance), 0.0  # no room to roll over the edge alone: the move fails there
            return 0.0, float(hit.distance), 1.0
        return float(onto_hidden(hit.edge, hit.next_face, hit.point)), float(hit.distance), 0.0
    if isinstance(move, EdgeMove):
        # an edge running down to the table ends at a vertex on it, where the table blocks the finger: the
        # executor finds that vertex (the only way to measure such an edge), so an edge move is never refused
        return 0.0, np.nan, np.nan
    if isinstance(move, VertexMove):
        e_m = h.edges.get(state.edge) if state.edge is not None else None
        v_m = h.vertices.get(state.vertex) if state.vertex is not None else None
        a_m = h.faces.get(move.across_face)
        if e_m is None or v_m is None or a_m is None:
            return np.nan, np.nan, np.nan
        try:
            hit = circle_vertex(poly, v_m, e_m, a_m, config.vertex_radius)
        except ValueError:
            return np.nan, np.nan, np.nan
        u = poly.edge_directions[e_m] * (1.0 if poly.edges[e_m, 1] == v_m else -1.0)
        pts = circle_points(poly.vertices[v_m], u, _inward(poly, e_m, a_m), config.vertex_radius,
                            VERTEX_START_ANGLE, hit.angle, np.deg2rad(3.0))  # fmt: skip
        n_w = t.rotate(poly.face_normals[a_m])
        if min(pad_clearance(q, n_w, config) for q in t.apply(pts)) < lim:
            return 1.0, np.nan, np.nan
        away = poly.edge_directions[hit.edge] * (1.0 if poly.edges[hit.edge, 0] == v_m else -1.0)
        at = poly.vertices[v_m] + config.vertex_radius * away
        return float(onto_hidden(hit.edge, hit.next_face, at)), np.nan, np.nan
    raise TypeError(f"unknown move {move!r}")


def _vertex_frame(
    state: SensorState, components: Mapping[int, DataComponent], face: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """From the data: the current vertex, the unit vector along the current edge toward it, the unit vector
    into data face ``face`` perpendicular to the edge, and that face's normal. None when the data lack one."""
    edge = components.get(state.edge) if state.edge is not None else None
    vertex = components.get(state.vertex) if state.vertex is not None else None
    f = components.get(face)
    if not isinstance(edge, DataEdge) or vertex is None or not isinstance(f, DataFace):
        return None
    b, n = edge.direction, f.normal
    mid = edge.point + 0.5 * edge.length * b
    u = b if (vertex.position - mid) @ b >= 0 else -b
    w = np.cross(n, b)
    w /= max(float(np.linalg.norm(w)), 1e-12)
    side = dict(edge.side_points).get(face) if edge.side_points else None
    ref = side if side is not None else f.points.mean(axis=0)
    if (ref - edge.point) @ w < 0:
        w = -w
    return vertex.position, u, w, n


def vertex_sweep_off_table(
    state: SensorState, components: Mapping[int, DataComponent], face: int, config: PlannerConfig
) -> float:
    """From the data alone: the angle the circle of a vertex move across data face ``face`` can sweep from its
    start before the pad would come onto the table (2π: never; 0: its start is out of reach) [rad]."""
    if config.table_z is None:
        return 2 * np.pi
    frame = _vertex_frame(state, components, face)
    if frame is None:
        return 2 * np.pi
    vtx, u, w, n = frame
    step = np.deg2rad(2.0)
    pts = circle_points(vtx, u, w, config.vertex_radius, VERTEX_START_ANGLE, 2 * np.pi - VERTEX_START_ANGLE, step)
    low = [i for i, q in enumerate(pts) if pad_clearance(q, n, config) < config.table_clearance]
    return float(low[0] * step) if low else 2 * np.pi


def data_table_conflict(
    move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> bool:
    """What the data alone say about the table, whatever the model: a face move heading down from a point
    already within the pad's reach of the table, or a vertex move whose circle cannot even start off it."""
    if config.table_z is None:
        return False
    if isinstance(move, FaceMove):
        face = components.get(state.face)
        if not isinstance(face, DataFace) or float(np.asarray(move.direction)[2]) >= 0.0:
            return False
        return pad_clearance(state.position, face.normal, config) < config.table_clearance
    if isinstance(move, VertexMove):
        return vertex_sweep_off_table(state, components, move.across_face, config) <= 0.0
    return False


def move_table_risk(
    move: Move,
    hypotheses: Sequence[Hypothesis],
    state: SensorState,
    components: Mapping[int, DataComponent],
    config: PlannerConfig,
) -> float:
    """Fraction of the hypotheses (that can say) predicting ``move`` to run into the table; 1 when the data
    alone say so; 0 without a table or a prediction."""
    if config.table_z is None:
        return 0.0
    if data_table_conflict(move, state, components, config):
        return 1.0
    vals = np.array([table_conflict(h, move, state, components, config) for h in hypotheses], dtype=float)
    return 0.0 if not len(vals) or np.isnan(vals).all() else float(np.nanmean(vals))


def table_safe_moves(
    moves: Sequence[Move],
    hypotheses: Sequence[Hypothesis],
    state: SensorState,
    components: Mapping[int, DataComponent],
    config: PlannerConfig,
) -> list[Move]:
    """``moves`` less those predicted to run into the table (risk ≥ ``config.table_risk``); all of them when
    that leaves none (the executor then says so). Unchanged without a table."""
    if config.table_z is None:
        return list(moves)
    safe = [m for m in moves if move_table_risk(m, hypotheses, state, components, config) < config.table_risk]
    return safe or list(moves)


def descent_risk(move: Move, config: PlannerConfig) -> float:
    """``config.steep_descent_risk`` for a face move heading down more steeply than ``config.steep_descent``,
    else 0."""
    if move.kind != "face" or config.steep_descent_risk <= 0.0:
        return 0.0
    return config.steep_descent_risk if float(np.asarray(move.direction)[2]) < -config.steep_descent else 0.0


def rests_on_table(poly: Polyhedron, world_from_model: SE3, config: PlannerConfig) -> bool:
    """Whether ``poly`` at ``world_from_model`` rests on the table: its lowest vertex at the table top within
    ``config.table_rest_tol`` (neither through it nor floating). True without a table."""
    if config.table_z is None:
        return True
    low = float(world_from_model.apply(poly.vertices)[:, 2].min()) - config.table_z
    return abs(low) <= config.table_rest_tol


def pose_fixed_by(components: Mapping[int, DataComponent]) -> bool:
    """Whether the data fix every interpretation's translation: a data vertex, or faces whose normals span
    space. (Until then a pose class's pose is one of many and says nothing about where the table is.)"""
    if any(c.kind == "vertex" for c in components.values()):
        return True
    normals = np.array([c.normal for c in components.values() if isinstance(c, DataFace)])
    return len(normals) >= 3 and float(np.linalg.svd(normals, compute_uv=False)[2]) > 0.3
