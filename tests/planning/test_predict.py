"""Predictions of move outcomes agree with what the geometric executor then measures."""

import numpy as np
import pytest

from haptic.executor.geometric import GeometricExecutor
from haptic.geometry import SE3, load_library
from haptic.matching.components import SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import CostModel
from haptic.planning.predict import candidate_moves, predict_one

SEED_EPISODE = {"verify": "none", "moves": "tracing"}
"""The seed's episodes: tracing moves, recognition without verification."""
LIB = load_library()


def _truth_hypothesis(ex: GeometricExecutor, model) -> Hypothesis:
    faces = {d: m for d, (k, m) in ex.truth.items() if k == "face"}
    edges = {d: m for d, (k, m) in ex.truth.items() if k == "edge"}
    vertices = {d: m for d, (k, m) in ex.truth.items() if k == "vertex"}
    return Hypothesis(model.name, model, ex.world_from_model, faces, edges, vertices)


def test_true_hypothesis_predicts_the_executed_distance():
    rng = np.random.default_rng(4)
    config = PlannerConfig()
    checked = 0
    for name in ("BOX01", "WEDGE01", "LBLOCK01", "TETRA01L", "BOX01N"):
        model = LIB[name]
        for _ in range(4):
            pose = SE3.random(rng, 0.1)
            ex = GeometricExecutor(model, pose, noise=SensorNoise().scaled(0.0), rng=rng, costs=CostModel())
            res = ex.start()
            comps = {c.id: c for c in res.components}
            state = res.state
            for _step in range(6):
                moves = candidate_moves(state, comps, config)
                move = moves[int(rng.integers(len(moves)))]
                h = _truth_hypothesis(ex, model)
                outcome, cost = predict_one(h, move, state, comps, config)
                res = ex.execute(move)
                if not res.ok:
                    continue
                if not np.isnan(outcome[0]) and move.kind in ("face", "edge"):
                    assert np.isclose(outcome[0], res.distance, atol=1e-6), (name, move)
                    assert np.isclose(cost, res.cost, atol=1e-6)
                    checked += 1
                for c in res.components:
                    comps[c.id] = c
                state = res.state
    assert checked >= 40


@pytest.mark.slow
def test_predicted_eliminations_agree_with_the_matcher():
    """The planner's attribute predictions (seed §4.1) against the matcher given each hypothesis's simulated
    data: over real decision points, the two agree on nearly every (true, eliminated) pair."""
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import run_episode
    from haptic.planning import policies as P
    from haptic.planning.efficiency import distinguishable
    from haptic.planning.move_scores import fresh_moves
    from haptic.planning.predict import predict
    from haptic.planning.search import matcher_eliminations

    agree = total = 0
    original = P.PlannerPolicy.choose

    def checking(self, ctx, rng):
        nonlocal agree, total
        for move in fresh_moves(ctx)[:6]:
            d_matcher, _ = matcher_eliminations(ctx, move)
            pred = predict(ctx.hypotheses, move, ctx.state, ctx.components, ctx.noise, ctx.config)
            d_attr = distinguishable(pred.outcomes, pred.bounds)
            agree += int((d_matcher == d_attr).sum())
            total += d_attr.size
        return original(self, ctx, rng)

    P.PlannerPolicy.choose = checking
    try:
        for name, seed in (("BOX01", 1), ("WEDGE01", 2), ("BOX01N", 3)):
            run_episode(EpisodeSpec(model=name, seed=seed, policy="planner", **SEED_EPISODE), library=LIB)
    finally:
        P.PlannerPolicy.choose = original
    assert total > 500
    assert agree / total > 0.95


def _hypotheses_on_faces(library_seed: int, seed: int, n: int):
    """``n`` hypotheses of a generated library, each with the sensor (at a fixed point) on a random point of a random
    face of its model at a random rotation: (models, the generator, the sensor's position, the hypotheses)."""
    from haptic.geometry import tracing
    from haptic.geometry.generate import generate_library

    models = generate_library(12, seed=library_seed)
    rng = np.random.default_rng(seed)
    pos = np.array([0.01, 0.02, 0.03])
    hyps = []
    for _ in range(n):
        m = models[int(rng.integers(len(models)))]
        f = int(rng.integers(m.n_faces))
        q = tracing.random_face_point(m, f, rng, margin=0.002)
        r = SE3.random(rng).rotation
        hyps.append(Hypothesis(m.name, m, SE3(r, pos - r @ q), {0: f}, {}, {}))
    return models, rng, pos, hyps


def test_trace_all_equals_trace_in_for_each_hypothesis():
    """The batched face trace gives each hypothesis the trace of its own world."""
    from haptic.planning.hypothesis import trace_in
    from haptic.planning.moves import FaceMove, SensorState
    from haptic.planning.predict import trace_all

    models, rng, pos, hyps = _hypotheses_on_faces(4, 0, 200)
    hyps.append(Hypothesis("none", models[0], None, {0: 0}, {}, {}))
    state = SensorState(position=pos, face=0)
    met = 0
    for _ in range(3):
        d = rng.normal(size=3)
        move = FaceMove(d / np.linalg.norm(d))
        for a, b in zip(trace_all(hyps, move, state), [trace_in(h, move, state) for h in hyps], strict=True):
            assert (a is None) == (b is None)
            if a is not None:
                met += 1
                assert (a.face, a.hit.edge, a.hit.next_face) == (b.face, b.hit.edge, b.hit.next_face)
                assert abs(a.hit.distance - b.hit.distance) < 1e-12
                assert np.allclose(a.hit.point, b.hit.point, atol=1e-12)
    assert met > 500


