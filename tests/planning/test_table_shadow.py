"""The table's shadow: what no pad kept clear of the table can touch, and the vertices whose moves change only that
(or what is measured), which the full verification takes on trust there
(:func:`haptic.planning.verify.table_shadow`)."""

from dataclasses import replace

import numpy as np

from haptic.geometry import SE3
from haptic.geometry.distance import surface_distance
from haptic.geometry.perturb import move_vertex
from haptic.geometry.shapes import box, prism
from haptic.planning.config import PlannerConfig
from haptic.planning.verify import cone_top, table_shadow

TABLE = 0.35
CONFIG = replace(PlannerConfig(), table_z=TABLE)  # the pad's radius 12 mm, kept 4 mm clear of the table
WALL = CONFIG.pad_radius + CONFIG.table_clearance  # the shadow beside a vertical face: 16 mm


def _on_table(poly, rotation: np.ndarray | None = None) -> SE3:
    rotation = np.eye(3) if rotation is None else rotation
    low = (poly.vertices @ rotation.T)[:, 2].min()
    return SE3(rotation, np.array([0.55, 0.0, TABLE - low]))


def _changed_top(variant, base, pose: SE3) -> float:
    """The highest point above the table where ``variant`` and ``base`` differ by more than 0.1 mm, at ``pose``."""
    tops = []
    for a, b in ((variant, base), (base, variant)):
        pts = [a.vertices]
        for i, j, k in a.triangles:
            u, v = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 41), indexing="ij")
            keep = u + v <= 1
            p, q, r = a.vertices[i], a.vertices[j], a.vertices[k]
            pts.append(p + u[keep][:, None] * (q - p) + v[keep][:, None] * (r - p))
        pts = np.concatenate(pts)
        off = pts[surface_distance(b, pts) > 1e-4]
        if len(off):
            tops.append(float(pose.apply(off)[:, 2].max()) - TABLE)
    return max(tops)


def _corner(poly, z: float) -> int:
    return int(np.flatnonzero(np.all(np.isclose(poly.vertices, [0.0, 0.0, z]), axis=1))[0])


def test_the_steepest_contact_normal_at_an_edge_or_a_vertex():
    """An apex is pressed from straight above; an edge between two walls leaning out from the vertical at most
    level; the ridge between two faces rising 30° is pressed from above too."""
    walls = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]])
    assert abs(cone_top(walls)) < 1e-12
    s, c = np.sin(np.radians(30)), np.cos(np.radians(30))
    assert abs(cone_top(np.array([[c, 0.0, s], [-c, 0.0, s]])) - 1.0) < 1e-12
    ridge = np.array([c, c, 2 * s]) / np.linalg.norm([c, c, 2 * s])  # between faces rising 30° toward x and y
    assert abs(cone_top(np.array([[c, 0.0, s], [0.0, c, s]])) - ridge[2]) < 1e-9
    assert abs(cone_top(np.array([[c, 0.0, -s], [-c, 0.0, -s]])) + s) < 1e-9  # both lean under: the arc tops there


def test_a_low_box_corner_on_the_table_lies_in_the_shadow():
    """A box 8 mm high on the table: its walls' corners at a bottom vertex reach 8 mm, under the 16 mm the pad
    pressing a vertical wall clear of the table cannot go below; its edges and the vertex are pressed at best level.
    The vertex is taken on trust up to 16 mm, and every move of it (2, 4, 8 mm) changes the box only below that.
    Its top corners are pressed from above."""
    poly = box(0.06, 0.04, 0.008)
    pose = _on_table(poly)
    v = _corner(poly, 0.0)
    assert abs(table_shadow(poly, pose, v, CONFIG) - WALL) < 1e-9
    for mm in (2, 4, 8):
        assert _changed_top(move_vertex(poly, v, mm * 1e-3), poly, pose) < WALL
    assert table_shadow(poly, pose, _corner(poly, 0.008), CONFIG) is None
    assert table_shadow(poly, pose, v, PlannerConfig()) is None  # no table, no shadow


