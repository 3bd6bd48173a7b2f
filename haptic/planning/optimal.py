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

taken over every candidate move (face-move directions discretised as the planner's, ``PlannerConfig``), and
the :data:`MAX_PROBES` free-space probes of highest planner efficiency when ``config.moves`` admits probes, to
``depth`` moves. A probe branches on its outcomes (:func:`~haptic.planning.search.probe_branches`): a hit
leaves the sensor on a new face, a miss leaves it where it was and the branch without the pose classes the
free line rules out; the probes carried out on the way to a node are not offered there again. Below that
depth a node is valued by *rolling out* the efficiency planner in the same model (its move over every
candidate, probes too, every branch, to ``rollout_moves`` moves; what is still unresolved then is charged
``unresolved_cost``). With the roll-out as the leaf value the search is a policy improvement over the
planner: in the model, its expected cost is never above the planner's.

It is exact only within the model: the matcher may eliminate more than the predicted attributes say, and the
physical outcome carries noise. It is meant for small libraries (tens of pose classes); with more than
``max_hypotheses`` classes it decides as the planner does (``Decision.candidates`` then hold the planner's
efficiencies, not expected costs).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import numpy as np

from haptic.errors import PlanningError
from haptic.matching.components import DataComponent
from haptic.planning.efficiency import class_weights
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.move_scores import (
    PROBE_RISK,
    Context,
    Decision,
    Scored,
    bounded,
    same_move,
    score_all,
    score_probe,
)
from haptic.planning.moves import CostModel, Move, ProbeMove, SensorState
from haptic.planning.policies import GreedyPolicy, PlannerPolicy, Policy
from haptic.planning.predict import Prediction
from haptic.planning.probe_prediction import ProbePrediction
from haptic.planning.search import Branch, branches, probe_branches

MAX_PROBES = 4
"""Free-space probes a node of the search expands: those of highest planner efficiency. Tracing moves are
few (eight face directions, two edge senses, two vertex moves) and all are expanded; probe candidates are
up to 64, and expanding each at each of two levels multiplies the search by hundreds. Roll-outs still follow
the planner over every candidate."""


class OptimalPolicy(Policy):
    """Least expected path cost to recognition by a ``depth``-move exhaustive search with planner roll-outs."""

    name = "optimal"

    def __init__(
        self,
        depth: int = 2,
        rollout_moves: int = 6,
        unresolved_cost: float = 20.0,
        max_hypotheses: int = 60,
        max_probes: int = MAX_PROBES,
    ) -> None:
        if depth < 1:
            raise PlanningError(f"optimal policy: depth must be at least 1, got {depth}")
        if max_probes < 0:
            raise PlanningError(f"optimal policy: max_probes must be 0 or more, got {max_probes}")
        self.depth = depth
        self.rollout_moves = rollout_moves
        self.unresolved_cost = unresolved_cost
        self.max_hypotheses = max_hypotheses
        self.max_probes = max_probes
        self._planner = PlannerPolicy()

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:
        if ctx.config.fingers > 1:  # the search simulates one sensor: placements are the planner's alone
            ctx = replace(ctx, config=replace(ctx.config, fingers=1))
        hyps = list(ctx.hypotheses)
        if len(hyps) > self.max_hypotheses or any(h.world_from_model is None for h in hyps):
            return self._planner.choose(ctx, rng)
        weights = class_weights([h.model for h in hyps])
        probed = tuple(m for m in ctx.avoid if isinstance(m, ProbeMove))
        root = score_all(ctx)
        search = _Search(ctx, self.rollout_moves, self.unresolved_cost, self.max_probes, root)
        scored = []
        for pred, _eff, elim, cost, risk in search.expanded(root):
            q = search.q(hyps, weights, pred, ctx.state, ctx.components, self.depth, probed)
            if q is not None:
                scored.append(Scored(pred.move, -q, cost, elim, risk))
        if not scored:
            return self._planner.choose(ctx, rng)
        scores = np.array([s.score for s in scored])
        best = np.flatnonzero(scores >= scores.max() - 1e-9 * max(1.0, abs(scores.max())))
        return Decision(scored[int(rng.choice(best))].move, tuple(scored))


class LookaheadPolicy(OptimalPolicy):
    """The roll-out policy over a ``base`` policy, by default the greedy one (the best myopic policy measured by
    ``scripts/bench_optimal.py``). The base policy's choice and each other candidate move are valued by their
    predicted outcomes (their branches), each branch by its cost plus the base policy's cost to recognition from
    there, simulated ``rollout_moves`` moves on (:class:`OptimalPolicy` searched one move deep, its roll-outs the
    base policy's). The base policy's choice stands unless another is expected to cost less by the share
    ``margin`` of its own value: the model is exact only within its predictions (the matcher may eliminate more,
    and what is unresolved at a roll-out's end is priced at ``unresolved_cost``), so a small expected gain is not
    worth a move away from the base policy, whose measured cost is what the roll-out improves on.

    A candidate whose least predicted cost alone is not that far below the base choice's value is never simulated
    (its value is at least that): few are, and the decision stays cheap. With more than ``max_hypotheses`` pose
    classes, any without a pose, or nothing one move is expected to eliminate, it decides as the base policy."""

    name = "lookahead"

    def __init__(
        self,
        rollout_moves: int = 4,
        unresolved_cost: float = 20.0,
        max_hypotheses: int = 30,
        max_probes: int = 2,
        base: str = "greedy",
        margin: float = 0.05,
    ) -> None:
        if base not in BASES:
            raise PlanningError(f"lookahead policy: unknown base policy {base!r}; valid: {', '.join(BASES)}")
        if not 0.0 <= margin < 1.0:
            raise PlanningError(f"lookahead policy: margin must be in [0, 1), got {margin}")
        super().__init__(1, rollout_moves, unresolved_cost, max_hypotheses, max_probes)
        self.base = base
        self.margin = margin
        self._base_policy = GreedyPolicy() if base == "greedy" else PlannerPolicy()

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:
        ctx = bounded(ctx)
        decision = self._base_policy.choose(ctx, rng)
        hyps = list(ctx.hypotheses)
        if len(hyps) > self.max_hypotheses or any(h.world_from_model is None for h in hyps):
            return decision
        root = [c for c in score_all(ctx) if isinstance(c[0], Prediction | ProbePrediction)]
        chosen = next((c for c in root if c[0].move is decision.move), None)
        if chosen is None or chosen[2] <= 0.0:
            return decision  # a placement, or the base policy's own look-ahead: nothing to compare it with
        one = ctx if ctx.config.fingers <= 1 else replace(ctx, config=replace(ctx.config, fingers=1))
        weights = class_weights([h.model for h in hyps])
        probed = tuple(m for m in ctx.avoid if isinstance(m, ProbeMove))
        search = _Search(one, self.rollout_moves, self.unresolved_cost, self.max_probes, root, self.base)
        q_base = search.q(hyps, weights, chosen[0], ctx.state, ctx.components, 1, probed)
        if q_base is None:
            return decision
        bar = q_base * (1.0 - self.margin)
        best, best_q = chosen, q_base
        scored = [Scored(chosen[0].move, -q_base, chosen[3], chosen[2], chosen[4])]
        for cand in sorted(search.expanded(root), key=_least_cost):
            if cand is chosen or not _least_cost(cand) < min(bar, best_q):
                continue  # its value is at least its cost in the world where it costs least
            q = search.q(hyps, weights, cand[0], ctx.state, ctx.components, 1, probed)
            if q is None:
                continue
            scored.append(Scored(cand[0].move, -q, cand[3], cand[2], cand[4]))
            if q < best_q:
                best, best_q = cand, q
        if best is chosen or not best_q < bar:
            return Decision(decision.move, tuple(scored))
        return Decision(best[0].move, tuple(scored))


def _least_cost(cand: tuple) -> float:
    """A lower bound of a scored candidate's value: its least predicted cost over the hypotheses (every branch's
    cost is a weighted mean of these)."""
    costs = np.asarray(cand[0].costs, dtype=float)
    return float(np.nanmin(costs)) if np.isfinite(costs).any() else np.inf


BASES = ("greedy", "planner")
"""The policies a roll-out can follow: :class:`_Search` picks their move at each node of a roll-out."""


class _Search:
    """Expected cost to recognition within the planner's model, from one decision's context."""

    def __init__(
        self,
        ctx: Context,
        rollout_moves: int,
        unresolved_cost: float,
        max_probes: int = MAX_PROBES,
        root=None,
        base: str = "planner",
    ) -> None:
        self.ctx = ctx
        self.base = base
        self.rollout_moves = rollout_moves
        self.unresolved_cost = unresolved_cost
        self.max_probes = max_probes
        self.nodes = 0
        # the decision's probe candidates, predicted once over its hypotheses; a node below predicts them for
        # its own by subsetting (ProbePrediction.subset): its hypotheses are the root's, poses unchanged
        root = score_all(ctx) if root is None and ctx.config.moves != "tracing" else (root or [])
        self._probes = [c[0] for c in root if isinstance(c[0], ProbePrediction)]
        self._index = {id(h.world_from_model): k for k, h in enumerate(ctx.hypotheses)}
        self._probe_table: _ProbeTable | None = None

    def expanded(self, scored: list) -> list:
        """The candidates a node expands: every tracing move, and the ``max_probes`` probes of highest planner
        efficiency (first best on ties), in their order."""
        probes = [k for k, c in enumerate(scored) if isinstance(c[0], ProbePrediction)]
        if len(probes) <= self.max_probes:
            return scored
        keep = set(sorted(probes, key=lambda k: -scored[k][1])[: self.max_probes])
        return [c for k, c in enumerate(scored) if k not in probes or k in keep]

    def _branches(self, hyps, weights, pred, state, components) -> list[Branch]:
        self.nodes += 1
        if isinstance(pred, ProbePrediction):
            return probe_branches(hyps, weights, pred, state, components, self.ctx.noise)
        return branches(hyps, weights, pred.move, state, components, self.ctx.noise, self.ctx.config)

    def _moves(self, hyps, state, components, probed) -> list[tuple]:
        """Candidate moves from a node, as :func:`score_all` scores them (the planner's efficiency, expected
        eliminations, cost, risk), less the probes carried out on the way there. The probes are the decision's
        own candidates, predicted for the node's hypotheses (:meth:`ProbePrediction.subset`: the costs from the
        node's sensor position, the free segment's margins of the decision's data): regenerating and
        predicting them at every node of the search would take most of its time. Of those, only the ones a policy
        could take from the node are predicted and returned (:meth:`_ProbeTable.contenders`, all scored at once):
        the ``max_probes`` of highest efficiency that a node expands, the base policy's choice and the cheapest."""
        config = self.ctx.config
        if config.moves == "tracing":
            return score_all(Context(hyps, state, components, self.ctx.noise, config, avoid=probed))
        idx = [self._index.get(id(h.world_from_model)) for h in hyps]
        if any(k is None for k in idx):  # not the decision's hypotheses: predict afresh
            return score_all(Context(hyps, state, components, self.ctx.noise, config, avoid=probed))
        out = []
        if config.moves != "probing":
            tracing = replace(config, moves="tracing")
            out = score_all(Context(hyps, state, components, self.ctx.noise, tracing))
        table = self._table()
        if table is None:
            return out
        done = np.array([any(same_move(p.move, m) for m in probed) for p in self._probes], dtype=bool)
        weights = class_weights([h.model for h in hyps])
        for k in table.contenders(idx, state.position, weights, ~done, self.max_probes, self.base):
            scored = score_probe(self._probes[k].subset(idx, state.position, config.costs), weights)
            if scored is not None:
                out.append(scored)
        return out

    def _table(self) -> _ProbeTable | None:
        """The decision's probe candidates as arrays (built once per search), None without any."""
        if self._probe_table is None and self._probes:
            self._probe_table = _ProbeTable(self._probes, self.ctx.config.costs or CostModel())
        return self._probe_table

    def q(
        self,
        hyps: Sequence[Hypothesis],
        weights: np.ndarray,
        pred: Prediction | ProbePrediction,
        state: SensorState,
        components: Mapping[int, DataComponent],
        depth: int,
        probed: tuple[ProbeMove, ...] = (),
    ) -> float | None:
        """Expected cost of the predicted move and of the best continuation ``depth - 1`` moves deep (then
        roll-outs); None when the move cannot be simulated in any hypothesis's world. ``probed``: the probes
        carried out so far (not offered again below)."""
        brs = self._branches(hyps, weights, pred, state, components)
        if not brs:
            return None
        after = _after(probed, pred.move)
        return _expected(
            brs, lambda b: self.value(list(b.hypotheses), b.weights, b.state, b.components, depth - 1, after)
        )

    def value(self, hyps, weights, state, components, depth: int, probed: tuple[ProbeMove, ...] = ()) -> float:
        """Least expected cost to recognition from a node."""
        if len(hyps) <= 1:
            return 0.0
        if depth <= 0:
            return self.rollout(hyps, weights, state, components, self.rollout_moves, probed)
        best = np.inf
        for cand in self.expanded(self._moves(hyps, state, components, probed)):
            q = self.q(hyps, weights, cand[0], state, components, depth, probed)
            if q is not None and q < best:
                best = q
        if not np.isfinite(best):
            return self.unresolved_cost
        return best

    def _base_move(self, cands: list[tuple]) -> Prediction | ProbePrediction | None:
        """The base policy's choice among scored candidates: the planner's highest efficiency (ties: the first), or
        greedy's most expected eliminations (ties: the cheaper, then the first); None when none eliminates
        anything."""
        key = np.array([c[2] if self.base == "greedy" else c[1] for c in cands])
        if not key.max() > 0:
            return None
        if self.base != "greedy":
            return cands[int(np.argmax(key))][0]
        top = np.flatnonzero(key >= key.max() * (1 - 1e-9))
        costs = np.array([cands[k][3] for k in top])
        return cands[int(top[int(np.argmin(costs))])][0]

    def rollout(self, hyps, weights, state, components, moves_left: int, probed: tuple[ProbeMove, ...] = ()) -> float:
        """Expected cost to recognition following the base policy (:meth:`_base_move`) over every candidate, probes
        too (with nothing to eliminate, the cheapest face or vertex move)."""
        if len(hyps) <= 1:
            return 0.0
        if moves_left <= 0:
            return self.unresolved_cost
        cands = self._moves(hyps, state, components, probed)
        if not cands:
            return self.unresolved_cost
        pred = self._base_move(cands)
        if pred is None:
            pool = [c for c in cands if c[0].move.kind in ("face", "vertex")] or cands
            costs = np.array([c[3] for c in pool])
            costs = np.where(np.isfinite(costs), costs, np.inf)
            pred = pool[int(np.argmin(costs))][0]
        brs = self._branches(hyps, weights, pred, state, components)
        if not brs:
            return self.unresolved_cost
        after = _after(probed, pred.move)
        return _expected(
            brs, lambda b: self.rollout(list(b.hypotheses), b.weights, b.state, b.components, moves_left - 1, after)
        )


class _ProbeTable:
    """A decision's probe predictions stacked, to score them all at once for the hypotheses of a node of the search
    (as :meth:`ProbePrediction.subset` and :func:`~haptic.planning.move_scores.score_probe` score one)."""

    def __init__(self, preds: Sequence[ProbePrediction], costs: CostModel) -> None:
        self.costs_model = costs
        self.eliminates = np.stack([p.eliminates() for p in preds])
        self.hit = np.stack([p.hit for p in preds])
        self.distance = np.nan_to_num(np.stack([p.distance for p in preds]))
        self.start = np.array([p.move.start for p in preds], dtype=float)
        self.end = np.array([p.move.end for p in preds], dtype=float)
        self.length = np.array([p.move.length for p in preds], dtype=float)
        hand = [p.fails is not None for p in preds]
        self.fails = np.stack([p.fails for p in preds]) if all(hand) else None
        self.costs = np.stack([p.costs for p in preds]) if all(hand) else None

    def scores(self, idx, position: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, ...]:
        """Per probe, for hypotheses ``idx`` with the sensor at ``position``: efficiency, expected eliminations,
        expected cost and risk, undiscounted by the risk."""
        idx = np.asarray(idx, dtype=int)
        w = np.asarray(weights, dtype=float) / np.sum(weights)
        eliminated = self.eliminates[:, idx][:, :, idx].sum(axis=2).astype(float)
        if self.costs is None:  # a point sensor: to the line's start, along it, back to the surface after a miss
            here = np.asarray(position, dtype=float)
            transfer = np.linalg.norm(self.start - here, axis=1)[:, None]
            back = np.linalg.norm(self.end - here, axis=1)[:, None]
            free = transfer + np.where(self.hit[:, idx], self.distance[:, idx], self.length[:, None] + back)
            costs = self.costs_model.c_p + self.costs_model.c_s * free
        else:  # the hand's path from where the decision's prediction was made
            costs = self.costs[:, idx]
        risk = self.fails[:, idx].astype(float) @ w if self.fails is not None else np.zeros(len(self.hit))
        return (eliminated / np.maximum(costs, 1e-12)) @ w, eliminated @ w, costs @ w, risk

    def contenders(self, idx, position, weights, allowed: np.ndarray, max_probes: int, base: str) -> list[int]:
        """Indices, in order, of the probes a policy could take from the node (of those ``allowed`` and offered,
        risk under :data:`~haptic.planning.move_scores.PROBE_RISK`): the ``max_probes`` of highest efficiency
        (first best on ties), the ``base`` policy's choice (greedy: most eliminations, the cheapest of those; the
        planner: the highest efficiency) and the cheapest, each as scored after the risk's discount."""
        eff, elim, cost, risk = self.scores(idx, position, weights)
        ok = allowed & (risk < PROBE_RISK)
        if not ok.any():
            return []
        eff, elim = eff * (1.0 - risk), elim * (1.0 - risk)
        live = np.flatnonzero(ok)
        keep = set(live[np.argsort(-eff[live], kind="stable")[: max(max_probes, 1)]].tolist())
        if base == "greedy":
            top = live[elim[live] >= elim[live].max() * (1 - 1e-9)]
            keep.add(int(top[np.argmin(cost[top])]))
        keep.add(int(live[np.argmin(np.where(np.isfinite(cost[live]), cost[live], np.inf))]))
        return sorted(keep)


def _after(probed: tuple[ProbeMove, ...], move: Move) -> tuple[ProbeMove, ...]:
    """The probes carried out once ``move`` is."""
    return (*probed, move) if isinstance(move, ProbeMove) else probed


def _expected(brs: Sequence[Branch], rest: Callable[[Branch], float]) -> float:
    """Expected cost over the branches of a move: each branch's share of the weight times its cost of the
    move plus ``rest(branch)``, the cost still to come from it."""
    total = sum(float(b.weights.sum()) for b in brs)
    return sum(float(b.weights.sum()) / total * (b.cost + rest(b)) for b in brs)
