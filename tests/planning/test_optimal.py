"""The optimal policy: least expected cost to recognition by exhaustive search, with planner roll-outs."""

import numpy as np
import pytest

from haptic.bench.runner import plan_sweep
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.errors import HapticError
from haptic.geometry import load_library
from haptic.planning.efficiency import class_weights
from haptic.planning.optimal import OptimalPolicy, _Search
from haptic.planning.policies import PlannerPolicy
from haptic.planning.registry import make_policy

pytestmark = pytest.mark.slow  # whole episodes under an exhaustive search

SMALL = ["BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R"]
LIB = {k: v for k, v in load_library().items() if k in SMALL}


class Recording(PlannerPolicy):
    """The planner, keeping every context it was asked to decide from."""

    def __init__(self):
        super().__init__()
        self.contexts = []

    def choose(self, ctx, rng):
        self.contexts.append(ctx)
        return super().choose(ctx, rng)


def _contexts(n_episodes=6, moves="tracing"):
    out = []
    for spec in plan_sweep(SMALL, n_episodes, seed=3, policies=["planner"], verify="none", moves=moves):
        pol = Recording()
        run_episode(spec, library=LIB, policy=pol)
        out += [c for c in pol.contexts if 2 <= len(c.hypotheses) <= 30]
    return out


def test_search_never_expects_more_than_following_the_planner():
    contexts = _contexts()
    assert contexts, "no decision with several pose classes"
    for ctx in contexts[:8]:
        hyps = list(ctx.hypotheses)
        w = class_weights([h.model for h in hyps])
        search = _Search(ctx, rollout_moves=6, unresolved_cost=20.0)
        planned = search.rollout(hyps, w, ctx.state, ctx.components, 6)
        best = search.value(hyps, w, ctx.state, ctx.components, depth=2)
        assert best <= planned + 1e-9
        assert best > 0


def test_optimal_recognizes_and_is_no_costlier_than_the_planner_on_small_library():
    specs = plan_sweep(SMALL, 6, seed=7, policies=["planner", "optimal"], verify="none", moves="tracing")
    cost = {"planner": [], "optimal": []}
    for s in specs:
        r = run_episode(s, library=LIB)
        assert r.outcome == "recognized" and r.correct, (s, r.outcome)
        cost[s.policy].append(r.path_cost)
    assert np.mean(cost["optimal"]) <= np.mean(cost["planner"])
    assert np.mean(cost["planner"]) <= 1.15 * np.mean(cost["optimal"])


def test_optimal_is_deterministic_and_named():
    # the default search (two moves deep, then planner roll-outs) on four of the models: a decision costs a tenth
    lib = {k: LIB[k] for k in ("BOX01", "WEDGE01", "PYR01", "TETRA01L")}
    spec = EpisodeSpec(model="WEDGE01", seed=4, policy="optimal", verify="none", moves="tracing")
    a, b = (run_episode(spec, library=lib).to_json() for _ in range(2))
    assert a["decision_times_s"]  # a move was decided, not only the opening
    for r in (a, b):
        r.pop("wall_time_s")
        r.pop("decision_times_s")
    assert a == b and a["policy"] == "optimal"
    assert isinstance(make_policy("optimal", depth=1), OptimalPolicy)
    with pytest.raises(HapticError, match="depth"):
        make_policy("optimal", depth=0)


def test_lookahead_expects_no_more_than_greedy_and_recognizes():
    """The roll-out policy's choice at each decision has an expected cost (within the planner's model) no more than
    following its base policy from there (greedy by default, or the planner), and its episodes recognise the right
    model."""
    from haptic.planning.optimal import LookaheadPolicy

    policy = make_policy("lookahead")
    assert isinstance(policy, LookaheadPolicy) and policy.depth == 1 and policy.base == "greedy"
    checked = 0
    for ctx in _contexts(4)[:6]:
        for p in (policy, LookaheadPolicy(base="planner")):
            hyps = list(ctx.hypotheses)
            w = class_weights([h.model for h in hyps])
            search = _Search(ctx, p.rollout_moves, p.unresolved_cost, base=p.base)
            followed = search.rollout(hyps, w, ctx.state, ctx.components, p.rollout_moves + 1)
            decision = p.choose(ctx, np.random.default_rng(0))
            if decision.candidates:
                checked += 1
                assert -max(c.score for c in decision.candidates) <= followed + 1e-9
    assert checked
    for s in plan_sweep(SMALL, 4, seed=11, policies=["lookahead"], verify="none", moves="tracing"):
        r = run_episode(s, library=LIB, policy=policy)
        assert r.correct, (s.model, r.outcome)


def test_lookahead_prunes_only_what_could_not_win():
    """Without its margin the roll-out policy picks the least expected cost of every candidate it expands, as
    valuing each of them would: the candidates it leaves unvalued (their least predicted cost above the best value
    found) could not have won."""
    from haptic.planning.move_scores import score_all
    from haptic.planning.optimal import LookaheadPolicy

    policy = LookaheadPolicy(margin=0.0)
    compared = 0
    for ctx in _contexts(4)[:6]:
        decision = policy.choose(ctx, np.random.default_rng(0))
        if not decision.candidates:
            continue
        hyps = list(ctx.hypotheses)
        w = class_weights([h.model for h in hyps])
        search = _Search(ctx, policy.rollout_moves, policy.unresolved_cost, policy.max_probes, base=policy.base)
        qs = [search.q(hyps, w, c[0], ctx.state, ctx.components, 1) for c in search.expanded(score_all(ctx))]
        best = min(q for q in qs if q is not None)
        assert -max(c.score for c in decision.candidates) == pytest.approx(best, rel=1e-9)
        assert len(decision.candidates) <= len(qs)
        compared += 1
    assert compared


def test_lookahead_options_are_checked():
    with pytest.raises(HapticError, match="base policy"):
        make_policy("lookahead", base="random")
    with pytest.raises(HapticError, match="margin"):
        make_policy("lookahead", margin=1.0)


def test_probe_contenders_value_as_every_probe_would(monkeypatch):
    """The search scores a node's probes all at once and predicts only those a policy could take from there; with
    every probe predicted and scored one by one instead, roll-outs and one-move searches come to the same values."""
    from haptic.planning import optimal

    contexts = [c for c in _contexts(6, moves="all") if c.config.moves == "all"][:4]
    assert contexts, "no decision with several pose classes"

    def values(ctx):
        hyps = list(ctx.hypotheses)
        w = class_weights([h.model for h in hyps])
        out = []
        for base in optimal.BASES:
            search = _Search(ctx, 4, 20.0, 2, base=base)
            out.append(search.rollout(hyps, w, ctx.state, ctx.components, 4))
            out.append(search.value(hyps, w, ctx.state, ctx.components, depth=1))
        return out

    fast = [values(ctx) for ctx in contexts]
    monkeypatch.setattr(optimal._ProbeTable, "contenders", lambda self, idx, pos, w, allowed, k, base: list(
        np.flatnonzero(allowed)))
    every = [values(ctx) for ctx in contexts]
    assert np.allclose(fast, every, rtol=1e-12)