def test_a_corner_that_reaches_out_of_the_shadow_is_taken_on_trust_only_measured_there():
    """A box 30 mm high: its walls' corners at a bottom vertex reach 30 mm, touchable above 16 mm, and a move of
    the vertex changes them there: not in the shadow, unless both walls are measured within their corners at the
    vertex and the vertical edge is measured (then what changes out of the shadow is measured, and the rest lies
    below 16 mm)."""
    poly = box(0.06, 0.04, 0.03)
    pose = _on_table(poly)
    v = _corner(poly, 0.0)
    assert _changed_top(move_vertex(poly, v, 0.004), poly, pose) > WALL
    assert table_shadow(poly, pose, v, CONFIG) is None
    z = pose.apply(poly.vertices)[:, 2] - TABLE
    walls = frozenset(int(f) for f in poly.vertex_faces[v] if abs(pose.rotate(poly.face_normals[int(f)])[2]) < 0.5)
    rising = frozenset(int(e) for e in poly.vertex_edges[v] if max(z[int(u)] for u in poly.edges[int(e)]) > 0.02)
    assert len(walls) == 2 and len(rising) == 1
    assert abs(table_shadow(poly, pose, v, CONFIG, walls, rising) - WALL) < 1e-9
    assert table_shadow(poly, pose, v, CONFIG, walls, frozenset()) is None
    assert table_shadow(poly, pose, v, CONFIG, frozenset(sorted(walls)[:1]), rising) is None


def test_a_vertex_under_an_overhang_lies_in_the_shadow_of_the_faces_turned_down():
    """An L block lying with its step's underside 6 mm over the table: the outer vertex under the overhang has the
    underside (turned down: the pad reaches none of it under 28 mm), the end face and the outer wall (16 mm, their
    corners there reaching 14 mm); pressed at best level (16 mm). The block's top vertices are pressed from
    above."""
    poly = prism([(0, 0), (0.02, 0), (0.02, 0.006), (0.04, 0.006), (0.04, 0.014), (0, 0.014)], 0.03)
    turn = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # the profile's y up, the extrusion level
    pose = _on_table(poly, turn)
    z = pose.apply(poly.vertices)[:, 2] - TABLE
    x = pose.apply(poly.vertices)[:, 0] - 0.55
    under = [int(v) for v in np.flatnonzero(np.isclose(z, 0.006) & np.isclose(x, 0.04))]
    assert len(under) == 2
    for v in under:
        assert abs(table_shadow(poly, pose, v, CONFIG) - (2 * CONFIG.pad_radius + CONFIG.table_clearance)) < 1e-9
        assert _changed_top(move_vertex(poly, v, 0.002), poly, pose) < WALL
    top = int(np.flatnonzero(np.isclose(z, 0.014))[0])
    assert table_shadow(poly, pose, top, CONFIG) is None


def test_a_pose_class_is_set_aside_only_when_none_of_its_interpretations_rests_on_the_table():
    """A pose class stands at its first interpretation's pose; at noise level 4 the classes group interpretations
    whose poses differ by a few degrees (BOX01N at 150 mm, seed 1: the true interpretation second in a class whose
    first sat 4.6° off it, through the table). Set aside at the first's pose, the truth went with it, and the class
    left, wrong, was recognised (verification then found a face 80 bounds off: no-match). The class is kept at the
    pose of an interpretation that rests on the table, and set aside when none does."""
    from types import SimpleNamespace

    from haptic.episode.perception import on_the_table
    from haptic.matching.components import DataVertex
    from haptic.matching.recognition import EXPLORING, RECOGNIZED, PoseClass, Recognition

    poly = box(0.15, 0.1, 0.05)
    pose = _on_table(poly)
    config = PlannerConfig(table_z=TABLE)
    c, s = np.cos(np.radians(4.6)), np.sin(np.radians(4.6))
    tilt = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    tilted = SE3(tilt @ pose.rotation, pose.translation + np.array([0.0, 0.0, 0.006]))  # floating off the table
    turned = SE3(np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]) @ pose.rotation, pose.translation)
    poses = {0: tilted, 1: pose, 2: turned, 3: tilted}
    tree = SimpleNamespace(poses=lambda leaves, refine=True: [poses[k] for k in leaves], data=())
    true, other = PoseClass(poly, (0, 1), tilted), PoseClass(poly, (2,), turned)
    rec = Recognition(EXPLORING, None, None, (true, other), 3, (poly.name,))
    vertex = {0: DataVertex(id=0, position=pose.apply(poly.vertices[:1])[0], position_bound=1e-3)}
    out = on_the_table(rec, tree, vertex, config)
    assert out.status != RECOGNIZED and len(out.classes) == 2
    kept = next(c for c in out.classes if 0 in c.leaves)
    assert kept.leaves[0] == 1 and kept.world_from_model is pose
    alone = Recognition(EXPLORING, None, None, (PoseClass(poly, (0, 3), tilted), other), 3, (poly.name,))
    assert on_the_table(alone, tree, vertex, config).model is not None  # none of the first rests: set aside


