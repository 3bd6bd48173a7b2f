"""Resting probes: another finger probing a neighbouring face while the exploring pad rests -- the planner's candidates,
what they cost, and that the index finger alone is offered none."""

from dataclasses import replace

import numpy as np
import pytest

from haptic.geometry import SE3, load_library
from haptic.matching.components import DataFace, SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.move_scores import Context, score_all, score_resting
from haptic.planning.moves import CostModel, ProbeMove, SensorState
from haptic.planning.resting import RestingConfig, RestingFinger, approaches, resting_lines

LIB = load_library()
NOISE = SensorNoise()


class _Reach:
    """A reach test that reaches every line (``reach``) or none, counting what it is asked."""

    def __init__(self, reach: bool = True) -> None:
        self.reach, self.asked, self.decisions = reach, 0, 0

    def fingers(self) -> list[RestingFinger]:
        return [RestingFinger("middle", np.array([0.0, 0.04, 0.05]), np.array([0.0, 0.04, 0.12]), 0.3)]

    def decided(self, lines: int) -> None:
        self.decisions += 1

    def __call__(self, move: ProbeMove, hypotheses) -> ProbeMove | None:
        self.asked += 1
        return replace(move, path=np.zeros((2, 22))) if self.reach else None


def _context(names, fingers: int, reach: _Reach | None, seed: int = 3) -> Context:
    """Pose classes of ``names`` that share data face 0, measured over a 30 mm patch round the sensor's point."""
    rng = np.random.default_rng(seed)
    base = SE3.random(rng, 0.0)
    hyps = []
    from haptic.planning.hypothesis import Hypothesis

    for name in names:
        poly = LIB[name]
        centre_m = poly.vertices[list(poly.faces[0])].mean(axis=0)
        pose = base @ SE3(np.eye(3), -centre_m)
        hyps.append(Hypothesis(model=name, poly=poly, world_from_model=pose, faces={0: 0}, edges={}, vertices={}))
    n = hyps[0].world_from_model.rotate(hyps[0].poly.face_normals[0])
    a = np.cross(n, [1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.cross(n, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    pts = np.array([base.translation + 0.015 * (i * a + j * b) for i in (-1, 0, 1) for j in (-1, 0, 1)])
    face = DataFace(0, n, pts, 0.01, 0.001)
    state = SensorState(base.translation.copy(), 0)
    return Context(tuple(hyps), state, {0: face}, NOISE, PlannerConfig(fingers=fingers, resting_reach=reach))


NAMES = ["BOX01", "WEDGE01", "PYR01", "BOX01N", "BOX01P"]


@pytest.fixture
def posed(monkeypatch):
    """The data taken to fix the position (one face alone does not: :func:`~haptic.planning.move_scores.weak_probes`
    would leave every line eliminating nothing, a rule of its own tests), so the lines' predictions count."""
    import haptic.planning.move_scores as move_scores

    monkeypatch.setattr(move_scores, "weak_probes", lambda ctx, preds: preds)


def test_a_resting_probe_costs_the_finger_s_closing_and_stroke_without_the_placement_s_fixed_cost():
    c = CostModel()
    assert c.resting_probe(0.1, True) == pytest.approx(c.c_q + c.c_s * 0.1 + c.c_n)
    assert c.resting_probe(0.1, False) == pytest.approx(c.c_q + c.c_s * 0.1)
    assert c.resting_probe(0.1, True) < c.placement_move(0.1, 1, 1) - c.c_m + 1e-9


def test_resting_probes_are_offered_with_several_fingers_and_a_reach_test_that_reaches_them(posed):
    ctx = _context(NAMES, fingers=4, reach=_Reach())
    offered = score_resting(ctx, np.ones(len(NAMES)) / len(NAMES))
    assert len(offered) == 1
    pred, eff, elim, cost, risk = offered[0]
    assert pred.move.resting and pred.move.finger == "middle" and pred.move.path is not None
    assert elim > 0.0 and cost < ctx.config.costs.c_m + ctx.config.costs.c_q  # no placement's fixed cost
    assert any(getattr(p.move, "resting", False) for p, *_ in score_all(ctx))


def test_one_finger_offers_no_resting_probe_even_with_a_reach_test(posed):
    reach = _Reach()
    ctx = _context(NAMES, fingers=1, reach=reach)
    assert not any(getattr(p.move, "resting", False) for p, *_ in score_all(ctx))
    assert reach.asked == 0 and reach.decisions == 0


def test_a_line_the_resting_hand_cannot_close_along_is_not_offered(posed):
    reach = _Reach(reach=False)
    ctx = _context(NAMES, fingers=4, reach=reach)
    assert score_resting(ctx, np.ones(len(NAMES)) / len(NAMES)) == []
    assert 0 < reach.asked <= RestingConfig().checks


def test_resting_lines_leave_out_the_face_the_pad_rests_on_and_what_no_finger_reaches():
    ctx = _context(["BOX01"], fingers=4, reach=_Reach())
    h = ctx.hypotheses[0]
    n0 = h.world_from_model.rotate(h.poly.face_normals[0])
    lines = resting_lines(ctx.hypotheses, np.ones(1), _Reach().fingers(), ctx.state.position, n0, RestingConfig())
    assert lines and all(m.resting and m.finger == "middle" for m in lines)
    assert not any(float(np.dot(m.direction, -n0)) > 0.99 for m in lines)  # none head-on onto the resting face
    near = RestingFinger("middle", ctx.state.position, ctx.state.position + 0.05 * n0, 0.001)
    assert resting_lines(ctx.hypotheses, np.ones(1), [near], ctx.state.position, n0, RestingConfig()) == []


def test_approaches_are_unit_and_come_onto_the_face():
    for n in (np.array([0.0, 0.0, 1.0]), np.array([0.6, 0.0, 0.8]), np.array([0.0, -1.0, 0.0])):
        dirs = approaches(n, np.deg2rad(45.0))
        assert len(dirs) == 5
        for u in dirs:
            assert np.linalg.norm(u) == pytest.approx(1.0)
            assert float(u @ n) <= -np.cos(np.deg2rad(45.0)) + 1e-9
