"""Probes planned for the simulated hand (haptic.planning.handpath and the pad's checks in
haptic.planning.probe_prediction and haptic.planning.finger_clearance):
the predicted path and its cost, and the lines on which the pad or the finger would touch the object otherwise
than the line-cast predicts. The BOX01N cases are the lines that failed on the hand in the physics episode
BOX01N seed 1 (``scripts/physics_episodes.py --objects BOX01N --poses 1 --moves all``), at that episode's
resting pose."""

from __future__ import annotations

import numpy as np
import pytest

from haptic.geometry import SE3, load_library
from haptic.geometry.se3 import quat_to_matrix
from haptic.matching.components import SensorNoise
from haptic.planning.finger_clearance import finger_clear
from haptic.planning.handpath import HandStart, foot_near_boundary, over_the_top, pad_touches_first, probe_distances
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import CostModel, ProbeMove
from haptic.planning.probe_prediction import predict_probes

PAD = 0.0118
UNDERCUT = np.deg2rad(20.0)
LIB = load_library()
# BOX01N at rest in episode seed 1: the slot lies on its side, its floor facing up at mid-height and its ceiling
# an overhang facing down
BOX01N_POSE = SE3(quat_to_matrix(np.array([0.603677588, 0.368202892, -0.603677588, 0.368202892])),
                  np.array([0.612514294, -0.027594684, 0.35]))  # fmt: skip


def _line(start, u, length) -> ProbeMove:
    u = np.asarray(u, dtype=float)
    return ProbeMove(np.asarray(start, dtype=float), u / np.linalg.norm(u), length)


def _box() -> Hypothesis:
    return Hypothesis("BOX01", LIB["BOX01"], SE3.identity(), {}, {}, {})


def test_the_path_goes_up_and_over_and_its_length_is_the_distance():
    tip, n = np.array([0.0, 0.0, 0.10]), np.array([0.0, 0.0, 1.0])
    start, u, length = np.array([0.3, 0.0, 0.05]), np.array([-1.0, 0.0, 0.0]), 0.1
    to_start, back = probe_distances(tip, n, 0.12, PAD, start[None], u[None], np.array([length]))
    z_safe = 0.12 + PAD + 0.03
    c0 = start - PAD * u
    lifted = tip + 0.008 * n
    way = np.vstack([tip, lifted, over_the_top(lifted, z_safe, c0)])
    assert np.allclose(way[2], [0.0, 0.0, z_safe]) and np.allclose(way[3], [c0[0], c0[1], z_safe])
    assert to_start[0] == pytest.approx(np.linalg.norm(np.diff(way, axis=0), axis=1).sum())
    c1 = c0 + length * u
    way_back = np.vstack([c1, over_the_top(c1, z_safe, lifted), tip])
    assert back[0] == pytest.approx(np.linalg.norm(np.diff(way_back, axis=0), axis=1).sum())
    assert to_start[0] > np.linalg.norm(start - tip) + 0.05  # the climb the straight transfer left out


def test_the_hands_prediction_adds_the_climb_and_the_stroke_a_point_sensors_does_not():
    box = _box()
    mid = LIB["BOX01"].vertices.mean(axis=0)
    top = LIB["BOX01"].vertices[:, 2].max()
    move = _line([0.2, mid[1], mid[2]], [-1.0, 0.0, 0.0], 0.3)
    here = np.array([mid[0], mid[1], top])
    costs = CostModel()
    (point,) = predict_probes([box], [move], here, [], SensorNoise(), costs)
    hand = HandStart.at(here, np.array([0.0, 0.0, 1.0]), here[None], PAD)
    (pad,) = predict_probes([box], [move], here, [], SensorNoise(), costs, hand)
    assert point.hit[0] and pad.hit[0] and point.fails is None and not pad.fails[0]
    to_start, _ = hand.distances(np.array([move.start]), np.array([move.direction]), np.array([move.length]))
    assert pad.costs[0] == pytest.approx(costs.probe_move(to_start[0] + pad.distance[0]) + costs.c_n)
    assert pad.costs[0] > point.costs[0] + 1.0


def test_a_pad_passing_an_edge_touches_it_first_and_one_head_on_does_not():
    poly = LIB["BOX01"]
    lo, hi = poly.vertices.min(axis=0), poly.vertices.max(axis=0)
    mid = 0.5 * (lo + hi)
    u = np.array([[-1.0, 0.0, 0.0]])
    head_on = np.array([[hi[0] + 0.05, mid[1], mid[2]]])
    # the leading point clears the side face by 5 mm: the pad's side (12 mm) brushes its edge
    beside = np.array([[hi[0] + 0.05, hi[1] + 0.005, mid[2]]])
    hit_at = np.array([0.05])
    assert not pad_touches_first(poly, head_on, u, hit_at, np.ones(1), PAD)[0]
    assert pad_touches_first(poly, beside, u, np.array([0.05 + hi[0] - lo[0]]), np.ones(1), PAD)[0]
    f = int(np.argmax(poly.face_normals @ np.array([1.0, 0.0, 0.0])))
    feet = np.array([[hi[0], mid[1], mid[2]], [hi[0], hi[1] - 0.004, mid[2]]])
    assert foot_near_boundary(poly, np.array([f, f]), feet).tolist() == [False, True]


@pytest.mark.parametrize(
    "start,u,length,why",
    [
        ([0.532, -0.122, 0.426], [0.39, 0.72, -0.58], 0.116, "the stroke's contact 6 mm from the slot wall's rim"),
        ([0.501, -0.106, 0.385], [0.6, 0.68, 0.42], 0.165, "the slot's ceiling, leaning under"),
        ([0.497, -0.104, 0.398], [0.86, 0.47, -0.19], 0.161, "the contact 1.5 mm from the slot wall's rim"),
    ],
)
def test_box01n_lines_that_failed_on_the_hand_are_predicted_to_fail(start, u, length, why):
    hyp = Hypothesis("BOX01N", LIB["BOX01N"], BOX01N_POSE, {}, {}, {})
    move = _line(start, u, length)
    here = np.array([0.6, 0.05, 0.45])
    hand = HandStart.at(here, np.array([0.0, 0.0, 1.0]), here[None], PAD, UNDERCUT)
    (pred,) = predict_probes([hyp], [move], here, [], SensorNoise(), CostModel(), hand)
    assert pred.hit[0], why
    assert pred.fails[0], why
    assert pred.risk() == 1.0 and not pred.eliminates().any()


def test_the_finger_slanting_into_box01ns_slot_is_blocked():
    """The line the hand was held back on ("approach along the line: blocked"): its pad fits the slot, but the
    finger's link, 8.5 mm thick, meets the slot's rim; a column of no thickness passes."""
    hyp = Hypothesis("BOX01N", LIB["BOX01N"], BOX01N_POSE, {}, {}, {})
    move = _line([0.516, -0.097, 0.423], [0.39, 0.72, -0.58], 0.111)
    assert not finger_clear([hyp], [move], PAD)[0]
    assert finger_clear([hyp], [move], PAD, finger_radius=0.0)[0]