def test_an_edge_rising_out_of_the_shadow_is_not_placed_by_its_other_end_and_the_corners_beside_it():
    """An eight-sided bipyramid (50 mm across, 40 mm tall) lying on a face: a vertex of its equator 9 mm over the
    table has two faces whose corners rise out of their shadow, the edge between them (to the apex) rising too, and
    an edge along the equator rising out of its shadow to the next vertex, a face in its shadow on the ridge's other
    side (the formula corpus's bipyramids lie so). The two corners measured within them, the edge to the apex
    measured and the equator's next vertex measured -- what placing a vertex by its faces' corners
    (:func:`~haptic.matching.acceptance.placed_near`) asks of an edge -- still leave the vertex free to slide along
    the edge to the apex: 2, 4 or 8 mm down it, within the vertex's shadow, keeps both corners' planes, that edge's
    line and the next vertex where they are, and turns the equator's ridge above its shadow, where a pad touches
    it. So that ridge must itself be measured, and the shadow does not take the vertex without it."""
    from haptic.geometry import Polyhedron
    from haptic.geometry.shapes import bipyramid
    from haptic.matching.acceptance import corner_triangle
    from haptic.planning.verify import shadow_of
    from tests.planning.test_verify_moves import _resting_on

    poly = bipyramid(8, 0.025, 0.02)
    pose, _ = _resting_on(poly, 0)  # on the table at TABLE
    z = pose.apply(poly.vertices)[:, 2] - TABLE
    n = pose.rotate(poly.face_normals)

    def edge_shadow(e: int) -> float:
        return shadow_of(cone_top(n[[int(poly.edge_left_face[e]), int(poly.edge_right_face[e])]]), CONFIG)

    found = 0
    for v in range(poly.n_vertices):
        faces = [int(f) for f in poly.vertex_faces[v]]
        if z[v] <= 1e-3 or z[v] >= shadow_of(cone_top(n[faces]), CONFIG):
            continue
        rising = [int(e) for e in poly.vertex_edges[v]
                  if max(z[v], z[int(sum(poly.edges[int(e)])) - v]) >= edge_shadow(int(e))]  # fmt: skip
        out = [f for f in faces
               if (pose.apply(corner_triangle(poly, v, f))[:, 2] - TABLE).max() >= shadow_of(n[f, 2], CONFIG)]
        if len(out) != 2:
            continue
        between = [e for e in rising if {int(poly.edge_left_face[e]), int(poly.edge_right_face[e])} == set(out)]
        ridges = [e for e in rising if e not in between]
        if len(between) != 1 or len(ridges) != 1:
            continue
        found += 1
        e = ridges[0]
        u = int(sum(poly.edges[e])) - v
        # both corners and the edge between them measured: the ridge along the equator keeps it out of the shadow
        assert table_shadow(poly, pose, v, CONFIG, frozenset(out), frozenset(between)) is None
        assert table_shadow(poly, pose, v, CONFIG, frozenset(out), frozenset(rising)) is not None
        along = poly.vertices[v] - poly.vertices[int(sum(poly.edges[between[0]])) - v]
        along /= np.linalg.norm(along)
        for mm in (2, 4, 8):  # away from the apex: down, the vertex kept in its shadow
            moved = poly.vertices.copy()
            moved[v] = moved[v] + mm * 1e-3 * along
            assert pose.apply(moved[v])[2] - TABLE < shadow_of(cone_top(n[faces]), CONFIG)
            variant = Polyhedron.from_faces(moved, [tuple(f) for f in poly.faces], name="slid")
            for f in out:  # the measured corners keep their planes
                assert np.allclose(variant.face_normals[f], poly.face_normals[f], atol=1e-9)
            assert np.allclose(variant.vertices[u], poly.vertices[u])  # the ridge's other end stays
            assert _changed_top(variant, poly, pose) > edge_shadow(e) + 1e-3  # the ridge turns above its shadow
    assert found >= 2


