"""Where look-alike hypotheses disagree (haptic.planning.disagree)."""

import numpy as np

from haptic.geometry import load_library
from haptic.geometry.polyhedron import LearnedBounds
from haptic.geometry.se3 import SE3, quat_to_matrix
from haptic.matching.components import SensorNoise
from haptic.planning.disagree import disagreeing_vertices, look_alikes
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.move_scores import Context
from haptic.planning.moves import SensorState


def _moved(poly, v, offset, bounds=None):
    from haptic.geometry import Polyhedron

    verts = np.array(poly.vertices, float)
    verts[v] += offset
    return Polyhedron.from_faces(verts, [list(f) for f in poly.faces], name=poly.name + "_MOVED",
                                 learned_bounds=bounds)  # fmt: skip


def _context(polys, pose, paired=()):
    hyps = [Hypothesis(p.name, p, pose, {}, {}, {k: v for k, v in enumerate(paired)}) for p in polys]
    return Context(hyps, SensorState(np.zeros(3), 0), {}, SensorNoise())


def _pose(rng):
    q = rng.normal(size=4)
    return SE3(quat_to_matrix(q / np.linalg.norm(q)), rng.normal(size=3) * 0.1)


def test_the_moved_vertex_is_where_two_look_alikes_disagree():
    rng = np.random.default_rng(3)
    tetra = load_library()["TETRA01L"]
    for _ in range(5):  # at any pose, the same vertex of each
        v = int(rng.integers(tetra.n_vertices))
        moved = _moved(tetra, v, 4e-3 * np.array([1.0, -1.0, 1.0]) / np.sqrt(3), LearnedBounds(0.016, 6e-4, 0.022))
        ctx = _context([tetra, moved], _pose(rng))
        assert look_alikes(ctx)
        assert [(h.model, set(ids)) for h, ids in disagreeing_vertices(ctx)] == [(tetra.name, {v}), (moved.name, {v})]


def test_a_vertex_within_the_bounds_is_no_disagreement():
    tetra = load_library()["TETRA01L"]
    moved = _moved(tetra, 2, np.array([0.0, 0.0, 0.8e-3]), LearnedBounds(0.016, 6e-4, 0.022))
    assert disagreeing_vertices(_context([tetra, moved], SE3.identity())) == []


def test_a_vertex_measured_is_no_target_and_other_shapes_are_no_look_alikes():
    lib = load_library()
    tetra = lib["TETRA01L"]
    moved = _moved(tetra, 2, np.array([0.0, 0.0, 4e-3]))
    assert disagreeing_vertices(_context([tetra, moved], SE3.identity(), paired=(2,))) == []
    assert not look_alikes(_context([tetra, lib["BOX01"]], SE3.identity()))
