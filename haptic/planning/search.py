"""Looking further than one move: each hypothesis simulates a move in its own world (noiseless), which gives
the data it would produce and the sensor state it would end in; from there the next moves are predicted.

Used by the planner when no single move is expected to eliminate anything (the discriminating features are
more than one move away), and to check predictions against the matcher itself
(:func:`matcher_eliminations`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from haptic.geometry.tracing import circle_vertex, trace_edge
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex, SensorNoise
from haptic.planning.efficiency import class_weights, outcome_groups
from haptic.planning.moves import EdgeMove, FaceMove, Move, SensorState, VertexMove
from haptic.planning.policies import Context, refusal, same_move, score_prediction
from haptic.planning.predict import Hypothesis, PlannerConfig, candidate_moves, predict, trace_in

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
    h: Hypothesis,
    move: Move,
    state: SensorState,
    components: Mapping[int, DataComponent],
    config: PlannerConfig,
    noise: SensorNoise | None = None,
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

    k = noise.k if noise is not None else 0.0
    nb = k * noise.normal_sigma if noise is not None else 0.0
    db = k * noise.direction_sigma if noise is not None else 0.0
    pb = k * noise.position_sigma if noise is not None else 0.0
    lb = k * noise.length_sigma if noise is not None else 0.0

    def face_comp(fid: int, g: int, point_m: np.ndarray, adjacent) -> DataFace:
        return DataFace(fid, t.rotate(poly.face_normals[g]), t.apply(point_m)[None, :], nb, pb, adjacent)

    if isinstance(move, FaceMove | VertexMove):
        if isinstance(move, FaceMove):
            tr = trace_in(h, move, state)
            if tr is None:
                return None
            e_m, g_m, at_m, from_face = tr.hit.edge, tr.hit.next_face, tr.hit.point, state.face
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
        inward = np.cross(poly.face_normals[g_m], b_m)
        if poly.edge_left_face[e_m] != g_m:
            inward = -inward
        onto = at_m + STEP_ONTO * inward
        f_from = h.faces[from_face]
        back = np.cross(poly.face_normals[f_from], b_m)
        if poly.edge_left_face[e_m] != f_from:
            back = -back
        sides = ((from_face, t.apply(at_m + STEP_ONTO * back)), (fid, t.apply(onto)))
        new[eid] = DataEdge(
            eid, t.rotate(b_m), t.apply(poly.edge_points[e_m] + lo * b_m), hi - lo, db, pb, lb,
            adjacent=adj, side_points=sides,
        )  # fmt: skip
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
        new[vid] = DataVertex(vid, v_w, pb, (ext.id,))
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
    if not pred.reliable(config) or pred.table_risk >= config.table_risk:
        return []
    if pred.edge_only is not None and (pred.edge_only == 1).any():
        return []  # not a step on to somewhere else: in some worlds the sensor stays where it is
    out = []
    for g in outcome_groups(pred.outcomes, pred.bounds):
        sims = [(i, simulate(hyps[i], move, state, components, config, noise)) for i in g]
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


def lookahead_choice(ctx: Context, depth: int = 2) -> Move | None:
    """The first move of the best ``depth``-move sequence by expected eliminations per expected cost, for
    when no single move is expected to eliminate anything. None when no sequence eliminates anything."""
    weights = class_weights([h.model for h in ctx.hypotheses])
    best, best_move = 0.0, None
    for move in candidate_moves(ctx.state, ctx.components, ctx.config):
        if any(same_move(move, bad) for bad in ctx.avoid):
            continue
        score = _lookahead_score(ctx, list(ctx.hypotheses), weights, move, ctx.state, ctx.components, depth, 0.0)
        if score > best:
            best, best_move = score, move
    return best_move


def _lookahead_score(ctx, hyps, weights, move, state, components, depth, spent) -> float:
    """Best expected (pose classes eliminated) / (expected cost) over sequences starting with ``move``: the
    last move scored as the planner scores one (with what the table and touched points tell, when known),
    the moves before it carried out in each group's world."""
    if depth == 1:
        return _last_move_score(ctx, hyps, weights, move, state, components, spent)
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


def _last_move_score(ctx, hyps, weights, move, state, components, spent) -> float:
    """The expected pose classes ``move`` eliminates, discounted by its risk, per the expected cost of the
    sequence ending with it."""
    pred = predict(hyps, move, state, components, ctx.noise, ctx.config)
    if not pred.reliable(ctx.config):
        return 0.0
    refused = refusal(pred, ctx.config)
    if refused >= ctx.config.table_risk:
        return 0.0
    w = np.asarray(weights, dtype=float)
    _, elim, cost, _ = score_prediction(pred, w / w.sum(), refused, ctx.config)
    return elim / (spent + cost) if elim > 0 else 0.0


def matcher_eliminations(ctx: Context, move: Move) -> tuple[np.ndarray, np.ndarray] | None:
    """``D[i, j]``: would the data that ``move`` yields if hypothesis ``i`` is true eliminate hypothesis ``j``,
    by the matcher itself (the move simulated in ``i``'s world, its components added to a copy of the tree)?
    Also each hypothesis's simulated cost. None without a tree in the context.
    """
    tree = ctx.tree
    if tree is None:
        return None
    n = len(ctx.hypotheses)
    leaf_class = np.full(tree.count, -1)
    for j, h in enumerate(ctx.hypotheses):
        leaf_class[list(h.leaves)] = j
    old = tree.assignments
    parent_of = {row.tobytes(): i for i, row in enumerate(old)}
    d = np.zeros((n, n), dtype=bool)
    pred = predict(ctx.hypotheses, move, ctx.state, ctx.components, ctx.noise, ctx.config)
    for i, h in enumerate(ctx.hypotheses):
        sim = simulate(h, move, ctx.state, ctx.components, ctx.config, ctx.noise)
        if sim is None:
            continue
        _, _, merged = sim
        t2 = tree.copy()
        for cid in sorted(set(merged) - set(ctx.components)) + sorted(
            c for c in merged if c in ctx.components and merged[c] is not ctx.components[c]
        ):
            t2.add(merged[cid])
        rows = t2.assignments[:, : old.shape[1]]
        alive = {leaf_class[parent_of[r.tobytes()]] for r in rows if r.tobytes() in parent_of}
        d[i] = [j not in alive for j in range(n)]
        d[i, i] = False
    return d, pred.costs