def test_a_ridge_rising_out_of_the_shadow_is_crossed_above_it():
    """A nine-sided bipyramid (30 mm across, 80 mm tall) lying on a face: an edge rises from a vertex 6 mm over the
    table to one 27 mm up, between a face leaning under 35° and a face standing nearly upright; no pad pressing it
    clear of the table reaches it under 16.5 mm, and its middle lies under that. A face move from the upright face
    aimed at its middle meets it in the shadow, where the pad would meet the table's clearance first; aimed at it as
    an edge the table's shadow needs (:func:`~haptic.planning.verify.ridge_target`), it meets it above, where a
    crossing measures it (bipyramid_10 of the formula corpus)."""
    from haptic.geometry.shapes import bipyramid
    from haptic.matching.components import DataFace
    from haptic.planning.hypothesis import Hypothesis
    from haptic.planning.moves import SensorState
    from haptic.planning.search import simulate
    from haptic.planning.verify import aimed_face_moves, ridges_out_of_shadow, shadow_of
    from tests.planning.test_verify_moves import _resting_on

    poly = bipyramid(9, 0.015, 0.04)
    pose, _ = _resting_on(poly, 0)
    hand = replace(CONFIG, concave_end_block=0.2)
    z = pose.apply(poly.vertices)[:, 2] - TABLE
    n = pose.rotate(poly.face_normals)
    crossed = 0
    for v in range(poly.n_vertices):
        if z[v] < 1e-3 or z[v] >= shadow_of(cone_top(n[[int(f) for f in poly.vertex_faces[v]]]), hand):
            continue
        for e in ridges_out_of_shadow(poly, pose, v, hand):
            faces = [int(poly.edge_left_face[e]), int(poly.edge_right_face[e])]
            height = shadow_of(cone_top(n[faces]), hand)
            ends = z[[int(u) for u in poly.edges[e]]]
            if float(ends.mean()) >= height:
                continue  # its middle above the shadow: aimed at as ever
            upright = max(faces, key=lambda f: float(n[f, 2]))
            loop = poly.vertices[list(poly.faces[upright])]
            centre = loop.mean(axis=0)
            face = DataFace(1, n[upright], pose.apply(centre + 0.3 * (loop - centre)), 1e-2, 1e-3)
            h = Hypothesis(poly.name, poly, pose, {1: upright}, {}, {})
            state = SensorState(pose.apply(centre) + 1e-3 * n[upright], face=1)
            missing = (frozenset(), frozenset({e}), frozenset())
            for ridges, above in ((frozenset(), False), (frozenset({e}), True)):
                moves = aimed_face_moves(h, state, {1: face}, missing, hand, ridges)
                assert len(moves) == 1
                h1, s1, _ = simulate(h, moves[0], state, {1: face}, hand)
                assert h1.edges[s1.edge] == e
                assert (float(s1.position[2]) - TABLE >= height) == above
            crossed += 1
    assert crossed >= 2


NORMAL_BOUND = np.radians(1.0)
"""About the hand's bound of a face's normal and of an edge's direction (3 × their systematic 0.25° and scatter)."""


def _touchable_changed_top(variant, base, pose: SE3, config: PlannerConfig = CONFIG) -> float:
    """The highest point above the table where ``variant`` and ``base`` differ by more than 0.1 mm and a pad kept
    clear of the table could touch it: at least the shadow of its own face's normal over the table (:func:`shadow_of`
    of the triangle it lies on, in the surface it belongs to); -1 where there is none."""
    from haptic.planning.verify import shadow_of

    top = -1.0
    for a, b in ((variant, base), (base, variant)):
        for i, j, k in a.triangles:
            p, q, r = a.vertices[i], a.vertices[j], a.vertices[k]
            probe = np.array([p, q, r, (p + q) / 2, (q + r) / 2, (r + p) / 2, (p + q + r) / 3])
            if float(surface_distance(b, probe).max()) < 1e-9:
                continue  # a piece of the surface both share
            u, w = np.meshgrid(np.linspace(0, 1, 21), np.linspace(0, 1, 21), indexing="ij")
            keep = u + w <= 1
            pts = p + u[keep][:, None] * (q - p) + w[keep][:, None] * (r - p)
            n = np.cross(q - p, r - p)
            height = shadow_of(float(pose.rotate(n / np.linalg.norm(n))[2]), config)
            z = pose.apply(pts)[:, 2] - TABLE
            off = (z >= height) & (surface_distance(b, pts) > 1e-4)
            if off.any():
                top = max(top, float(z[off].max()))
    return top


def _turn(a: np.ndarray, b: np.ndarray) -> float:
    """The angle between two lines' directions (or two planes' normals) [rad]."""
    c = abs(float(a @ b)) / (float(np.linalg.norm(a)) * float(np.linalg.norm(b)))
    return float(np.arccos(min(c, 1.0)))


