"""The table as a workspace prior: which moves would bring the fingertip pad onto it, and which poses rest on it.

The fingers point down and end in a pad of radius ``config.pad_radius``; the table top is at ``config.table_z``
(the robot's workspace, never the object). Each hypothesis predicts through its own pose whether a move runs
into the table (:func:`table_conflict`); the data alone say so for some moves whatever the model
(:func:`data_table_conflict`). Without a table (``config.table_z`` None, the geometric executor) nothing here
refuses a move or a pose.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from functools import lru_cache

import numpy as np

from haptic.geometry.distance import point_triangle_distance, surface_samples_on_faces
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.raycast import line_hits
from haptic.geometry.se3 import SE3
from haptic.geometry.tracing import FaceHit, circle_vertex, trace_face
from haptic.matching.components import DataComponent, DataEdge, DataFace
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import FaceTrace, Hypothesis, trace_in
from haptic.planning.moves import EdgeMove, FaceMove, Move, SensorState, VertexMove, start_state

EDGE_ROLL = np.deg2rad(12.0)
"""How far the pad's normal must turn over an edge, before it leans under past ``max_undercut``, for the
executor to measure the edge from the roll alone (its segmenter wants 10°): from a face leaning under
within this of the limit, a move ending at an edge onto a face out of reach tells nothing [rad]."""
EDGE_ONLY_CLEARANCE = 0.008
"""A face move ends at its edge with the next face out of reach, reporting the edge alone, only where it meets
the edge at least this far from both its ends: the pad rolls some 40° over it, its centre as far past the
edge's line as ``pad_radius · sin 40°``, and nearer an end it touches the faces round the vertex [m]."""
TABLE_STEP_ONTO = 0.003
"""How far onto the next face a face or vertex move strokes for its normal (for the table check) [m]."""
LEVEL_RISE = np.deg2rad(5.0)
"""A face move whose slide heading down comes within the pad's reach of the table goes on across the face at
this rise above the level, toward the side it was heading (clear of the table's limit it reached) [rad] ..."""
LEVEL_MIN_SLOPE = np.deg2rad(20.0)
"""... on a face sloping at least this much (nearer level it has no side to go on to) ... [rad]"""
LEVEL_MIN_HEADING = np.deg2rad(20.0)
"""... when the slide headed at least this much from straight down the face [rad]."""
_UP = np.array([0.0, 0.0, 1.0])
FINGER_ABOVE = 0.03
"""How far above the pad's centre a face of the object over it blocks the finger pointing down: its distal link
runs 26.7 mm from the pad's centre to the DIP joint, the medial link 38.4 mm on (``assets/mjcf/hand/README.md``).
On the seed library's verification, the floor of BOX01N's slot stood on an end, 18 mm under its upper wall, blocked
4 of 5 moves onto it (the medial link met the wall); the lower wall of FRAME01's hole stood on an end, 48 mm under
the upper one, 4 of 12 (a link meeting the rim tilts the hand away) [m]."""


def pad_height(point: np.ndarray, normal: np.ndarray, pad_radius: float, table_z: float) -> float:
    """Height above the table top (at ``table_z``) of the lowest point of a pad of radius ``pad_radius`` when it
    touches ``point`` of a surface of outward ``normal``, the fingers pointing down [m]."""
    return float(point[2] + pad_radius * normal[2] - pad_radius - table_z)


def pad_clearance(point: np.ndarray, normal: np.ndarray, config: PlannerConfig) -> float:
    """:func:`pad_height` with the planner's pad and table; +inf without a table."""
    if config.table_z is None:
        return float("inf")
    return pad_height(point, normal, config.pad_radius, config.table_z)


def level_heading(d: np.ndarray, n: np.ndarray) -> np.ndarray | None:
    """The heading a slide along ``d`` across a face of outward ``n`` (world frame) goes on along once the table
    stops it heading down: level, toward the side ``d`` heads, rising :data:`LEVEL_RISE`; None where the face is
    nearly level or ``d`` heads nearly straight down it (there is no side). The hand's rule, which the planner
    predicts with the same function."""
    side = np.cross(n, _UP)
    norm = float(np.linalg.norm(side))
    if norm < np.sin(LEVEL_MIN_SLOPE):
        return None
    side = side / norm
    across = float(side @ d) / max(float(np.linalg.norm(d)), 1e-12)
    if abs(across) < np.sin(LEVEL_MIN_HEADING):
        return None
    up = _UP - float(n[2]) * n
    up = up / float(np.linalg.norm(up))
    return np.copysign(np.cos(LEVEL_RISE), across) * side + np.sin(LEVEL_RISE) * up


