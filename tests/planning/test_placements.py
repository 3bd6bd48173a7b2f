"""Placements of several fingertips at once: their cost, the candidates the hypotheses give, and their scores
beside the other moves."""

import numpy as np
import pytest

from haptic.geometry import SE3, load_library
from haptic.matching.components import DataFace, SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.efficiency import class_weights
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.move_scores import Context, placement_lines, same_move, score_all
from haptic.planning.moves import CostModel, FingerApproach, PlacementMove, SensorState
from haptic.planning.placements import (
    HAND_FINGERS,
    PlacementConfig,
    candidate_placements,
    compatible,
    placement_costs,
)
from haptic.planning.policies import PlannerPolicy

LIB = load_library()
NOISE = SensorNoise()


def _context(names, fingers: int, seed: int = 3) -> Context:
    """Pose classes of ``names`` that share data face 0: each model at one random rotation with the centre of its
    face 0 at the sensor's point."""
    rng = np.random.default_rng(seed)
    base = SE3.random(rng, 0.0)
    hyps = []
    for name in names:
        poly = LIB[name]
        centre_m = poly.vertices[list(poly.faces[0])].mean(axis=0)
        pose = base @ SE3(np.eye(3), -centre_m)
        hyps.append(Hypothesis(model=name, poly=poly, world_from_model=pose, faces={0: 0}, edges={}, vertices={}))
    n = hyps[0].world_from_model.rotate(hyps[0].poly.face_normals[0])
    face = DataFace(0, n, base.translation[None, :], 0.01, 0.001)
    state = SensorState(base.translation.copy(), 0)
    return Context(tuple(hyps), state, {0: face}, NOISE, PlannerConfig(fingers=fingers))


def test_a_placement_costs_the_fixed_cost_its_travel_a_closing_per_finger_and_a_stroke_per_normal():
    c = CostModel()
    assert c.placement_move(0.1, 2, 2) == pytest.approx(3.0 + 20.0 * 0.1 + 2 * 0.5 + 2 * 0.5)
    assert c.placement_move(0.1, 4, 3) == pytest.approx(3.0 + 2.0 + 4 * 0.5 + 3 * 0.5)
    # no dearer than as many probes, each travelling as far as the hand does (a point sensor: no strokes)
    assert c.placement_move(0.1, 2, 0) == pytest.approx(2 * c.probe_move(0.05))
    assert c.placement_move(0.1, 4, 0) < 4 * c.probe_move(0.025)


def test_a_point_sensor_s_placement_pays_no_stroke_the_hand_s_does():
    from haptic.planning.handpath import HandStart

    ctx = _context(["BOX01", "WEDGE01", "PYR01", "BOX01N"], fingers=2)
    weights = class_weights([h.model for h in ctx.hypotheses])
    lines = [p for p in placement_lines(ctx) if p.hit.all()][:2]
    assert len(lines) == 2
    point = placement_costs(lines, ctx.state.position, ctx.config.costs)
    n = ctx.components[0].normal
    hand = HandStart.at(ctx.state.position, n, ctx.state.position[None], 0.012)
    on_hand = placement_costs(lines, ctx.state.position, ctx.config.costs, hand)
    no_strokes = placement_costs(lines, ctx.state.position, CostModel(c_n=0.0), hand)
    assert on_hand == pytest.approx(no_strokes + 2 * ctx.config.costs.c_n)
    assert point.shape == on_hand.shape == weights.shape


def test_a_placement_says_what_is_wrong_with_it():
    f = FingerApproach("index", np.zeros(3), np.array([0.0, 0.0, -1.0]), 0.1)
    assert "2 to 4" in PlacementMove((f,)).problem()
    assert "at most once" in PlacementMove((f, f)).problem()
    g = FingerApproach("middle", np.zeros(3), np.array([0.0, 0.0, -2.0]), 0.1)
    assert "middle" in PlacementMove((f, g)).problem()
    ok = FingerApproach("middle", np.array([0.05, 0.0, 0.0]), np.array([0.0, 0.0, -1.0]), 0.1)
    assert PlacementMove((f, ok)).problem() is None


def test_one_finger_offers_no_placement_and_scores_as_before():
    ctx1 = _context(["BOX01", "WEDGE01", "PYR01"], fingers=1)
    assert not any(p.move.kind == "placement" for p, *_ in score_all(ctx1))


