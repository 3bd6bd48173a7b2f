"""Looking further than one move: each hypothesis simulates a move in its own world (noiseless), which gives
the data it would produce and the sensor state it would end in; from there the next moves are predicted.

Used by the planner when no single move is expected to eliminate anything (the discriminating features are
more than one move away), and by the ``optimal`` policy: an exhaustive search over move sequences
(directions discretised, depth limited) for the least expected path cost to recognition.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from haptic.geometry.tracing import circle_vertex, trace_edge, trace_face
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex, SensorNoise
from haptic.planning.efficiency import class_weights, outcome_groups
from haptic.planning.moves import EdgeMove, FaceMove, Move, SensorState, VertexMove
from haptic.planning.policies import Context, Decision, Policy, Scored
from haptic.planning.predict import Hypothesis, PlannerConfig, candidate_moves, predict

STEP_ONTO = 0.003
"""How far onto the next face a simulated face or vertex move steps for its normal [m]."""
EDGE_PROBE = 0.004
"""Length of edge explored when an edge is first met [m]."""


@dataclass(frozen=True, eq=False)
class Branch:
    """Where a group of hypotheses that one move cannot separate would be after it."""

    hypotheses: tuple[Hypothesis, ...]
    """The group's hypotheses with correspondences extended by the move's new components."""
    weights: np.ndarray
    """Their prior weights (not normalised)."""
    state: SensorState
    """Sensor state after the move (as the group's first hypothesis simulates it)."""
    components: Mapping[int, DataComponent]
    """Data so far plus the move's simulated components."""
    cost: float
    """Weighted mean cost of the move within the group [units]."""


def simulate(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> tuple[Hypothesis, SensorState, dict[int, DataComponent]] | None:
    """The move carried out exactly in hypothesis ``h``'s world: its extended correspondence, the new sensor
    state and the new (noiseless) data components; None when ``h`` cannot say (no pose, meets a vertex) or
    when a vertex move would only circle back to an edge and face already explored."""
    if h.world_from_model is None:
        return None
    t = h.world_from_model
    poly = h.poly
    p_m = t.inverse().apply(state.position)
    nxt = max(components) + 1 if components else 0
    new: dict[int, DataComponent] = {}
    faces, edges, vertices = dict(h.faces), dict(h.edges), dict(h.vertices)

    def face_comp(fid: int, g: int, point_m: np.ndarray, adjacent) -> DataFace:
        return DataFace(fid, t.rotate(poly.face_normals[g]), t.apply(point_m)[None, :], 0.0, 0.0, adjacent)

    if isinstance(move, FaceMove | VertexMove):
        if isinstance(move, FaceMove):
            f_m = h.faces.get(state.face)
            if f_m is None:
                return None
            d_m = t.inverse().rotate(move.direction)
            hit = trace_face(poly, f_m, p_m, d_m)
            if hit is None:
                return None
            e_m, g_m, at_m, from_face = hit.edge, hit.next_face, hit.point, state.face
        else:
            e0, v_m, a_m = (h.edges.get(state.edge), h.vertices.get(state.vertex), h.faces.get(move.across_face))
            if e0 is None or v_m is None or a_m is None:
                return None
            try:
                vh = circle_vertex(poly, v_m, e0, a_m, config.vertex_radius)
            except ValueError:
                return None
            e_m, g_m, from_face = vh.edge, vh.next_face, move.across_face
            away = poly.edge_directions[e_m] * (1.0 if poly.edges[e_m, 0] == v_m else -1.0)
            at_m = poly.vertices[v_m] + config.vertex_radius * away
        if e_m in h.edges.values() and g_m in h.faces.values() and isinstance(move, VertexMove):
            return None  # circles back to an edge and face already explored: nothing new to see
        b_m = poly.edge_directions[e_m]
        s = float(np.clip((at_m - poly.edge_points[e_m]) @ b_m, 0.0, poly.edge_lengths[e_m]))
        lo = max(0.0, s - EDGE_PROBE / 2)
        hi = min(float(poly.edge_lengths[e_m]), s + EDGE_PROBE / 2)
        eid, fid = nxt, nxt + 1
        adj = (from_face,) if isinstance(move, FaceMove) else (state.vertex, from_face)
        new[eid] = DataEdge(
            eid, t.rotate(b_m), t.apply(poly.edge_points[e_m] + lo * b_m), hi - lo, 0.0, 0.0, 0.0, adjacent=adj
        )
        inward = np.cross(poly.face_normals[g_m], b_m)
        if poly.edge_left_face[e_m] != g_m:
            inward = -inward
        onto = at_m + STEP_ONTO * inward
        new[fid] = face_comp(fid, g_m, onto, (eid,))
        edges[eid], faces[fid] = e_m, g_m
        vertex = state.vertex if isinstance(move, VertexMove) else None
        new_state = SensorState(t.apply(onto), fid, eid, vertex, (from_face, fid))
    elif isinstance(move, EdgeMove):
        e_m = h.edges.get(state.edge)
        data_edge = components.get(state.edge)
        if e_m is None or not isinstance(data_edge, DataEdge):
            return None
        sense_m = move.sense if t.rotate(poly.edge_directions[e_m]) @ data_edge.direction > 0 else -move.sense
        eh = trace_edge(poly, e_m, p_m, sense_m)
        vid = nxt
        v_w = t.apply(poly.vertices[eh.vertex])
        b, p, length = data_edge.direction, data_edge.point, data_edge.length
        if move.sense > 0:
            ext = replace(data_edge, length=max(length, float((v_w - p) @ b)), end_vertex=vid)
        else:
            end = p + length * b
            ext = replace(data_edge, point=v_w, length=max(0.0, float((end - v_w) @ b)), start_vertex=vid)
        new[ext.id] = ext
        new[vid] = DataVertex(vid, v_w, 0.0, (ext.id,))
        vertices[vid] = eh.vertex
        new_state = SensorState(v_w, state.face, state.edge, vid, state.edge_faces)
    else:
        raise TypeError(f"unknown move {move!r}")
    merged = dict(components)
    merged.update(new)
    return replace(h, faces=faces, edges=edges, vertices=vertices), new_state, merged


def branches(
    hyps: Sequence[Hypothesis],
    weights: np.ndarray,
    move: Move,
    state: SensorState,
    components: Mapping[int, DataComponent],
    noise: SensorNoise,
    config: PlannerConfig,
) -> list[Branch]:
    """Split the hypotheses by what ``move`` would show, and simulate each group onward."""
    pred = predict(hyps, move, state, components, noise, config)
    out = []
    for g in outcome_groups(pred.outcomes, pred.bounds):
        sims = [(i, simulate(hyps[i], move, state, components, config)) for i in g]
        sims = [(i, s) for i, s in sims if s is not None]
        if not sims:
            continue
        idx = [i for i, _ in sims]
        w = weights[idx]
        _, st, comps = sims[0][1]
        out.append(
            Branch(tuple(s[0] for _, s in sims), w, st, comps, float(pred.costs[idx] @ (w / w.sum())))
        )
    return out


def expected_cost_to_go(
    hyps: Sequence[Hypothesis],
    weights: np.ndarray,
    state: SensorState,
    components: Mapping[int, DataComponent],
    noise: SensorNoise,
    config: PlannerConfig,
    depth: int,
    leaf_cost: float,
) -> tuple[float, Move | None]:
    """Least expected cost until one hypothesis remains, searching ``depth`` moves ahead.

    A node with one hypothesis costs 0; a node still unresolved at depth 0 costs ``leaf_cost`` per halving
    still needed (``leaf_cost · log2 n``), an optimistic estimate of the rest.
    """
    n = len(hyps)
    if n <= 1:
        return 0.0, None
    if depth == 0:
        return leaf_cost * float(np.log2(n)), None
    best, best_move = np.inf, None
    total = float(weights.sum())
    for move in candidate_moves(state, components, config):
        bs = branches(hyps, weights, move, state, components, noise, config)
        covered = sum(float(br.weights.sum()) for br in bs) / total
        if covered < 1e-9:
            continue  # no hypothesis can carry the move out (or it only circles back)
        # hypotheses that cannot simulate the move learn nothing from it: they stay where they were
        value = (1.0 - covered) * (max((br.cost for br in bs), default=0.0) + leaf_cost * float(np.log2(n)))
        for br in sorted(bs, key=lambda b: -float(b.weights.sum())):
            p = float(br.weights.sum()) / total
            rest, _ = expected_cost_to_go(
                br.hypotheses, br.weights, br.state, br.components, noise, config, depth - 1, leaf_cost
            )
            value += p * (br.cost + rest)
            if value >= best:
                break
        if value < best:
            best, best_move = value, move
    return best, best_move


class OptimalPolicy(Policy):
    """Exhaustive depth-limited search for the least expected path cost to recognition.

    ``depth`` moves are searched exhaustively over the discretised candidates (``n_directions`` face-move
    directions); beyond it, an optimistic ``leaf_cost · log2 n`` stands for the rest. Re-planned after every
    move (receding horizon). Feasible for small libraries: the work grows as (candidates)^depth.
    """

    name = "optimal"

    def __init__(self, depth: int = 3, n_directions: int = 6, leaf_cost: float | None = None) -> None:
        self.depth = depth
        self.n_directions = n_directions
        self.leaf_cost = leaf_cost

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:
        config = replace(ctx.config, n_directions=self.n_directions)
        weights = class_weights([h.model for h in ctx.hypotheses])
        leaf = self.leaf_cost if self.leaf_cost is not None else config.costs.face_move(0.03)
        value, move = expected_cost_to_go(
            ctx.hypotheses, weights, ctx.state, ctx.components, ctx.noise, config, self.depth, leaf
        )
        if move is None:
            from haptic.planning.policies import PlannerPolicy

            return PlannerPolicy().choose(ctx, rng)
        return Decision(move, (Scored(move, -value, value, float("nan")),))


def lookahead_choice(ctx: Context, depth: int = 2) -> Move | None:
    """The first move of the best ``depth``-move sequence by expected eliminations per expected cost, for
    when no single move is expected to eliminate anything. None when no sequence eliminates anything."""
    weights = class_weights([h.model for h in ctx.hypotheses])
    best, best_move = 0.0, None
    for move in candidate_moves(ctx.state, ctx.components, ctx.config):
        score = _lookahead_score(ctx, list(ctx.hypotheses), weights, move, ctx.state, ctx.components, depth, 0.0)
        if score > best:
            best, best_move = score, move
    return best_move


def _lookahead_score(ctx, hyps, weights, move, state, components, depth, spent) -> float:
    """Best expected (pose classes eliminated) / (expected cost) over sequences starting with ``move``."""
    total_w = float(weights.sum())
    n = len(hyps)
    score = 0.0
    for br in branches(hyps, weights, move, state, components, ctx.noise, ctx.config):
        p = float(br.weights.sum()) / total_w
        eliminated = n - len(br.hypotheses)
        cost = spent + br.cost
        here = eliminated / cost if eliminated > 0 else 0.0
        further = 0.0
        if depth > 1 and eliminated == 0:
            for m2 in candidate_moves(br.state, br.components, ctx.config):
                further = max(
                    further,
                    _lookahead_score(
                        ctx, list(br.hypotheses), br.weights, m2, br.state, br.components, depth - 1, cost
                    ),
                )
        score += p * max(here, further)
    return score
