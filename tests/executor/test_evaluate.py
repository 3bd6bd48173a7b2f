"""Evaluation (outside the executor): coplanar faces are told apart by where the touched points lie."""

import numpy as np

from haptic.executor.evaluate import EvaluationTolerances, score_face
from haptic.geometry import load_library
from haptic.matching.components import DataFace

LIB = load_library()


def test_score_face_picks_the_coplanar_face_holding_the_points():
    # BOX01N's faces 4 (x in [0.065, 0.1]) and 8 (x in [0, 0.035]) both lie in z = 0.06 with normal +z
    poly = LIB["BOX01N"]
    rot, trans = np.eye(3), np.array([0.3, -0.1, 0.5])
    for face, xs in ((8, (0.005, 0.02, 0.03)), (4, (0.07, 0.08, 0.095))):
        pts = np.array([[x, y, 0.06] for x in xs for y in (0.02, 0.06)]) + trans
        c = DataFace(0, np.array([0.0, 0.0, 1.0]), pts, 0.01, 0.001)
        s = score_face(c, poly, rot, trans, EvaluationTolerances())
        assert s.true_id == face
        assert s.angle_deg < 1e-6 and s.position_mm < 1e-6
