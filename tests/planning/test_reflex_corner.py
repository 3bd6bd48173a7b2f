"""Verification on the hand at a reflex corner: the vertex where a concave edge ends on a top face is measured
from the convex edge beside it, not by aiming into the corner (haptic.planning.verify.aimed_face_moves)."""

import numpy as np

from haptic.geometry import SE3, load_library
from haptic.matching.components import DataEdge, DataFace
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import EdgeMove, SensorState
from haptic.planning.search import simulate
from haptic.planning.table import _inward, table_conflict
from haptic.planning.tour import CONCAVE_STEP_OFF
from haptic.planning.verify import AIM_NEAR_VERTEX, aimed_face_moves

LIB = load_library()
TABLE_Z = 0.35
HAND = PlannerConfig(table_z=TABLE_Z, pad_radius=0.012, concave_end_block=0.2)
REFLEX, BELOW, WALL, TOP_EDGE, CONCAVE = 3, 9, 4, 10, 11
"""LBLOCK01's reflex corner: vertex 3 on the L-shaped face 0, the concave edge 11 down from it to vertex 9 between
the inner walls 4 and 5, and the convex edge 10 along the top of wall 4 (the test checks these)."""


def _in_the_corner(height: float):
    """LBLOCK01 upside down on the table (the L-shaped face 0 on top, as at seed 3 of the physics benchmark), the
    sensor on wall 4 against the concave edge ``height`` above the table: the true hypothesis, state, components."""
    poly = LIB["LBLOCK01"]
    assert poly.edge_convexity[CONCAVE] < 0 < poly.edge_convexity[TOP_EDGE]
    assert set(poly.edges[CONCAVE].tolist()) == {REFLEX, BELOW} and REFLEX in poly.edges[TOP_EDGE]
    pose = SE3(np.diag([1.0, -1.0, -1.0]), np.array([0.55, 0.05, TABLE_Z + 0.05]))
    n = pose.rotate(poly.face_normals[WALL])
    loop = poly.vertices[list(poly.faces[WALL])]
    face = DataFace(1, n, pose.apply(loop.mean(axis=0) + 0.3 * (loop - loop.mean(axis=0))), 1e-2, 1e-3)
    a, b = pose.apply(poly.vertices[BELOW]), pose.apply(poly.vertices[REFLEX])
    inner = 0.3 * (b - a)
    edge = DataEdge(2, (b - a) / np.linalg.norm(b - a), a + inner, float(np.linalg.norm(b - a - 2 * inner)), 1e-2,
                    1e-3, 1e-3)  # fmt: skip
    h = Hypothesis("LBLOCK01", poly, pose, {1: WALL}, {2: CONCAVE}, {})
    at = a + (height - a[2] + TABLE_Z) * edge.direction / edge.direction[2]
    state = SensorState(at + 0.001 * n, face=1, edge=2, edge_faces=(1,))
    return h, state, {1: face, 2: edge}


def test_a_reflex_corners_vertex_is_aimed_at_beside_the_corner_and_an_edge_move_reaches_it():
    """From low on the concave edge (its hidden top end refused to an edge move) and from near its top, the move
    aimed at the corner's vertex, started where the pad rests in the corner (its radius in from the edge), ends on the
    convex edge along the wall's top more than the pad's radius from the corner (nearer, the pad touches the wall
    across the corner and the move ends on the concave edge), and an edge move from there, not refused,
    measures the vertex."""
    for height in (0.01, 0.045):
        h, state, comps = _in_the_corner(height)
        inward = h.world_from_model.rotate(_inward(h.poly, CONCAVE, WALL))
        stepped = SensorState(state.position + (HAND.pad_radius + CONCAVE_STEP_OFF) * inward, face=state.face,
                              edge=state.edge, edge_faces=state.edge_faces)  # fmt: skip
        missing = (frozenset(), frozenset(), frozenset({REFLEX}))
        moves = aimed_face_moves(h, state, comps, missing, HAND)
        assert moves, height
        reached = False
        for m in moves:
            sim = simulate(h, m, stepped, comps, HAND)
            assert sim is not None
            h1, s1, c1 = sim
            assert h1.edges[s1.edge] == TOP_EDGE
            end = h.world_from_model.inverse().apply(s1.position)
            assert np.linalg.norm(end - h.poly.vertices[REFLEX]) > HAND.pad_radius + AIM_NEAR_VERTEX / 2
            for sense in (1, -1):
                sim2 = simulate(h1, EdgeMove(sense), s1, c1, HAND)
                if sim2 is not None and REFLEX in sim2[0].vertices.values():
                    assert table_conflict(h1, EdgeMove(sense), s1, c1, HAND) == 0.0
                    reached = True
        assert reached, height


def test_off_the_hand_the_corner_is_aimed_at_as_any_vertex():
    """Without ``concave_end_block`` (the geometric executor, which follows a concave edge to its end) the aimed
    moves are those of any vertex: none along the current edge, the others AIM_NEAR_VERTEX from it."""
    h, state, comps = _in_the_corner(0.045)
    missing = (frozenset(), frozenset(), frozenset({REFLEX}))
    assert [m.direction.tolist() for m in aimed_face_moves(h, state, comps, missing)] == [
        m.direction.tolist() for m in aimed_face_moves(h, state, comps, missing, PlannerConfig())]


