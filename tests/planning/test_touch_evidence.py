"""Touched points as evidence: a face move that cannot step onto its next face still tells how far the face
reaches, and the episode sets aside pose classes that leave touched points off their surface."""

import numpy as np

from haptic.episode.perception import fits_touches
from haptic.geometry import SE3, load_library
from haptic.matching.recognition import PoseClass
from haptic.planning.config import PlannerConfig
from haptic.planning.move_scores import eliminates, refusal
from haptic.planning.moves import FaceMove
from haptic.planning.predict import Prediction

LIB = load_library()


def _prediction(edge, table, reach):
    n = len(edge)
    outcomes = np.column_stack([edge, np.zeros(n), np.zeros(n)])
    return Prediction(FaceMove(np.array([1.0, 0.0, 0.0])), outcomes, np.array([0.002, 0.02, 0.02]),
                      np.ones(n), np.full(n, 0.02), np.asarray(table, float), np.asarray(reach, float))


def test_a_trace_failing_past_its_edge_rules_out_only_shorter_faces():
    # hypotheses 0 and 2 predict the face to reach 68 and 92 mm and the next face out of reach; 1 reaches 57
    pred = _prediction([0.068, 0.057, 0.092], table=[1, 0, 1], reach=[0.068, 0.057, 0.092])
    on, off = PlannerConfig(table_z=0.0, touch_evidence=True), PlannerConfig(table_z=0.0)
    d = eliminates(pred, on)
    assert d[0].tolist() == [False, True, False]  # 0's trace passes 1's edge, stops before 2's
    assert d[2].tolist() == [True, True, False]
    assert d[1].tolist() == [True, False, True]  # 1's move succeeds: every attribute counts
    assert refusal(pred, on) == 0.0
    assert np.isclose(refusal(pred, off), 2 / 3)
    assert eliminates(pred, off).tolist() == [[False, True, True], [True, False, True], [True, True, False]]


def test_a_trace_stopped_by_the_table_tells_as_far_as_it_went():
    # in hypothesis 2 the slide runs down to the table after 40 mm: far enough to pass 1's edge only
    pred = _prediction([0.068, 0.030, 0.092], table=[0, 0, 1], reach=[0.068, 0.030, 0.040])
    on = PlannerConfig(table_z=0.0, touch_evidence=True)
    assert eliminates(pred, on)[2].tolist() == [False, True, False]
    assert refusal(pred, on) == 0.0
    short = _prediction([0.068, 0.030, 0.092], table=[0, 0, 1], reach=[0.068, 0.030, 0.003])
    assert np.isclose(refusal(short, on), 1 / 3)  # stopped at once: it tells nothing


def test_touches_off_a_class_surface_set_it_aside():
    box, slotted = LIB["BOX01"], LIB["BOX01N"]
    pose = SE3(np.eye(3), np.array([0.1, 0.2, 0.0]))
    # points along the top face's middle, across where BOX01N has its slot (x 35-65 mm, 20 deep)
    xs = np.linspace(0.01, 0.09, 41)
    touched = pose.apply(np.column_stack([xs, np.full_like(xs, 0.04), np.full_like(xs, 0.06)]))
    noisy = touched + np.random.default_rng(0).normal(0.0, 0.0002, touched.shape)
    up = np.tile([0.0, 0.0, 1.0], (len(xs), 1))
    cfg = PlannerConfig()
    assert fits_touches(PoseClass(box, (0,), pose), (noisy, up), cfg)
    assert not fits_touches(PoseClass(slotted, (0,), pose), (noisy, up), cfg)


def test_a_touch_just_past_an_edge_is_off_the_face_however_near_the_surface():
    # down BOX01's side face to 6 mm below where BOX01N's slot cuts it: within 6 mm of BOX01N's surface (the
    # slot's ceiling), but on no face of BOX01N facing that way
    box, slotted = LIB["BOX01"], LIB["BOX01N"]
    flip = SE3(np.diag([1.0, -1.0, -1.0]), np.array([0.0, 0.0, 0.06]))  # slot against the table, z 0-20 mm
    zs = np.linspace(0.05, 0.014, 37)
    side = flip.apply(np.column_stack([np.full_like(zs, 0.05), np.zeros_like(zs), 0.06 - zs]))
    normal = np.tile(flip.rotate(np.array([0.0, -1.0, 0.0])), (len(zs), 1))
    cfg = PlannerConfig()
    assert fits_touches(PoseClass(box, (0,), flip), (side, normal), cfg)
    assert not fits_touches(PoseClass(slotted, (0,), flip), (side, normal), cfg)
    assert fits_touches(PoseClass(slotted, (0,), flip), (side[:-3], normal[:-3]), cfg)  # to 3 mm past: one stray
