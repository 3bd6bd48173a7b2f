"""The ideal-sensor executor: exact outcomes of the three moves, adjacency, noise within bounds, invalid moves."""

import subprocess
import sys

import numpy as np
import pytest

from haptic.executor.geometric import GeometricExecutor, random_walk
from haptic.geometry import SE3, load_library
from haptic.matching.components import DataEdge, DataFace, DataVertex, SensorNoise
from haptic.planning.moves import EdgeMove, FaceMove, VertexMove

LIB = load_library()


def _exact(name="BOX01", seed=0):
    rng = np.random.default_rng(seed)
    pose = SE3.random(rng, 0.1)
    return GeometricExecutor(LIB[name], pose, SensorNoise().scaled(0.0), rng), pose, rng


def test_executor_does_not_import_a_simulator():
    code = "import sys, haptic.executor, haptic.executor.geometric; print('mujoco' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_start_lands_on_a_face_and_acquires_its_normal():
    ex, pose, _ = _exact("WEDGE01")
    res = ex.start()
    assert res.ok and len(res.components) == 1
    f = res.components[0]
    assert isinstance(f, DataFace) and f.id == 0 and f.adjacent == ()
    true_face = ex.truth[0][1]
    assert np.allclose(f.normal, pose.rotate(ex.model.face_normals[true_face]))
    q = pose.inverse().apply(f.points)
    assert np.allclose(q @ ex.model.face_normals[true_face], ex.model.face_offsets[true_face])
    assert ex.state.face == 0 and ex.state.edge is None


def test_face_move_yields_an_adjacent_edge_and_face():
    ex, pose, rng = _exact()
    ex.start(face=1, point_in_model=[0.05, 0.04, 0.06])
    res = ex.execute(FaceMove(pose.rotate(np.array([1.0, 0, 0]))))
    assert res.ok
    edge, face = res.components
    assert isinstance(edge, DataEdge) and edge.adjacent == (0,)
    assert isinstance(face, DataFace) and face.adjacent == (edge.id,)
    assert res.distance == pytest.approx(0.05)
    assert res.cost == pytest.approx(ex.costs.face_move(0.05))
    e = ex.truth[edge.id][1]
    b_m = ex.model.edge_directions[e]
    assert abs(abs(edge.direction @ pose.rotate(b_m)) - 1) < 1e-12
    assert ex.state.edge == edge.id and ex.state.face == face.id and ex.state.edge_faces == (0, face.id)
    assert edge.length <= 2 * ex.settings.edge_probe + 1e-12


def test_edge_move_extends_the_edge_to_a_vertex():
    ex, pose, rng = _exact()
    ex.start(face=1, point_in_model=[0.05, 0.04, 0.06])
    edge0 = ex.execute(FaceMove(pose.rotate(np.array([1.0, 0, 0])))).components[0]
    res = ex.execute(EdgeMove(1))
    assert res.ok
    edge, vertex = res.components
    assert edge.id == edge0.id and edge.length > edge0.length
    assert isinstance(vertex, DataVertex) and vertex.adjacent == (edge.id,)
    assert edge.end_vertex == vertex.id and edge.start_vertex is None
    assert np.allclose(edge.end_point, vertex.position, atol=1e-9)
    v = ex.truth[vertex.id][1]
    assert np.allclose(vertex.position, pose.apply(ex.model.vertices[v]))
    assert ex.state.vertex == vertex.id
    # going the other way reaches the other vertex: the interval now spans the whole edge
    res = ex.execute(EdgeMove(-1))
    edge2 = res.components[0]
    assert edge2.start_vertex is not None and edge2.end_vertex == vertex.id
    assert edge2.length == pytest.approx(ex.model.edge_lengths[ex.truth[edge.id][1]])


def test_vertex_move_finds_the_next_edge_around_the_vertex():
    ex, pose, rng = _exact("PYR01", 2)
    ex.start()
    ex.execute(ex.admissible_moves(rng, 1)[0])
    ex.execute(EdgeMove(1))
    vid = ex.state.vertex
    res = ex.execute(VertexMove(ex.state.edge_faces[0]))
    assert res.ok
    edge, face = res.components
    assert set(edge.adjacent) == {vid, ex.state.edge_faces[0]}
    assert face.adjacent == (edge.id,)
    v = ex.truth[vid][1]
    e = ex.truth[edge.id][1]
    assert v in ex.model.edges[e]
    assert res.cost == pytest.approx(ex.costs.vertex_move(res.distance))


