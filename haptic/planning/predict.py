"""Candidate moves and their predicted outcomes under each hypothesis (seed §4.1).

A hypothesis is one pose class of one model: a model, its pose ``world_from_model`` and the correspondence of
data components to model components. Through the pose, each hypothesis predicts what a candidate move would
yield "in its world": the distance travelled, the new edge's angle, the new face's angle; and what the move
would cost there. The planner compares these predictions (:mod:`haptic.planning.efficiency`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3
from haptic.geometry.tracing import circle_vertex, trace_edge, trace_face
from haptic.matching.components import DataComponent, DataEdge, DataFace, SensorNoise
from haptic.planning.moves import CostModel, EdgeMove, FaceMove, Move, SensorState, VertexMove


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
        if (face.points.mean(axis=0) - state.position) @ inward < 0:
            inward = -inward
        angles = (np.arange(n) + 0.5) * np.pi / n
        return [np.cos(a) * b + np.sin(a) * inward for a in angles]
    u = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(u) < 0.1:
        u = np.cross(normal, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(normal, u)
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


def predict_one(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> tuple[np.ndarray, float]:
    """One hypothesis's predicted outcome attributes and cost for a move (NaN attributes when it can't say)."""
    out, cost, _ = _predict_one(h, move, state, components, config)
    return out, cost


def _predict_one(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> tuple[np.ndarray, float, float]:
    nan_face, nan_edge, nan_vertex = np.full(3, np.nan), np.full(1, np.nan), np.full(2, np.nan)
    costs = config.costs
    if h.world_from_model is None:
        return {"face": nan_face, "edge": nan_edge, "vertex": nan_vertex}[move.kind], np.nan, np.nan
    model_from_world = h.world_from_model.inverse()
    p_m = model_from_world.apply(state.position)
    poly = h.poly
    if isinstance(move, FaceMove):
        f_m = h.faces.get(state.face)
        if f_m is None:
            return nan_face, np.nan, np.nan
        n = poly.face_normals[f_m]
        p_m = p_m - (p_m @ n - poly.face_offsets[f_m]) * n
        d_m = model_from_world.rotate(move.direction)
        hit = trace_face(poly, f_m, p_m, d_m)
        if hit is None:
            return nan_face, np.nan, np.nan
        out = np.array(
            [
                hit.distance,
                _line_angle(poly.edge_directions[hit.edge], d_m),
                _signed_dihedral(poly, f_m, hit.next_face, hit.edge),
            ]
        )
        s_hit = float((hit.point - poly.edge_points[hit.edge]) @ poly.edge_directions[hit.edge])
        clearance = min(s_hit, float(poly.edge_lengths[hit.edge]) - s_hit)
        return out, costs.face_move(hit.distance), clearance
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
    for h in hypotheses:
        o, c, cl = _predict_one(h, move, state, components, config)
        rows.append(o)
        costs.append(c)
        clear.append(cl)
    costs_arr = np.array(costs, dtype=float)
    if np.isnan(costs_arr).all():
        costs_arr[:] = 1.0
    else:
        costs_arr = np.where(np.isnan(costs_arr), np.nanmean(costs_arr), costs_arr)
    return Prediction(move, np.array(rows), outcome_bounds(noise)[move.kind], costs_arr, np.array(clear, dtype=float))
