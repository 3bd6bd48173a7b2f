"""A probe eliminates no posed hypothesis while the data fix a position too weakly for the matcher to test probe data
against posed leaves (``haptic.matching.free_space.MIN_SPAN``): predicting otherwise, the planner chose probe after
probe at a re-identified L-block's three pose classes, each a miss that eliminated nothing, to the episode's
budget."""

import numpy as np

from haptic.geometry import SE3, load_library
from haptic.matching.components import DataFace, SensorNoise
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.move_scores import Context, predict_probe_moves, weak_probes
from haptic.planning.moves import SensorState
from haptic.planning.probe_lines import ProbeConfig, candidate_probes

POLY = load_library()["LBLOCK01"]


def _eliminations(components: dict) -> int:
    rng = np.random.default_rng(4)
    pose = SE3.random(rng, 0.0)
    shifted = SE3(pose.rotation, pose.translation + np.array([0.03, 0.0, 0.0]))
    hyps = [Hypothesis("LBLOCK01", POLY, t, {}, {}, {}) for t in (pose, shifted)]
    moves = candidate_probes(hyps, ProbeConfig(max_candidates=24))
    ctx = Context(hyps, SensorState(np.zeros(3), 0), components, SensorNoise())
    return sum(int(p.eliminates().sum()) for p in weak_probes(ctx, predict_probe_moves(ctx, moves)))


def test_a_probe_eliminates_nothing_while_the_data_fix_no_position():
    one_face = {0: DataFace(0, np.array([0.0, 0.0, 1.0]), np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0]]), 0.01, 6e-4)}
    assert _eliminations(one_face) == 0


def test_a_probe_eliminates_where_the_data_fix_a_position():
    corner = {i: DataFace(i, n, np.array([0.01 * n]), 0.01, 6e-4) for i, n in enumerate(np.eye(3))}
    assert _eliminations(corner) > 0
