"""The table on a small object: a face move's slide goes on over an edge too shallow for the pad to feel, and what
the table lets it do is judged where it ends; an edge move sets off only where the pad can touch a face of the edge
next to it off the table; a slide down into a concave corner is judged where the pad meets the next face; a level
face low beside the table counts in reach; a step onto a face the pad cannot stroke is predicted to stop."""

from dataclasses import replace

import numpy as np
import pytest

from haptic.geometry import SE3
from haptic.geometry.shapes import convex_hull, extrusion_xz, l_bracket
from haptic.matching.components import DataEdge, DataFace
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis, trace_in
from haptic.planning.moves import EdgeMove, FaceMove, SensorState
from haptic.planning.reach import TRACE_ROOM, reachable
from haptic.planning.table import (
    MADE,
    NARROW,
    TABLE,
    data_table_conflict,
    move_outlook,
    over_shallow,
    pad_fits,
    slide_end_clearance,
)

CFG = PlannerConfig(table_z=0.0, pad_radius=0.012, table_clearance=0.004)


def _roof():
    """A block 40 mm long, 20 mm wide, resting on the table, its top two faces sloping down along +x, 20° then 27°
    (a convex edge turning 7° between them, at x = 20 mm, 12.7 mm high), the lower one ending 2.5 mm above the
    table; the sensor on the upper one at x = 5 mm, and the true hypothesis."""
    x_mid, h3 = 0.02, 0.02
    h2 = h3 - x_mid * np.tan(np.deg2rad(20.0))
    h1 = h2 - 0.02 * np.tan(np.deg2rad(27.0))
    profile = [(0.0, 0.0), (0.04, 0.0), (0.04, h1), (x_mid, h2), (0.0, h3)]
    poly = convex_hull([(x, y, z) for x, z in profile for y in (0.0, 0.02)], name="roof")
    n_up = np.array([np.sin(np.deg2rad(20.0)), 0.0, np.cos(np.deg2rad(20.0))])
    upper = int(np.argmax(poly.face_normals @ n_up))
    at = np.array([0.005, 0.01, h3 - 0.005 * np.tan(np.deg2rad(20.0))])
    comps = {0: DataFace(0, n_up, np.array([at, at + [0.002, 0.0, -0.0007]]), 0.01, 1e-3)}
    h = Hypothesis("roof", poly, SE3(np.eye(3), np.zeros(3)), {0: upper}, {}, {})
    return h, SensorState(position=at, face=0), comps


def test_a_slide_over_an_edge_too_shallow_to_feel_is_judged_where_it_ends():
    """Straight across the 7° edge the pad steps onto the lower face 10 mm above the table's clearance, made; the
    hand does not feel that edge, slides on down the lower face and meets the table's clearance before its far edge
    (augmented_sphenocorona of the public polyhedra at 30 mm, seed 1: two face moves so predicted made failed)."""
    h, state, comps = _roof()
    move = FaceMove(np.array([1.0, 0.0, 0.0]))
    tr = trace_in(h, move, state)
    assert move_outlook(h, move, state, comps, CFG)[0] == MADE  # every edge felt (no felt_edge)
    felt = replace(CFG, felt_edge=np.deg2rad(10.0))
    beyond = over_shallow(h, tr, felt)
    assert beyond is not tr and beyond.face == tr.hit.next_face and np.isclose(beyond.hit.point[0], 0.04)
    why, reach, _ = move_outlook(h, move, state, comps, felt)
    assert why == TABLE and np.isclose(reach, tr.hit.distance)  # it touches all of the face it set off on
    # an edge turning more than the pad feels stops the slide there, as before
    assert over_shallow(h, tr, replace(CFG, felt_edge=np.deg2rad(5.0))) is tr
    assert move_outlook(h, move, state, comps, replace(CFG, felt_edge=np.deg2rad(5.0)))[0] == MADE


def _edge_alone(height: float):
    """An edge along x at ``height`` above the table, reported alone from a face sloping up from it at 30° (its
    outward normal leaning 30° toward -y), the sensor on the face next to it."""
    n = np.array([0.0, -np.sin(np.deg2rad(30.0)), np.cos(np.deg2rad(30.0))])
    w = np.array([0.0, np.cos(np.deg2rad(30.0)), np.sin(np.deg2rad(30.0))])  # into the face, up the slope
    p = np.array([0.0, 0.0, height])
    face = DataFace(0, n, np.array([p + 0.006 * w, p + 0.01 * w + [0.01, 0.0, 0.0]]), 0.01, 1e-3)
    edge = DataEdge(1, np.array([1.0, 0.0, 0.0]), p, 0.012, 0.01, 1e-3, 1e-3, adjacent=(0,),
                    side_points=((0, p + [0.006, 0.0, 0.0] + 0.002 * w),))  # fmt: skip
    return {0: face, 1: edge}, SensorState(position=p + 0.002 * w, face=0, edge=1)