def test_invalid_moves_return_invalid_and_never_raise():
    ex, pose, rng = _exact()
    assert ex.execute(EdgeMove(1)).status == "invalid"  # before start
    ex.start()
    assert ex.execute(EdgeMove(1)).status == "invalid"  # no edge
    assert ex.execute(VertexMove(0)).status == "invalid"  # no vertex
    assert ex.execute(FaceMove(np.array([np.nan, 0, 0]))).status == "invalid"
    n = ex.components[0].normal
    assert ex.execute(FaceMove(n)).status == "invalid"  # out of the plane
    ex.execute(ex.admissible_moves(rng, 1)[0])
    assert ex.execute(EdgeMove(2)).status == "invalid"
    ex.execute(EdgeMove(1))
    assert ex.execute(EdgeMove(1)).status == "invalid"  # already at that vertex
    assert ex.execute(VertexMove(999)).status == "invalid"


def test_noise_stays_inside_the_reported_bounds():
    rng = np.random.default_rng(5)
    for name in ("TETRA01L", "LBLOCK01", "FRAME01"):
        pose = SE3.random(rng, 0.1)
        ex = GeometricExecutor(LIB[name], pose, SensorNoise().scaled(3.0), rng)
        random_walk(ex, 12, rng)
        m = ex.model
        for c in ex.components:
            kind, i = ex.truth[c.id]
            if kind == "face":
                n = pose.rotate(m.face_normals[i])
                assert np.arccos(np.clip(c.normal @ n, -1, 1)) <= c.normal_bound + 1e-12
                dist = pose.inverse().apply(c.points) @ m.face_normals[i] - m.face_offsets[i]
                assert np.abs(dist).max() <= c.position_bound + 1e-12
            elif kind == "edge":
                b = pose.rotate(m.edge_directions[i])
                assert np.arccos(min(abs(c.direction @ b), 1.0)) <= c.direction_bound + 1e-12
                p = pose.inverse().apply(c.point) - m.edge_points[i]
                perp = p - (p @ m.edge_directions[i]) * m.edge_directions[i]
                assert np.linalg.norm(perp) <= c.position_bound + 1e-12
            else:
                assert np.linalg.norm(c.position - pose.apply(m.vertices[i])) <= c.position_bound + 1e-12


def test_random_walk_is_reproducible_from_the_generator():
    def run():
        rng = np.random.default_rng(11)
        ex = GeometricExecutor(LIB["HEXPRISM01"], SE3.random(rng, 0.1), SensorNoise(), rng)
        random_walk(ex, 10, rng)
        return np.concatenate(
            [
                np.atleast_1d(getattr(c, "normal", getattr(c, "direction", None)))
                for c in ex.components
                if c.kind != "vertex"
            ]
        )

    assert np.array_equal(run(), run())


def test_a_placement_gives_a_face_per_finger_that_touches_and_a_failed_finger_fails_alone():
    import numpy as np

    from haptic.executor.geometric import GeometricExecutor
    from haptic.geometry import SE3, load_library
    from haptic.matching.components import DataFace, SensorNoise
    from haptic.planning.moves import CostModel, FingerApproach, PlacementMove

    box = load_library()["BOX01"]
    ex = GeometricExecutor(box, SE3.identity(), SensorNoise(), np.random.default_rng(0))
    here = ex.start(face=0).state.position
    hi, lo = box.vertices.max(axis=0), box.vertices.min(axis=0)
    mid = (hi + lo) / 2
    down = FingerApproach("index", np.array([mid[0], mid[1], hi[2] + 0.02]), np.array([0.0, 0.0, -1.0]), 0.05)
    side = FingerApproach("middle", np.array([hi[0] + 0.02, mid[1], mid[2]]), np.array([-1.0, 0.0, 0.0]), 0.05)
    away = FingerApproach("ring", np.array([hi[0] + 0.02, mid[1], hi[2] + 0.05]), np.array([-1.0, 0.0, 0.0]), 0.05)
    inside = FingerApproach("thumb", mid, np.array([0.0, 1.0, 0.0]), 0.05)
    res = ex.execute(PlacementMove((down, side, away, inside)))
    assert res.ok
    assert [f["status"] for f in res.info["fingers"]] == ["touched", "touched", "missed", "unreachable"]
    assert len(res.components) == 2 and all(isinstance(c, DataFace) and c.adjacent == () for c in res.components)
    assert np.allclose(res.components[0].normal, [0, 0, 1], atol=0.01)
    assert np.allclose(res.components[1].normal, [1, 0, 0], atol=0.01)
    assert len(res.free_space) == 3, "the lines of the fingers that closed, free up to contact or their end"
    assert res.state.face == res.components[0].id
    transfer = max(float(np.linalg.norm(f.start - here)) for f in (down, side, away))
    assert res.distance == pytest.approx(transfer + 0.05), "to the farthest line, then the longest closing (the miss)"
    assert res.cost == pytest.approx(CostModel().placement_move(res.distance, 4, 0)), "no strokes: normals at contact"
    bad = ex.execute(PlacementMove((inside, FingerApproach("index", mid, np.array([1.0, 0.0, 0.0]), 0.05))))
    assert not bad.ok and bad.status == "unreachable" and bad.components == ()
    assert "2 to 4" in ex.execute(PlacementMove((down,))).reason
