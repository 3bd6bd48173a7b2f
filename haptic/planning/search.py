"""Looking further than one move: each hypothesis simulates a move in its own world (noiseless), which gives
the data it would produce and the sensor state it would end in; from there the next moves are predicted.

Used by the planner when no single move is expected to eliminate anything (the discriminating features are
more than one move away), by the optimal policy's search (:mod:`haptic.planning.optimal`), and to check
predictions against the matcher itself (:func:`matcher_eliminations`).

A free-space probe branches on its predicted outcomes (:func:`probe_branches`): a miss leaves no data, so
what it tells is carried as the hypotheses it leaves. Those that predict a hit too shallow for the miss to
rule out stay in the miss's branch with weight zero: in the (noiseless) model they cannot give it, but the
matcher keeps them, so the branch is not recognised until something else eliminates them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from haptic.matching.components import DataComponent, SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.efficiency import class_weights, outcome_groups
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.move_scores import Context, predict_probe_moves, refusal, same_move, score_prediction
from haptic.planning.moves import Move, ProbeMove, SensorState
from haptic.planning.predict import candidate_moves, predict
from haptic.planning.probe_prediction import ProbePrediction
from haptic.planning.simulate import simulate, simulate_probe


@dataclass(frozen=True, eq=False)
class Branch:
    """Where a group of hypotheses that one move cannot separate would be after it."""

    hypotheses: tuple[Hypothesis, ...]
    """The group's hypotheses with correspondences extended by the move's new components."""
    weights: np.ndarray
    """Their prior weights (not normalised; zero for a hypothesis alive after the outcome that its own world
    would not give, :func:`probe_branches`)."""
    state: SensorState
    """Sensor state after the move (as the group's first hypothesis simulates it)."""
    components: Mapping[int, DataComponent]
    """Data so far plus the move's simulated components."""
    cost: float
    """Weighted mean cost of the move within the group [units]."""


def branches(
    hyps: Sequence[Hypothesis],
    weights: np.ndarray,
    move: Move,
    state: SensorState,
    components: Mapping[int, DataComponent],
    noise: SensorNoise,
    config: PlannerConfig,
) -> list[Branch]:
    """Split the hypotheses by what ``move`` would show, and simulate each group onward (a probe:
    :func:`probe_branches`). Groups of no weight are left out: in the model they never occur."""
    if isinstance(move, ProbeMove):
        if any(h.world_from_model is None for h in hyps):
            return []
        (pp,) = predict_probe_moves(Context(hyps, state, components, noise, config), [move])
        return probe_branches(hyps, weights, pp, state, components, noise)
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
        if not w.sum() > 0.0:
            continue
        _, st, comps = sims[0][1]
        out.append(
            Branch(tuple(s[0] for _, s in sims), w, st, comps, float(pred.costs[idx] @ (w / w.sum())))
        )
    return out


def probe_branches(
    hyps: Sequence[Hypothesis],
    weights: np.ndarray,
    pred: ProbePrediction,
    state: SensorState,
    components: Mapping[int, DataComponent],
    noise: SensorNoise,
) -> list[Branch]:
    """The branches of a probe by its predicted outcomes (:meth:`ProbePrediction.outcome_groups`), each with
    the weighted mean of its producers' predicted costs. A hit's branch: its hypotheses with correspondences
    extended by the face each hits, the data face and sensor state of the first one's world
    (:func:`~haptic.planning.simulate.simulate_probe`). The miss's: every hypothesis it leaves, unchanged, the
    sensor back where it was and the data as they were; those that would not miss weigh nothing in it."""
    out = []
    for producers, alive in pred.outcome_groups():
        w_p = weights[producers]
        if not w_p.sum() > 0.0:
            continue
        cost = float(pred.costs[producers] @ (w_p / w_p.sum()))
        if pred.hit[producers[0]]:
            sims = [simulate_probe(hyps[i], pred.move, state, components, noise) for i in producers]
            _, st, comps = sims[0]
            out.append(Branch(tuple(s[0] for s in sims), w_p, st, comps, cost))
        else:
            w = np.where(pred.hit[alive], 0.0, weights[alive])
            out.append(Branch(tuple(hyps[i] for i in alive), w, state, dict(components), cost))
    return out


def lookahead_choice(ctx: Context, depth: int = 2) -> Move | None:
    """The first move of the best ``depth``-move sequence by expected eliminations per expected cost, for
    when no single move is expected to eliminate anything. None when no sequence eliminates anything."""
    return lookahead_best(ctx, depth)[0]


def lookahead_best(ctx: Context, depth: int = 2) -> tuple[Move | None, float]:
    """:func:`lookahead_choice` with the sequence's score: its expected pose classes eliminated per expected cost
    (0 with None: no sequence eliminates anything)."""
    weights = class_weights([h.model for h in ctx.hypotheses])
    best, best_move = 0.0, None
    for move in candidate_moves(ctx.state, ctx.components, ctx.config):
        if any(same_move(move, bad) for bad in ctx.avoid):
            continue
        score = _lookahead_score(ctx, list(ctx.hypotheses), weights, move, ctx.state, ctx.components, depth, 0.0)
        if score > best:
            best, best_move = score, move
    return best_move, best


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