def test_face_outcomes_equal_the_predictions_one_hypothesis_at_a_time():
    """The face moves' outcomes, costs and clearances stacked over (moves, hypotheses, sides) are each hypothesis's
    own prediction (:func:`predict` from its :func:`trace_in`), hypotheses that cannot say included."""
    from haptic.planning.hypothesis import trace_in
    from haptic.planning.moves import FaceMove, SensorState
    from haptic.planning.predict import face_outcomes, predict_moves

    models, rng, pos, hyps = _hypotheses_on_faces(5, 1, 120)
    hyps.insert(7, Hypothesis("none", models[0], None, {0: 0}, {}, {}))
    hyps.insert(9, Hypothesis("unmatched", models[1], hyps[0].world_from_model, {}, {}, {}))
    state = SensorState(position=pos, face=0)
    config = PlannerConfig()
    moves = []
    for _ in range(6):
        d = rng.normal(size=3)
        moves.append(FaceMove(d / np.linalg.norm(d)))
    said = 0
    for move, (out, cost, clear) in zip(moves, face_outcomes(hyps, moves, state, config), strict=True):
        for i, h in enumerate(hyps):
            one, c1 = predict_one(h, move, state, {}, config)
            assert np.array_equal(np.isnan(out[i]), np.isnan(one))
            assert np.allclose(out[i], one, rtol=0, atol=1e-12, equal_nan=True)
            assert np.isclose(cost[i], c1, rtol=0, atol=1e-12, equal_nan=True)
            tr = trace_in(h, move, state)
            assert (tr is None) == np.isnan(clear[i])
            if tr is not None:
                assert abs(clear[i] - tr.clearance(h.poly)) < 1e-12
                said += 1
    assert said > 300
    # the predictions predict_moves forms from them are those of predict, move by move
    from haptic.planning.predict import predict

    for p in predict_moves(hyps, moves, state, {}, SensorNoise(), config):
        q = predict(hyps, p.move, state, {}, SensorNoise(), config)
        assert np.allclose(p.outcomes, q.outcomes, rtol=0, atol=1e-12, equal_nan=True)
        assert np.allclose(p.costs, q.costs, rtol=0, atol=1e-12) and np.array_equal(p.bounds, q.bounds)
        assert np.allclose(p.clearance, q.clearance, rtol=0, atol=1e-12, equal_nan=True)


def test_edge_outcomes_equal_the_predictions_one_hypothesis_at_a_time():
    """The edge moves' distances and costs in every hypothesis at once are each hypothesis's own prediction
    (:func:`predict_one`), for both senses, with hypotheses that cannot say (no pose, the edge not matched)."""
    from haptic.geometry.generate import generate_library
    from haptic.matching.components import DataEdge
    from haptic.planning.moves import EdgeMove, SensorState
    from haptic.planning.predict import edge_outcomes

    models = generate_library(12, seed=6)
    rng = np.random.default_rng(2)
    pos = np.array([0.01, 0.02, 0.03])
    direction = np.array([0.0, 0.6, 0.8])
    hyps = []
    for _ in range(80):
        m = models[int(rng.integers(len(models)))]
        e = int(rng.integers(m.n_edges))
        q = m.edge_points[e] + rng.uniform(0.1, 0.9) * m.edge_lengths[e] * m.edge_directions[e]
        r = SE3.random(rng).rotation
        hyps.append(Hypothesis(m.name, m, SE3(r, pos - r @ q), {0: 0}, {1: e}, {}))
    hyps.insert(3, Hypothesis("none", models[0], None, {0: 0}, {1: 0}, {}))
    hyps.insert(5, Hypothesis("unmatched", models[1], hyps[0].world_from_model, {0: 0}, {}, {}))
    comps = {1: DataEdge(1, direction, pos - 0.01 * direction, 0.02, 0.01, 0.001, 0.001)}
    state = SensorState(position=pos, face=0, edge=1)
    config = PlannerConfig()
    moves = [EdgeMove(1), EdgeMove(-1)]
    said = 0
    for move, (out, cost, clear) in zip(moves, edge_outcomes(hyps, moves, state, comps, config), strict=True):
        assert np.isnan(clear).all()
        for i, h in enumerate(hyps):
            one, c1 = predict_one(h, move, state, comps, config)
            assert np.allclose(out[i], one, rtol=0, atol=1e-15, equal_nan=True)
            assert np.isclose(cost[i], c1, rtol=0, atol=1e-13, equal_nan=True)
            said += not np.isnan(one[0])
    assert said == 2 * 80
