"""A face move that rolls over a convex edge onto a face leaning under, out of the pad's reach, reports the
edge alone: predicted per hypothesis, scored by the edge's distance and angle, and avoided near the edge's
ends where the pad would roll round the vertex."""

from dataclasses import replace

import numpy as np

from haptic.geometry import SE3, load_library
from haptic.matching.components import DataFace, SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.move_scores import Context, eliminates, fresh_moves
from haptic.planning.moves import FaceMove, SensorState
from haptic.planning.predict import predict

LIB = load_library()
CFG = PlannerConfig(table_z=0.0, max_undercut=np.deg2rad(30.0), touch_evidence=True)
# upside down, resting on the table: BOX01N's slot (x 35-65 mm) lies against it, 20 mm high; the model's face
# y = 0 faces world +y at y = 0.1
FLIP = SE3(np.diag([1.0, -1.0, -1.0]), np.array([0.2, 0.1, 0.06]))
DOWN = FaceMove(np.array([0.0, 0.0, -1.0]))


def _setup(x: float):
    points = np.array([[x, 0.1, 0.05], [x + 0.01, 0.1, 0.05]])
    comps = {0: DataFace(0, np.array([0.0, 1.0, 0.0]), points, 0.01, 1e-3)}
    state = SensorState(position=np.array([x, 0.1, 0.05]), face=0)
    hyps = []
    for name in ("BOX01N", "BOX01"):
        poly = LIB[name]
        face = int(np.argmax(poly.face_normals @ np.array([0.0, -1.0, 0.0])))
        hyps.append(Hypothesis(name, poly, FLIP, {0: face}, {}, {}))
    return hyps, state, comps


def test_down_the_side_over_the_slot_ends_at_its_edge():
    hyps, state, comps = _setup(0.25)  # over the slot's middle
    pred = predict(hyps, DOWN, state, comps, SensorNoise(), CFG)
    assert pred.edge_only.tolist() == [1.0, 0.0]  # BOX01N: the slot's edge 30 mm down, its ceiling out of reach
    assert pred.table.tolist() == [0.0, 1.0]  # BOX01: the slide runs down to the table
    assert np.isclose(pred.outcomes[0, 0], 0.03)
    d = eliminates(pred, CFG)
    assert d[0, 1]  # the edge alone rules BOX01 out
    # BOX01's trace stops 4 mm past where BOX01N's face ends: too few touches beyond it to rule BOX01N out
    assert np.isclose(pred.reach[1], 0.034) and not d[1, 0]


def test_near_the_slot_s_end_the_roll_would_go_round_the_vertex():
    hyps, state, comps = _setup(0.238)  # 3 mm from the slot's side
    pred = predict(hyps, DOWN, state, comps, SensorNoise(), CFG)
    assert pred.edge_only.tolist() == [0.0, 0.0]
    assert pred.table.tolist() == [1.0, 1.0]


def test_moves_toward_an_edge_that_failed_are_tried_last():
    hyps, state, comps = _setup(0.25)
    failed = FaceMove(np.array([0.0, 0.0, 1.0]))  # up to the top edge
    ctx = Context(hyps, state, comps, SensorNoise(), CFG, avoid=(failed,))
    fresh = fresh_moves(ctx)
    # 10 mm under the top edge, every move heading up (at 45°, 90°, 135°) crosses it: left out while the
    # five heading sideways or down remain
    assert len(fresh) == 5 and all(float(m.direction[2]) < 1e-9 for m in fresh)


def test_the_outlook_names_what_stops_a_move():
    from haptic.planning.table import EDGE_ONLY, MADE, TABLE, UNDERCUT, move_outlook, table_prediction

    hyps, state, comps = _setup(0.25)
    assert [move_outlook(h, DOWN, state, comps, CFG)[0] for h in hyps] == [EDGE_ONLY, TABLE]
    up = FaceMove(np.array([0.0, 0.0, 1.0]))  # onto the top face: the pad rolls over
    assert [move_outlook(h, up, state, comps, CFG)[0] for h in hyps] == [MADE, MADE]
    hyps, state, comps = _setup(0.238)  # near the slot's side: no room to roll over its edge alone
    assert move_outlook(hyps[0], DOWN, state, comps, CFG)[0] == UNDERCUT
    # table_conflict is 1 for exactly the outlooks that stop
    assert [table_prediction(h, DOWN, state, comps, CFG)[0] for h in hyps] == [1.0, 1.0]


def test_onto_a_face_the_table_hides_the_roll_gives_the_edge_alone():
    """A face move down an end of HEXPRISM01 lying on a side, toward the edge with a lower side face (leaning 30°
    under, its far edge on the table): the pad rolls over the edge and reaches the table's clearance before that
    face, and the hand reports the edge alone (HEXPRISM01 s1 and s3 under verification: predicted to run into the
    table, all went through)."""
    from haptic.planning.hypothesis import trace_in
    from haptic.planning.table import EDGE_ONLY, hand_trace, move_outlook, rolls_to_edge, table_prediction

    poly = LIB["HEXPRISM01"]
    rx = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # model y up, model z toward world -y
    pose = SE3(rx, np.array([0.3, 0.0, float(-(poly.vertices @ rx.T)[:, 2].min())]))
    cap = int(np.argmin(poly.face_normals[:, 2]))  # model z = 0: faces world +y
    low = int(np.argmax(poly.face_normals @ np.array([-0.87, -0.5, 0.0])))  # leans under in the world
    e = next(int(x) for x in poly.face_edges[cap] if low in (poly.edge_left_face[x], poly.edge_right_face[x]))
    n = poly.face_normals[cap]
    w = np.cross(n, poly.edge_directions[e])
    w = w if poly.edge_left_face[e] == cap else -w
    mid = poly.edge_points[e] + 0.5 * poly.edge_lengths[e] * poly.edge_directions[e]
    start_w = pose.apply(mid + 0.02 * w)
    comps = {0: DataFace(0, pose.rotate(n), np.array([start_w, start_w + 0.01 * pose.rotate(w)]), 0.01, 1e-3)}
    state = SensorState(position=start_w, face=0)
    h = Hypothesis("HEXPRISM01", poly, pose, {0: cap}, {}, {})
    move = FaceMove(pose.rotate(-w))
    cfg = PlannerConfig(table_z=0.0, max_undercut=np.deg2rad(35.0))
    assert move_outlook(h, move, state, comps, cfg)[0] == EDGE_ONLY
    table, reach, edge_only = table_prediction(h, move, state, comps, cfg)
    assert (table, edge_only) == (0.0, 1.0) and np.isclose(reach, 0.02)
    # with no room to roll before the table's clearance, the table stops the roll where the straight slide meets the
    # edge; the slide, heading 30 degrees off straight down, stops short of the edge there and goes on level to it,
    # meeting it higher up (level_leg), with room to roll
    higher = replace(cfg, table_clearance=0.012)
    straight = trace_in(h, move, state)
    assert not rolls_to_edge(h, straight, higher)
    levelled = hand_trace(h, move, state, higher)
    assert levelled.hit.edge == e and pose.apply(levelled.hit.point)[2] > pose.apply(straight.hit.point)[2] + 0.005
    assert move_outlook(h, move, state, comps, higher)[0] == EDGE_ONLY
