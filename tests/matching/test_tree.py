"""The interpretation tree on the seed's results (§2.5) and its incremental behaviour."""

import numpy as np
import pytest

from haptic.errors import MatchError
from haptic.executor.geometric import GeometricExecutor, random_walk
from haptic.geometry import SE3, load_library
from haptic.geometry.shapes import box
from haptic.matching.components import DataEdge, DataFace, SensorNoise
from haptic.matching.recognition import NO_MATCH, RECOGNIZED, recognize
from haptic.matching.tree import InterpretationTree
from haptic.planning.moves import EdgeMove, FaceMove, VertexMove

from .helpers import feed, true_leaves

LIB = load_library()


def _sub(*names):
    return {n: LIB[n] for n in names}


def _walk_until(tree, ex, rng, max_moves, done):
    """Random moves, feeding the tree after each, until ``done(tree)`` or the budget runs out."""
    feed(tree, ex)
    fed = len(ex.components)
    for _ in range(max_moves):
        if done(tree):
            break
        for _attempt in range(10):
            moves = ex.admissible_moves(rng, n_directions=1)
            res = ex.execute(moves[int(rng.integers(len(moves)))])
            if res.ok:
                break
        for c in ex.components[fed:]:
            tree.add(c)
        fed = len(ex.components)
    return tree


@pytest.mark.parametrize("seed", range(4))
def test_figure_6_box_and_wedge(seed):
    """Seed Figure 6: F, E, F, E, F on WEDGE01's box-like corner leaves both models; E, F more leave one."""
    rng = np.random.default_rng(seed)
    wedge = LIB["WEDGE01"]
    pose = SE3.random(rng, 0.1)
    ex = GeometricExecutor(wedge, pose, SensorNoise().scaled(0.5), rng)
    # back face (x = 0) → its bottom edge → bottom face → its front edge → front triangle (y = 0)
    ex.start(face=4, point_in_model=[0.0, 0.03, 0.03])
    for d in ([0, 0, -1.0], [0, -1.0, 0]):
        assert ex.execute(FaceMove(pose.rotate(np.array(d)))).ok
    tree = InterpretationTree(_sub("BOX01", "WEDGE01"))
    counts = feed(tree, ex)
    assert [c.kind for c in ex.components] == ["face", "edge", "face", "edge", "face"]
    summary = tree.summary()
    assert summary.get("BOX01", 0) >= 2 and summary.get("WEDGE01", 0) >= 2, (counts, summary)
    # across the front triangle to the slanted edge and onto the slanted face
    res = ex.execute(FaceMove(pose.rotate(np.array([1.0, 0, 0]))))
    assert res.ok and [c.kind for c in res.components] == ["edge", "face"]
    for c in res.components:
        tree.add(c)
    assert tree.summary() == {"WEDGE01": 1}
    assert len(true_leaves(tree, ex)) == 1


@pytest.mark.parametrize(("data", "other"), [("TETRA01L", "TETRA01R"), ("TETRA01R", "TETRA01L")])
def test_mirror_tetrahedra_are_told_apart(data, other):
    moves = []
    for seed in range(8):
        rng = np.random.default_rng(seed)
        ex = GeometricExecutor(LIB[data], SE3.random(rng, 0.1), SensorNoise(), rng)
        ex.start()
        tree = _walk_until(InterpretationTree(_sub(data, other)), ex, rng, 40, lambda t: other not in t.summary())
        assert other not in tree.summary(), (seed, tree.summary())
        assert len(true_leaves(tree, ex)) == 1
        moves.append(len(ex.components))
    assert np.median(moves) <= 12, moves


@pytest.mark.parametrize(("data", "other"), [("BOX01N", "BOX01P"), ("BOX01P", "BOX01N")])
def test_notched_boxes_are_told_apart(data, other):
    rejected = 0
    for seed in range(4):
        rng = np.random.default_rng(seed)
        ex = GeometricExecutor(LIB[data], SE3.random(rng, 0.1), SensorNoise(), rng)
        ex.start()
        tree = _walk_until(InterpretationTree(_sub(data, other)), ex, rng, 120, lambda t: other not in t.summary())
        assert len(true_leaves(tree, ex)) == 1
        rejected += other not in tree.summary()
    assert rejected == 4


def test_box_ends_with_four_pose_equivalent_interpretations():
    for seed in range(3):
        rng = np.random.default_rng(seed)
        ex = GeometricExecutor(LIB["BOX01"], SE3.random(rng, 0.1), SensorNoise(), rng)
        ex.start()
        tree = _walk_until(InterpretationTree(LIB), ex, rng, 150, lambda t: recognize(t).status != "exploring")
        rec = recognize(tree)
        assert rec.status == RECOGNIZED and rec.model == "BOX01"
        assert tree.count == 4 and len(rec.classes) == 1 and len(rec.classes[0].leaves) == 4


def test_object_not_in_library_ends_with_no_match():
    other = box(0.09, 0.075, 0.055, name="BOX_ODD")
    for seed in range(5):
        rng = np.random.default_rng(seed)
        ex = GeometricExecutor(other, SE3.random(rng, 0.1), SensorNoise(), rng)
        ex.start()
        seen = []
        tree = InterpretationTree(LIB)

        def done(t, seen=seen):
            seen.append(recognize(t).status)
            return t.count == 0

        _walk_until(tree, ex, rng, 150, done)
        assert recognize(tree).status == NO_MATCH
        assert RECOGNIZED not in seen


