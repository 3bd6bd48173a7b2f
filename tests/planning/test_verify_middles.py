"""The faces' middles under ``full`` with probes (haptic.planning.verify): a middle counts as measured when a move
already made passed over it -- a face move's trace across the face, an edge traced past it -- and the
verification's tracing moves that pass over one are worth the probe they save."""

import numpy as np

from haptic.geometry import SE3, load_library
from haptic.geometry.shapes import box
from haptic.matching.components import DataEdge, SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import EdgeMove, FaceMove
from haptic.planning.search import simulate
from haptic.planning.verify import (
    MIDDLE_REACH,
    Verifier,
    _passed_middles,
    _through_middles,
    face_middle,
    middle_probe_cost,
    plan_verification_move,
    unmeasured_middles,
)
from tests.planning.test_verify_moves import _on_a_face

LIB = load_library()
ALL = PlannerConfig(moves="all")


def _top(poly) -> int:
    return int(np.argmax(poly.face_normals[:, 2]))


def test_a_face_moves_trace_over_the_middle_measures_it_and_its_ends_alone_do_not():
    b = LIB["BOX01"]
    pose = SE3.random(np.random.default_rng(3), 0.1)
    top = _top(b)
    loop = b.vertices[list(b.faces[top])]
    m = face_middle(b, top)
    # from near one corner, across the middle, to the far edge: both ends far from the middle
    start, end = 0.8 * loop[0] + 0.2 * m, m + 0.9 * (m - (0.8 * loop[0] + 0.2 * m))
    assert min(np.linalg.norm(start - m), np.linalg.norm(end - m)) > 5 * MIDDLE_REACH
    seg = pose.apply(np.stack([start, end]))
    faces = frozenset(range(b.n_faces))
    assert top in unmeasured_middles(b, pose, [], faces)
    assert top not in unmeasured_middles(b, pose, [], faces, [seg])
    # a trace that passes the middle farther than the reach does not count
    off = np.cross(b.face_normals[top], end - start)
    off *= 2 * MIDDLE_REACH / np.linalg.norm(off)
    assert top in unmeasured_middles(b, pose, [], faces, [pose.apply(np.stack([start + off, end + off]))])


def test_an_edge_traced_past_a_narrow_faces_middle_measures_it():
    """A face 8 mm wide has its middle 4 mm from its long edges: the edge traced along it, from end to end, passes
    within the reach; its two ends are far from the middle."""
    slab = box(0.1, 0.008, 0.06, name="slab")
    pose = SE3.identity()
    f = next(i for i in range(slab.n_faces) if abs(slab.face_normals[i, 2]) > 0.9)
    m = face_middle(slab, f)
    e = next(int(e) for e in slab.face_edges[f] if slab.edge_lengths[e] > 0.05)
    p, u, length = slab.edge_points[e], slab.edge_directions[e], float(slab.edge_lengths[e])
    assert np.linalg.norm(p - m) > 5 * MIDDLE_REACH and np.linalg.norm(p + length * u - m) > 5 * MIDDLE_REACH
    edge = DataEdge(0, u, p, length, 0.01, 1e-3, 1e-3)
    faces = frozenset({f})
    assert unmeasured_middles(slab, pose, [], faces) == [f]
    assert unmeasured_middles(slab, pose, [edge], faces) == []


def test_the_verifier_books_a_face_moves_trace_from_its_start_to_the_edge_it_met():
    h, state, comps, ex = _on_a_face("BOX01", 4)
    v = Verifier("full", SensorNoise(), ALL)
    f_m = h.faces[state.face]
    d = h.world_from_model.rotate(face_middle(h.poly, f_m)) + h.world_from_model.translation - state.position
    d -= (d @ comps[state.face].normal) * comps[state.face].normal
    result = ex.execute(FaceMove(d / np.linalg.norm(d)))
    assert result.ok
    v.observe(state, result)
    assert len(v.traces) == 1
    a, b = h.world_from_model.inverse().apply(v.traces[0])
    assert np.allclose(a, h.world_from_model.inverse().apply(state.position))
    # the end lies on the model edge the move met, on the face it crossed
    e = ex.truth[next(c.id for c in result.components if c.kind == "edge")][1]
    p, u = h.poly.edge_points[e], h.poly.edge_directions[e]
    assert np.linalg.norm((b - p) - ((b - p) @ u) * u) < 1e-9
    assert f_m in (h.poly.edge_left_face[e], h.poly.edge_right_face[e])
    # aimed through the middle: that face's middle is measured by the trace
    assert f_m not in unmeasured_middles(h.poly, h.world_from_model, [], frozenset({f_m}), v.traces)
    v.observe(state, ex.execute(EdgeMove(1)))  # an edge move traces no face
    assert len(v.traces) == 1


