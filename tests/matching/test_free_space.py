"""Matching with free-space probes: a hit is a face adjacent to nothing, a miss is free space.

Soundness (property, in the manner of ``test_soundness.py``): with noise inside the error bounds, and with
every draw exactly at its bound, neither probe hits nor misses (grazing ones included) prune the true
interpretation. And the constraints do prune: a segment through a posed model contradicts it.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from haptic.errors import MatchError
from haptic.executor.geometric import GeometricExecutor, GeometricSettings, random_walk
from haptic.geometry import SE3, load_library, tracing
from haptic.matching.components import DataFace, SensorNoise
from haptic.matching.free_space import MAX_POSED, FreeSegment, apply_probes, free_segment_consistent, probe_face
from haptic.matching.library import LibraryArrays
from haptic.matching.recognition import PoseTolerance
from haptic.matching.tree import InterpretationTree
from haptic.planning.moves import CostModel, ProbeMove

from .helpers import true_leaves

LIB = load_library()
NAMES = sorted(LIB)
ARRAYS = LibraryArrays.build(LIB)


def random_probe(ex: GeometricExecutor, rng: np.random.Generator) -> ProbeMove:
    """A line at the true object (evaluation side): aimed at a random surface point from outside its face, or
    grazing its face's plane at a height of 0-3 mm (a near miss, or a hit on another part)."""
    m, t = ex.model, ex.world_from_model
    f = int(rng.choice(m.n_faces, p=m.face_areas / m.face_areas.sum()))
    p = t.apply(tracing.random_face_point(m, f, rng, margin=0.0))
    n = t.rotate(m.face_normals[f])
    v = rng.normal(size=3)
    v /= np.linalg.norm(v)
    if rng.random() < 0.5:
        u = v - max(0.0, float(v @ n) + 0.3) * n
        u /= np.linalg.norm(u)
        if u @ n > -0.2:
            u = -n
        start = p - 0.15 * u
    else:
        u = v - (v @ n) * n
        u /= np.linalg.norm(u)
        start = p + rng.uniform(0.0, 0.003) * n - 0.15 * u
    return ProbeMove(start, u, 0.3)


def _check(name: str, seed: int, n_moves: int, n_probes: int, level: float, at_bounds: bool) -> tuple[int, int]:
    rng = np.random.default_rng(seed)
    ex = GeometricExecutor(
        LIB[name], SE3.random(rng, 0.2), SensorNoise().scaled(level), rng,
        settings=GeometricSettings(at_bounds=at_bounds),
    )  # fmt: skip
    random_walk(ex, n_moves, rng)
    tree = InterpretationTree(ARRAYS)
    for c in ex.components:
        tree.add(c)
    free, hits, outcome = [], [], [0, 0]
    for _ in range(n_probes):
        res = _probe_and_check(ex, tree, random_probe(ex, rng), free, hits, (name, seed))
        if res is not None:
            outcome[len(res.components)] += 1
    return outcome[0], outcome[1]


def _probe_and_check(ex, tree, move, free: list, hits: list, label: tuple):
    """Carry out ``move``, match its data (hits in the tree, then the probe filter over all the probe data so
    far), asserting after each step that the true interpretation is left; the result, None when it failed."""
    res = ex.execute(move)
    if not res.ok:
        return None
    for c in res.components:
        tree.add(c)
        hits.append(c.id)
        assert len(true_leaves(tree, ex)) >= 1, (*label, "tree", c)
    free.extend(res.free_space)
    apply_probes(tree, free, hits)
    assert len(true_leaves(tree, ex)) >= 1, (*label, "probe filter", len(free), len(hits))
    return res


_common = settings(deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)


@pytest.mark.slow  # a property over many random episodes: make test, not make check
@settings(_common, max_examples=40)
@given(
    name=st.sampled_from(NAMES),
    seed=st.integers(0, 2**31),
    n_moves=st.integers(1, 6),
    n_probes=st.integers(1, 4),
    level=st.sampled_from([0.0, 0.3, 1.0, 2.0, 4.0]),
)
def test_true_interpretation_survives_probes_with_noise_inside_bounds(name, seed, n_moves, n_probes, level):
    _check(name, seed, n_moves, n_probes, level, at_bounds=False)


@pytest.mark.slow  # a property over many random episodes: make test, not make check
@settings(_common, max_examples=30)
@given(name=st.sampled_from(NAMES), seed=st.integers(0, 2**31), n_moves=st.integers(1, 6),
       n_probes=st.integers(1, 4))  # fmt: skip
def test_true_interpretation_survives_probes_with_noise_at_the_bounds(name, seed, n_moves, n_probes):
    _check(name, seed, n_moves, n_probes, 1.0, at_bounds=True)