@pytest.mark.parametrize("fingers", [2, 4])
def test_candidate_placements_close_compatible_fingers_on_different_predicted_faces(fingers):
    ctx = _context(["BOX01", "WEDGE01", "PYR01", "BOX01N"], fingers=fingers)
    weights = class_weights([h.model for h in ctx.hypotheses])
    lines = placement_lines(ctx)
    cfg = PlacementConfig()
    preds = candidate_placements(lines, weights, fingers, ctx.state.position, ctx.config.costs, config=cfg)
    assert preds, "the hypotheses give placements"
    sizes = {len(p.move.fingers) for p in preds}
    assert sizes <= set(range(2, fingers + 1)) and 2 in sizes
    for p in preds:
        names = [f.finger for f in p.move.fingers]
        assert names == list(HAND_FINGERS[: len(names)])
        assert p.move.problem() is None
        for a in range(len(p.lines)):
            for b in range(a + 1, len(p.lines)):
                assert compatible(p.lines[a], p.lines[b], weights, cfg)
                ua, ub = p.move.fingers[a].direction, p.move.fingers[b].direction
                assert float(ua @ ub) >= np.cos(cfg.max_spread) - 1e-12
        # a hypothesis is eliminated by the placement exactly when one of its fingers' outcomes eliminates it
        d = p.eliminates()
        assert np.array_equal(d, np.logical_or.reduce([q.eliminates() for q in p.lines]))
        assert p.costs == pytest.approx(placement_costs(p.lines, ctx.state.position, ctx.config.costs))
    for i, a in enumerate(preds):  # each candidate once
        assert not any(same_move(a.move, b.move) for b in preds[i + 1 :])


def test_the_planner_ranks_placements_with_the_other_moves():
    ctx = _context(["BOX01", "WEDGE01", "PYR01", "BOX01N", "BOX01P"], fingers=4)
    scored = score_all(ctx)
    kinds = {p.move.kind for p, *_ in scored}
    assert "placement" in kinds and "face" in kinds
    for p, eff, elim, cost, _risk in scored:
        if p.move.kind == "placement":
            e, el, co = p.score(class_weights([h.model for h in ctx.hypotheses]))
            assert (eff, elim, cost) == pytest.approx((e, el, co))
            assert cost >= ctx.config.costs.c_m
    decision = PlannerPolicy().choose(ctx, np.random.default_rng(0))
    best = max(c.score for c in decision.candidates)
    chosen = [c for c in decision.candidates if c.move is decision.move]
    assert chosen and chosen[0].score == pytest.approx(best)


def test_a_failed_placement_is_not_offered_again():
    ctx = _context(["BOX01", "WEDGE01", "PYR01", "BOX01N"], fingers=2)
    first = [p.move for p, *_ in score_all(ctx) if p.move.kind == "placement"]
    assert first
    again = Context(ctx.hypotheses, ctx.state, ctx.components, NOISE, ctx.config, avoid=(first[0],))
    assert not any(same_move(first[0], p.move) for p, *_ in score_all(again) if p.move.kind == "placement")


def test_the_planner_predicts_what_the_ideal_sensor_does_with_a_placement():
    """With the true pose among the hypotheses, its predicted faces touched and cost are what the geometric
    executor then reports for each candidate placement."""
    from haptic.executor.geometric import GeometricExecutor

    rng = np.random.default_rng(2)
    ctx = _context(["BOX01", "WEDGE01", "PYR01", "BOX01N"], fingers=4)
    weights = class_weights([h.model for h in ctx.hypotheses])
    preds = candidate_placements(placement_lines(ctx), weights, 4, ctx.state.position, ctx.config.costs)
    assert preds
    for i, h in enumerate(ctx.hypotheses):
        for p in preds:
            ex = GeometricExecutor(h.poly, h.world_from_model, SensorNoise(), rng)
            ex.start(face=0, point_in_model=h.model_from_world.apply(ctx.state.position))
            res = ex.execute(p.move)
            assert res.ok
            touched = [f["status"] == "touched" for f in res.info["fingers"]]
            assert touched == [bool(q.hit[i]) for q in p.lines]
            assert [ex.truth[c.id][1] for c in res.components] == [int(q.face[i]) for q in p.lines if q.hit[i]]
            assert res.cost == pytest.approx(p.costs[i], abs=1e-6)


def test_with_a_reach_test_only_a_placement_it_reaches_is_offered_with_its_fingers():
    """``PlannerConfig.placement_reach``: asked for the best placements (beating every other candidate, here all of
    them: ``beat`` at -inf), most efficient first; the first it reaches is the one offered, with the fingers it
    gives; none when it reaches none."""
    from dataclasses import replace

    from haptic.planning.move_scores import score_placements

    ctx = _context(["BOX01", "WEDGE01", "PYR01", "BOX01N"], fingers=2)
    weights = class_weights([h.model for h in ctx.hypotheses])
    free = score_placements(ctx, weights)
    assert len(free) > 1
    asked: list[PlacementMove] = []

    def swap(move, hypotheses):
        asked.append(move)
        assert hypotheses[0] is ctx.hypotheses[int(np.argmax(weights))]
        if len(asked) < 2:
            return None
        return PlacementMove(tuple(replace(f, finger=n) for f, n in zip(move.fingers, ("thumb", "ring"),
                                                                           strict=False)))  # fmt: skip

    reach_ctx = replace(ctx, config=replace(ctx.config, placement_reach=swap))
    (offered,) = score_placements(reach_ctx, weights)
    best = sorted(free, key=lambda c: -c[1])
    assert [m.fingers[0].start.tolist() for m in asked] == [c[0].move.fingers[0].start.tolist() for c in best[:2]]
    assert [f.finger for f in offered[0].move.fingers] == ["thumb", "ring"]
    assert offered[1:] == best[1][1:]  # scored as before
    nothing = replace(ctx, config=replace(ctx.config, placement_reach=lambda m, h: None))
    assert score_placements(nothing, weights) == []
    assert score_placements(reach_ctx, weights, beat=(np.inf, np.inf)) == []  # nothing beats the best other move


