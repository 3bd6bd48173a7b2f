"""Probes by another finger, or a tilted one, at the faces of table vertices the index pointing down cannot press
(:mod:`haptic.planning.finger_faces`): the lines the verification weighs, the stroke kept within a face's room, and
an episode of the formula corpus whose verification completes only with such probes."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from haptic.geometry import SE3, Polyhedron
from haptic.matching.acceptance import Coverage, corner_triangle, in_corner, placed_near
from haptic.matching.components import DataFace, SensorNoise
from haptic.matching.tree import Interpretation
from haptic.planning.config import PlannerConfig
from haptic.planning.finger_faces import (
    MIN_ROOM,
    RUN_UP,
    CornerProbes,
    TableFaceProbes,
    corner_lines,
    faces_to_probe,
    pad_positions,
    table_face_lines,
)
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import ProbeMove
from haptic.planning.verify import Verifier


def _octahedron(size: float) -> tuple[Polyhedron, SE3]:
    """A regular octahedron resting on a face (table at z = 0), ``size`` from vertex to opposite vertex [m]."""
    a = size / 2.0
    v = np.array([[a, 0, 0], [-a, 0, 0], [0, a, 0], [0, -a, 0], [0, 0, a], [0, 0, -a]], dtype=float)
    faces = []
    for sx in (0, 1):
        for sy in (2, 3):
            for sz in (4, 5):
                tri = [sx, sy, sz]
                n = np.cross(v[tri[1]] - v[tri[0]], v[tri[2]] - v[tri[0]])
                faces.append(tri if n @ v[tri].mean(axis=0) > 0 else tri[::-1])
    poly = Polyhedron.from_faces(v, faces, name="octahedron")
    # onto the face (0, 2, 4)'s opposite, (1, 3, 5): its normal turned straight down, resting on z = 0
    n = -np.ones(3) / math.sqrt(3.0)
    axis = np.cross(n, [0.0, 0.0, -1.0])
    angle = math.asin(float(np.linalg.norm(axis)))
    axis /= np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rot = np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * k @ k
    m = np.eye(4)
    m[:3, :3] = rot
    m[2, 3] = -float((poly.vertices @ rot.T)[:, 2].min())
    return poly, SE3.from_matrix(m)


def _config() -> PlannerConfig:
    return PlannerConfig(table_z=0.0, pad_radius=0.012, max_undercut=math.radians(10.0))


def _table_vertices(poly, pose) -> list[int]:
    z = pose.apply(poly.vertices)[:, 2]
    return [int(v) for v in np.flatnonzero(z < 1e-6)]


def test_the_faces_leaning_under_at_the_table_vertices_are_the_ones_weighed():
    poly, pose = _octahedron(0.1)
    config = _config()
    got = faces_to_probe(poly, pose, _table_vertices(poly, pose), frozenset(), config)
    z = pose.apply(poly.vertices)[:, 2]
    assert len(got) == 6  # the bottom face rests on the table; the six around it rise from the table
    for _, f in got:
        assert not np.all(z[list(poly.faces[f])] < 1e-6)
    measured = frozenset(f for _, f in got[:2])
    assert {f for _, f in faces_to_probe(poly, pose, _table_vertices(poly, pose), measured, config)} == {
        f for _, f in got[2:]}  # fmt: skip


def test_a_line_meets_its_face_level_with_room_for_a_stroke():
    poly, pose = _octahedron(0.1)
    config = _config()
    for v, f in faces_to_probe(poly, pose, _table_vertices(poly, pose), frozenset(), config):
        n = pose.rotate(poly.face_normals[f])
        lines = table_face_lines(poly, pose, v, f, config)
        if n[2] >= 0.0:
            continue
        assert lines, f"face {f} leans under {np.degrees(np.arcsin(-n[2])):.0f}° and has room high on it"
        for line in lines:
            assert abs(float(line.direction[2])) < 1e-9  # level
            assert line.room is not None and line.room >= MIN_ROOM - 1e-9
            # the pad's centre along the line comes to a pad's radius off the face's plane, above the table
            p0 = pose.apply(poly.vertices[poly.faces[f][0]])
            t = np.linspace(0.0, line.length, 2001)
            centres = line.start + t[:, None] * line.direction
            d = (centres - p0) @ n
            k = int(np.argmin(np.abs(d - config.pad_radius)))
            assert abs(d[k] - config.pad_radius) < 1e-3
            assert centres[k, 2] - config.pad_radius >= config.table_clearance - 1e-9


def test_a_small_octahedron_leaves_no_room_clear_of_the_table():
    # 30 mm from vertex to vertex: its faces leaning under rise 20 mm, and a pad pressing one (its lowest point
    # r (1 + sin 19.5°) = 16 mm under its contact) would have to touch it above 20 mm
    poly, pose = _octahedron(0.03)
    config = _config()
    for v, f in faces_to_probe(poly, pose, _table_vertices(poly, pose), frozenset(), config):
        n = pose.rotate(poly.face_normals[f])
        if n[2] < 0.0:
            assert not len(pad_positions(poly, pose, v, f, config))


def _setup():
    """The octahedron at its pose, the planner's configuration and its hypothesis there."""
    poly, pose = _octahedron(0.1)
    h = Hypothesis(model="octahedron", poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
    return poly, pose, _config(), h


def _nobody(asked: list[ProbeMove]):
    """A reach test no finger passes, booking each line it is asked about in ``asked``."""

    def reach(line, hypotheses):
        asked.append(line)

    return reach


def _thumb(line, hypotheses):
    """A reach test the thumb passes for every line."""
    return ProbeMove(line.start, line.direction, line.length, finger="thumb", room=line.room)


def test_the_probes_ask_each_line_once_and_name_what_no_finger_reaches():
    poly, pose, config, h = _setup()
    asked: list[ProbeMove] = []
    probes = TableFaceProbes(_nobody(asked))
    vertices = _table_vertices(poly, pose)
    assert probes.next(h, vertices, frozenset(), config) is None
    assert probes.next(h, vertices, frozenset(), config) is None
    n_lines = sum(len(table_face_lines(poly, pose, v, f, config))
                  for v, f in faces_to_probe(poly, pose, vertices, frozenset(), config))  # fmt: skip
    assert len(asked) == n_lines == probes.asked
    assert "no finger reaches" in probes.unmeasured(vertices, h, frozenset(), config)
    probes = TableFaceProbes(_thumb)
    got = probes.next(h, vertices, frozenset(), config)
    assert got is not None and got.finger == "thumb" and probes.take() is got and probes.take() is None
    assert probes.fingers == {"thumb": 1}


def test_the_stroke_is_kept_within_the_faces_room():
    from haptic.executor.placement import PROBE_SETTINGS, stroke_within

    assert stroke_within(PROBE_SETTINGS, 0.02) == PROBE_SETTINGS
    s = stroke_within(PROBE_SETTINGS, MIN_ROOM)
    assert math.hypot(s.stroke, s.stroke_across) <= MIN_ROOM + 1e-9
    # the L still spans what a face's stroke must: 3 mm along its diagonal, 1.5 mm across, as the pad's travel (a
    # probe's legs run on until the pad has travelled them)
    assert s.stroke_overrun > 1.0
    assert math.hypot(s.stroke, s.stroke_across) >= 0.003
    assert s.stroke * s.stroke_across / math.hypot(s.stroke, s.stroke_across) >= 0.0015
    # with a room per leg (the level stroke), each leg within its own
    s = stroke_within(PROBE_SETTINGS, 0.02, 0.002)
    assert (s.stroke, s.stroke_across) == (PROBE_SETTINGS.stroke, 0.002)


def test_a_line_on_a_wall_between_two_faces_has_the_room_the_pad_has_between_them():
    # BOX01N at seed 1 lies with its slot on a side: the slot's back wall stands upright, 30 mm tall between the slot's
    # floor and ceiling, and the 12 mm pad touches it alone only within 6 mm of height, whatever the distance to the
    # wall's rim; the stroke there runs level along the slot, then up, each leg within the pad's room
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import build_episode
    from haptic.planning.finger_faces import MIN_LEVEL_ROOM, MIN_UP_ROOM, corner_lines

    ep = build_episode(EpisodeSpec(model="BOX01N", seed=1, executor="physics", verify="full"))
    poly, pose, config = ep.true_model, ep.world_from_model, ep.config
    back = 6
    assert abs(float(pose.rotate(poly.face_normals[back])[2])) < 1e-6  # upright
    lines = [line for v in (4, 5, 12, 13) for line in corner_lines(poly, pose, v, back, config)]
    assert lines
    for line in lines:
        assert line.room_up is not None and MIN_UP_ROOM <= line.room_up <= 0.006 + 1e-9
        assert line.room >= MIN_LEVEL_ROOM


@pytest.mark.slow
def test_a_verification_completes_with_probes_by_a_turned_finger(tmp_path):
    # trapezohedron_05 of the sized formula corpus (seed 1) rests with two vertices on the table whose faces lean
    # under 35°: the index pointing down cannot press them, and the verification ended incomplete ("2 on the table
    # with neither an edge rising from them nor two of their faces in reach"). The reach solver finds a finger and
    # a wrist turn for a level line onto each face; the probes measure them, and the model is confirmed.
    from haptic.episode.loop import EpisodeObserver
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import run_episode
    from tests.test_episode_physics import _sized_corpus

    moves = []
    obs = EpisodeObserver(on_move=lambda i, res, *a: moves.append(res), on_failed_move=lambda i, res: moves.append(res))
    rec = run_episode(EpisodeSpec(model="trapezohedron_05", seed=1, executor="physics", verify="full",
                                  models=_sized_corpus(tmp_path)), observer=obs)  # fmt: skip
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    by_finger = [r for r in moves if r.move.kind == "probe" and r.move.finger is not None]
    assert by_finger, "no probe by a named finger"
    assert all(r.move.path is not None for r in by_finger)  # the planner's path, from the reach solver
    measured = [r for r in by_finger if r.ok and r.components]
    assert len(measured) >= 2
    assert rec.verified["finger_faces"]["faces_probed"] >= 2


def _top_vertex(poly, pose) -> int:
    return int(np.argmax(pose.apply(poly.vertices)[:, 2]))


def test_a_line_to_a_corner_touches_the_face_within_the_corner_with_room_for_a_stroke():
    poly, pose = _octahedron(0.1)
    config = _config()
    v = _top_vertex(poly, pose)
    inv = pose.inverse()
    for f in (int(f) for f in poly.vertex_faces[v]):
        lines = corner_lines(poly, pose, v, f, config)
        assert lines, f"face {f} has room within its corner at the top vertex"
        tri = corner_triangle(poly, v, f)
        n = pose.rotate(poly.face_normals[f])
        for line in lines:
            # the pad's touch: a pad's radius back from its centre where the line meets the face
            centre = line.start + (RUN_UP - config.pad_radius) * line.direction
            touch = inv.apply((centre - config.pad_radius * n)[None])
            assert in_corner(touch, tri, poly.face_normals[f], slack=-MIN_ROOM + 1e-6)[0]
            assert MIN_ROOM - 1e-9 <= line.room
            if line.room_up is None:
                # its room is the corner's, less than the face's where the corner's far side crosses the face
                assert in_corner(touch, tri, poly.face_normals[f], slack=-line.room + 1e-6)[0]
                continue
            # the stroke runs level, then up: the pad slid that far each way still touches the corner
            level = np.cross([0.0, 0.0, 1.0], n)
            level /= np.linalg.norm(level)
            up = np.cross(n, level)
            up = up if up[2] >= 0 else -up
            t = (centre - config.pad_radius * n)
            ends = [t + line.room * level, t - line.room * level, t + line.room_up * up]
            assert np.all(in_corner(inv.apply(np.array(ends)), tri, poly.face_normals[f], slack=1e-6))


def test_the_corner_probes_ask_nothing_while_some_vertex_cannot_be_placed():
    poly, pose, config, h = _setup()
    asked: list[ProbeMove] = []
    nobody = _nobody(asked)
    v = _top_vertex(poly, pose)
    table = _table_vertices(poly, pose)[0]
    faces = frozenset(int(f) for f in poly.vertex_faces[v])
    # a vertex on the table has faces whose corner the pad cannot touch clear of the table: nothing is asked
    below = frozenset(int(f) for f in poly.vertex_faces[table])
    everything = frozenset(range(poly.n_edges))
    probes = CornerProbes(nobody)
    assert probes.next(h, {v: faces, table: below}, everything, frozenset(), config) is None
    assert not asked and probes.no_position
    # the top vertex alone: its first face's lines are asked in turn and named used up when no finger reaches
    probes = CornerProbes(nobody)
    assert probes.next(h, {v: faces}, everything, frozenset(), config) is None
    first = min(faces)
    assert probes.used_up == [(v, first)] and probes.asked == len(asked) >= 1
    assert f"no finger reaches face {first} at {v}" in probes.unmeasured([v])
    # an edge at the vertex with neither itself nor its other end measured: nothing is asked, and that is named
    probes = CornerProbes(nobody)
    asked.clear()
    assert probes.next(h, {v: faces}, frozenset(), frozenset(), config) is None
    assert not asked and probes.open_edges == [v] and "neither itself nor its other end" in probes.unmeasured([v])
    probes = CornerProbes(_thumb)
    got = probes.next(h, {v: faces}, everything, frozenset(), config)
    assert got is not None and got.finger == "thumb" and probes.take() is got and probes.take() is None
    assert probes.probed == {(v, first): 1} and probes.fingers == {"thumb": 1}


def test_the_verification_probes_the_corners_of_a_vertex_out_of_reach_and_then_counts_it_placed():
    # the octahedron's top vertex taken as out of reach (every other vertex measured): once every vertex in reach is
    # measured the verification asks the reach test for a line within a corner of its faces and makes that probe;
    # with every face measured within its corner the vertex is placed
    poly, pose = _octahedron(0.1)
    asked: list[ProbeMove] = []

    def thumb(line, hypotheses):
        asked.append(line)
        return replace(line, finger="thumb")

    config = replace(_config(), finger_reach=thumb)
    v = _top_vertex(poly, pose)
    others = frozenset(range(poly.n_vertices)) - {v}
    every = frozenset(range(poly.n_faces))
    ver = Verifier("full", SensorNoise(), config)
    ver._hyp = Hypothesis(model="octahedron", poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
    ver.hidden = [v]
    ver.coverage = Coverage(frozenset(), frozenset(), others, every, frozenset(), others)
    it = Interpretation(poly, 0, {}, {}, {}, {}, pose, 0)
    assert ver._corner_probe_next([], it)
    move = ver.choose(ver._hyp, None, {}, ())
    assert move is not None and move.finger == "thumb" and len(asked) == 1 and ver.corner_probes.pending is None
    # each face touched round the middle of its corner at the vertex: placed
    faces = [int(f) for f in poly.vertex_faces[v]]
    data = []
    for i, f in enumerate(faces):
        tri = corner_triangle(poly, v, f)
        touched = pose.apply(0.8 * tri.mean(axis=0) + 0.2 * tri)  # three points round the corner's middle
        data.append(DataFace(i, pose.rotate(poly.face_normals[f]), touched, math.radians(1.0), 8e-4))
    measured = Interpretation(poly, 0, {i: f for i, f in enumerate(faces)}, {}, {}, {}, pose, 0)
    assert not placed_near(poly, data[:-1], Interpretation(poly, 0, {i: f for i, f in enumerate(faces[:-1])},
                                                           {}, {}, {}, pose, 0), pose, v, frozenset(), others)
    assert placed_near(poly, data, measured, pose, v, frozenset(), others)


@pytest.mark.slow
def test_a_probe_by_another_finger_measures_a_face_within_its_corner_at_a_vertex_out_of_reach():
    # BOX01N at seed 1 lies with its slot on a side: the slot's four inner corners are out of the index's reach. The
    # slot's back wall, level, is reached by the thumb turned level (scripts/reach_hidden.py); a line within the
    # wall's corner at one of them, carried out on the hand, measures the wall there and nowhere else: every touched
    # point in the corner triangle, the normal the model's.
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import build_episode
    from haptic.matching.acceptance import corner_triangle, in_corner
    from haptic.planning.finger_faces import corner_lines
    from haptic.planning.verify import TABLE_CONTACT, reachable_features

    ep = build_episode(EpisodeSpec(model="BOX01N", seed=1, executor="physics", verify="full"))
    poly, pose, config = ep.true_model, ep.world_from_model, ep.config
    reach = reachable_features(poly, pose, config)
    z = pose.apply(poly.vertices)[:, 2] - config.table_z
    hidden = [v for v in range(poly.n_vertices) if v not in reach[2] and z[v] > TABLE_CONTACT]
    assert len(hidden) == 4
    h = Hypothesis(model=poly.name, poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
    probe = None
    for v in hidden:
        for f in (int(f) for f in poly.vertex_faces[v]):
            if f in reach[0]:
                continue
            probe = next((g for g in (config.finger_reach(line, [h])
                                      for line in corner_lines(poly, pose, v, f, config)) if g is not None), None)
            if probe is not None:
                break
        if probe is not None:
            break
    assert probe is not None and probe.finger != "index"
    assert ep.executor.start().ok
    res = ep.executor.execute(probe)
    assert res.ok and res.components, res.reason
    face = res.components[0]
    tri = corner_triangle(poly, v, f)
    assert np.all(in_corner(pose.inverse().apply(face.points), tri, poly.face_normals[f], face.position_bound))
    assert float(face.normal @ pose.rotate(poly.face_normals[f])) > math.cos(math.radians(1.0))


def test_the_corner_probes_for_the_tables_shadow_ask_nothing_of_the_edges_and_another_finger_after_a_miss():
    # the octahedron's top vertex, no edge measured: placing it by its corners asks nothing (a chamfer of an edge
    # would not be seen), but the table's shadow asks only that its corners be measured: a line is asked. Its face
    # still to measure at the next decision, the finger that probed it measured nothing there: the next line is
    # asked of another finger first
    poly, pose, config, h = _setup()
    v = _top_vertex(poly, pose)
    faces = frozenset(int(f) for f in poly.vertex_faces[v])
    asked: list[tuple[str, tuple[str, ...]]] = []

    def reach(line, hypotheses, avoid=()):
        finger = next(f for f in ("index", "thumb") if f not in avoid)
        asked.append((finger, tuple(avoid)))
        return replace(line, finger=finger)

    probes = CornerProbes(reach)
    assert probes.next(h, {v: faces}, frozenset(), frozenset(), config) is None and not asked
    got = probes.next(h, {v: faces}, frozenset(), frozenset(), config, placing=False)
    assert got is not None and got.finger == "index" and probes.take() is got
    got = probes.next(h, {v: faces}, frozenset(), frozenset(), config, placing=False)
    assert got is not None and got.finger == "thumb" and asked[-1] == ("thumb", ("index",))
    assert probes.tried == {(v, min(faces)): ["index", "thumb"]} and probes.fingers == {"index": 1, "thumb": 1}


def test_the_verification_probes_the_corners_that_keep_a_vertex_out_of_the_tables_shadow():
    # trapezohedron_08 of the formula corpus lying on a kite: its two vertices 11 mm up cannot be placed by their
    # corners (a kite leaning under 56° leaves the pad no position within its corner, and an edge at each runs to a
    # table vertex nothing measures), but the table's shadow takes them with the corners of the two upright kites
    # measured there and the two edges rising out of it crossed: the verification asks for those corners first,
    # then for the edges (with the corners measured, :meth:`Verifier._ridges_next`)
    from haptic.geometry.shapes import trapezohedron
    from haptic.planning.verify import corners_out_of_shadow, ridges_out_of_shadow
    from tests.planning.test_verify_moves import _resting_on

    poly = trapezohedron(8, 0.0499, 0.00222)
    pose, config = _resting_on(poly, 0)
    asked: list[ProbeMove] = []

    def index(line, hypotheses, avoid=()):
        asked.append(line)
        return replace(line, finger="index")

    config = replace(config, finger_reach=index, concave_end_block=0.2)
    z = pose.apply(poly.vertices)[:, 2] - config.table_z
    hidden = [int(v) for v in np.flatnonzero((z > 0.005) & (z < 0.015))]
    assert len(hidden) == 2
    rising = frozenset().union(*(ridges_out_of_shadow(poly, pose, v, config) for v in hidden))
    edges = frozenset(range(poly.n_edges)) - rising
    vertices = frozenset(range(poly.n_vertices)) - set(hidden)
    every = frozenset(range(poly.n_faces))
    ver = Verifier("full", SensorNoise(), config)
    ver._hyp = Hypothesis(model=poly.name, poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
    ver.check = type("Check", (), {"world_from_model": pose})()
    ver._model = poly
    ver.hidden = hidden
    ver.coverage = Coverage(every, edges, vertices, every, edges, vertices)
    it = Interpretation(poly, 0, {}, {}, {}, {}, pose, 0)
    assert not ver._corner_probe_next([], it) and not ver._ridges_next([], it)
    # the faces rising from the middle measured, the top one 5 mm off its place: the acceptance test rejects the
    # data as they are, and nothing is probed
    up = pose.rotate(poly.face_normals)[:, 2]
    faces = [int(f) for f in np.flatnonzero(up > 0.1)]
    top = int(np.argmax(up))
    data = []
    for shift in (0.005, 0.0):
        data = []
        for i, f in enumerate(faces):
            loop = poly.vertices[list(poly.faces[f])]
            touched = pose.apply(0.8 * loop.mean(axis=0) + 0.2 * loop)
            touched += (shift if f == top else 0.0) * pose.rotate(poly.face_normals[f])
            data.append(DataFace(i, pose.rotate(poly.face_normals[f]), touched, math.radians(1.0), 8e-4))
        measured = Interpretation(poly, 0, dict(enumerate(faces)), {}, {}, {}, pose, 0)
        assert len(faces) >= 4 and ver._shadow_probe_next(data, measured) == (shift == 0.0)
    assert len(asked) == 1
    v, f = next(iter(ver.corner_probes.probed))
    assert v == hidden[0] and f in corners_out_of_shadow(poly, pose, v, config)
    move = ver.choose(ver._hyp, None, {}, ())
    assert move is not None and move.finger == "index" and ver.corner_probes.pending is None