def test_both_outcomes_occur_in_the_property_runs():
    """The generator does produce misses and hits (else the properties above would test one kind only)."""
    misses = hits = 0
    for seed in range(4):
        m, h = _check(NAMES[seed % len(NAMES)], seed, 2, 4, 1.0, at_bounds=True)
        misses, hits = misses + m, hits + h
    assert misses >= 2 and hits >= 2


@pytest.mark.parametrize("name", NAMES)
def test_a_grazing_miss_displaced_into_the_object_by_its_bound_keeps_the_truth(name):
    """The worst miss: a true path skimming a face 0.05 mm above it, reported displaced by exactly its bound
    toward the face (into the object), across the middle of the face."""
    rng = np.random.default_rng(4)
    ex = GeometricExecutor(LIB[name], SE3.random(rng, 0.1), SensorNoise(), rng,
                           settings=GeometricSettings(at_bounds=True))  # fmt: skip
    random_walk(ex, 6, rng)
    tree = InterpretationTree(ARRAYS)
    for c in ex.components:
        tree.add(c)
    m, t = ex.model, ex.world_from_model
    rho = ex.noise.k * ex.noise.position_sigma
    segments = []
    for f in rng.permutation(m.n_faces)[:4]:
        n = t.rotate(m.face_normals[f])
        p = t.apply(tracing.random_face_point(m, f, rng, margin=0.002))
        u = np.cross(n, rng.normal(size=3))
        u /= np.linalg.norm(u)
        start = p + 5e-5 * n - 0.15 * u
        if ex.execute(ProbeMove(start, u, 0.3)).components:
            continue  # the path meets another part of the object: not a miss
        segments.append(FreeSegment(start - rho * n, u, 0.3, rho))
    assert segments
    (leaf,) = true_leaves(tree, ex)[:1]
    assert tree.count <= MAX_POSED and tree.interpretation(int(leaf)).world_from_model is not None  # tested
    apply_probes(tree, segments)
    assert len(true_leaves(tree, ex)) >= 1


def test_a_segment_through_the_posed_model_contradicts_it():
    poly = LIB["BOX01"]
    pose = SE3.random(np.random.default_rng(1), 0.1)
    tol = PoseTolerance.from_data([DataFace(0, [0, 0, 1], [[0, 0, 0]], np.deg2rad(0.9), 0.6e-3)])
    c = pose.apply(poly.centroid)
    u = pose.rotate(np.array([1.0, 0.0, 0.0]))
    half = 0.5 * float(poly.extents[0])
    through = FreeSegment(c - (half + 0.05) * u, u, 2 * half + 0.1, 0.6e-3)
    assert not free_segment_consistent(poly, pose, through, tol)
    stops_short = FreeSegment(c - (half + 0.05) * u, u, 0.05, 0.6e-3)  # ends at the surface
    assert free_segment_consistent(poly, pose, stops_short, tol)
    # a segment entering by less than the bounds (the pose error grows with the distance from the centroid)
    shallow = FreeSegment(c - (half + 0.05) * u, u, 0.05 + 0.002, 0.6e-3)
    assert free_segment_consistent(poly, pose, shallow, tol)


def test_probe_hits_prune_by_the_face_pair_angle_without_adjacency():
    """A hit pairs with every model face; the face-pair angle with the earlier face (seed §2.6) keeps only the
    pairings at the right angle."""
    rng = np.random.default_rng(5)
    ex = GeometricExecutor(LIB["PYR01"], SE3.random(rng, 0.1), SensorNoise(), rng)
    ex.start()
    tree = InterpretationTree(ARRAYS)
    tree.add(ex.components[0])
    n_faces = sum(p.n_faces for p in LIB.values())
    m = ex.model
    f = int(np.argmax(m.face_areas))
    p = ex.world_from_model.apply(m.vertices[list(m.faces[f])].mean(axis=0))
    n = ex.world_from_model.rotate(m.face_normals[f])
    res = ex.execute(ProbeMove(p + 0.1 * n, -n, 0.2))
    assert res.ok and len(res.components) == 1 and res.components[0].adjacent == ()
    before = tree.count
    tree.add(res.components[0])
    assert tree.count < before * n_faces / 4


def test_probe_face_and_free_segment_records():
    f = probe_face(3, [0.1, 0.2, 0.3], [0, 0, 1], 0.01, 0.001)
    assert f.points.shape == (1, 3) and f.adjacent == () and f.id == 3
    s = FreeSegment([0, 0, 0], [1, 0, 0], 0.2, 1e-3)
    assert FreeSegment.from_dict(s.to_dict()).end == pytest.approx([0.2, 0.0, 0.0])