def test_an_edge_move_is_refused_where_the_pad_cannot_touch_a_face_next_to_the_edge_off_the_table():
    """The hand sets off along an edge touching a face of it 4 mm in from it: 2 mm above the table, on a face
    sloping 30°, the pad's lowest point there is 0.4 mm above the table (its limit 2, the planner's 4), and the move
    fails at once (elongated_triangular_bipyramid of the public polyhedra at 30 mm, seed 1: an edge reported alone,
    the roll over it stopped by the table, and both moves along it failed so). 6 mm above the table it has room."""
    hand = replace(CFG, edge_reentry=0.004)
    comps, state = _edge_alone(0.002)
    assert data_table_conflict(EdgeMove(1), state, comps, hand)
    assert data_table_conflict(EdgeMove(-1), state, comps, hand)
    comps, state = _edge_alone(0.006)
    assert not data_table_conflict(EdgeMove(1), state, comps, hand)
    # without a table, or without the hand's way back to the edge, nothing is refused
    comps, state = _edge_alone(0.002)
    assert not data_table_conflict(EdgeMove(1), state, comps, replace(hand, table_z=None))
    assert not data_table_conflict(EdgeMove(1), state, comps, CFG)


def test_the_hand_world_gives_the_planner_the_executors_way_back_to_an_edge():
    """The planner judges an edge move's return with the physics executor's own distance in from the edge."""
    pytest.importorskip("mujoco")
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import build_episode
    from haptic.executor.physics import PhysicsSettings

    episode = build_episode(EpisodeSpec(model="BOX01", seed=1, executor="physics"))
    assert episode.config.edge_reentry == PhysicsSettings().edge_reentry


def _bracket():
    """An L bracket standing on its foot (40 mm long, 8 mm thick; the upright leg 60 mm tall, 30 mm wide), its
    bottom on the table, and its upright leg's inner face (facing +x, at x = 8 mm)."""
    poly = l_bracket(0.040, 0.060, 0.008, 0.030, name="bracket")
    inner = next(f for f in range(poly.n_faces) if poly.face_normals[f][0] > 0.99
                 and poly.vertices[list(poly.faces[f])][:, 0].max() < 0.009)  # fmt: skip
    return poly, SE3(np.eye(3), np.zeros(3)), inner


def test_a_slide_down_into_a_concave_corner_is_judged_where_the_pad_meets_the_next_face():
    """Sliding down the bracket's upright leg, the pad meets the foot's top first, its centre a radius from both
    faces: its lowest point there 8 mm above the table, not 4 mm under it as at the edge on the leg alone. The move
    is made (part_lbracket of scripts/make_parts.py, seed 1: such a move predicted stopped by the table, the two
    poses it would tell apart were left)."""
    poly, pose, inner = _bracket()
    at = np.array([0.008, 0.015, 0.040])
    n = np.array([1.0, 0.0, 0.0])
    comps = {0: DataFace(0, n, np.array([at, at + [0.0, 0.002, 0.002]]), 0.01, 1e-3)}
    h = Hypothesis("bracket", poly, pose, {0: inner}, {}, {})
    state, down = SensorState(position=at, face=0), FaceMove(np.array([0.0, 0.0, -1.0]))
    tr = trace_in(h, down, state)
    assert poly.edge_convexity[tr.hit.edge] < 0
    assert slide_end_clearance(h, tr, CFG) == pytest.approx(0.008)
    assert move_outlook(h, down, state, comps, CFG)[0] == MADE


def test_a_level_face_low_beside_the_table_counts_in_reach_to_tell_poses_apart():
    """The foot's top, 8 mm above the table, is touched from above (a trace across it stays that high): its points
    clear of the upright leg count in reach; a face rising from the table is out of reach below the trace's room."""
    poly, pose, inner = _bracket()
    pts, nrm = reachable(poly, pose, CFG)
    foot = (nrm[:, 2] > 0.99) & (np.abs(pts[:, 2] - 0.008) < 1e-9)
    assert foot.any() and pts[foot, 0].min() >= 0.008 + CFG.pad_radius - 1e-3
    side = np.abs(nrm[:, 2]) < 1e-9
    assert side.any() and pts[side, 2].min() >= CFG.table_clearance + TRACE_ROOM