def test_no_edge_or_vertex_move_starts_at_the_corners_vertex_on_the_hand():
    """The sensor at the corner's vertex 3 (the concave edge 11 ends there) on the convex edge 10: on the hand
    (``leave_concave_vertices`` False) an edge move away along edge 10 and a vertex move round the corner count as
    refused (the pad resting there touches wall 5); at the edge's other end, vertex 2, and off the hand, not."""
    from dataclasses import replace

    from haptic.planning.moves import VertexMove
    from haptic.planning.table import at_concave_vertex

    hand = replace(HAND, leave_concave_vertices=False)
    h, _, _ = _in_the_corner(0.02)
    poly, pose = h.poly, h.world_from_model
    a, b = (pose.apply(poly.vertices[v]) for v in poly.edges[TOP_EDGE])
    edge = DataEdge(2, (b - a) / np.linalg.norm(b - a), a, float(np.linalg.norm(b - a)), 1e-2, 1e-3, 1e-3)
    face = DataFace(1, pose.rotate(poly.face_normals[WALL]), np.array([a, b, 0.5 * (a + b)]), 1e-2, 1e-3)
    comps = {1: face, 2: edge}
    for v, refused in ((REFLEX, True), (int(poly.edges[TOP_EDGE][0] + poly.edges[TOP_EDGE][1]) - REFLEX, False)):
        hv = Hypothesis("LBLOCK01", poly, pose, {1: WALL}, {2: TOP_EDGE}, {5: v})
        at = SensorState(pose.apply(poly.vertices[v]), face=1, edge=2, vertex=5, edge_faces=(1,))
        assert at_concave_vertex(hv, at, hand) == refused and not at_concave_vertex(hv, at, HAND)
        away = 1 if int(poly.edges[TOP_EDGE][0]) == v else -1  # the data edge runs along the model edge
        for move in (EdgeMove(away), VertexMove(1)):
            assert (table_conflict(hv, move, at, comps, hand) == 1.0) == refused, (v, move)


def test_in_a_slot_the_move_out_of_the_corner_keeps_the_pad_off_the_far_wall():
    """BOX01N standing on an end face with its slot upright (seed 2 of the physics benchmark): 30 mm wide for the
    24 mm pad. From the slot's floor against one concave edge (its data point on the edge's line), the move aimed
    at the floor's top corners, the slot's reflex corners on the top face, is aimed from where the pad rests (its
    radius in from the edge): it heads up the floor, and the pad's centre on the way to the top edge keeps clear
    of the far wall. Aimed from the edge's line it heads diagonally into that wall."""
    poly = LIB["BOX01N"]
    floor, near_edge, far_wall, top_edge = 6, 17, 7, 4
    assert poly.edge_convexity[near_edge] < 0 < poly.edge_convexity[top_edge]
    assert {int(poly.edge_left_face[near_edge]), int(poly.edge_right_face[near_edge])} == {floor, 5}
    # model y (the slot's length) up, the face y = 0.08 on the table
    pose = SE3(np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
               np.array([0.55, 0.0, TABLE_Z + 0.08]))  # fmt: skip
    assert np.isclose(pose.apply(poly.vertices)[:, 2].min(), TABLE_Z)
    n = pose.rotate(poly.face_normals[floor])
    a, b = (pose.apply(poly.vertices[v]) for v in poly.edges[near_edge])
    lo, hi = (a, b) if a[2] < b[2] else (b, a)
    loop = poly.vertices[list(poly.faces[floor])]
    face = DataFace(1, n, pose.apply(loop.mean(axis=0) + 0.3 * (loop - loop.mean(axis=0))), 1e-2, 1e-3)
    edge = DataEdge(2, (hi - lo) / np.linalg.norm(hi - lo), lo, float(np.linalg.norm(hi - lo)), 1e-2, 1e-3, 1e-3)
    h = Hypothesis("BOX01N", poly, pose, {1: floor}, {2: near_edge}, {})
    on_line = lo + 0.03 * edge.direction  # 30 mm up from the table
    state = SensorState(on_line, face=1, edge=2, edge_faces=(1,))
    missing = (frozenset(), frozenset(), frozenset(int(v) for v in poly.edges[top_edge]))
    moves = aimed_face_moves(h, state, {1: face, 2: edge}, missing, HAND)
    assert moves
    inward = pose.rotate(_inward(poly, near_edge, floor))
    rest = on_line + HAND.pad_radius * inward
    wall_n, wall_p = pose.rotate(poly.face_normals[far_wall]), pose.apply(poly.vertices[poly.faces[far_wall][0]])
    top = pose.apply(poly.vertices[poly.edges[top_edge][0]])[2]
    for m in moves:
        assert m.direction[2] > 0
        travel = (top - rest[2]) / m.direction[2]
        path = rest + np.linspace(0.0, travel, 20)[:, None] * m.direction
        gap = (path - wall_p) @ wall_n  # the pad centre's distance from the far wall's plane
        assert gap.min() > HAND.pad_radius - 0.5e-3, (m.direction, gap.min())