def test_retain_checks_its_mask():
    tree = InterpretationTree(ARRAYS)
    tree.add(DataFace(0, [0, 0, 1], [[0, 0, 0]], 0.01, 0.001))
    with pytest.raises(MatchError, match="one flag per leaf"):
        tree.retain(np.ones(tree.count + 1, dtype=bool))
    keep = np.zeros(tree.count, dtype=bool)
    keep[:3] = True
    assert tree.retain(keep) == 3 and tree.counts[-1] == 3


def test_probe_cost_is_a_constant_plus_free_space_distance():
    costs = CostModel(c_p=2.0, c_s=20.0)
    assert costs.probe_move(0.0) == 2.0
    assert costs.probe_move(0.1) == pytest.approx(4.0)


def _check_probes_alone(name: str, seed: int, n_probes: int, level: float, at_bounds: bool) -> int:
    """The start, then probes only: the opening's lines toward the region the contacts leave (as under ``--moves
    probing``, before poses), every few a random line at the object; returns how many hits."""
    from haptic.planning.opening_probes import LibraryExtent, opening_probes

    rng = np.random.default_rng(seed)
    ex = GeometricExecutor(
        LIB[name], SE3.random(rng, 0.2), SensorNoise().scaled(level), rng,
        settings=GeometricSettings(at_bounds=at_bounds),
    )  # fmt: skip
    extent = LibraryExtent.of(LIB.values())
    tree = InterpretationTree(ARRAYS)
    tree.add(ex.start().components[0])
    free, hits = [], []
    for k in range(n_probes):
        faces = [c for c in ex.components if isinstance(c, DataFace)]
        lines = opening_probes(faces, extent)
        move = random_probe(ex, rng) if k % 3 == 2 or not lines else lines[int(rng.integers(min(3, len(lines))))]
        _probe_and_check(ex, tree, move, free, hits, (name, seed))
    return len(hits)


@pytest.mark.slow  # a property over many random episodes: make test, not make check
@settings(_common, max_examples=30)
@given(name=st.sampled_from(NAMES), seed=st.integers(0, 2**31), n_probes=st.integers(2, 6),
       level=st.sampled_from([0.0, 1.0, 3.0]), at_bounds=st.booleans())  # fmt: skip
def test_true_interpretation_survives_probes_alone(name, seed, n_probes, level, at_bounds):
    _check_probes_alone(name, seed, n_probes, level, at_bounds)


def test_opening_probes_hit_the_object():
    """The opening's lines do reach the object: most of them hit (else the property above tests misses only)."""
    hits = sum(_check_probes_alone(name, seed, 3, 1.0, False) for seed, name in enumerate(NAMES))
    assert hits >= 2 * len(NAMES)


def test_position_span_says_when_the_data_fix_a_position_in_every_direction():
    from haptic.matching.free_space import MIN_SPAN, position_span

    def face(i, n):
        return probe_face(i, np.zeros(3), np.asarray(n, dtype=float) / np.linalg.norm(n), 0.01, 0.0005)

    axes = [face(0, [1, 0, 0]), face(1, [0, 1, 0]), face(2, [0, 0, 1])]
    assert position_span(axes) == pytest.approx(1.0)
    assert position_span(axes[:2]) == 0.0  # two planes leave a line
    flat = [face(0, [1, 0, 0]), face(1, [0, 1, 0]), face(2, [1, 1, 0.1])]  # nearly coplanar normals
    assert position_span(flat) < MIN_SPAN <= position_span(axes)


def test_segments_whose_samples_are_bounded_within_their_margins_are_not_measured_and_the_verdict_is_the_same():
    """The free-space check measures only the samples whose depth bound exceeds their margin: the verdict of
    measuring every sample, for poses near and far from the truth."""
    from haptic.geometry.raycast import depth_samples_many
    from haptic.matching.free_space import free_margin, free_segments_consistent

    def every_sample(model, pose, free, tol):
        inv = pose.inverse()
        samples = depth_samples_many(model, inv.apply(np.array([s.start for s in free])),
                                     inv.rotate(np.array([s.direction for s in free])),
                                     np.array([s.length for s in free]))  # fmt: skip
        return all(not len(d) or (d <= free_margin(s, tol, pose, model, pose.apply(p))).all()
                   for s, (p, d) in zip(free, samples, strict=True))  # fmt: skip

    rng = np.random.default_rng(11)
    tol = PoseTolerance()
    verdicts = set()
    for name in ("BOX01", "LBLOCK01", "FRAME01", "WEDGE01"):
        model = LIB[name]
        for _ in range(40):
            pose = SE3.random(rng, 0.05)
            c = pose.apply(model.centroid)
            free = []
            for _ in range(int(rng.integers(1, 5))):
                u = rng.normal(size=3)
                u /= np.linalg.norm(u)
                start = c - u * rng.uniform(0.03, 0.15) + rng.normal(scale=0.02, size=3)
                free.append(FreeSegment(start, u, float(rng.uniform(0.01, 0.2)), 1e-3))
            want = every_sample(model, pose, free, tol)
            assert free_segments_consistent(model, pose, free, tol) == want
            verdicts.add(want)
    assert verdicts == {True, False}