def slide_end_clearance(h: Hypothesis, tr: FaceTrace, config: PlannerConfig) -> float:
    """The pad's clearance of the table (:func:`pad_clearance`) where face move trace ``tr`` of ``h`` meets its
    edge: on the face, at the edge; at a concave edge, in the corner, where the pad sliding down the face meets the
    next face first, its centre a radius from both planes (sliding down the upright leg of an L bracket standing on
    its foot, the pad meets the foot's top 10 mm above the table, its lowest point there, not 12 mm lower).
    +inf without a table."""
    poly, t, hit = h.poly, h.world_from_model, tr.hit
    n_f = poly.face_normals[tr.face]
    if config.table_z is not None and poly.edge_convexity[hit.edge] < 0:
        n_g = poly.face_normals[hit.next_face]
        k = 1.0 + float(n_f @ n_g)
        if k > 1e-6:
            centre = t.apply(hit.point + config.pad_radius * (n_f + n_g) / k)
            return float(centre[2] - config.pad_radius - config.table_z)
    return pad_clearance(t.apply(hit.point), t.rotate(n_f), config)


def level_leg(h: Hypothesis, tr: FaceTrace, config: PlannerConfig) -> tuple[bool, FaceTrace | None]:
    """Whether face move trace ``tr`` of ``h`` goes on level (:func:`level_heading`): its slide heads down and
    comes within ``config.table_clearance`` of the table before its edge, on a face with a side to go to; and
    then the trace the hand follows, from where the slide stopped along the level heading to the edge it meets
    (its distance the two legs' together; None when it meets a vertex). False, None without a table."""
    t = h.world_from_model
    if config.table_z is None or t is None:
        return False, None
    poly, hit, lim = h.poly, tr.hit, config.table_clearance
    n_m = poly.face_normals[tr.face]
    u_m = tr.direction - float(tr.direction @ n_m) * n_m
    norm = float(np.linalg.norm(u_m))
    if norm < 1e-9:
        return False, None
    u_m = u_m / norm
    n_w, u_w = t.rotate(n_m), t.rotate(u_m)
    if float(u_w[2]) >= 0.0 or slide_end_clearance(h, tr, config) >= lim:
        return False, None
    level = level_heading(u_w, n_w)
    if level is None:
        return False, None
    start = pad_clearance(t.apply(tr.start), n_w, config)
    s = float(np.clip((start - lim) / -float(u_w[2]), 0.0, hit.distance))
    at = tr.start + s * u_m
    lev_m = h.model_from_world.rotate(level)
    got = trace_face(poly, tr.face, at, lev_m)
    if got is None:
        return True, None
    return True, FaceTrace(tr.face, at, lev_m, FaceHit(got.edge, s + got.distance, got.point, got.next_face))


def hand_trace(
    h: Hypothesis, move: FaceMove, state: SensorState, config: PlannerConfig, tr: FaceTrace | None | bool = False
) -> FaceTrace | None:
    """Face move ``move`` traced in ``h``'s world as the hand follows it (``tr``: its :func:`trace_in`, when already
    computed): the straight trace, or where the table stops it heading down, its level leg (:func:`level_leg`);
    None when ``h`` cannot say. The straight trace without a table."""
    tr = trace_in(h, move, state) if tr is False else tr
    if tr is None or config.table_z is None:
        return tr
    levelled, leg = level_leg(h, tr, config)
    return leg if levelled else tr


SHALLOW_HOPS = 3
"""The most edges too shallow to feel (:attr:`PlannerConfig.felt_edge`) a slide is traced over [-]."""
SHALLOW_STEP = 1e-5
"""How far past an edge too shallow to feel the slide's trace on the next face starts [m]."""


def over_shallow(h: Hypothesis, tr: FaceTrace, config: PlannerConfig) -> FaceTrace | None:
    """Face move trace ``tr`` of ``h`` as the hand's slide goes on over convex edges too shallow to feel (their
    faces' normals within ``config.felt_edge``): the trace on the face past the last such edge, from where the slide
    crosses onto it to the edge it meets there, its direction the move's in that face's plane; ``tr`` itself when it
    meets an edge the pad feels (or without ``config.felt_edge``); None when the slide meets a vertex past one, or
    crosses more than :data:`SHALLOW_HOPS`. The hand does not stop there: on the public polyhedra at 30 mm
    (augmented_sphenocorona, seed 1), face moves predicted to roll over its 8.2° edge 15 mm above the table slid on
    to the next edge, 4 mm lower, and rolled into the table's clearance."""
    if config.felt_edge is None:
        return tr
    poly, cos = h.poly, float(np.cos(config.felt_edge))
    for _ in range(SHALLOW_HOPS + 1):
        hit = tr.hit
        turn = float(poly.face_normals[tr.face] @ poly.face_normals[hit.next_face])
        if poly.edge_convexity[hit.edge] <= 0 or turn < cos:
            return tr
        g = hit.next_face
        n = poly.face_normals[g]
        d = tr.direction - float(tr.direction @ n) * n
        norm = float(np.linalg.norm(d))
        if norm < 1e-9:
            return None
        d = d / norm
        got = trace_face(poly, g, hit.point + SHALLOW_STEP * d, d)
        if got is None:
            return None
        tr = FaceTrace(g, hit.point, d, FaceHit(got.edge, got.distance + SHALLOW_STEP, got.point, got.next_face))
    return None


