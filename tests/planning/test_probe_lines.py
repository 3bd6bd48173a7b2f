"""Probe candidates and predictions: the true hypothesis predicts what the line does at the true object."""

import numpy as np
import pytest

from haptic.executor.geometric import GeometricExecutor
from haptic.geometry import SE3, load_library
from haptic.matching.components import SensorNoise
from haptic.planning.efficiency import class_weights
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import CostModel
from haptic.planning.probe_lines import ProbeConfig, candidate_probes
from haptic.planning.probe_prediction import predict_probes

LIB = load_library()


def _hyp(name: str, pose: SE3) -> Hypothesis:
    return Hypothesis(model=name, poly=LIB[name], world_from_model=pose, faces={}, edges={}, vertices={})


@pytest.mark.parametrize("name", sorted(LIB))
def test_prediction_under_the_true_pose_is_the_geometric_outcome(name):
    """Candidates aimed at this object and at a look-alike elsewhere (so that some miss): the true
    hypothesis's hit, face and distance are what the executor finds casting the line at the true object."""
    rng = np.random.default_rng(11)
    truth = SE3.random(rng, 0.05)
    other = sorted(LIB)[(sorted(LIB).index(name) + 3) % len(LIB)]
    hyps = [_hyp(name, truth), _hyp(other, SE3.random(rng, 0.05))]
    moves = candidate_probes(hyps, ProbeConfig(max_candidates=24))
    assert len(moves) >= 8
    ex = GeometricExecutor(LIB[name], truth, SensorNoise().scaled(0.0), rng)
    ex.start()
    kinds = set()
    for mv in moves:
        (pred,) = predict_probes(hyps, [mv], ex.state.position, [], SensorNoise().scaled(0.0))
        res = ex.execute(mv)
        assert res.ok
        hit = len(res.components) == 1
        kinds.add(hit)
        assert bool(pred.hit[0]) == hit
        if hit:
            assert ex.truth[res.components[0].id] == ("face", int(pred.face[0]))
            assert pred.distance[0] == pytest.approx(res.info["contact"], abs=1e-9)
            assert pred.normal[0] == pytest.approx(res.components[0].normal, abs=1e-9)
        assert pred.costs[0] == pytest.approx(res.cost)
    assert kinds == {True, False}


def test_candidates_aim_at_surfaces_and_stay_clear_of_the_table():
    rng = np.random.default_rng(2)
    poly = LIB["LBLOCK01"]
    pose = SE3.random(rng, 0.0)
    table = float(pose.apply(poly.vertices)[:, 2].min())
    config = ProbeConfig(table_z=table)
    hyps = [_hyp("LBLOCK01", pose), _hyp("BOX01", SE3.random(rng, 0.01))]
    moves = candidate_probes(hyps, config)
    assert 8 <= len(moves) <= config.max_candidates
    preds = predict_probes(hyps, moves, np.zeros(3), [], SensorNoise())
    for mv, pred in zip(moves, preds, strict=True):
        assert min(mv.start[2], mv.end[2]) >= table + config.table_clearance - 1e-12
        assert mv.direction[2] <= config.max_climb
        assert pred.hit.any()  # aimed at some hypothesis's surface


def test_candidates_for_a_pad_keep_it_off_the_table_and_reachable_from_above():
    """With the hand's pad: its lowest point (up to a radius below the line) clears the table, the pad centre at
    the start and the column above it lie outside the sphere holding every hypothesis by the radius, and no
    face leaning under past the limit is aimed at -- while the point sensor's candidates include such lines."""
    from haptic.planning.probe_lines import _region

    rng = np.random.default_rng(2)
    poly = LIB["LBLOCK01"]
    pose = SE3.random(rng, 0.0)
    table = float(pose.apply(poly.vertices)[:, 2].min())
    hyps = [_hyp("LBLOCK01", pose), _hyp("PYR01", SE3.random(rng, 0.01))]
    r, lean = 0.012, np.deg2rad(30.0)
    point = candidate_probes(hyps, ProbeConfig(table_z=table, max_candidates=1000))
    config = ProbeConfig(table_z=table, pad_radius=r, max_undercut=lean, max_candidates=1000)
    moves = candidate_probes(hyps, config)
    assert 8 <= len(moves) < len(point)
    centre, hold = _region(hyps)
    for mv in moves:
        u = mv.direction
        for p in (mv.start, mv.end):
            assert p[2] - r * u[2] - r >= table + config.table_clearance - 1e-9
        c0 = mv.start - r * u
        w = c0 - centre
        assert np.linalg.norm(w) >= hold + r
        assert w[2] >= 0.0 or np.hypot(w[0], w[1]) >= hold + r
    preds = predict_probes(hyps, moves, np.zeros(3), [], SensorNoise())
    for pred in preds:
        hit = pred.hit
        # the face a line was aimed at leans under by at most the limit, in some hypothesis that it hits
        assert (pred.normal[hit, 2] >= -np.sin(lean) - 1e-9).any()