def test_a_placement_the_reach_test_reaches_is_costed_along_its_way():
    """The placement offered is costed along the way the reach test found: the hand to the path's start (its
    exploring pad's place there, ``home``), the farthest pad's way along the path (``travel``), the closing and the
    way back; each metre more of the path's way costs ``c_s`` more, and its efficiency is scored from that cost."""
    from dataclasses import replace

    from haptic.planning.move_scores import hand_start, score_placements
    from haptic.planning.placements import placement_costs, placement_path_costs

    ctx = _context(["BOX01", "WEDGE01", "PYR01", "BOX01N"], fingers=2)
    weights = class_weights([h.model for h in ctx.hypotheses])
    home = np.asarray(ctx.state.position, dtype=float) + np.array([0.0, 0.0, 0.15])

    def along(travel):
        def reach(move, hypotheses):
            return replace(move, path=np.zeros((2, 3)), travel=travel, home=home)
        return reach

    offered = {}
    for travel in (0.1, 0.3):
        (offered[travel],) = score_placements(replace(ctx, config=replace(ctx.config, placement_reach=along(travel))),
                                              weights)  # fmt: skip
    near, far = offered[0.1], offered[0.3]
    assert near[0].move.travel == 0.1 and far[0].move.travel == 0.3
    assert far[0].costs == pytest.approx(near[0].costs + ctx.config.costs.c_s * 0.2)
    lines, hand = near[0].lines, hand_start(ctx)
    assert near[0].costs == pytest.approx(placement_path_costs(lines, near[0].move, ctx.state.position,
                                                               ctx.config.costs, hand))  # fmt: skip
    # the way through the path's start costs more than the straight way the estimate before the test assumes
    assert np.all(near[0].costs > placement_costs(lines, ctx.state.position, ctx.config.costs, hand))
    assert far[3] > near[3] and far[1] <= near[1]  # dearer, no more efficient
    assert near[1:4] == pytest.approx(near[0].score(weights))
    # without the way (an executor finding its own), the estimate before the test stands
    bare = replace(near[0].move, travel=None, home=None)
    assert np.array_equal(placement_path_costs(lines, bare, ctx.state.position, ctx.config.costs, hand),
                          placement_costs(lines, ctx.state.position, ctx.config.costs, hand))  # fmt: skip


def test_a_placement_no_other_move_rivals_is_taken_only_where_it_beats_the_look_ahead(monkeypatch):
    """When the placement is the best candidate and no other kind of candidate is expected to eliminate anything,
    the planner weighs it against the look-ahead's best sequence of tracing moves (eliminations per unit cost
    both): the sequence's first move where that is as efficient or more, else the placement. A tracing move
    that scores above zero keeps the comparison one move against one, as before."""
    from types import SimpleNamespace

    import haptic.planning.policies as policies
    from haptic.planning.moves import FaceMove
    from haptic.planning.policies import GreedyPolicy

    ctx = _context(["BOX01", "WEDGE01"], fingers=2)
    placement = PlacementMove((FingerApproach("index", np.zeros(3), np.array([0.0, 0.0, -1.0]), 0.05),
                               FingerApproach("thumb", np.ones(3), np.array([0.0, 0.0, -1.0]), 0.05)))  # fmt: skip
    face, step = FaceMove(direction=np.array([1.0, 0.0, 0.0])), FaceMove(direction=np.array([0.0, 1.0, 0.0]))
    asked: list[int] = []

    def choose(face_eff: float, sequence: tuple, policy=None) -> object:
        cands = [(SimpleNamespace(move=placement), 0.1, 2.0, 20.0, 0.0),
                 (SimpleNamespace(move=face), face_eff, face_eff * 5.0, 5.0, 0.0)]  # fmt: skip
        monkeypatch.setattr(policies, "score_all", lambda c: cands)

        def best(c, depth=2):
            asked.append(depth)
            return sequence

        monkeypatch.setattr(policies, "lookahead_best", best)
        return (policy or PlannerPolicy()).choose(ctx, np.random.default_rng(0)).move

    assert choose(0.0, (step, 0.2)) is step  # the sequence is more efficient
    assert asked == [2]
    assert choose(0.0, (step, 0.1)) is step  # as efficient: the index finger's tracing
    assert choose(0.0, (step, 0.05)) is placement  # the placement is more efficient than any sequence
    assert asked[-2:] == [2, 3]  # two and three moves weighed
    assert choose(0.0, (None, 0.0)) is placement  # no sequence eliminates anything
    asked.clear()
    assert choose(0.05, (step, 0.2)) is placement  # a tracing move scores too: one move against one
    assert asked == []
    assert choose(0.0, (step, 0.2), GreedyPolicy()) is placement  # a score of eliminations: no comparison
    assert asked == []
