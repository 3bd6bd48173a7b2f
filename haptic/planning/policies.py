"""Policies that choose the next move: the efficiency planner (§4.1) and its baselines.

- ``planner``: the candidate of highest efficiency (expected pose classes eliminated per expected cost).
- ``greedy``: the candidate of most expected eliminations, whatever it costs.
- ``random``: a random admissible move (a random move type, then a random move of that type).
- ``optimal``: the least expected path cost to recognition by exhaustive search over move sequences, for
  small libraries (:mod:`haptic.planning.optimal`).

The best possible cost of an episode is measured from outside, in hindsight: :mod:`haptic.bench.oracle`.

Every policy sees only data-side information (hypotheses derived from the data, the sensor state, the data
components) and draws any random choice from the generator it is given.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from haptic.errors import PlanningError
from haptic.matching.components import DataComponent, SensorNoise
from haptic.planning.efficiency import class_weights, distinguishable, efficiency_of, expected_eliminated
from haptic.planning.moves import FaceMove, Move, SensorState
from haptic.planning.predict import (
    Hypothesis,
    PlannerConfig,
    Prediction,
    candidate_moves,
    crossed_edge,
    descent_risk,
    predict,
    table_safe_moves,
)


@dataclass(frozen=True, eq=False)
class Context:
    """What a policy decides from."""

    hypotheses: Sequence[Hypothesis]
    """Surviving pose classes."""
    state: SensorState
    """Where the sensor is."""
    components: Mapping[int, DataComponent]
    """Data components so far, by id (latest version of re-reported edges)."""
    noise: SensorNoise
    """Sensor-noise model (for outcome bounds)."""
    config: PlannerConfig = field(default_factory=PlannerConfig)
    """Candidate generation and cost options."""
    avoid: tuple[Move, ...] = ()
    """Moves that failed from the current state (they are not offered again until a move succeeds)."""
    tree: object | None = None
    """The matcher's interpretation tree (an ``InterpretationTree``), when a policy or a check wants to ask
    the matcher itself which hypotheses a predicted outcome would eliminate."""


@dataclass(frozen=True, eq=False)
class Scored:
    """A candidate move with its score under the deciding policy."""

    move: Move
    score: float
    """Efficiency, expected eliminations, or negative expected cost, by policy."""
    expected_cost: float
    """Weighted mean predicted cost [units]."""
    expected_eliminated: float
    """Weighted mean pose classes eliminated."""
    risk: float = 0.0
    """Predicted chance that the executor cannot carry the move out (the table, a steep descent)."""


@dataclass(frozen=True, eq=False)
class Decision:
    """The chosen move and every candidate considered, for recording and analysis."""

    move: Move
    candidates: tuple[Scored, ...] = ()


def _score_all(ctx: Context) -> list[tuple[Prediction, float, float, float, float]]:
    """Efficiency, expected eliminations, expected cost and risk of every fresh, reliable candidate move; the
    eliminations come from comparing predicted outcome attributes (§4.1). With a table (``config.table_z``),
    moves the hypotheses predict to run into it are left out and the rest discounted by that risk."""
    weights = class_weights([h.model for h in ctx.hypotheses])
    preds = [predict(ctx.hypotheses, m, ctx.state, ctx.components, ctx.noise, ctx.config) for m in _fresh_moves(ctx)]
    preds = [p for p in preds if p.reliable(ctx.config)] or preds
    refused = [(p, refusal(p, ctx.config)) for p in preds]
    refused = [(p, r) for p, r in refused if r < ctx.config.table_risk] or refused
    return [(pred, *score_prediction(pred, weights, r, ctx.config)) for pred, r in refused]


def score_prediction(
    pred: Prediction, weights: np.ndarray, refused: float, config: PlannerConfig
) -> tuple[float, float, float, float]:
    """Efficiency and expected eliminations of one predicted move, both discounted by its risk (``refused``,
    :func:`refusal`, and a steep descent), its expected cost and that risk; ``weights`` sum to 1."""
    d = eliminates(pred, config)
    eff, _ = efficiency_of(d, pred.costs, weights)
    elim = expected_eliminated(d, weights)
    ok = (1.0 - refused) * (1.0 - descent_risk(pred.move, config))
    return eff * ok, elim * ok, float(pred.costs @ weights), 1.0 - ok


def _failing(pred: Prediction, config: PlannerConfig) -> np.ndarray | None:
    """Hypotheses in which the face move fails for the table (or a face out of reach) after touching its
    face some way, when touched points count as evidence; None when there are none."""
    if not config.touch_evidence or pred.reach is None or pred.table is None:
        return None
    fails = pred.table == 1
    return fails if fails.any() else None


def refusal(pred: Prediction, config: PlannerConfig) -> float:
    """Predicted chance that the move is refused or aborted for the table before it tells anything: with
    touched points as evidence, a face move failing after a trace of at least ``config.min_face_travel`` has
    told how far its face reaches."""
    fails = _failing(pred, config)
    if fails is None:
        return pred.table_risk
    t = np.where(fails & (pred.reach >= config.min_face_travel), 0.0, pred.table)
    return 0.0 if np.isnan(t).all() else float(np.nanmean(t))


def eliminates(pred: Prediction, config: PlannerConfig) -> np.ndarray:
    """``D[i, j]``: hypothesis ``j`` eliminated if ``i`` is true. By the predicted attributes (§4.1); where the
    face move ends at its edge in ``i``'s world, the next face out of reach, by the edge's distance and angle
    alone; where it fails in ``i``'s world, only the hypotheses whose face ends sooner than ``i``'s trace (it
    touches points beyond their edge)."""
    d = distinguishable(pred.outcomes, pred.bounds)
    if pred.edge_only is not None and (pred.edge_only == 1).any():
        d_edge = distinguishable(pred.outcomes[:, :2], pred.bounds[:2])
        d = np.where((pred.edge_only == 1)[:, None], d_edge, d)
    fails = _failing(pred, config)
    if fails is None:
        return d
    with np.errstate(invalid="ignore"):
        beyond = pred.reach[:, None] - pred.outcomes[None, :, 0] > max(pred.bounds[0], config.touch_margin)
    return np.where(fails[:, None], beyond, d)


def bounded(ctx: Context) -> Context:
    """``ctx`` with at most ``config.max_hypotheses`` hypotheses (:mod:`haptic.planning.bound`)."""
    from haptic.planning.bound import reduce_hypotheses

    kept = reduce_hypotheses(ctx.hypotheses, ctx.config.max_hypotheses)
    return ctx if len(kept) == len(ctx.hypotheses) else replace(ctx, hypotheses=tuple(kept))


def _fresh_moves(ctx: Context) -> list[Move]:
    """Candidate moves, less vertex moves that every hypothesis says circle back to an explored edge, and
    (while others remain) face moves that the hypotheses, by at least half their weight, say cross the edge a face
    move that failed from here was to cross: the pad did not get over it, and at another angle seldom does."""
    from haptic.planning.search import simulate

    out, again = [], []
    failed_face = [bad for bad in ctx.avoid if isinstance(bad, FaceMove)]
    for move in candidate_moves(ctx.state, ctx.components, ctx.config):
        if any(same_move(move, bad) for bad in ctx.avoid):
            continue
        if move.kind == "vertex" and ctx.hypotheses and all(
            simulate(h, move, ctx.state, ctx.components, ctx.config) is None for h in ctx.hypotheses
        ):
            continue
        if isinstance(move, FaceMove) and any(_same_crossing(move, bad, ctx) for bad in failed_face):
            again.append(move)
            continue
        out.append(move)
    return out or again


def _same_crossing(a: FaceMove, b: FaceMove, ctx: Context) -> bool:
    """Whether the hypotheses that can say, by at least half their weight, predict face moves ``a`` and ``b``
    to cross the same edge."""
    weights = class_weights([h.model for h in ctx.hypotheses])
    same = differ = 0.0
    for h, w in zip(ctx.hypotheses, weights, strict=True):
        ea, eb = crossed_edge(h, a, ctx.state), crossed_edge(h, b, ctx.state)
        if ea is None or eb is None:
            continue
        if ea == eb:
            same += w
        else:
            differ += w
    return same > 0.0 and same >= differ


def same_move(a: Move, b: Move) -> bool:
    """Two moves are the same when of one kind with the same parameter (face directions within ~8°)."""
    if a.kind != b.kind:
        return False
    if a.kind == "face":
        return float(np.dot(a.direction, b.direction)) > 0.99
    if a.kind == "edge":
        return a.sense == b.sense
    return a.across_face == b.across_face


class Policy:
    """Base: ``choose(ctx, rng) -> Decision``."""

    name = "policy"

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:  # pragma: no cover - interface
        raise NotImplementedError


class _ScoringPolicy(Policy):
    """The best-scoring candidate; when no candidate scores above zero (what separates the hypotheses is
    further away), the first move of the most efficient sequence of ``lookahead`` moves, failing that the
    cheapest move that reaches a new edge and face."""

    def __init__(self, lookahead: int = 3) -> None:
        self.lookahead = lookahead

    def score(self, efficiency: float, eliminated: float) -> float:  # pragma: no cover - interface
        raise NotImplementedError

    def tie_break(self, cands: Sequence[Scored], best: np.ndarray, rng: np.random.Generator) -> Move:
        return cands[int(rng.choice(best))].move

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:
        ctx = bounded(ctx)
        scored = _score_all(ctx)
        if not scored:
            raise PlanningError("no admissible move from the current sensor state")
        cands = tuple(
            Scored(p.move, self.score(eff, elim), cost, elim, risk) for p, eff, elim, cost, risk in scored
        )
        scores = np.array([c.score for c in cands])
        if scores.max() <= 0:
            return Decision(_further(ctx, cands, rng, self.lookahead), cands)
        best = np.flatnonzero(scores >= scores.max() * (1 - 1e-9))
        return Decision(self.tie_break(cands, best, rng), cands)


class PlannerPolicy(_ScoringPolicy):
    """Highest efficiency (expected pose classes eliminated per expected cost, §4.1); ties at random."""

    name = "planner"

    def score(self, efficiency: float, eliminated: float) -> float:
        return efficiency


class GreedyPolicy(_ScoringPolicy):
    """Most expected eliminations, ignoring cost; ties go to the cheaper move."""

    name = "greedy"

    def score(self, efficiency: float, eliminated: float) -> float:
        return eliminated

    def tie_break(self, cands: Sequence[Scored], best: np.ndarray, rng: np.random.Generator) -> Move:
        costs = np.array([cands[i].expected_cost for i in best])
        return cands[int(best[int(np.argmin(costs))])].move


class RandomPolicy(Policy):
    """A random admissible move: a random move type among those available, then a random one of it."""

    name = "random"

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:
        moves = [
            m for m in candidate_moves(ctx.state, ctx.components, ctx.config)
            if not any(same_move(m, bad) for bad in ctx.avoid)
        ]
        moves = table_safe_moves(moves, ctx.hypotheses, ctx.state, ctx.components, ctx.config)
        if not moves:
            raise PlanningError("no admissible move from the current sensor state")
        kinds = sorted({m.kind for m in moves})
        kind = kinds[int(rng.integers(len(kinds)))]
        of_kind = [m for m in moves if m.kind == kind]
        return Decision(of_kind[int(rng.integers(len(of_kind)))])


def _further(ctx: Context, cands: Sequence[Scored], rng: np.random.Generator, depth: int) -> Move:
    from haptic.planning.search import lookahead_choice

    for d in range(2, depth + 1):
        move = lookahead_choice(ctx, depth=d)
        if move is not None:
            return move
    return _cheapest_exploring(cands, rng)


def _cheapest_exploring(cands: Sequence[Scored], rng: np.random.Generator) -> Move:
    """With nothing to gain now, move on to new components: face and vertex moves reach a new edge and face;
    of those, the least risky, then the cheapest."""
    pool = [c for c in cands if c.move.kind in ("face", "vertex")] or list(cands)
    least = min(c.risk for c in pool)
    pool = [c for c in pool if c.risk <= least + 1e-9]
    costs = np.array([c.expected_cost for c in pool])
    costs = np.where(np.isfinite(costs), costs, np.inf)
    best = np.flatnonzero(costs <= costs.min() * (1 + 1e-9)) if np.isfinite(costs).any() else np.arange(len(pool))
    return pool[int(rng.choice(best))].move


def _optimal(**options) -> Policy:
    from haptic.planning.optimal import OptimalPolicy

    return OptimalPolicy(**options)


POLICIES: dict[str, Callable[..., Policy]] = {
    "planner": PlannerPolicy,
    "greedy": GreedyPolicy,
    "random": RandomPolicy,
    "optimal": _optimal,
}


def make_policy(name: str, **options) -> Policy:
    """A policy by name: planner, greedy, random, optimal."""
    try:
        return POLICIES[name](**options)
    except KeyError:
        raise PlanningError(f"unknown policy {name!r}; valid: {', '.join(POLICIES)}") from None


POLICY_NAMES = tuple(POLICIES)