def test_efficiency_ranks_probes_that_separate_hypotheses():
    """Two models at one pose: probes that tell them apart have positive efficiency; the same hypothesis twice
    cannot be told apart by any probe."""
    pose = SE3.identity()
    hyps = [_hyp("BOX01", pose), _hyp("LBLOCK01", pose)]
    moves = candidate_probes(hyps)
    preds = predict_probes(hyps, moves, np.array([0.0, 0.0, 0.3]), [], SensorNoise(), CostModel())
    w = class_weights([h.model for h in hyps])
    effs = np.array([p.score(w)[0] for p in preds])
    assert effs.max() > 0.0
    best = preds[int(np.argmax(effs))]
    assert best.eliminates().any()
    same = [_hyp("BOX01", pose), _hyp("BOX01", pose)]
    for p in predict_probes(same, candidate_probes(same), np.zeros(3), [], SensorNoise()):
        assert not p.eliminates().any()


def test_probe_cost_counts_free_space_travel():
    pose = SE3.identity()
    hyps = [_hyp("BOX01", pose)]
    mv = candidate_probes(hyps)[0]
    costs = CostModel(c_p=3.0, c_s=10.0)
    here = mv.start + np.array([0.0, 0.0, 0.1])
    (pred,) = predict_probes(hyps, [mv], here, [], SensorNoise(), costs)
    assert pred.hit[0]
    assert pred.costs[0] == pytest.approx(3.0 + 10.0 * (0.1 + pred.distance[0]))