def test_a_face_move_through_the_current_faces_middle_is_offered_and_passes_over_it():
    h, state, comps, _ = _on_a_face("HEXPRISM01", 5)
    f_m = h.faces[state.face]
    assert _through_middles(h, state, comps, None) == []
    assert _through_middles(h, state, comps, {(f_m + 1) % h.poly.n_faces: np.zeros(3)}) == []
    middles = {f_m: face_middle(h.poly, f_m)}
    (move,) = _through_middles(h, state, comps, middles)
    sim = simulate(h, move, state, comps, ALL)
    assert sim is not None
    assert _passed_middles(h, state, sim[1], middles) == 1


def test_with_a_middle_to_probe_the_verification_takes_a_move_over_it_where_that_saves_the_probe():
    """From a face of the hexagonal prism with every vertex missing, at 8 poses: without middles the verification
    never chooses a move that passes over the face's middle; with the face's middle still to probe, a move that
    does is worth a probe more (:func:`middle_probe_cost`), and it is chosen where it costs less than that."""
    noise = SensorNoise()
    plain, credited = 0, 0
    for seed in range(8):
        h, state, comps, _ = _on_a_face("HEXPRISM01", seed)
        f_m = h.faces[state.face]
        missing = (frozenset(), frozenset(), frozenset(range(h.poly.n_vertices)))
        middles = {f_m: face_middle(h.poly, f_m)}

        def passes(move, h=h, state=state, comps=comps, middles=middles) -> int:
            sim = simulate(h, move, state, comps, ALL) if move.kind != "probe" else None
            return _passed_middles(h, state, sim[1], middles) if sim is not None else 0

        plain += passes(plan_verification_move(h, state, comps, missing, noise, ALL)[0])
        credited += passes(plan_verification_move(h, state, comps, missing, noise, ALL, middles=middles)[0])
    assert middle_probe_cost(LIB["HEXPRISM01"], ALL) > ALL.costs.c_p
    assert plain == 0
    assert credited >= 3


def test_a_trace_over_the_next_face_does_not_measure_a_narrow_faces_middle():
    """A face 8 mm wide has its middle 4 mm from its long edges: a trace over the face beside it, 2 mm below their
    common edge, passes within the reach of that middle but not over the face; the same trace on the face does."""
    slab = box(0.1, 0.008, 0.06, name="slab")
    pose = SE3.identity()
    f = next(i for i in range(slab.n_faces) if slab.face_normals[i, 2] > 0.9)  # the top, 8 mm wide
    m = face_middle(slab, f)
    side = next(i for i in range(slab.n_faces) if slab.face_normals[i, 1] > 0.9)
    edge_y = float(slab.vertices[:, 1].max())
    on_side = np.array([[m[0] - 0.03, edge_y, m[2] - 0.002], [m[0] + 0.03, edge_y, m[2] - 0.002]])
    assert abs(slab.face_normals[side] @ on_side[0] - slab.face_offsets[side]) < 1e-12
    assert np.linalg.norm(on_side.mean(axis=0) - m) < MIDDLE_REACH
    assert unmeasured_middles(slab, pose, [], frozenset({f}), [on_side]) == [f]
    on_top = np.array([[m[0] - 0.03, m[1] + 0.003, m[2]], [m[0] + 0.03, m[1] + 0.003, m[2]]])
    assert unmeasured_middles(slab, pose, [], frozenset({f}), [on_top]) == []