def _inward(poly: Polyhedron, edge: int, face: int) -> np.ndarray:
    """Unit vector in ``face``'s plane, perpendicular to ``edge``, pointing into the face (model frame)."""
    w = np.cross(poly.face_normals[face], poly.edge_directions[edge])
    return w if poly.edge_left_face[edge] == face else -w


def circle_points(
    vertex: np.ndarray, u: np.ndarray, w: np.ndarray, radius: float, start: float, stop: float, step: float
) -> np.ndarray:
    """Points of the circle of a vertex move: ``vertex + radius (−cos θ u + sin θ w)`` for θ from ``start`` to
    ``stop`` (``u`` along the current edge toward the vertex, ``w`` into the crossed face), shape (K, 3)."""
    th = np.arange(start, stop + 1e-9, step) if stop > start else np.array([start])
    return vertex + radius * (-np.cos(th)[:, None] * u + np.sin(th)[:, None] * w)


VERTEX_START_ANGLE = np.deg2rad(25.0)
"""A vertex move's circle starts this far from the current edge (the physics executor's start) [rad]."""
SWEEP_STEP = np.deg2rad(2.0)
"""Spacing of the points of a vertex circle checked against the table [rad] (how far it can sweep) ..."""
CIRCLE_CHECK_STEP = np.deg2rad(3.0)
"""... and of those checked for a vertex move's admissibility under a hypothesis [rad]."""


def circle_sweep_off_table(
    vertex: np.ndarray,
    u: np.ndarray,
    w: np.ndarray,
    normal: np.ndarray,
    radius: float,
    table_z: float,
    pad_radius: float,
    clearance: float,
    start: float = VERTEX_START_ANGLE,
) -> float:
    """The angle the circle of a vertex move (:func:`circle_points` from ``start``) can sweep before the pad,
    touching the circle's face of outward ``normal``, comes closer than ``clearance`` to the table top (2π:
    never; 0: not even its start is that far from it) [rad]. The planner checks the circle from the data with
    its margin, the physics executor with its own limit."""
    pts = circle_points(vertex, u, w, radius, start, 2 * np.pi - start, SWEEP_STEP)
    low = [i for i, q in enumerate(pts) if pad_height(q, normal, pad_radius, table_z) < clearance]
    return float(low[0] * SWEEP_STEP) if low else 2 * np.pi


