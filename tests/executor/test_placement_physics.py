"""Placements on the simulated hand: two fingertips placed by the reach solver close on two faces of an object
resting on the table, each pressing and stroking its own face; each finger's contacts give its own face component,
within its bounds of the true face; a finger that fails does not fail the other. Ground truth is read here, by the
test (to make the candidate placements and score what was measured), never by the executor."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import build_episode
from haptic.executor.placement import PlacementReach
from haptic.matching.components import DataFace, SensorNoise
from haptic.planning.efficiency import class_weights
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.move_scores import probe_config
from haptic.planning.moves import PlacementMove
from haptic.planning.placements import PlacementConfig, candidate_placements
from haptic.planning.probe_lines import candidate_probes
from haptic.planning.probe_prediction import predict_probes


def _placed(model: str, seed: int, spoil: bool = False):
    """The physics episode's world, the first candidate placement the reach test offers (the true pose the one
    hypothesis) and its result after the start, with the number of components before it. ``spoil``: the second
    finger's line turned to point away from the object and lengthened to 25 cm, farther than the finger can go."""
    ep = build_episode(EpisodeSpec(model=model, seed=seed, executor="physics", verify="none", fingers=2))
    poly, pose = ep.true_model, ep.world_from_model
    h = Hypothesis(model=model, poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
    lines = candidate_probes([h], probe_config(ep.config))
    centre = pose.apply(poly.centroid)
    preds = predict_probes([h], lines, centre, [], SensorNoise(), ep.config.costs)
    cands = candidate_placements(preds, class_weights([model]), 2, centre, ep.config.costs, config=PlacementConfig())
    reach = PlacementReach()
    move = next(m for m in (reach(c.move, [h]) for c in cands) if m is not None)
    if spoil:
        a, b = move.fingers
        move = replace(move, fingers=(a, replace(b, direction=-np.asarray(b.direction), length=0.25)))
    first = ep.executor.start()
    assert first.ok, first.reason
    before = len(ep.executor.components)
    return ep, move, ep.executor.execute(move), before


@pytest.fixture(scope="module")
def two_faces():
    return _placed("BOX01P", 2)


@pytest.fixture(scope="module")
def one_fails():
    return _placed("BOX01P", 2, spoil=True)


def _true_face(ep, face: DataFace) -> tuple[float, float]:
    """The angle [rad] and the mean distance [m] of ``face`` from the true face nearest in normal."""
    poly, pose = ep.true_model, ep.world_from_model
    normals = pose.rotate(poly.face_normals)
    f = int(np.argmax(normals @ face.normal))
    p0 = pose.apply(poly.vertices[poly.faces[f][0]])
    ang = float(np.arccos(np.clip(normals[f] @ face.normal, -1.0, 1.0)))
    return ang, float(np.abs((np.atleast_2d(face.points) - p0) @ normals[f]).mean())


def test_two_fingers_measure_two_faces_within_their_bounds(two_faces):
    ep, move, res, before = two_faces
    assert isinstance(res.move, PlacementMove) and res.ok, res.reason
    told = {i["finger"]: i for i in res.info["fingers"]}
    assert set(told) == {f.finger for f in move.fingers}
    assert all(i["status"] == "touched" for i in told.values()), told
    assert len(res.components) == 2 and len({c.id for c in res.components}) == 2
    assert {c.id for c in ep.executor.components[before:]} == {c.id for c in res.components}
    normals = [c.normal for c in res.components]
    assert float(normals[0] @ normals[1]) < np.cos(np.deg2rad(20.0))  # two faces, not one
    for face in res.components:
        ang, dist = _true_face(ep, face)
        assert ang <= face.normal_bound and dist <= face.position_bound, (np.rad2deg(ang), dist * 1000)
    assert len(res.free_space) == 2  # each finger's way to its contact is free
    assert res.cost == pytest.approx(ep.executor.costs.placement_move(res.distance, 2, 2))
    assert res.state.face in {c.id for c in res.components}  # the sensor rests on a face measured


def test_a_failed_finger_does_not_fail_the_other(one_fails):
    ep, _, res, _ = one_fails
    assert res.ok, res.reason
    statuses = {i["finger"]: i["status"] for i in res.info["fingers"]}
    touched = [i for i in res.info["fingers"] if i["status"] == "touched"]
    failed = [i for i in res.info["fingers"] if i["status"] not in ("touched", "missed")]
    assert len(touched) == 1 and len(failed) == 1, statuses
    assert failed[0]["finger"] == res.move.fingers[1].finger and failed[0]["reason"]  # why, in words
    (face,) = res.components
    assert face.id == touched[0]["component"]
    ang, dist = _true_face(ep, face)
    assert ang <= face.normal_bound and dist <= face.position_bound


def test_a_placement_is_costed_along_the_way_the_hand_went(two_faces):
    """The hand's way as it went: to the lines' starts (no shorter than the farthest pad's straight way from the
    path's start to its line's start, and than the planned path's farthest pad's way), the longest closing, and back
    to the face the sensor rests on; the cost is the placement's of their sum."""
    from haptic.executor.placement import pad_target

    ep, move, res, _ = two_faces
    way = res.info["travel"]
    assert set(way) == {"to", "closing", "back"} and all(v > 0.0 for v in way.values()), way
    assert res.distance == pytest.approx(sum(way.values()), abs=1e-3)
    assert way["to"] >= move.travel - 0.01  # the path's way, followed (the servo within a centimetre)
    starts = np.array([pad_target(f) for f in move.fingers])
    assert way["to"] >= float(np.linalg.norm(starts - move.home, axis=1).min())
    assert way["closing"] == pytest.approx(max(i["travel"] for i in res.info["fingers"]), abs=1e-3)
    assert res.cost == pytest.approx(ep.executor.costs.placement_move(res.distance, 2, 2))
