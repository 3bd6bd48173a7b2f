"""The free-space probe on the simulated hand: a line aimed at a face of an object placed by the test hits it,
with the sensed point on the true face plane and the normal within their bounds; a line aimed past the object
misses and reports its path free. Ground truth is read here, by the test, never by the executor."""

from __future__ import annotations

import numpy as np
import pytest

from haptic.executor.physics import PhysicsExecutor
from haptic.geometry import SE3, load_library
from haptic.geometry.raycast import depth_samples
from haptic.matching.components import DataFace, SensorNoise
from haptic.planning.handpath import HandStart
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import ProbeMove
from haptic.planning.probe_prediction import predict_probes
from haptic.sim import RobotInterface, SimulatedSensorNoise, Simulation, compose_scene, random_object_pose
from haptic.sim.scene import PAD_RADIUS, TABLE_TOP_Z, scene_object_from_polyhedron


@pytest.fixture(scope="module")
def probed():
    poly = load_library()["BOX01"]
    obj = scene_object_from_polyhedron(poly)
    pose = random_object_pose(obj, np.random.default_rng(4))
    sim = Simulation(compose_scene(obj, pose), noise=SimulatedSensorNoise.from_notes(), seed=4)
    ex = PhysicsExecutor(RobotInterface(sim), rng=np.random.default_rng(4))
    first = ex.start()
    assert first.ok, first.info
    truth = SE3.from_matrix(sim.ground_truth().world_from_object)
    normals = truth.rotate(poly.face_normals)
    # a side face (horizontal normal) facing away from the robot's base, approached head-on at mid-height
    side = [f for f in range(poly.n_faces) if abs(normals[f, 2]) < 0.1]
    f = max(side, key=lambda k: normals[k, 0])
    n = normals[f]
    verts = truth.apply(poly.vertices[list(poly.faces[f])])
    target = verts.mean(axis=0)
    target[2] = max(target[2], TABLE_TOP_Z + PAD_RADIUS + 0.008)
    before_hit = (first.state, list(ex.components))
    hit = ex.execute(ProbeMove(target + 0.05 * n, -n, 0.08))
    # the same direction, shifted sideways past the object's extent
    across = np.cross(n, [0.0, 0.0, 1.0])
    width = float(np.ptp(truth.apply(poly.vertices) @ across))
    miss_move = ProbeMove(target + 0.05 * n + (width + 0.03) * across, -n, 0.10)
    state_before = hit.state
    ex.before = (before_hit, (hit.state, list(ex.components)))  # for the cost predictions
    miss = ex.execute(miss_move)
    return poly, truth, f, hit, state_before, miss, ex


def _predicted_cost(ex, poly, truth, state, components, move) -> tuple[bool, float]:
    """The planner's predicted outcome and cost of ``move`` on the hand, from the data before it (the true
    pose as the one hypothesis: the test may read it)."""
    face = next(c for c in components if c.id == state.face)
    assert isinstance(face, DataFace)
    contacts = np.concatenate([np.atleast_2d(c.points) for c in components if isinstance(c, DataFace)])
    hand = HandStart.at(state.position, face.normal, contacts, PAD_RADIUS)
    hyp = Hypothesis("BOX01", poly, truth, {}, {}, {})
    (pred,) = predict_probes([hyp], [move], state.position, components, SensorNoise(), ex.costs, hand)
    return bool(pred.hit[0]), float(pred.costs[0])


def test_the_planner_predicts_the_hands_probe_cost(probed):
    """The prediction follows the hand's path up and over the object (haptic.planning.handpath), a hit's normal
    stroke included: within a unit of the cost the executor reports (a straight transfer would fall short by
    the climb over the object, several units)."""
    poly, truth, _, hit, _, miss, ex = probed
    for result, (state, comps) in zip((hit, miss), ex.before, strict=True):
        assert result.ok, result.reason
        would_hit, cost = _predicted_cost(ex, poly, truth, state, comps, result.move)
        assert would_hit == bool(result.components)
        assert cost == pytest.approx(result.cost, abs=1.0), (result.move, cost, result.cost)
        straight = float(np.linalg.norm(np.asarray(result.move.start) - state.position))
        assert result.cost > ex.costs.probe_move(straight) + 1.0  # the path rule matters here


