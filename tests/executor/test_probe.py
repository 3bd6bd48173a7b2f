"""The geometric executor's free-space probe: exact contact plus noise within the bounds; misses; bad moves."""

import numpy as np
import pytest

from haptic.executor.geometric import GeometricExecutor, GeometricSettings
from haptic.geometry import SE3, load_library
from haptic.matching.components import SensorNoise
from haptic.planning.moves import FaceMove, ProbeMove

LIB = load_library()


def _executor(name="BOX01", seed=0, at_bounds=False):
    rng = np.random.default_rng(seed)
    ex = GeometricExecutor(LIB[name], SE3.random(rng, 0.1), SensorNoise(), rng,
                           settings=GeometricSettings(at_bounds=at_bounds))  # fmt: skip
    ex.start()
    return ex


def _at_face(ex, f, height=0.1):
    m, t = ex.model, ex.world_from_model
    p = t.apply(m.vertices[list(m.faces[f])].mean(axis=0))
    n = t.rotate(m.face_normals[f])
    return p, n, ProbeMove(p + height * n, -n, 2 * height)


@pytest.mark.parametrize("at_bounds", [False, True])
def test_a_hit_is_a_face_within_its_bounds_and_the_sensor_rests_on_it(at_bounds):
    ex = _executor(at_bounds=at_bounds)
    f = int(np.argmax(ex.model.face_areas))
    p, n, move = _at_face(ex, f)
    res = ex.execute(move)
    assert res.ok and len(res.components) == 1
    face = res.components[0]
    assert ex.truth[face.id] == ("face", f) and face.adjacent == ()
    off = abs(float((face.points[0] - p) @ n))
    ang = float(np.arccos(np.clip(face.normal @ n, -1, 1)))
    assert off <= face.position_bound + 1e-12 and ang <= face.normal_bound + 1e-9
    if at_bounds:
        assert off == pytest.approx(face.position_bound) and ang == pytest.approx(face.normal_bound, abs=1e-9)
    (free,) = res.free_space
    assert free.length == pytest.approx(0.1) and res.info["contact"] == pytest.approx(0.1)
    assert float(np.linalg.norm(free.start - move.start)) <= free.position_bound + 1e-12
    assert res.cost == pytest.approx(ex.costs.probe_move(res.distance))
    # the sensor is on the face it touched: tracing goes on from there
    assert ex.state.face == face.id
    u = np.cross(face.normal, [1.0, 0.0, 0.0])
    assert ex.execute(FaceMove(u / np.linalg.norm(u))).ok


def test_a_miss_reports_the_whole_line_free_and_leaves_the_sensor_where_it_was():
    ex = _executor()
    p, n, move = _at_face(ex, 0)
    before = ex.state
    away = ProbeMove(p + 0.05 * n, n, 0.1)  # heading away from the object
    res = ex.execute(away)
    assert res.ok and res.components == () and res.info["contact"] is None
    assert res.free_space[0].length == pytest.approx(0.1)
    assert ex.state is before
    back = float(np.linalg.norm(away.end - before.position))
    there = float(np.linalg.norm(away.start - before.position))
    assert res.distance == pytest.approx(there + 0.1 + back)


def test_bad_probes_are_refused_without_raising():
    ex = _executor()
    inside = ex.world_from_model.apply(ex.model.centroid)
    assert ex.execute(ProbeMove(inside, [0, 0, 1.0], 0.1)).status == "unreachable"
    assert ex.execute(ProbeMove([0, 0, 1.0], [0, 0, 2.0], 0.1)).status == "invalid"
    assert ex.execute(ProbeMove([0, 0, 1.0], [0, 0, 1.0], -1.0)).status == "invalid"
    assert ex.execute(ProbeMove([0, np.nan, 1.0], [0, 0, 1.0], 0.1)).status == "invalid"
    fresh = GeometricExecutor(LIB["BOX01"], SE3.identity())
    assert fresh.execute(ProbeMove([0, 0, 1.0], [0, 0, -1.0], 1.0)).status == "invalid"