def test_a_step_onto_a_face_the_pad_touches_nowhere_alone_is_predicted_to_stop():
    """A small stepped block (scripts/make_parts.py's part_small_step: 30 mm long, its upper part 18 mm long and
    15 mm high, the step 8 mm high): the 7 mm riser between them is touched nowhere by the 12 mm pad without it
    touching the step's top too, and a face move across the upper top onto it is predicted to stop there; the upper
    top and every face of a convex solid fit the pad."""
    outline = [(0.0, 0.0), (0.030, 0.0), (0.030, 0.008), (0.018, 0.008), (0.018, 0.015), (0.0, 0.015)]
    poly = extrusion_xz(outline, 0.020, name="step")
    riser = next(f for f in range(poly.n_faces) if poly.face_normals[f][0] > 0.99
                 and poly.vertices[list(poly.faces[f])][:, 0].max() < 0.019)  # fmt: skip
    tread = next(f for f in range(poly.n_faces) if poly.face_normals[f][2] > 0.99
                 and poly.vertices[list(poly.faces[f])][:, 2].max() < 0.009)  # fmt: skip
    top = next(f for f in range(poly.n_faces) if poly.face_normals[f][2] > 0.99
               and poly.vertices[list(poly.faces[f])][:, 2].min() > 0.014)  # fmt: skip
    assert not pad_fits(poly, riser, CFG)
    assert not pad_fits(poly, tread, CFG)  # 12 mm long beside the riser: the pad clear of it only 1.6 mm from the end
    assert pad_fits(poly, top, CFG)
    hull, _, _ = _roof()
    assert all(pad_fits(hull.poly, f, CFG) for f in range(hull.poly.n_faces))
    # a channel's floor as wide as the pad (part_uchannel: 24 mm between walls 16 mm tall) leaves it 0.6 mm to move
    channel = [(0.0, 0.0), (0.060, 0.0), (0.060, 0.030), (0.042, 0.030), (0.042, 0.014), (0.018, 0.014),
               (0.018, 0.030), (0.0, 0.030)]  # fmt: skip
    u = extrusion_xz(channel, 0.035, name="channel")
    floor = next(f for f in range(u.n_faces) if u.face_normals[f][2] > 0.99
                 and u.vertices[list(u.faces[f])][:, 2].max() < 0.015)  # fmt: skip
    assert not pad_fits(u, floor, CFG)
    assert pad_fits(extrusion_xz([(x + 0.006 * (x > 0.03), z) for x, z in channel], 0.035), floor, CFG)  # 36 mm

    at = np.array([0.008, 0.010, 0.015])
    comps = {0: DataFace(0, np.array([0.0, 0.0, 1.0]), np.array([at, at + [0.002, 0.0, 0.0]]), 0.01, 1e-3)}
    h = Hypothesis("step", poly, SE3(np.eye(3), np.zeros(3)), {0: top}, {}, {})
    move = FaceMove(np.array([1.0, 0.0, 0.0]))
    assert move_outlook(h, move, SensorState(position=at, face=0), comps, CFG)[0] == NARROW


def _channel(width: float):
    """A U channel 60 mm by 30 mm in x and z, its slot ``width`` wide and 16 mm deep in the middle of its top,
    extruded 35 mm along y (part_uchannel of scripts/make_parts.py at 24 mm), and its slot's two walls."""
    a, b = 0.030 - width / 2, 0.030 + width / 2
    outline = [(0.0, 0.0), (0.060, 0.0), (0.060, 0.030), (b, 0.030), (b, 0.014), (a, 0.014), (a, 0.030), (0.0, 0.030)]
    u = extrusion_xz(outline, 0.035, name="channel")
    walls = [f for f in range(u.n_faces) if abs(u.face_normals[f][0]) > 0.99
             and 0.001 < u.vertices[list(u.faces[f])][:, 0].mean() < 0.059]  # fmt: skip
    return u, walls


