"""The pad's rise above the object before a probe (:func:`haptic.executor.physics_probe.rise`) gets round what holds
it back: an arm whose posture pulls the pad off a straight rise (a joint near its limit), and a face leaning over the
pad. Ground truth is read here, by the test (to put the hand where the episodes left it), never by the executor."""

from __future__ import annotations

import numpy as np

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import build_episode
from haptic.executor.physics_probe import rise
from haptic.sim.scene import PAD_RADIUS
from tests.executor.test_finger_probe import LEANING
from tests.test_episode_physics import _sized_corpus

SPEED, LAG = 0.15, 0.012
"""The probes' rise: its speed [m/s] and the pad's lag that stops it [m]."""

HELD_BACK = np.array([-0.017, 0.691, 0.501, 1.559, 0.374, -1.503])
"""The arm's posture where HEXPRISM01's episode at seed 3 left it after a failed vertex move (its pad 17 mm above the
highest contact, nothing touching): commanded straight up, the pad ran 3 cm sideways and the probe that followed
failed, "transfer to the probe's line: blocked"."""


def _started(model: str, seed: int, models: str | None = None):
    ep = build_episode(EpisodeSpec(model=model, seed=seed, executor="physics", verify="none", models=models))
    assert ep.executor.start().ok
    return ep


def _hold(ep, q: np.ndarray) -> None:
    ep.executor.robot.hold_posture(q)
    for _ in range(400):
        ep.executor.toucher.tick("free")


def test_a_rise_held_back_by_the_arms_posture_gets_up():
    ep = _started("HEXPRISM01", 3)
    t = ep.executor.toucher
    t.move_free(t.tip + np.array([0.0, 0.0, 0.03]))
    _hold(ep, HELD_BACK)
    z = float(t.tip[2]) + 0.025
    plain = t.move_guarded(np.array([t.tip[0], t.tip[1], z]), SPEED, max_lag=LAG)
    assert plain.event == "blocked" and t.link_touch() is None  # the posture, not a touch, holds it back
    _hold(ep, HELD_BACK)
    pieces = []
    res = rise(t, z, SPEED, LAG, pieces)
    assert res.ok and res.event == "done", res.event
    assert abs(float(t.tip[2]) - z) < 0.003


def test_a_rise_under_a_face_leaning_over_the_finger_steps_out_and_gets_up(tmp_path):
    # trapezohedron_05 of the sized corpus, seed 1: a face leaning under 35.5°. The finger, pointing down, comes in
    # level toward it 30 mm above the table until something touches (its medial link, under the face), as the
    # formula corpus's antiprism_08 left it before a probe by the thumb ("rising above the object: contact"); straight
    # up it meets the face again
    ep = _started("trapezohedron_05", 1, _sized_corpus(tmp_path))
    t = ep.executor.toucher
    poly, pose = ep.true_model, ep.world_from_model
    n = pose.rotate(poly.face_normals[LEANING])
    out = n * np.array([1.0, 1.0, 0.0])
    out /= np.linalg.norm(out)
    up = np.array([0.0, 0.0, 1.0]) - n[2] * n
    up /= np.linalg.norm(up)
    middle = pose.apply(poly.vertices[list(poly.faces[LEANING])]).mean(axis=0)
    on_face = middle + (ep.config.table_z + 0.03 - middle[2]) / up[2] * up
    corners = pose.apply(poly.vertices)
    outside = on_face + (float(((corners - on_face) @ out).max()) + PAD_RADIUS + 0.01) * out
    top = float(corners[:, 2].max()) + 0.03

    def under_the_face():
        t.move_free(t.tip + 0.004 * (t.normal if t.normal is not None else np.array([0.0, 0.0, 1.0])))
        for w in (np.array([t.tip[0], t.tip[1], top]), np.array([outside[0], outside[1], top]), outside):
            assert t.move_free(w).ok
        met = t.move_guarded(on_face, 0.05, max_lag=0.004)
        assert met.event in ("contact", "blocked")

    under_the_face()
    plain = t.move_guarded(np.array([t.tip[0], t.tip[1], top]), SPEED, max_lag=LAG)
    assert plain.event != "done"  # the face leans over the finger
    under_the_face()
    pieces = []
    res = rise(t, top, SPEED, LAG, pieces)
    assert res.ok and res.event == "done", res.event
    assert abs(float(t.tip[2]) - top) < 0.003
