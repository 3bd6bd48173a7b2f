"""Free-space probes in the optimal policy's search: a probe simulated in one hypothesis's world, the branches
of its outcomes, and episodes of ``--policy optimal --moves all``."""

import numpy as np
import pytest

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import SE3, load_library
from haptic.matching.components import DataFace, SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import ProbeMove, SensorState
from haptic.planning.optimal import OptimalPolicy
from haptic.planning.probe_prediction import predict_probes
from haptic.planning.search import branches
from haptic.planning.simulate import simulate, simulate_probe

SMALL = ["BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R"]
LIB = load_library()
NOISE = SensorNoise()


def _world(name: str, pose: SE3, touched: int = 0):
    """Hypothesis ``name`` at ``pose`` with data face 0 on its model face ``touched``, the sensor there."""
    poly = LIB[name]
    centre = pose.apply(poly.vertices[list(poly.faces[touched])].mean(axis=0))
    face = DataFace(0, pose.rotate(poly.face_normals[touched]), centre[None, :], 0.01, 0.001)
    h = Hypothesis(model=name, poly=poly, world_from_model=pose, faces={0: touched}, edges={}, vertices={})
    return h, SensorState(centre, 0), {0: face}


def _aimed(poly, pose: SE3, g: int, back: float = 0.1) -> tuple[ProbeMove, np.ndarray]:
    """A probe head-on at the centre of model face ``g`` (posed), from ``back`` out; the centre."""
    target = pose.apply(poly.vertices[list(poly.faces[g])].mean(axis=0))
    n = pose.rotate(poly.face_normals[g])
    return ProbeMove(target + back * n, -n, 2 * back), target


def _other_face(poly, touched: int) -> int:
    return int(np.argmin(poly.face_normals @ poly.face_normals[touched]))  # the face most opposite


def test_a_probe_hit_gives_the_face_hit_at_the_contact():
    rng = np.random.default_rng(5)
    pose = SE3.random(rng, 0.05)
    h, state, comps = _world("BOX01", pose)
    g = _other_face(h.poly, 0)
    move, target = _aimed(h.poly, pose, g)
    h2, st, merged = simulate(h, move, state, comps, PlannerConfig(), NOISE)
    (fid,) = set(merged) - set(comps)
    face = merged[fid]
    assert fid == 1 and isinstance(face, DataFace) and face.adjacent == ()
    assert face.points[0] == pytest.approx(target, abs=1e-9)
    assert face.normal == pytest.approx(pose.rotate(h.poly.face_normals[g]), abs=1e-12)
    assert face.normal_bound == pytest.approx(NOISE.k * NOISE.normal_sigma)
    assert face.position_bound == pytest.approx(NOISE.k * NOISE.position_sigma)
    assert h2.faces == {0: 0, 1: g} and h.faces == {0: 0}
    assert st.face == fid and st.edge is None and st.vertex is None and st.edge_faces == ()
    assert st.position == pytest.approx(target, abs=1e-9)


def test_a_probe_miss_gives_the_state_back():
    rng = np.random.default_rng(5)
    pose = SE3.random(rng, 0.05)
    h, state, comps = _world("BOX01", pose)
    move, _ = _aimed(h.poly, pose, _other_face(h.poly, 0))
    away = ProbeMove(np.asarray(move.start) + np.array([0.0, 0.0, 0.5]), move.direction, move.length)
    h2, st, merged = simulate_probe(h, away, state, comps, NOISE)
    assert h2 is h and st is state and merged == comps and merged is not comps


def test_a_probe_that_separates_two_hypotheses_gives_two_branches_of_their_weights():
    """One pose hit head-on, the other far to the side: a hit's branch and a miss's, each with its hypothesis,
    its weight and its predicted cost."""
    rng = np.random.default_rng(8)
    pose = SE3.random(rng, 0.0)
    h0, state, comps = _world("BOX01", pose)
    shifted = SE3(pose.rotation, pose.translation + np.array([0.0, 0.0, 0.3]))
    h1 = Hypothesis(model="WEDGE01", poly=LIB["WEDGE01"], world_from_model=shifted, faces={0: 0}, edges={},
                    vertices={})  # fmt: skip
    move, target = _aimed(h0.poly, pose, _other_face(h0.poly, 0))
    w = np.array([0.25, 0.75])
    (pred,) = predict_probes([h0, h1], [move], state.position, comps, NOISE)
    assert pred.hit.tolist() == [True, False]
    brs = branches([h0, h1], w, move, state, comps, NOISE, PlannerConfig())
    assert len(brs) == 2
    hit, miss = sorted(brs, key=lambda b: len(b.components), reverse=True)
    assert [h.model for h in hit.hypotheses] == ["BOX01"] and hit.weights.tolist() == [0.25]
    assert hit.state.face == 1 and hit.state.position == pytest.approx(target, abs=1e-9)
    assert hit.cost == pytest.approx(pred.costs[0])
    assert [h.model for h in miss.hypotheses] == ["WEDGE01"] and miss.weights.tolist() == [0.75]
    assert miss.state is state and set(miss.components) == {0}
    assert miss.cost == pytest.approx(pred.costs[1])


def test_a_probe_that_cannot_separate_gives_one_branch_with_every_hypothesis():
    rng = np.random.default_rng(8)
    pose = SE3.random(rng, 0.0)
    h0, state, comps = _world("BOX01", pose)
    h1 = Hypothesis(model="BOX01", poly=h0.poly, world_from_model=pose, faces={0: 0}, edges={}, vertices={})
    move, _ = _aimed(h0.poly, pose, _other_face(h0.poly, 0))
    (br,) = branches([h0, h1], np.array([0.5, 0.5]), move, state, comps, NOISE, PlannerConfig())
    assert len(br.hypotheses) == 2 and br.weights.sum() == pytest.approx(1.0)
    assert all(h.faces[1] == _other_face(h0.poly, 0) for h in br.hypotheses)


class Recording(OptimalPolicy):
    """The optimal policy, keeping every decision it made."""

    def __init__(self, **options):
        super().__init__(**options)
        self.decisions = []

    def choose(self, ctx, rng):
        d = super().choose(ctx, rng)
        self.decisions.append(d)
        return d


def test_optimal_with_every_move_recognises_and_weighs_probes():
    lib = {k: v for k, v in LIB.items() if k in SMALL}
    pol = Recording()
    spec = EpisodeSpec(model="WEDGE01", seed=2, policy="optimal", moves="all", verify="none")
    rec = run_episode(spec, library=lib, policy=pol)
    assert rec.outcome == "recognized" and rec.correct, rec
    assert rec.move_set == "all" and "probe" in rec.move_kinds
    searched = [d for d in pol.decisions if len(d.candidates) > 1]
    assert searched and all({c.move.kind for c in d.candidates} >= {"probe", "face"} for d in searched)