def table_conflict(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> float:
    """Whether hypothesis ``h`` predicts ``move`` to bring the pad onto the table (1.0), not (0.0), or cannot
    say (NaN): a face move sliding down to an edge within the pad's reach of the table or stepping onto a face
    the table hides; a vertex move whose circle, before it meets the next edge, would put the pad on the table,
    or whose next face the table hides; an edge move toward an end the hand cannot locate
    (:func:`edge_end_on_table`, :func:`hidden_concave_end`); an edge or vertex move from a vertex that ends a
    concave edge, where ``config.leave_concave_vertices`` is False (the hand: :func:`at_concave_vertex`). A
    workspace prior (``config.table_z``) with the hypothesis's own pose; 0.0 without a table. With
    ``config.max_undercut``, a vertex move stepping over a convex edge onto a face that leans under further than
    the pad reaches counts too (a face move doing so ends at the edge instead:
    :attr:`~haptic.planning.predict.Prediction.edge_only`)."""
    return table_prediction(h, move, state, components, config)[0]


MADE, EDGE_ONLY, TABLE, UNDERCUT, CONCAVE = "made", "edge only", "table", "undercut", "concave"
OVERHANG, NARROW = "overhang", "narrow"
"""What a hypothesis predicts of a move on the hand (:func:`move_outlook`): carried out; a face move ending at its
edge, the next face leaning under out of the pad's reach (a success that reports the edge alone); stopped by the
table (the pad would come onto it, or the next face is too close to it); stopped at a convex edge onto a face
leaning under further than the pad reaches; stopped at a concave edge's end or vertex the hand cannot tell; stopped
stepping onto a face the object overhangs, where the finger's links meet it (:func:`overhung`); stopped stepping
onto a face the pad touches nowhere without touching the object elsewhere (:func:`pad_fits`), or not where the move
steps onto it (:func:`crowded`)."""
STOPS = (TABLE, UNDERCUT, CONCAVE, OVERHANG, NARROW)
"""The outlooks of a move the hand is predicted not to carry out."""


MARGIN = 0.0005
"""Slack of the pad-clearance tests against the object (:func:`pad_fits`,
:func:`~haptic.planning.reach.touchable`) [m]."""
PAD_ROOM = 0.003
"""Room the pad needs on a face to stroke it (:func:`pad_fits`): some place on it from which it can move this far
across the face in every direction touching no other face [m]. A stroke's legs run a few millimetres; a wall 12 mm
tall above a step 7 mm deep (part_small_step of ``scripts/make_parts.py`` standing on its end) leaves the pad 2 mm
at its top, and face moves onto it failed 6 times of 7 on the hand ("the pad reached the rim of another edge"); the
floor of a channel 24 mm wide (part_uchannel's) leaves it 0.6 mm."""
PAD_GAP = 0.0005
"""Room :func:`pad_fits` asks between the pad and a face turned towards the one it strokes [m]. Where two
walls stand the pad's diameter apart (the slot of part_uchannel in ``scripts/make_parts.py``, 24 mm) the pad pressing
on one touches the other: at seed 2 moves into the slot failed 12 times in 67 moves ("the pad reached the rim of another
edge", "crossing the concave edge: limit", "could not reach the face next to the vertex"), the verification stalling
at its corners; with the walls out of the pad's reach the episode ends in 18 moves, naming those corners out of
reach."""
FIT_SPACING = 0.001
"""Spacing of the points :func:`pad_fits` tries on a face [m]."""


@lru_cache(maxsize=4096)
def _faces_the_pad_fits(poly: Polyhedron, radius: float) -> frozenset[int]:
    """:func:`pad_fits` for every face of ``poly`` at once (model frame: the pose does not enter)."""
    if poly.is_convex:  # the pad a radius off any face of a convex solid is a radius off all of it
        return frozenset(range(poly.n_faces))
    from scipy.spatial import cKDTree

    pts, faces = surface_samples_on_faces(poly, FIT_SPACING)
    tri = poly.vertices[poly.triangles]
    fits = set()
    for f in range(poly.n_faces):
        n = poly.face_normals[f]
        p_f = pts[faces == f]
        # the faces that can touch the pad on this one rise in front of its plane (across a convex edge they fall
        # away behind it)
        front = (poly.triangle_faces != f) & (((tri - p_f[0]) @ n).max(axis=1) > 1e-9)
        if not front.any():
            fits.add(f)
            continue
        centre = p_f + radius * n
        clear = np.ones(len(p_f), dtype=bool)
        for start in range(0, len(p_f), 2048):
            d = point_triangle_distance(centre[start : start + 2048], tri[front]).min(axis=1)
            clear[start : start + 2048] = d >= radius - MARGIN
        clear[clear] = clear_of_facing(poly, centre[clear], n, radius)
        if clear.all():
            fits.add(f)
        elif clear.any():
            room, _ = cKDTree(p_f[~clear]).query(p_f[clear])
            if float(room.max()) >= PAD_ROOM:
                fits.add(f)
    return frozenset(fits)


def clear_of_facing(poly: Polyhedron, centres: np.ndarray, normals: np.ndarray, radius: float) -> np.ndarray:
    """Whether the pad centred at each of ``centres`` (model frame), touching a face of outward normal ``normals``,
    clears every face turned towards that one (a slot's far wall) by :data:`PAD_GAP`; shape (P,) bool. A face
    beside it the pad need only not touch (within :data:`MARGIN`), which the callers test against the whole
    surface."""
    centres = np.atleast_2d(np.asarray(centres, dtype=float))
    out = np.ones(len(centres), dtype=bool)
    if poly.is_convex or not len(centres):  # a convex solid's far faces lie behind it
        return out
    normals = np.broadcast_to(np.asarray(normals, dtype=float), centres.shape)
    tri = poly.vertices[poly.triangles]
    tri_n = poly.face_normals[poly.triangle_faces]
    keys, group = np.unique(np.round(normals, 9), axis=0, return_inverse=True)  # a face's points share its normal
    for g, n in enumerate(keys):
        facing = tri_n @ n < -0.5
        if not facing.any():
            continue
        at = np.flatnonzero(group.ravel() == g)
        for start in range(0, len(at), 2048):
            idx = at[start : start + 2048]
            out[idx] = point_triangle_distance(centres[idx], tri[facing]).min(axis=1) >= radius + PAD_GAP
    return out


def pad_fits(poly: Polyhedron, face: int, config: PlannerConfig) -> bool:
    """Whether the pad (radius ``config.pad_radius``) can stroke face ``face`` of ``poly`` touching no other face:
    somewhere on it, its centre a radius off the face, no nearer the rest of the object, with :data:`PAD_ROOM` to
    move in every direction along the face. A face narrower than that between walls or above a step (the floor of a
    channel as wide as the pad, a wall above a step less deep than the pad's radius) the hand stepping onto it meets
    the rim of the face beyond (the stroke's first leg turns its normal), and the move fails."""
    return face in _faces_the_pad_fits(poly, float(config.pad_radius))


def table_prediction(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> tuple[float, float, float]:
    """:func:`table_conflict`; for a face move, how far its trace touches the face
    (:attr:`~haptic.planning.predict.Prediction.reach`) and whether it ends at its edge, the next face out of
    reach (:attr:`~haptic.planning.predict.Prediction.edge_only`); NaN, NaN for other moves."""
    if config.table_z is None:
        return 0.0, np.nan, np.nan
    why, reach, edge_only = move_outlook(h, move, state, components, config)
    return (np.nan if why is None else float(why in STOPS)), reach, edge_only


def move_outlook(
    h: Hypothesis, move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> tuple[str | None, float, float]:
    """What hypothesis ``h`` predicts of ``move`` on the hand, through its own pose: one of :data:`MADE`,
    :data:`EDGE_ONLY`, :data:`TABLE`, :data:`UNDERCUT`, :data:`CONCAVE` (None: it cannot say); for a face move, how
    far its trace touches the face and whether it ends at its edge (1.0, else 0.0; NaN, NaN for other moves). Without
    a table (``config.table_z`` None) every move it can say of is made."""
    if config.table_z is None:
        return MADE, np.nan, np.nan
    state = start_state(move, state)
    t = h.world_from_model
    if t is None:
        return None, np.nan, np.nan
    poly, lim = h.poly, config.table_clearance

    def leans_under(e_m: int, g_m: int) -> bool:
        """Whether the pad cannot roll over convex edge ``e_m`` onto ``g_m``: it leans under, out of reach."""
        if config.max_undercut is None or poly.edge_convexity[e_m] <= 0:
            return False
        return float(t.rotate(poly.face_normals[g_m])[2]) < -np.sin(config.max_undercut)

    def onto(e_m: int, g_m: int, at_m: np.ndarray) -> str:
        """Stepping over edge ``e_m`` onto face ``g_m`` at ``at_m``: made, or stopped by an undercut, a face too narrow
        for the pad, the table or an overhang."""
        if leans_under(e_m, g_m):
            return UNDERCUT
        if not pad_fits(poly, g_m, config):  # the pad steps onto the rim beyond first, the table or not
            return NARROW
        q_m = at_m + TABLE_STEP_ONTO * _inward(poly, e_m, g_m)
        if crowded(poly, e_m, g_m, q_m, config):  # the pad steps on next to a wall or under an overhang there
            return NARROW
        if pad_clearance(t.apply(q_m), t.rotate(poly.face_normals[g_m]), config) < lim:
            return TABLE
        return OVERHANG if overhung(h, q_m, g_m, config) else MADE

    if isinstance(move, FaceMove):
        tr = trace_in(h, move, state)
        if tr is None:
            return None, np.nan, np.nan
        levelled, leg = level_leg(h, tr, config)
        if levelled and leg is None:
            return None, np.nan, np.nan
        tr = leg if levelled else tr  # the table stops the slide heading down: it goes on level to another edge
        d_z = float(np.asarray(move.direction)[2])
        beyond = over_shallow(h, tr, config)
        if beyond is None:
            return None, np.nan, np.nan
        crossed, first = beyond is not tr, float(tr.hit.distance)
        if crossed:  # the slide goes on over an edge too shallow to feel, touching all of the face it set off on
            tr, levelled, d_z = beyond, False, float(t.rotate(beyond.direction)[2])
        hit = tr.hit
        n_w = t.rotate(poly.face_normals[tr.face])
        if not levelled and d_z < 0.0 and slide_end_clearance(h, tr, config) < lim:
            # the slide stops where the pad comes too close to the table
            if crossed:
                return TABLE, first, 0.0
            start = pad_clearance(t.apply(tr.start), n_w, config)
            return TABLE, float(np.clip((start - lim) / -d_z, 0.0, hit.distance)), 0.0
        if crossed:
            hit = replace(hit, distance=first)  # how far the trace touches the face the move sets off on
        if leans_under(hit.edge, hit.next_face):
            near_end = tr.clearance(poly) < EDGE_ONLY_CLEARANCE
            if near_end or float(n_w[2]) < -np.sin(config.max_undercut - EDGE_ROLL):
                return UNDERCUT, float(hit.distance), 0.0  # no room to roll over the edge alone: the move fails there
            return EDGE_ONLY, float(hit.distance), 1.0
        what = onto(hit.edge, hit.next_face, hit.point)
        if what == TABLE and rolls_to_edge(h, tr, config):
            return EDGE_ONLY, float(hit.distance), 1.0  # the roll gives the edge, the table hides the next face
        return what, float(hit.distance), 0.0
    if isinstance(move, EdgeMove):
        # refused toward an end where the pad on the ridge would meet the table first (a motion the table stops
        # locates no vertex), or toward a concave edge's end the hand cannot tell (config.concave_end_block)
        if edge_end_on_table(h, move, state, components, config):
            return TABLE, np.nan, np.nan
        if hidden_concave_end(h, move, state, components, config) or at_concave_vertex(h, state, config):
            return CONCAVE, np.nan, np.nan
        return MADE, np.nan, np.nan
    if isinstance(move, VertexMove):
        e_m = h.edges.get(state.edge) if state.edge is not None else None
        v_m = h.vertices.get(state.vertex) if state.vertex is not None else None
        a_m = h.faces.get(move.across_face)
        if e_m is None or v_m is None or a_m is None:
            return None, np.nan, np.nan
        if at_concave_vertex(h, state, config):
            return CONCAVE, np.nan, np.nan
        try:
            hit = circle_vertex(poly, v_m, e_m, a_m, config.vertex_radius)
        except ValueError:
            return None, np.nan, np.nan
        u = poly.edge_directions[e_m] * (1.0 if poly.edges[e_m, 1] == v_m else -1.0)
        pts = circle_points(poly.vertices[v_m], u, _inward(poly, e_m, a_m), config.vertex_radius,
                            VERTEX_START_ANGLE, hit.angle, CIRCLE_CHECK_STEP)  # fmt: skip
        n_w = t.rotate(poly.face_normals[a_m])
        if min(pad_clearance(q, n_w, config) for q in t.apply(pts)) < lim:
            return TABLE, np.nan, np.nan
        away = poly.edge_directions[hit.edge] * (1.0 if poly.edges[hit.edge, 0] == v_m else -1.0)
        at = poly.vertices[v_m] + config.vertex_radius * away
        return onto(hit.edge, hit.next_face, at), np.nan, np.nan
    raise TypeError(f"unknown move {move!r}")


def crowded(poly: Polyhedron, edge: int, face: int, at_m: np.ndarray, config: PlannerConfig) -> bool:
    """Whether the pad stepped over ``edge`` onto ``face`` of ``poly``, touching it at ``at_m`` (model frame), would
    dig into a face other than the edge's two there by more than :data:`PAD_ROOM`: a face the pad fits somewhere
    (:func:`pad_fits`) may still be crowded where a move steps onto it (part_tblock of ``scripts/make_parts.py``: a
    face move across the T's top crossing onto the stem's side 4 mm under the bar, the pad jammed in the corner under
    it and the move failed, "the pad reached the rim of another edge", 3 times in an episode). Less than that the
    pad may settle beside it: cad_slotted of the formula corpus, crossed onto a wall of its slot 10 mm above the floor
    (the pad 2.1 mm into the floor), measures the wall, and predicting such steps stopped cost that episode its
    confirmation; part_tblock's stem side crossed onto 10.4 mm under the bar (1.6 mm) failed. The depth alone does
    not tell the two apart, and the test takes the one that costs no confirmation. Over a convex edge only (into a
    concave corner the pad meets the next face at the corner, touching both), and not on a convex model, where the pad
    a radius off any face is a radius off all of it."""
    if poly.is_convex or poly.edge_convexity[edge] <= 0:  # into a concave corner the pad meets the next face there
        return False
    own = (int(poly.edge_left_face[edge]), int(poly.edge_right_face[edge]))
    rest = (poly.triangle_faces != own[0]) & (poly.triangle_faces != own[1])
    if not rest.any():
        return False
    centre = np.asarray(at_m, dtype=float) + config.pad_radius * poly.face_normals[face]
    d = point_triangle_distance(centre[None], poly.vertices[poly.triangles[rest]]).min()
    return bool(d < config.pad_radius - PAD_ROOM)


def overhung(h: Hypothesis, at_m: np.ndarray, face: int, config: PlannerConfig) -> bool:
    """Whether the pad of the fingers pointing down, touching face ``face`` of ``h`` at ``at_m`` (model frame), has
    another face of the object above its centre within :data:`FINGER_ABOVE`: the finger's links meet the object
    over it (BOX01N stood on an end: the pad on the floor of its slot, 30 mm under the slot's upper wall, cannot
    stroke the floor; its medial link meets the wall). Not checked on a convex model: the pad near an edge has none
    of the object above it but the face it touches where that leans under, which ``config.max_undercut`` judges."""
    poly = h.poly
    if poly.is_convex:
        return False
    centre = at_m + config.pad_radius * poly.face_normals[face]
    hits = line_hits(poly, centre[None], h.model_from_world.rotate(_UP)[None])
    return bool(hits.first[0] < FINGER_ABOVE and int(hits.face[0]) != face)


def rolls_to_edge(h: Hypothesis, tr: FaceTrace, config: PlannerConfig) -> bool:
    """Whether face move trace ``tr`` of ``h``, meeting a convex edge onto a face the table hides, ends at the edge
    with the edge alone, as the hand does there: clear of the edge's ends (:data:`EDGE_ONLY_CLEARANCE`), its pad can
    roll over the edge by :data:`EDGE_ROLL` -- enough for the edge from the roll -- before coming within
    ``config.table_clearance`` of the table."""
    poly, t, hit = h.poly, h.world_from_model, tr.hit
    if poly.edge_convexity[hit.edge] <= 0 or tr.clearance(poly) < EDGE_ONLY_CLEARANCE:
        return False
    n_a, n_b = t.rotate(poly.face_normals[tr.face]), t.rotate(poly.face_normals[hit.next_face])
    toward = n_b - float(n_b @ n_a) * n_a
    norm = float(np.linalg.norm(toward))
    if norm < 1e-9:
        return False
    rolled = np.cos(EDGE_ROLL) * n_a + np.sin(EDGE_ROLL) * toward / norm
    return pad_clearance(t.apply(hit.point), rolled, config) >= config.table_clearance


def _edge_end(
    h: Hypothesis, move: EdgeMove, state: SensorState, components: Mapping[int, DataComponent]
) -> tuple[int, int, np.ndarray] | None:
    """The model edge of the current data edge in ``h``, the vertex ``move`` runs to and its direction of travel
    (model frame); None when ``h`` cannot say."""
    if h.world_from_model is None or state.edge is None:
        return None
    poly, t = h.poly, h.world_from_model
    e_m = h.edges.get(state.edge)
    data_edge = components.get(state.edge)
    if e_m is None or not isinstance(data_edge, DataEdge):
        return None
    sense = move.sense if float(t.rotate(poly.edge_directions[e_m]) @ data_edge.direction) > 0 else -move.sense
    v = int(poly.edges[e_m, 1] if sense > 0 else poly.edges[e_m, 0])
    return int(e_m), v, poly.edge_directions[e_m] * sense


def edge_end_on_table(
    h: Hypothesis, move: EdgeMove, state: SensorState, components: Mapping[int, DataComponent],
    config: PlannerConfig,
) -> bool:
    """Whether the pad following ``move``'s edge of ``h`` (touching both faces, its normal between theirs) comes
    within ``config.table_clearance`` of the table at the edge's end."""
    end = _edge_end(h, move, state, components) if config.table_z is not None else None
    if end is None:
        return False
    e_m, v, _ = end
    poly, t = h.poly, h.world_from_model
    ridge = poly.face_normals[poly.edge_left_face[e_m]] + poly.face_normals[poly.edge_right_face[e_m]]
    ridge = ridge / max(float(np.linalg.norm(ridge)), 1e-12)
    return pad_clearance(t.apply(poly.vertices[v]), t.rotate(ridge), config) < config.table_clearance


def hidden_concave_end(
    h: Hypothesis, move: EdgeMove, state: SensorState, components: Mapping[int, DataComponent],
    config: PlannerConfig,
) -> bool:
    """Whether ``move`` runs along a concave edge of ``h`` to an end where no face blocks the pad (the surface
    falls away past it), which the hand cannot locate (:attr:`PlannerConfig.concave_end_block`)."""
    end = _edge_end(h, move, state, components) if config.concave_end_block is not None else None
    if end is None or h.poly.edge_convexity[end[0]] >= 0:
        return False
    poly = h.poly
    e_m, v, u = end
    own = {int(poly.edge_left_face[e_m]), int(poly.edge_right_face[e_m])}
    return not any(float(poly.face_normals[f] @ u) < -config.concave_end_block
                   for f in poly.vertex_faces[v] if int(f) not in own)  # fmt: skip


def at_concave_vertex(h: Hypothesis, state: SensorState, config: PlannerConfig) -> bool:
    """Whether the sensor is at a vertex of ``h`` where a concave edge ends and moves may not start there
    (:attr:`PlannerConfig.leave_concave_vertices` False: the hand)."""
    if config.leave_concave_vertices or state.vertex is None:
        return False
    v_m = h.vertices.get(state.vertex)
    return v_m is not None and any(h.poly.edge_convexity[e] < 0 for e in h.poly.vertex_edges[v_m])


def _vertex_frame(
    state: SensorState, components: Mapping[int, DataComponent], face: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """From the data: the current vertex, the unit vector along the current edge toward it, the unit vector
    into data face ``face`` perpendicular to the edge, and that face's normal. None when the data lack one."""
    edge = components.get(state.edge) if state.edge is not None else None
    vertex = components.get(state.vertex) if state.vertex is not None else None
    f = components.get(face)
    if not isinstance(edge, DataEdge) or vertex is None or not isinstance(f, DataFace):
        return None
    b, n = edge.direction, f.normal
    mid = edge.point + 0.5 * edge.length * b
    u = b if (vertex.position - mid) @ b >= 0 else -b
    w = np.cross(n, b)
    w /= max(float(np.linalg.norm(w)), 1e-12)
    side = dict(edge.side_points).get(face) if edge.side_points else None
    ref = side if side is not None else f.points.mean(axis=0)
    if (ref - edge.point) @ w < 0:
        w = -w
    return vertex.position, u, w, n


def vertex_sweep_off_table(
    state: SensorState, components: Mapping[int, DataComponent], face: int, config: PlannerConfig
) -> float:
    """From the data alone: the angle the circle of a vertex move across data face ``face`` can sweep from its
    start before the pad would come onto the table (2π: never; 0: its start is out of reach) [rad]."""
    if config.table_z is None:
        return 2 * np.pi
    frame = _vertex_frame(state, components, face)
    if frame is None:
        return 2 * np.pi
    vtx, u, w, n = frame
    return circle_sweep_off_table(
        vtx, u, w, n, config.vertex_radius, config.table_z, config.pad_radius, config.table_clearance
    )


def edge_return_in_reach(state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig) -> bool:
    """From the data alone: whether the pad, to follow the current convex edge, can touch one of its faces
    :attr:`PlannerConfig.edge_reentry` in from it somewhere along its explored interval with its lowest point
    ``config.table_clearance`` above the table (the hand sets off along an edge so; where no such point is, the edge
    move fails at once, "the edge next to the table is out of the pad's reach"). True without
    ``config.edge_reentry`` and where the data cannot say: no edge, no face of it known beside it
    (:attr:`~haptic.matching.components.DataEdge.side_points`: the faces the hand knows the way into from the edge),
    or a concave edge (the hand returns into its corner instead). On the public polyhedra at 30 mm
    (elongated_triangular_bipyramid, seed 1) an edge reported alone, the roll over it stopped by the table, had its
    one face's strip along it within 2 mm of the table, and both moves along it failed so."""
    edge = components.get(state.edge) if state.edge is not None else None
    if config.edge_reentry is None or not isinstance(edge, DataEdge):
        return True
    b, sides = edge.direction, dict(edge.side_points)
    faces = [(f, components[f]) for f in sides if isinstance(components.get(f), DataFace)]
    if not faces:
        return True
    for (f, face), (g, _) in zip(faces, faces[::-1], strict=True):
        if f != g and float((sides[g] - edge.point) @ face.normal) > 0.0:
            return True  # concave: each face's side point lies outside the other's plane
    for f, face in faces:
        w = np.cross(face.normal, b)
        w = w / max(float(np.linalg.norm(w)), 1e-12)
        if float((sides[f] - edge.point) @ w) < 0.0:
            w = -w
        # the clearance is linear along the edge: highest at one end of the explored interval
        inward = config.edge_reentry * w
        if any(pad_clearance(edge.point + s * b + inward, face.normal, config) >= config.table_clearance
               for s in (0.0, edge.length)):  # fmt: skip
            return True
    return False


def data_table_conflict(
    move: Move, state: SensorState, components: Mapping[int, DataComponent], config: PlannerConfig
) -> bool:
    """What the data alone say about the table, whatever the model: a face move heading down from a point
    already within the pad's reach of the table with no side to go on to level (:func:`level_heading`), an edge
    move along an edge whose faces the pad cannot touch next to it off the table (:func:`edge_return_in_reach`), or
    a vertex move whose circle cannot even start off it."""
    if config.table_z is None:
        return False
    if isinstance(move, EdgeMove):
        return not edge_return_in_reach(state, components, config)
    if isinstance(move, FaceMove):
        face = components.get(start_state(move, state).face)
        d = np.asarray(move.direction, dtype=float)
        if not isinstance(face, DataFace) or float(d[2]) >= 0.0 or level_heading(d, face.normal) is not None:
            return False
        return pad_clearance(state.position, face.normal, config) < config.table_clearance
    if isinstance(move, VertexMove):
        return vertex_sweep_off_table(state, components, move.across_face, config) <= 0.0
    return False


def move_table_risk(
    move: Move,
    hypotheses: Sequence[Hypothesis],
    state: SensorState,
    components: Mapping[int, DataComponent],
    config: PlannerConfig,
) -> float:
    """Fraction of the hypotheses (that can say) predicting ``move`` to run into the table; 1 when the data
    alone say so; 0 without a table or a prediction."""
    if config.table_z is None:
        return 0.0
    if data_table_conflict(move, state, components, config):
        return 1.0
    vals = np.array([table_conflict(h, move, state, components, config) for h in hypotheses], dtype=float)
    return 0.0 if not len(vals) or np.isnan(vals).all() else float(np.nanmean(vals))


def table_safe_moves(
    moves: Sequence[Move],
    hypotheses: Sequence[Hypothesis],
    state: SensorState,
    components: Mapping[int, DataComponent],
    config: PlannerConfig,
) -> list[Move]:
    """``moves`` less those predicted to run into the table (risk ≥ ``config.table_risk``); all of them when
    that leaves none (the executor then says so). Unchanged without a table."""
    if config.table_z is None:
        return list(moves)
    safe = [m for m in moves if move_table_risk(m, hypotheses, state, components, config) < config.table_risk]
    return safe or list(moves)


def descent_risk(move: Move, config: PlannerConfig) -> float:
    """``config.steep_descent_risk`` for a face move heading down more steeply than ``config.steep_descent``,
    else 0."""
    if move.kind != "face" or config.steep_descent_risk <= 0.0:
        return 0.0
    return config.steep_descent_risk if float(np.asarray(move.direction)[2]) < -config.steep_descent else 0.0


def rests_on_table(poly: Polyhedron, world_from_model: SE3, config: PlannerConfig) -> bool:
    """Whether ``poly`` at ``world_from_model`` rests on the table: its lowest vertex at the table top within
    ``config.table_rest_tol`` (neither through it nor floating). True without a table."""
    if config.table_z is None:
        return True
    low = float(world_from_model.apply(poly.vertices)[:, 2].min()) - config.table_z
    return abs(low) <= config.table_rest_tol


def pose_fixed_by(components: Mapping[int, DataComponent]) -> bool:
    """Whether the data fix every interpretation's translation: a data vertex, or faces whose normals span
    space. (Until then a pose class's pose is one of many and says nothing about where the table is.)"""
    if any(c.kind == "vertex" for c in components.values()):
        return True
    normals = np.array([c.normal for c in components.values() if isinstance(c, DataFace)])
    return len(normals) >= 3 and float(np.linalg.svd(normals, compute_uv=False)[2]) > 0.3