def test_first_component_pairs_with_every_model_face():
    rng = np.random.default_rng(0)
    ex = GeometricExecutor(LIB["PYR01"], SE3.random(rng, 0.1), SensorNoise(), rng)
    ex.start()
    tree = InterpretationTree(LIB)
    assert tree.add(ex.components[0]) == sum(m.n_faces for m in LIB.values())


def test_first_edge_pairs_by_the_length_index_as_by_a_scan():
    """A tree started from an edge takes its candidates from the library's length index: exactly the model
    edges a scan of the intrinsic test keeps, in global order."""
    from haptic.matching import constraints as C

    lib = InterpretationTree(LIB).library
    bounds = {"direction_bound": 0.01, "position_bound": 1e-3, "length_bound": 2e-3}
    eps = C.edge_length_epsilon(bounds["length_bound"], bounds["position_bound"], bounds["direction_bound"])
    sizes = []
    # explored intervals from nothing to longer than any model edge, and right at the boundary of some
    lengths = [1e-4, *np.quantile(lib.edge_length, [0.25, 0.5, 0.9]), *(lib.edge_length[:5] + eps), 1.0]
    for length in lengths:
        first = DataEdge(id=0, direction=(1, 0, 0), point=(0, 0, 0), length=float(length), **bounds)
        tree = InterpretationTree(lib)
        tree.add(first)
        scan = np.flatnonzero(C.edge_length_test(first.length, lib.edge_length, eps))
        assert np.array_equal(tree.assignments[:, 0], scan)
        sizes.append(len(scan))
    assert sizes[0] == lib.count(1) and sizes[-1] == 0 and 0 < sizes[2] < lib.count(1)


def test_test_predicts_without_changing_the_tree():
    rng = np.random.default_rng(3)
    ex = GeometricExecutor(LIB["WEDGE01"], SE3.random(rng, 0.1), SensorNoise(), rng)
    random_walk(ex, 3, rng)
    comps = ex.components
    tree = InterpretationTree(LIB)
    for c in comps[:-1]:
        tree.add(c)
    before = (tree.count, tree.assignments.copy())
    keep = tree.test(comps[-1])
    assert tree.count == before[0] and np.array_equal(tree.assignments, before[1])
    assert keep.shape == (tree.count,)
    # the survivors of the real add are exactly the children of the leaves test() kept
    tree.add(comps[-1])
    assert keep.any() == (tree.count > 0)


def test_rereported_edge_retests_and_can_only_prune():
    rng = np.random.default_rng(4)
    ex = GeometricExecutor(LIB["LBLOCK01"], SE3.random(rng, 0.1), SensorNoise(), rng)
    ex.start()
    ex.execute(ex.admissible_moves(rng, 1)[0])
    ex.execute(EdgeMove(1))
    edges = [c for c in ex.components if c.kind == "edge"]
    assert len(edges) == 2 and edges[0].id == edges[1].id and edges[1].length > edges[0].length
    tree = InterpretationTree(LIB)
    counts = feed(tree, ex)
    assert counts[3] <= counts[2]
    assert len(true_leaves(tree, ex)) >= 1


def test_bad_input_raises_match_error():
    tree = InterpretationTree(LIB)
    face = DataFace(0, [0, 0, 1.0], [[0, 0, 0]], 0.01, 0.001)
    tree.add(face)
    with pytest.raises(MatchError, match="out of order"):
        tree.add(DataFace(5, [0, 0, 1.0], [[0, 0, 0]], 0.01, 0.001))
    with pytest.raises(MatchError, match="not an earlier component"):
        tree.add(DataEdge(1, [1.0, 0, 0], [0, 0, 0], 0.01, 0.01, 0.001, 0.001, adjacent=(7,)))
    with pytest.raises(MatchError, match="only an edge may be re-reported"):
        tree.add(DataFace(0, [0, 0, 1.0], [[0, 0, 0]], 0.01, 0.001))
    with pytest.raises(MatchError, match="not a data component"):
        tree.add("F0")


def test_vertex_move_data_are_consistent():
    rng = np.random.default_rng(7)
    ex = GeometricExecutor(LIB["HEXPRISM01"], SE3.random(rng, 0.1), SensorNoise(), rng)
    ex.start()
    assert ex.execute(ex.admissible_moves(rng, 1)[0]).ok
    assert ex.execute(EdgeMove(-1)).ok
    assert ex.execute(VertexMove(ex.state.edge_faces[0])).ok
    tree = InterpretationTree(LIB)
    feed(tree, ex)
    assert len(true_leaves(tree, ex)) >= 1
    assert set(tree.summary()) <= {"HEXPRISM01", "FRAME01", "BOX01", "BOX01N", "BOX01P", "LBLOCK01", "WEDGE01"}


def test_retain_keeps_each_kept_leaf_with_its_own_pose():
    # poses are kept per leaf between adds: after leaves are eliminated, a leaf's pose must still be its own
    rng = np.random.default_rng(4)
    ex = GeometricExecutor(LIB["BOX01"], SE3.random(rng, 0.1), SensorNoise(), rng)
    random_walk(ex, 3, rng)
    posed, fresh = InterpretationTree(LIB), InterpretationTree(LIB)
    for c in ex.components:
        posed.add(c)
        fresh.add(c)
    n = posed.count
    assert n > 4
    posed.poses(range(n))  # kept for the leaves as they are numbered now
    keep = np.arange(n) % 3 == 1
    posed.retain(keep)
    fresh.retain(keep)
    for a, b in zip(posed.poses(range(posed.count)), fresh.poses(range(fresh.count)), strict=True):
        assert (a is None) == (b is None)
        if a is not None:
            assert np.allclose(a.as_matrix(), b.as_matrix(), atol=1e-12)
