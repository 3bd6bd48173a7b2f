"""Policies that choose the next move: the efficiency planner (§4.1) and its baselines.

- ``planner``: the candidate of highest efficiency (expected pose classes eliminated per expected cost).
- ``greedy``: the candidate of most expected eliminations, whatever it costs.
- ``random``: a random admissible move (a random move type, then a random move of that type).
- ``optimal``: the least expected path cost to recognition by exhaustive search over move sequences (tracing
  moves and free-space probes alike), for small libraries (:mod:`haptic.planning.optimal`).

The best possible cost of an episode is measured from outside, in hindsight: :mod:`haptic.bench.oracle`.

Every policy sees only data-side information (hypotheses derived from the data, the sensor state, the data
components) and draws any random choice from the generator it is given.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from haptic.errors import PlanningError
from haptic.planning.disagree import disagreement_move
from haptic.planning.move_scores import (  # noqa: F401 -- Context, Decision, refusal, same_move: re-exported
    Context,
    Decision,
    Scored,
    bounded,
    probe_moves,
    refusal,
    same_move,
    score_all,
)
from haptic.planning.moves import Move
from haptic.planning.predict import candidate_moves
from haptic.planning.search import lookahead_best, lookahead_choice
from haptic.planning.table import table_safe_moves


class Policy:
    """Base: ``choose(ctx, rng) -> Decision``."""

    name = "policy"

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:  # pragma: no cover - interface
        raise NotImplementedError


class _ScoringPolicy(Policy):
    """The best-scoring candidate; when no candidate scores above zero (what separates the hypotheses is
    further away), toward where look-alike hypotheses disagree (:func:`~haptic.planning.disagree.disagreement_move`),
    else the first move of the most efficient sequence of ``lookahead`` moves, failing that the cheapest move that
    reaches a new edge and face."""

    weighs_sequences = False
    """Whether a placement that no other candidate move's score rivals must also beat the look-ahead's best
    sequence of tracing moves (:func:`_placement_or_sequence`): for a policy whose score is an efficiency."""

    def __init__(self, lookahead: int = 3) -> None:
        self.lookahead = lookahead

    def score(self, efficiency: float, eliminated: float) -> float:  # pragma: no cover - interface
        raise NotImplementedError

    def tie_break(self, cands: Sequence[Scored], best: np.ndarray, rng: np.random.Generator) -> Move:
        return cands[int(rng.choice(best))].move

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:
        ctx = bounded(ctx)
        scored = score_all(ctx)
        if not scored:
            raise PlanningError("no admissible move from the current sensor state")
        cands = tuple(
            Scored(p.move, self.score(eff, elim), cost, elim, risk) for p, eff, elim, cost, risk in scored
        )
        scores = np.array([c.score for c in cands])
        if scores.max() <= 0:
            return Decision(_further(ctx, cands, rng, self.lookahead), cands)
        best = np.flatnonzero(scores >= scores.max() * (1 - 1e-9))
        move = self.tie_break(cands, best, rng)
        if move.kind == "placement" and self.weighs_sequences:
            move = _placement_or_sequence(ctx, cands, move, self.lookahead)
        return Decision(move, cands)


class PlannerPolicy(_ScoringPolicy):
    """Highest efficiency (expected pose classes eliminated per expected cost, §4.1); ties at random."""

    name = "planner"
    weighs_sequences = True

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
    """A random admissible move: a random move type among those available (free-space probes too when
    ``config.moves`` admits them and the hypotheses have poses), then a random one of it."""

    name = "random"

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:
        moves = []
        if ctx.config.moves != "probing":
            moves = [
                m for m in candidate_moves(ctx.state, ctx.components, ctx.config)
                if not any(same_move(m, bad) for bad in ctx.avoid)
            ]
            moves = table_safe_moves(moves, ctx.hypotheses, ctx.state, ctx.components, ctx.config)
        moves += probe_moves(ctx)
        if not moves:
            raise PlanningError("no admissible move from the current sensor state")
        kinds = sorted({m.kind for m in moves})
        kind = kinds[int(rng.integers(len(kinds)))]
        of_kind = [m for m in moves if m.kind == kind]
        return Decision(of_kind[int(rng.integers(len(of_kind)))])


def _placement_or_sequence(ctx: Context, cands: Sequence[Scored], placement: Move, depth: int) -> Move:
    """``placement``, the most efficient candidate, or, when no other kind of candidate is expected to eliminate
    anything, the first move of the look-ahead's best sequence of tracing moves (:func:`~haptic.planning.search.
    lookahead_best`, two to ``depth`` moves) where that sequence is expected to eliminate at least as many pose
    classes per unit cost. Without the comparison a placement expected to eliminate anything at all beats every
    one-move score of zero, however dear: on the hand, where a placement's way there and back is 24-36 units
    against 3-15 for a tracing move, the seed library's placements were taken only there and each left the
    episode dearer than the index finger's tracing (BOX01 seed 3: 36 units for no pose class eliminated)."""
    if ctx.config.moves == "probing" or any(c.score > 0 for c in cands if c.move.kind != "placement"):
        return placement
    own = max(c.score for c in cands if c.move is placement)
    for d in range(2, depth + 1):
        move, score = lookahead_best(ctx, depth=d)
        if move is not None and score >= own:
            return move
    return placement


def _further(ctx: Context, cands: Sequence[Scored], rng: np.random.Generator, depth: int) -> Move:
    if ctx.config.moves == "probing":  # the look-ahead simulates tracing moves only; a probe measures no vertex
        return _cheapest_exploring(cands, rng)
    move = disagreement_move(ctx)  # look-alikes: only where they disagree tells them apart
    if move is not None:
        return move
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
