"""The table as a workspace prior: moves the hypotheses predict to run into it are not offered, and pose classes
that would not rest on it are set aside -- only when a table is configured (the geometric setting has none)."""

from dataclasses import replace

import numpy as np

from haptic.executor.geometric import GeometricExecutor
from haptic.geometry import SE3, load_library
from haptic.matching.components import DataFace, SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import CostModel, FaceMove, SensorState
from haptic.planning.table import (
    MADE,
    OVERHANG,
    TABLE,
    hand_trace,
    move_outlook,
    rests_on_table,
    table_conflict,
    table_safe_moves,
)

LIB = load_library()
TABLE_Z = 0.35


def _on_a_side_face():
    """BOX01 resting on the table (its bottom at ``TABLE_Z``), the sensor on a vertical face, and the true
    hypothesis."""
    box = LIB["BOX01"]
    pose = SE3(np.eye(3), np.array([0.5, 0.0, TABLE_Z]))  # model z = 0 is the bottom face
    for seed in range(50):
        ex = GeometricExecutor(box, pose, noise=SensorNoise().scaled(0.0), rng=np.random.default_rng(seed),
                               costs=CostModel())  # fmt: skip
        res = ex.start()
        face = res.components[0]
        if abs(face.normal[2]) < 1e-6:
            truth = {d: m for d, (k, m) in ex.truth.items() if k == "face"}
            h = Hypothesis(box.name, box, pose, truth, {}, {})
            return h, res.state, {c.id: c for c in res.components}
    raise AssertionError("no start on a side face")


def test_a_face_move_down_to_the_table_is_predicted_and_not_offered():
    h, state, comps = _on_a_side_face()
    config = PlannerConfig(table_z=TABLE_Z)
    down, up = FaceMove(np.array([0.0, 0.0, -1.0])), FaceMove(np.array([0.0, 0.0, 1.0]))
    assert table_conflict(h, down, state, comps, config) == 1.0
    assert table_conflict(h, up, state, comps, config) == 0.0
    assert table_safe_moves([down, up], [h], state, comps, config) == [up]
    # without a table (the geometric setting) nothing is predicted or filtered
    assert table_conflict(h, down, state, comps, PlannerConfig()) == 0.0
    assert table_safe_moves([down, up], [h], state, comps, PlannerConfig()) == [down, up]


def test_a_pose_through_or_above_the_table_does_not_rest_on_it():
    box = LIB["BOX01"]
    config = PlannerConfig(table_z=TABLE_Z)
    on = SE3(np.eye(3), np.array([0.5, 0.0, TABLE_Z]))
    assert rests_on_table(box, on, config)
    assert not rests_on_table(box, SE3(np.eye(3), on.translation - [0, 0, 0.02]), config)
    assert not rests_on_table(box, SE3(np.eye(3), on.translation + [0, 0, 0.02]), config)
    assert rests_on_table(box, SE3(np.eye(3), on.translation - [0, 0, 0.02]), replace(config, table_z=None))


def test_a_face_move_heading_down_beside_the_table_is_predicted_to_go_on_level_to_the_side_edge():
    # The hand's slide heading down a side face stops within the pad's reach of the table and goes on nearly level
    # toward the side it headed (level_heading); the planner predicts that edge, not a stop at the table.
    h, state, comps = _on_a_side_face()
    config = PlannerConfig(table_z=TABLE_Z)
    n = comps[state.face].normal
    side = np.cross(n, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    steep = FaceMove(np.cos(np.deg2rad(60.0)) * side - np.sin(np.deg2rad(60.0)) * np.array([0.0, 0.0, 1.0]))
    why, reach, _ = move_outlook(h, steep, state, comps, config)
    assert why == MADE, why
    tr = hand_trace(h, steep, state, config)
    edge = h.world_from_model.rotate(h.poly.edge_directions[tr.hit.edge])
    assert abs(edge[2]) > 0.99  # the upright edge at the side, not the one along the table
    assert reach == tr.hit.distance > np.linalg.norm(tr.hit.point - h.model_from_world.apply(state.position)) - 1e-9
    assert table_conflict(h, steep, state, comps, config) == 0.0
    # straight down the face there is no side to go to: still a stop at the table
    assert move_outlook(h, FaceMove(np.array([0.0, 0.0, -1.0])), state, comps, config)[0] == TABLE


def test_a_face_move_onto_the_floor_of_an_overhung_slot_is_predicted_to_stop():
    # BOX01N stood on an end (seed 1 of the seed library): its slot runs level across a side, 30 mm tall, its upper
    # wall over its lower one. A face move up the side below the slot crosses onto the lower wall, which faces up,
    # but the finger pointing down meets the upper wall before its pad strokes there (the hand: "the finger's
    # index_medial met the object", then "stroke on the next face failed: blocked", 8 times in one episode).
    box = LIB["BOX01N"]
    pose = SE3(np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]]), np.array([0.5, 0.0, TABLE_Z]))
    below = next(f for f in range(box.n_faces) if box.face_normals[f][2] > 0.99
                 and box.vertices[list(box.faces[f])][:, 0].max() < 0.04)  # fmt: skip
    start = pose.apply(np.array([0.015, 0.04, 0.06]))
    n = pose.rotate(box.face_normals[below])
    comps = {0: DataFace(0, n, np.array([start, start + [0.0, 0.01, 0.0]]), 0.01, 1e-3)}
    state = SensorState(position=start, face=0)
    h = Hypothesis(box.name, box, pose, {0: below}, {}, {})
    config = PlannerConfig(table_z=TABLE_Z, max_undercut=np.deg2rad(31.0))
    up = FaceMove(np.array([0.0, 0.0, 1.0]))
    assert move_outlook(h, up, state, comps, config)[0] == OVERHANG
    assert table_conflict(h, up, state, comps, config) == 1.0
    # the same move on the box without a slot steps onto its top: made
    plain = LIB["BOX01"]
    top = next(f for f in range(plain.n_faces) if plain.face_normals[f][2] > 0.99)
    h = Hypothesis(plain.name, plain, pose, {0: top}, {}, {})
    assert move_outlook(h, up, state, comps, config)[0] == MADE