def test_the_walls_of_a_slot_as_wide_as_the_pad_do_not_fit_it():
    """A slot 24 mm wide, the pad's diameter: the pad pressing on one wall touches the other (part_uchannel, seed 2:
    moves into it failed 12 times in 67 moves), so neither wall fits; 2 mm wider, both do."""
    u, walls = _channel(0.024)
    assert len(walls) == 2 and not any(pad_fits(u, f, CFG) for f in walls)
    wide, walls = _channel(0.026)
    assert len(walls) == 2 and all(pad_fits(wide, f, CFG) for f in walls)
    # nor does the verification count the walls' points in reach (standing on its base, the slot open above)
    for poly, touched in ((u, False), (wide, True)):
        pts, nrm = reachable(poly, SE3(np.eye(3), np.zeros(3)), CFG)
        in_slot = (np.abs(nrm[:, 0]) > 0.99) & (pts[:, 0] > 0.001) & (pts[:, 0] < 0.059)
        assert in_slot.any() == touched


def _tblock():
    """A T block (part_tblock: a stem 15 mm wide and 28 mm tall under a bar 49 mm wide and 12 mm thick), extruded
    30 mm, lying on its side -- the outline's face (at y = 0, normal -y) up, the extrusion down to the table --, its
    pose and that top face."""
    outline = [(0.0, 0.0), (0.015, 0.0), (0.015, 0.028), (0.032, 0.028), (0.032, 0.040), (-0.017, 0.040),
               (-0.017, 0.028), (0.0, 0.028)]  # fmt: skip
    poly = extrusion_xz(outline, 0.030, name="tblock")
    lie = SE3(np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]), np.array([0.0, 0.0, 0.030]))
    top = next(f for f in range(poly.n_faces) if poly.face_normals[f][1] < -0.99)
    return poly, lie, top


def test_a_crossing_under_an_overhang_is_predicted_to_stop_where_the_pad_would_jam():
    """A T block (part_tblock: a stem 15 mm wide and 28 mm tall under a bar 49 mm wide and 12 mm thick), extruded
    30 mm, lying on its side: a face move across its top (the T's outline) onto the stem's side 4 mm under the bar
    puts the pad in the corner under the bar, and is predicted to stop (on the hand it failed there, "the pad reached
    the rim of another edge"); the same move 14 mm under the bar is made. The stem's side fits the pad as a face."""
    poly, lie, top = _tblock()
    side = next(f for f in range(poly.n_faces) if poly.face_normals[f][0] > 0.99
                and poly.vertices[list(poly.faces[f])][:, 0].max() < 0.016)  # fmt: skip
    assert pad_fits(poly, side, CFG)
    h = Hypothesis("tblock", poly, lie, {0: top}, {}, {})
    outlooks = []
    for z in (0.024, 0.014):
        at = lie.apply(np.array([0.005, 0.0, z]))
        comps = {0: DataFace(0, np.array([0.0, 0.0, 1.0]), np.array([at, at + [0.002, 0.0, 0.0]]), 0.01, 1e-3)}
        outlooks.append(move_outlook(h, FaceMove(np.array([1.0, 0.0, 0.0])), SensorState(position=at, face=0),
                                     comps, CFG)[0])  # fmt: skip
    assert outlooks == [NARROW, MADE]


def test_the_verification_takes_no_step_onto_a_face_too_narrow_for_the_pad():
    """With touched points as evidence the planner counts a face move predicted to stop as telling how far its face
    reaches; the verification, which measures edges and vertices, counts one that steps onto a face too narrow for
    the pad as refused (part_tblock, seed 2: five such moves of its verification failed). Its risk is 1 where the
    planner's is 0, and it is offered only when nothing else is."""
    from haptic.matching.components import SensorNoise
    from haptic.planning.move_scores import refusal
    from haptic.planning.predict import candidate_moves, predict_moves
    from haptic.planning.verify import _moves

    poly, lie, top = _tblock()
    h = Hypothesis("tblock", poly, lie, {0: top}, {}, {})
    at = lie.apply(np.array([0.005, 0.0, 0.024]))
    comps = {0: DataFace(0, np.array([0.0, 0.0, 1.0]), np.array([at, at + [0.002, 0.0, 0.0]]), 0.01, 1e-3)}
    state = SensorState(position=at, face=0)
    cfg = replace(CFG, touch_evidence=True)
    moves = candidate_moves(state, comps, cfg)
    narrow = [m for m in moves if move_outlook(h, m, state, comps, cfg)[0] == NARROW]
    assert narrow
    preds = predict_moves([h], narrow, state, comps, SensorNoise(), cfg)
    assert any(refusal(p, cfg) == 0.0 for p in preds)  # the planner's: its trace tells the face
    offered = [m for m, _, _ in _moves(h, state, comps, SensorNoise(), cfg, ())]
    assert offered and not any(move_outlook(h, m, state, comps, cfg)[0] == NARROW for m in offered)