def test_bench_probes_at_a_small_size():
    """scripts/bench_probes.py at a small size: at each decision point the best probe is carried out and
    matched, the true pose class survives, and the prediction under it is never above what the matcher
    eliminated by more than a class or two (it is an expectation; the matcher also has the tree's tests)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
    try:
        from bench_probes import run
    finally:
        sys.path.pop(0)
    rows = run(trials=3, seed=1, quiet=True)
    assert len(rows) == 3
    for r in rows:
        assert r["true_survived"]
        assert r["candidates"] >= 1 and r["probe_eff"] >= 0.0
        if r["predicted"] is not None and r["eliminated"] is not None:
            assert r["predicted"] <= r["eliminated"] + 2


def test_a_hypothesis_without_a_pose_is_refused_by_name():
    from haptic.errors import PlanningError

    hyps = [_hyp("BOX01", SE3.identity())]
    mv = candidate_probes(hyps)[0]
    unposed = Hypothesis(model="PYR01", poly=LIB["PYR01"], world_from_model=None, faces={}, edges={}, vertices={})
    assert candidate_probes([unposed]) == []
    with pytest.raises(PlanningError, match="PYR01.*no pose"):
        predict_probes([hyps[0], unposed], [mv], np.zeros(3), [], SensorNoise())


def test_the_finger_above_the_pad_must_clear_every_hypothesis():
    """A line running under a hypothesis's object (a ledge over the pad) is blocked for the finger above the pad,
    up to where that hypothesis is met; one running beside it, or stopping at its face, is clear."""
    from haptic.planning.finger_clearance import finger_clear
    from haptic.planning.moves import ProbeMove

    poly = LIB["BOX01"]
    lo, hi = poly.vertices.min(axis=0), poly.vertices.max(axis=0)
    pose = SE3.from_matrix(np.eye(4))
    hyps = [_hyp("BOX01", pose)]
    under = ProbeMove(np.array([lo[0] - 0.03, 0.5 * (lo[1] + hi[1]), lo[2] - 0.03]), np.array([1.0, 0.0, 0.0]), 0.2)
    beside = ProbeMove(np.array([lo[0] - 0.03, hi[1] + 0.03, lo[2] - 0.03]), np.array([1.0, 0.0, 0.0]), 0.2)
    at_face = ProbeMove(np.array([lo[0] - 0.03, 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])]),
                        np.array([1.0, 0.0, 0.0]), 0.2)  # fmt: skip
    assert finger_clear(hyps, [under, beside, at_face], 0.012).tolist() == [False, True, True]


def _aimed_every_line(h, targets, config):
    """:func:`aimed_probes` making every admissible line of every target before keeping the first of each (the
    form before a target's first line ended its directions)."""
    from haptic.planning.finger_clearance import finger_clear
    from haptic.planning.probe_lines import _hypothesis_balls, _probe_line, _region, fibonacci_directions

    t = h.world_from_model
    centre, radius = _region([h])
    big, balls = radius + config.standoff, _hypothesis_balls([h])
    dirs = fibonacci_directions(config.n_directions)
    lines = []
    for k, (point, f) in enumerate(targets):
        n = t.rotate(h.poly.face_normals[f])
        if config.max_undercut is not None and n[2] < -np.sin(config.max_undercut):
            continue
        near = dirs[dirs @ -n >= np.cos(config.max_incidence)]
        for u in (-n, *near[np.argsort(-(near @ -n))]):
            if config.table_z is not None and u[2] > config.max_climb:
                continue
            move = _probe_line(t.apply(point), u, centre, big, radius, balls, config)
            if move is not None:
                lines.append((move, k))
    if lines and config.pad_radius > 0.0 and config.table_z is not None:
        clear = finger_clear([h], [mv for mv, _ in lines], config.pad_radius)
        lines = [x for x, ok in zip(lines, clear, strict=True) if ok]
    out, seen = [], set()
    for mv, k in lines:
        if k not in seen:
            seen.add(k)
            out.append((mv, k))
    return out


def _bits(lines) -> list:
    return [(k, mv.start.tobytes(), mv.direction.tobytes(), mv.length) for mv, k in lines]


def test_aimed_probes_are_the_first_admissible_line_of_each_target():
    """:func:`aimed_probes` stops at a target's first admissible line where nothing sets lines aside afterwards, and
    makes them all with a pad over a table (the finger's clearance may drop the first): the same lines, to the bit,
    as making every line, on every seed model at random poses, aimed at each face's targets and at points beside
    its vertices, without a table, with a table, and with a pad over a table (where the finger's clearance sets some
    targets' first lines aside: stopping at the first there fails this test); and, with a filter and a limit, the
    first lines of those the filter keeps."""
    from haptic.planning.probe_lines import aimed_probes, face_targets

    rng = np.random.default_rng(8)
    configs = [ProbeConfig(), ProbeConfig(table_z=-0.05), ProbeConfig(table_z=-0.05, pad_radius=0.012,
                                                                      max_undercut=np.deg2rad(30.0))]  # fmt: skip
    for name in sorted(LIB):
        poly = LIB[name]
        for _ in range(3):
            h = _hyp(name, SE3.random(rng, 0.02))
            centres = face_targets(poly)
            targets = [(centres[f], f) for f in range(poly.n_faces)]
            targets += [(0.8 * poly.vertices[v] + 0.2 * centres[f], int(f)) for v in range(poly.n_vertices)
                        for f in poly.vertex_faces[v]]  # fmt: skip
            for config in configs:
                got, want = aimed_probes(h, targets, config), _aimed_every_line(h, targets, config)
                assert _bits(got) == _bits(want), (name, config)
                for most in (1, 2, 5):  # the first lines a filter keeps: the targets after them not aimed at

                    def keep(mv):
                        return mv.direction[2] < 0.3

                    got = aimed_probes(h, targets, config, keep=keep, most=most)
                    assert _bits(got) == _bits([x for x in want if keep(x[0])][:most]), (name, config, most)