def test_a_vertex_whose_corners_and_ridges_rise_out_of_the_shadow_is_taken_once_both_are_measured():
    """An eight-sided trapezohedron (its zigzag 50 mm from the axis, 2.2 mm either side of the middle: trapezohedron_08
    of the formula corpus) lying on a kite: two vertices 11 mm over the table, in their shadow, have two upright
    kites whose corners run up to the apex, out of their shadows, and two edges rising out of theirs (to the apex,
    and to a vertex 20 mm up); the third kite, leaning under 56°, has its corner in its shadow. With the two corners
    measured within them and the two edges measured the table's shadow takes the vertex, up to 26 mm
    (:func:`~haptic.planning.verify.table_shadow`), and with either left out it does not. The promise: every move of
    the vertex by 2, 4 and 8 mm (:func:`~haptic.geometry.perturb.move_vertex`, along its normal, along and against
    each face's normal and each edge) changes surface a pad clear of the table can touch only where it tilts one of
    those corners or turns one of those edges by twice the hand's bound or more, and neither the corners alone nor
    the edges alone see every such move; a chamfer of one of those edges (2, 4, 8 mm) cuts it where a crossing
    measures it (:func:`~haptic.planning.verify.ridge_target`), and one of its other edge changes surface a pad can
    touch only under the claim's height."""
    from haptic.geometry.perturb import chamfer_edge
    from haptic.geometry.shapes import trapezohedron
    from haptic.matching.acceptance import corner_triangle
    from haptic.planning.verify import (
        TABLE_CONTACT,
        corners_out_of_shadow,
        ridge_target,
        ridges_out_of_shadow,
        shadow_of,
    )
    from tests.planning.test_verify_moves import _resting_on

    poly = trapezohedron(8, 0.0499, 0.00222)
    pose, _ = _resting_on(poly, 0)
    z = pose.apply(poly.vertices)[:, 2] - TABLE
    n = pose.rotate(poly.face_normals)
    found = 0
    for v in range(poly.n_vertices):
        if z[v] <= TABLE_CONTACT or z[v] >= shadow_of(cone_top(n[[int(f) for f in poly.vertex_faces[v]]]), CONFIG):
            continue
        corners = corners_out_of_shadow(poly, pose, v, CONFIG)
        ridges = ridges_out_of_shadow(poly, pose, v, CONFIG)
        if not corners or not ridges:
            continue
        found += 1
        height = table_shadow(poly, pose, v, CONFIG, corners, ridges)
        assert height is not None and abs(height - 0.026) < 5e-4
        assert table_shadow(poly, pose, v, CONFIG, corners, frozenset()) is None
        assert table_shadow(poly, pose, v, CONFIG, frozenset(), ridges) is None
        tris = {f: corner_triangle(poly, v, f) for f in corners}
        ends = {e: poly.vertices[int(sum(poly.edges[e])) - v] for e in ridges}
        directions = [None] + [s * poly.face_normals[int(f)] for f in poly.vertex_faces[v] for s in (1.0, -1.0)]
        for e in (int(e) for e in poly.vertex_edges[v]):
            d = poly.vertices[int(sum(poly.edges[e])) - v] - poly.vertices[v]
            directions += [d / np.linalg.norm(d), -d / np.linalg.norm(d)]
        alone = {"corners": False, "ridges": False}  # a move changing touchable surface that one alone misses
        for d in directions:
            for mm in (2, 4, 8):
                variant = move_vertex(poly, v, mm * 1e-3, direction=d)
                moved = variant.vertices[v]
                tilt = max(_turn(np.cross(t[1] - t[0], t[2] - t[0]), np.cross(t[1] - moved, t[2] - moved))
                           for t in tris.values())  # fmt: skip
                turn = max(_turn(u - poly.vertices[v], u - moved) for u in ends.values())
                if _touchable_changed_top(variant, poly, pose) < height:
                    continue
                assert max(tilt, turn) >= 2 * NORMAL_BOUND, (v, d, mm)
                alone["corners"] |= tilt < 2 * NORMAL_BOUND
                alone["ridges"] |= turn < 2 * NORMAL_BOUND
        assert alone == {"corners": True, "ridges": True}
        for e in (int(e) for e in poly.vertex_edges[v]):
            for mm in (2, 4, 8):
                variant = chamfer_edge(poly, e, mm * 1e-3)
                if e in ridges:
                    assert float(surface_distance(variant, ridge_target(poly, pose, e, CONFIG)[None])[0]) > 5e-4
                else:
                    assert _touchable_changed_top(variant, poly, pose) < height
    assert found == 2