def test_a_probe_at_a_face_hits_it_within_the_bounds(probed):
    poly, truth, f, hit, _, _, ex = probed
    assert hit.ok, hit.reason
    assert hit.move.kind == "probe"
    (face,) = hit.components
    assert face.kind == "face" and face.adjacent == ()
    n_true = truth.rotate(poly.face_normals[f])
    d_true = float(n_true @ truth.apply(poly.vertices[poly.faces[f][0]]))
    off = np.abs(face.points @ n_true - d_true)
    assert off.max() <= face.position_bound, (off.max(), face.position_bound)
    err = np.arccos(np.clip(face.normal @ n_true, -1.0, 1.0))
    assert err <= face.normal_bound, (np.degrees(err), np.degrees(face.normal_bound))
    assert hit.state.face == face.id
    # the approach's path up to the contact is free of the object, and ends next to the face
    (seg,) = hit.free_space
    inv = truth.inverse()
    _, depth = depth_samples(poly, inv.apply(seg.start), inv.rotate(seg.direction), seg.length)
    assert len(depth) == 0 or depth.max() <= seg.position_bound
    out = float(n_true @ seg.end) - d_true  # how far outside the face the free path ends
    assert -seg.position_bound <= out < 0.005, out
    assert hit.cost == pytest.approx(ex.costs.probe_move(hit.distance) + ex.costs.c_n)


def test_a_probe_past_the_object_misses_and_returns_to_the_face(probed):
    poly, truth, _, hit, state_before, miss, _ = probed
    assert miss.ok, miss.reason
    assert miss.components == () and miss.info["contact"] is None
    (seg,) = miss.free_space
    assert seg.length == pytest.approx(miss.move.length, abs=0.002)
    inv = truth.inverse()
    _, depth = depth_samples(poly, inv.apply(seg.start), inv.rotate(seg.direction), seg.length)
    assert len(depth) == 0
    # the sensor is back on the face the probe left, as the state says
    assert miss.state.face == state_before.face and miss.info["returned"]
    assert miss.distance > 2 * seg.length


def test_a_transfer_the_hands_reach_cuts_short_still_probes():
    """Over an object as tall as the hand's reach over the region allows, the transfer's clearance above the
    highest contact is cut short at that reach instead of failing the probe (a 150 mm solid standing 160 mm tall:
    every probe its verification asked for failed); where the reach leaves the pad less than
    ``ProbeSettings.min_clearance`` over the object, the probe fails, saying so."""
    from dataclasses import replace

    from haptic.executor.physics_probe import SETTINGS, _highest_contact

    poly = load_library()["BOX01"]
    obj = scene_object_from_polyhedron(poly)
    pose = random_object_pose(obj, np.random.default_rng(4))
    sim = Simulation(compose_scene(obj, pose), noise=SimulatedSensorNoise.from_notes(), seed=4)
    ex = PhysicsExecutor(RobotInterface(sim), rng=np.random.default_rng(4))
    assert ex.start().ok
    truth = SE3.from_matrix(sim.ground_truth().world_from_object)
    normals = truth.rotate(poly.face_normals)
    f = max((k for k in range(poly.n_faces) if abs(normals[k, 2]) < 0.1), key=lambda k: normals[k, 0])
    n = normals[f]
    target = truth.apply(poly.vertices[list(poly.faces[f])]).mean(axis=0)
    target[2] = max(target[2], TABLE_TOP_Z + PAD_RADIUS + 0.008)
    move = ProbeMove(target + 0.05 * n, -n, 0.08)
    over = _highest_contact(ex) + PAD_RADIUS - TABLE_TOP_Z  # the pad's centre just clear of the highest contact
    assert float(move.start[2]) - TABLE_TOP_Z < over
    ex.settings = replace(ex.settings, max_approach_height=over + 0.5 * (SETTINGS.clearance + SETTINGS.min_clearance))
    hit = ex.execute(move)
    assert hit.ok and hit.components, hit.reason
    ex.settings = replace(ex.settings, max_approach_height=over + 0.5 * SETTINGS.min_clearance)
    low = ex.execute(move)
    assert not low.ok and "leaves the pad no way over the object" in low.reason