def test_a_leafs_pose_check_kept_for_the_data_is_a_fresh_one_and_follows_retain():
    """The pose check the free-space test and the verification share (kept per leaf until the next add) equals a
    fresh :func:`~haptic.matching.acceptance.pose_check`, also after ``retain`` renumbers the leaves."""
    from haptic.matching.acceptance import leaf_pose_check, pose_check

    rng = np.random.default_rng(12)
    walk = GeometricExecutor(LIB["LBLOCK01"], SE3.random(rng, 0.1), SensorNoise(), rng)
    random_walk(walk, 3, rng)
    tree, checked = InterpretationTree(LIB), 0
    for count in map(tree.add, walk.components):
        n = min(count, 30)
        if n < 2:
            continue
        kept = [leaf_pose_check(tree, leaf) for leaf in range(n)]
        assert all(leaf_pose_check(tree, leaf) is k for leaf, k in enumerate(kept))  # kept, not recomputed
        keep = np.ones(tree.count, dtype=bool)
        keep[0] = False
        tree.retain(keep)
        for leaf in range(n - 1):
            it = tree.interpretation(leaf, with_pose=True, refine=True)
            fresh = pose_check(it.model, tree.data, it)
            got = leaf_pose_check(tree, leaf)
            assert got is kept[leaf + 1]
            assert (got.ok, got.worst, got.component, got.what) == (fresh.ok, fresh.worst, fresh.component, fresh.what)
            checked += 1
    assert checked > 10


def test_the_position_span_kept_in_the_tree_is_the_datas_own_after_every_add():
    """The free-space test reads the data's position span from the tree (``tree.data_memo``, computed once per
    add): after every add and every retain it is :func:`position_span` of the data then, to the bit, on random
    walks with probes; an add that kept the span of the data before it would fail here."""
    from haptic.matching.free_space import consistent_leaves, position_span

    seen = set()
    for seed in range(4):
        rng = np.random.default_rng(seed)
        ex = GeometricExecutor(LIB[NAMES[seed]], SE3.random(rng, 0.2), SensorNoise(), rng)
        random_walk(ex, 3, rng)
        tree = InterpretationTree(ARRAYS)
        free, hits = [], []
        moves = [(c,) for c in ex.components]
        for _ in range(3):
            res = ex.execute(random_probe(ex, rng))
            if res.ok:
                free.extend(res.free_space)
                moves.append(tuple(res.components))
                hits.extend(c.id for c in res.components)
        for cs in moves:
            for c in cs:
                tree.add(c)
            if tree.count == 0:
                break
            far = [FreeSegment(np.full(3, 1.0), np.array([1.0, 0, 0]), 0.1, 1e-3)]  # a miss far from the object
            tree.retain(consistent_leaves(tree, free or far, hits, max_posed=10**6))
            want = position_span(tree.data)
            assert tree.data_memo["position span"] == want
            seen.add(round(want, 6))
    assert len(seen) > 3  # the span changes along the walks


def test_position_span_takes_each_edges_own_directions_across_it():
    """:func:`position_span` keeps the directions across each data edge by the edge component: the span equals the
    one computed afresh, to the bit, and a re-reported edge (the same id, a longer edge in another direction) is a
    new component with its own directions."""
    from dataclasses import replace

    from haptic.matching.free_space import _ACROSS, position_span

    rng = np.random.default_rng(3)
    ex = GeometricExecutor(LIB["BOX01"], SE3.random(rng, 0.2), SensorNoise(), rng)
    random_walk(ex, 6, rng)
    data = list(ex.components)
    edges = [k for k, c in enumerate(data) if c.kind == "edge"]
    assert edges
    first = position_span(data)
    _ACROSS.clear()
    assert position_span(data) == first
    k = edges[0]
    turned = SE3.random(rng).rotate(data[k].direction)
    data[k] = replace(data[k], direction=turned / np.linalg.norm(turned), length=data[k].length + 0.01)
    again = position_span(data)
    _ACROSS.clear()
    assert position_span(data) == again != first
