"""The ``optimal`` policy: the move that minimises the expected path cost to recognition, by exhaustive search.

The search runs in the planner's own model of the world. Each surviving pose class (hypothesis) carries a
prior weight (:func:`~haptic.planning.efficiency.class_weights`: every model alike). A candidate move splits
the hypotheses into groups whose predicted outcomes one measurement cannot tell apart
(:func:`~haptic.planning.search.branches`); each group is one branch of the outcome, with probability its
share of the weight, the group's expected cost of the move, and the sensor state and data the move would
leave behind (the move simulated, noiseless, in the group's world). A branch with one pose class left is
recognised. So the expected cost to recognition of a node is

    V(node) = 0                                                    one pose class left
            = min over moves m of  sum_b p_b (cost_b + V(b))        otherwise

taken over every candidate move (face-move directions discretised as the planner's, ``PlannerConfig``) to
``depth`` moves. Below that depth a node is valued by *rolling out* the efficiency planner in the same model
(its move, every branch, to ``rollout_moves`` moves; what is still unresolved then is charged
``unresolved_cost``). With the roll-out as the leaf value the search is a policy improvement over the
planner: in the model, its expected cost is never above the planner's.

It is exact only within the model: the matcher may eliminate more than the predicted attributes say, and the
physical outcome carries noise. It is meant for small libraries (tens of pose classes); with more than
``max_hypotheses`` classes it decides as the planner does (``Decision.candidates`` then hold the planner's
efficiencies, not expected costs).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from haptic.errors import PlanningError
from haptic.matching.components import DataComponent
from haptic.planning.efficiency import class_weights
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import Move, SensorState
from haptic.planning.policies import PlannerPolicy, Policy
from haptic.planning.scoring import Context, Decision, Scored, score_all
from haptic.planning.search import Branch, branches


class OptimalPolicy(Policy):
    """Least expected path cost to recognition by a ``depth``-move exhaustive search with planner roll-outs."""

    name = "optimal"

    def __init__(
        self,
        depth: int = 2,
        rollout_moves: int = 6,
        unresolved_cost: float = 20.0,
        max_hypotheses: int = 60,
    ) -> None:
        if depth < 1:
            raise PlanningError(f"optimal policy: depth must be at least 1, got {depth}")
        self.depth = depth
        self.rollout_moves = rollout_moves
        self.unresolved_cost = unresolved_cost
        self.max_hypotheses = max_hypotheses
        self._planner = PlannerPolicy()

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:
        hyps = list(ctx.hypotheses)
        if len(hyps) > self.max_hypotheses or any(h.world_from_model is None for h in hyps):
            return self._planner.choose(ctx, rng)
        weights = class_weights([h.model for h in hyps])
        search = _Search(ctx, self.rollout_moves, self.unresolved_cost)
        scored = []
        for pred, _eff, elim, cost, risk in score_all(ctx):
            q = search.q(hyps, weights, pred.move, ctx.state, ctx.components, self.depth)
            if q is not None:
                scored.append(Scored(pred.move, -q, cost, elim, risk))
        if not scored:
            return self._planner.choose(ctx, rng)
        scores = np.array([s.score for s in scored])
        best = np.flatnonzero(scores >= scores.max() - 1e-9 * max(1.0, abs(scores.max())))
        return Decision(scored[int(rng.choice(best))].move, tuple(scored))


class _Search:
    """Expected cost to recognition within the planner's model, from one decision's context."""

    def __init__(self, ctx: Context, rollout_moves: int, unresolved_cost: float) -> None:
        self.ctx = ctx
        self.rollout_moves = rollout_moves
        self.unresolved_cost = unresolved_cost
        self.nodes = 0

    def _branches(self, hyps, weights, move, state, components) -> list[Branch]:
        self.nodes += 1
        return branches(hyps, weights, move, state, components, self.ctx.noise, self.ctx.config)

    def _moves(self, hyps, state, components) -> list[tuple[Move, float, float]]:
        """Candidate moves from a node with the planner's score (efficiency) and expected cost."""
        sub = Context(hyps, state, components, self.ctx.noise, self.ctx.config)
        return [(p.move, eff, cost) for p, eff, _elim, cost, _risk in score_all(sub)]

    def q(
        self,
        hyps: Sequence[Hypothesis],
        weights: np.ndarray,
        move: Move,
        state: SensorState,
        components: Mapping[int, DataComponent],
        depth: int,
    ) -> float | None:
        """Expected cost of ``move`` and of the best continuation ``depth - 1`` moves deep (then roll-outs);
        None when the move cannot be simulated in any hypothesis's world."""
        brs = self._branches(hyps, weights, move, state, components)
        if not brs:
            return None
        return _expected(brs, lambda b: self.value(list(b.hypotheses), b.weights, b.state, b.components, depth - 1))

    def value(self, hyps, weights, state, components, depth: int) -> float:
        """Least expected cost to recognition from a node."""
        if len(hyps) <= 1:
            return 0.0
        if depth <= 0:
            return self.rollout(hyps, weights, state, components, self.rollout_moves)
        best = np.inf
        for move, _eff, _cost in self._moves(hyps, state, components):
            q = self.q(hyps, weights, move, state, components, depth)
            if q is not None and q < best:
                best = q
        if not np.isfinite(best):
            return self.unresolved_cost
        return best

    def rollout(self, hyps, weights, state, components, moves_left: int) -> float:
        """Expected cost to recognition following the efficiency planner (deterministic ties: first best;
        with nothing to eliminate, the cheapest face or vertex move)."""
        if len(hyps) <= 1:
            return 0.0
        if moves_left <= 0:
            return self.unresolved_cost
        cands = self._moves(hyps, state, components)
        if not cands:
            return self.unresolved_cost
        effs = np.array([e for _, e, _ in cands])
        if effs.max() > 0:
            move = cands[int(np.argmax(effs))][0]
        else:
            pool = [c for c in cands if c[0].kind in ("face", "vertex")] or cands
            costs = np.array([c[2] for c in pool])
            costs = np.where(np.isfinite(costs), costs, np.inf)
            move = pool[int(np.argmin(costs))][0]
        brs = self._branches(hyps, weights, move, state, components)
        if not brs:
            return self.unresolved_cost
        return _expected(
            brs, lambda b: self.rollout(list(b.hypotheses), b.weights, b.state, b.components, moves_left - 1)
        )


def _expected(brs: Sequence[Branch], rest: Callable[[Branch], float]) -> float:
    """Expected cost over the branches of a move: each branch's share of the weight times its cost of the
    move plus ``rest(branch)``, the cost still to come from it."""
    total = sum(float(b.weights.sum()) for b in brs)
    return sum(float(b.weights.sum()) / total * (b.cost + rest(b)) for b in brs)
