"""The verification's tour (haptic.planning.tour): leg costs, the tour over the features still to measure, its
cost from wherever a move leaves the sensor, and the lower bound every verification's cost stays above."""

import itertools

import numpy as np
import pytest

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import load_library
from haptic.planning import kernels as planning_kernels
from haptic.planning.config import PlannerConfig
from haptic.planning.tour import (
    VERTEX,
    LegCosts,
    arrival_costs,
    features,
    least_path,
    leg_matrix,
    plan_tour,
    spanning_tree_bound,
    start_costs,
    tour_lower_bound,
)

LIB = load_library()
ALL, TRACING = LegCosts.of(PlannerConfig(moves="all")), LegCosts.of(PlannerConfig(moves="tracing"))


def _vertices(poly) -> np.ndarray:
    f = features(poly)
    return np.flatnonzero(f.kinds == VERTEX)


def _closed_cost(order, m) -> float:
    o = np.asarray(order)
    return float(m[o, np.roll(o, -1)].sum())


@pytest.mark.parametrize("legs", [ALL, TRACING], ids=["all", "tracing"])
def test_legs_are_symmetric_and_an_edge_between_near_vertices_is_the_way_along_it(legs):
    for name in ("BOX01", "LBLOCK01", "TETRA01L"):
        poly = LIB[name]
        keys = _vertices(poly)
        m = leg_matrix(poly, keys, legs)
        assert np.allclose(m, m.T) and np.all(np.diag(m) == 0) and np.all(m[~np.eye(len(keys), dtype=bool)] > 0)
        for e, (a, b) in enumerate(poly.edges):  # along the edge, or cheaper another way
            along = legs.turn + legs.edge_rate * poly.edge_lengths[e] + legs.vertex_event
            assert m[a, b] <= along + 1e-9
    # probes, where admitted, make no leg dearer
    poly = LIB["BOX01"]
    assert np.all(leg_matrix(poly, _vertices(poly), ALL) <= leg_matrix(poly, _vertices(poly), TRACING) + 1e-9)


def test_the_tour_visits_every_target_once_and_2opt_is_optimal_on_small_ones():
    for name in ("TETRA01R", "PYR01", "WEDGE01", "BOX01"):
        poly = LIB[name]
        keys = _vertices(poly)
        tour = plan_tour(poly, keys, ALL)
        assert sorted(tour.order) == sorted(int(k) for k in keys)
        m = leg_matrix(poly, keys, ALL)
        pos = {int(k): i for i, k in enumerate(keys)}
        assert tour.cost == pytest.approx(_closed_cost([pos[t] for t in tour.order], m))
        # against every tour (the first target fixed) on the models of up to 8 vertices
        best = min(_closed_cost((0, *p), m) for p in itertools.permutations(range(1, len(keys))))
        assert tour.cost <= best * 1.05 + 1e-9, name


def test_replanning_keeps_the_order_of_what_is_left():
    poly = LIB["BOX01N"]
    keys = _vertices(poly)
    first = plan_tour(poly, keys, TRACING)
    left = np.array(sorted(first.order[2:]))
    again = plan_tour(poly, left, TRACING, previous=first)
    assert sorted(again.order) == sorted(int(k) for k in left)
    m = leg_matrix(poly, left, TRACING)
    pos = {int(k): i for i, k in enumerate(left)}
    assert again.cost <= _closed_cost([pos[t] for t in first.order[2:]], m) + 1e-9


def test_cost_from_enters_where_cheapest_and_leaves_out_what_a_move_measured():
    poly = LIB["BOX01"]
    keys = _vertices(poly)
    tour = plan_tour(poly, keys, ALL)
    here = start_costs(poly, poly.vertices[0] + [0.0, 0.0, 0.0], None, None, keys, ALL)
    assert tour.cost_from(here) < tour.cost + here.min() + 1e-9  # open: one leg of the tour left out
    assert tour.cost_from(here, frozenset(int(k) for k in keys)) == 0.0
    one = frozenset(int(k) for k in keys[1:])
    assert tour.cost_from(here, one) == pytest.approx(here[0])
    assert tour.cost_from(here, frozenset({int(keys[3])})) <= tour.cost_from(here) + 1e-9


def test_on_an_edge_its_end_is_one_edge_move_away():
    poly = LIB["BOX01"]
    keys = _vertices(poly)
    a, b = (int(v) for v in poly.edges[0])
    at = poly.vertices[a] + 0.25 * (poly.vertices[b] - poly.vertices[a])
    cost = start_costs(poly, at, int(poly.edge_left_face[0]), 0, keys, TRACING)
    d = 0.75 * float(poly.edge_lengths[0])
    assert cost[b] == pytest.approx(min(TRACING.edge_rate * d + TRACING.vertex_event, cost[b]))
    assert cost[b] <= TRACING.edge_rate * d + TRACING.vertex_event + 1e-9


@pytest.mark.slow
@pytest.mark.parametrize("moves", ["all", "tracing"])
def test_no_verification_costs_less_than_its_lower_bound(moves):
    """Geometric episodes of the seed library: each verification's path cost is at least the lower bound the
    record gives (with the faces' middles under ``--moves all``), and the record has the tour planned at the start
    and the vertices' and the spanning tree's bounds."""
    seen = 0
    for k, name in enumerate(("BOX01", "PYR01", "WEDGE01", "TETRA01L", "LBLOCK01")):
        r = run_episode(EpisodeSpec(model=name, seed=100 + k, verify="full", moves=moves)).to_json()
        v = r["verified"]
        if "tour_bound" not in v:
            continue
        seen += 1
        assert v["cost"] >= v["tour_bound"] - 1e-6, (name, v["cost"], v["tour_bound"])
        # the tour is planned over the vertices: at least their bound, itself at least the spanning tree's
        assert v["tour_planned"] >= v["tour_vertex_bound"] - 1e-6
        assert v["tour_bound"] >= v["tour_vertex_bound"] - 1e-9
        assert v["tour_vertex_bound"] >= v["tour_tree_bound"] - 1e-9
    assert seen >= 4


def test_the_bound_grows_with_what_is_left_and_is_zero_without_vertices():
    poly = LIB["BOX01"]
    keys = _vertices(poly)
    here = poly.vertices[0]
    assert tour_lower_bound(poly, here, keys[:0], ALL) == 0.0
    assert tour_lower_bound(poly, here, keys[:4], ALL) <= tour_lower_bound(poly, here, keys, ALL)
    assert tour_lower_bound(poly, here, keys, ALL) <= tour_lower_bound(poly, here, keys, TRACING)


def test_every_vertex_but_the_first_adds_the_least_cost_of_getting_onto_an_edge_at_it():
    poly = LIB["LBLOCK01"]
    keys = _vertices(poly)
    for legs in (ALL, TRACING):
        arrive = arrival_costs(poly, legs)
        for v in range(poly.n_vertices):  # a face or vertex move's events, or going back along the shortest edge
            at = [e for e in range(poly.n_edges) if v in poly.edges[e]]
            back = (legs.edge_rate - legs.face_rate) * min(poly.edge_lengths[e] for e in at)
            assert arrive[v] == pytest.approx(min(legs.face_events, back))
        # at a vertex with nothing else to measure: only its detection (the sensor may be on its edge already)
        assert tour_lower_bound(poly, poly.vertices[0], keys[:1], legs) == pytest.approx(legs.vertex_event)
        # two vertices, the sensor at the first: the leg between them, two detections, the second's arrival
        d = float(np.linalg.norm(poly.vertices[1] - poly.vertices[0]))
        leg = min(legs.face_rate * d, legs.probe_fixed + legs.probe_rate * d) if legs.probes else legs.face_rate * d
        expected = leg + 2 * legs.vertex_event + arrive[1]
        assert tour_lower_bound(poly, poly.vertices[0], keys[:2], legs) == pytest.approx(expected)
        # on no edge (after a probe) the first vertex too is arrived at on an edge; on an edge, at its ends only
        assert tour_lower_bound(poly, poly.vertices[0], keys[:1], legs, frozenset()) == pytest.approx(
            legs.vertex_event + arrive[0])
        e = next(k for k in range(poly.n_edges) if 0 not in poly.edges[k])
        assert tour_lower_bound(poly, poly.vertices[0], keys[:1], legs, frozenset(poly.edges[e])) == pytest.approx(
            legs.vertex_event + arrive[0])


def _lower_legs(poly, position, vertex_ids, legs) -> np.ndarray:
    """The bound's legs between the sensor (0) and the vertices, written out: ``min(c_f d, c_p + c_s d)``."""
    p = np.vstack([position[None], poly.vertices[vertex_ids]])
    d = np.linalg.norm(p[:, None] - p[None], axis=2)
    return np.minimum(legs.face_rate * d, legs.probe_fixed + legs.probe_rate * d) if legs.probes else legs.face_rate * d


@pytest.mark.parametrize("legs", [ALL, TRACING], ids=["all", "tracing"])
def test_the_bound_is_the_best_order_over_its_legs_and_above_the_spanning_tree(legs):
    """A property test: random vertices (up to 7) of the libraries' models, random sensor places and edges; the bound
    is the least cost over every order of measuring them (brute force over the same legs, each vertex's arrival but
    the first's where the sensor may start on its edge, ``c_k`` each), and at least the spanning tree's; over the
    draws it is more than the spanning tree's somewhere."""
    rng = np.random.default_rng(31)
    lib = {**LIB, **load_library("assets/libraries/lookalike")}
    names = sorted(lib)
    above = 0
    for _ in range(60):
        poly = lib[names[int(rng.integers(len(names)))]]
        keys = _vertices(poly)
        n = int(rng.integers(1, min(7, poly.n_vertices) + 1))
        chosen = np.sort(rng.choice(len(keys), n, replace=False))
        targets = keys[chosen]
        lo, hi = poly.vertices.min(axis=0), poly.vertices.max(axis=0)
        here = lo + rng.random(3) * (hi - lo)
        way = int(rng.integers(3))  # any first vertex free, none, or the ends of a random edge
        first = None if way == 0 else frozenset() if way == 1 else frozenset(
            int(v) for v in poly.edges[int(rng.integers(poly.n_edges))])
        arrive = arrival_costs(poly, legs)[chosen]
        free = np.ones(n, bool) if first is None else np.isin(chosen, sorted(first))
        w = _lower_legs(poly, here, chosen, legs)
        brute = min(
            w[0, o[0] + 1] + (0.0 if free[o[0]] else arrive[o[0]])
            + sum(w[o[i - 1] + 1, o[i] + 1] + arrive[o[i]] for i in range(1, n))
            for o in itertools.permutations(range(n))
        ) + n * legs.vertex_event  # fmt: skip
        bound = tour_lower_bound(poly, here, targets, legs, first)
        tree = spanning_tree_bound(poly, here, targets, legs, first)
        assert bound == pytest.approx(brute, rel=1e-9, abs=1e-9)
        assert tree <= bound + 1e-9
        above += bound > tree + 1e-6
    assert above > 0


def test_middles_beyond_the_exact_path_keep_it_a_bound(monkeypatch):
    """A property test: with room in the exact path for fewer nodes than there are (the rest counted by what taking
    each out of a path at least saves), or for none (the spanning tree and every middle so), the bound stays at most
    the best order's cost over the same legs (brute force), on random vertices and middles of the seed models."""
    import haptic.planning.tour as tour_module
    from haptic.planning.verify import MIDDLE_REACH, face_middle

    rng = np.random.default_rng(7)
    names = sorted(LIB)
    for _ in range(30):
        poly = LIB[names[int(rng.integers(len(names)))]]
        keys = _vertices(poly)
        n, m = int(rng.integers(1, 4)), int(rng.integers(1, 4))
        chosen = np.sort(rng.choice(len(keys), n, replace=False))
        mids = np.array([face_middle(poly, int(f)) for f in rng.choice(poly.n_faces, m, replace=False)])
        here = poly.vertices[int(rng.integers(poly.n_vertices))] + rng.normal(0, 0.01, 3)
        monkeypatch.setattr(tour_module, "HELD_KARP_MOST", 16)
        exact = tour_lower_bound(poly, here, keys[chosen], ALL, None, mids, MIDDLE_REACH)
        for room in (n + m - 1, n, 0):
            monkeypatch.setattr(tour_module, "HELD_KARP_MOST", room)
            assert tour_lower_bound(poly, here, keys[chosen], ALL, None, mids, MIDDLE_REACH) <= exact + 1e-9


def test_middles_add_a_probe_each_and_the_bound_is_the_best_order_with_them():
    """A property test: random vertices and faces' middles (up to 6 nodes) of the seed models; the bound with the
    middles is the least cost over every order of the same legs (into a middle a probe over the distance less the
    reach, out of it a leg over the distance less the reach), at least the bound without them, somewhere more by
    nearly ``c_p`` a middle; a middle at the one vertex to measure, the sensor there, still costs a probe."""
    from haptic.planning.verify import MIDDLE_REACH, face_middle

    rng = np.random.default_rng(58)
    names = sorted(LIB)
    more = 0
    for _ in range(40):
        poly = LIB[names[int(rng.integers(len(names)))]]
        keys = _vertices(poly)
        n = int(rng.integers(1, 4))
        m = int(rng.integers(1, 4))
        chosen = np.sort(rng.choice(len(keys), n, replace=False))
        faces = rng.choice(poly.n_faces, m, replace=False)
        mids = np.array([face_middle(poly, int(f)) for f in faces])
        here = poly.vertices[int(rng.integers(poly.n_vertices))] + rng.normal(0, 0.01, 3)
        arrive = arrival_costs(poly, ALL)[chosen]
        pts = np.vstack([here[None], poly.vertices[chosen], mids])
        is_mid = np.arange(len(pts)) > n
        d = np.linalg.norm(pts[:, None] - pts[None], axis=2)
        d = np.maximum(d - MIDDLE_REACH * (is_mid[:, None].astype(float) + is_mid[None, :]), 0.0)
        leg = np.minimum(ALL.face_rate * d, ALL.probe_fixed + ALL.probe_rate * d)
        leg[:, is_mid] = ALL.probe_fixed + ALL.probe_rate * d[:, is_mid]
        enter = np.concatenate([arrive, np.zeros(m)])
        brute = min(
            leg[0, o[0] + 1] + sum(leg[o[i - 1] + 1, o[i] + 1] + enter[o[i]] for i in range(1, n + m))
            for o in itertools.permutations(range(n + m))
        ) + n * ALL.vertex_event  # fmt: skip
        bound = tour_lower_bound(poly, here, keys[chosen], ALL, None, mids, MIDDLE_REACH)
        alone = tour_lower_bound(poly, here, keys[chosen], ALL)
        assert bound == pytest.approx(brute, rel=1e-9, abs=1e-9)
        assert bound >= alone - 1e-9
        more += bound >= alone + m * (ALL.probe_fixed - 1.0)
    assert more > 0
    poly = LIB["BOX01"]
    one = tour_lower_bound(poly, poly.vertices[0], _vertices(poly)[:1], ALL, None, poly.vertices[:1], MIDDLE_REACH)
    assert one == pytest.approx(ALL.vertex_event + ALL.probe_fixed)


def test_only_a_probe_reaches_the_middles_the_bound_counts():
    """The faces whose middle the bound counts as a probe's (:func:`~haptic.planning.verify.probe_only_middles`):
    no point a traced move measures on the geometric executor (stepping onto a face, a vertex move's circle) lies
    within the middle's reach; some of FRAME01's faces, 16 mm wide, are not among them."""
    from haptic.executor.geometric import GeometricSettings
    from haptic.planning.verify import MIDDLE_REACH, TRACED_DEPTH, face_middle, probe_only_middles

    g = GeometricSettings()
    assert TRACED_DEPTH >= max(g.step_onto_face, g.vertex_radius, PlannerConfig().vertex_radius)
    for name in ("BOX01", "TETRA01L", "FRAME01", "LBLOCK01"):
        poly = LIB[name]
        ok = probe_only_middles(poly)
        for f in ok:
            loop = poly.vertices[list(poly.faces[f])]
            m = face_middle(poly, f)
            # every point of the face within the traced depth of its boundary is farther than the reach from m
            a, b = loop, np.roll(loop, -1, axis=0)
            for s in np.linspace(0.0, 1.0, 21):
                q = a + s * (b - a)
                assert np.linalg.norm(q - m, axis=1).min() > MIDDLE_REACH + TRACED_DEPTH
    assert len(probe_only_middles(LIB["BOX01"])) == LIB["BOX01"].n_faces
    frame = LIB["FRAME01"]
    assert 0 < len(probe_only_middles(frame)) < frame.n_faces  # the narrow faces' middles are near their edges


def test_least_path_is_exact_on_random_legs():
    """Held-Karp against brute force on random asymmetric legs and node costs, up to 7 nodes."""
    rng = np.random.default_rng(5)
    for _ in range(100):
        n = int(rng.integers(1, 8))
        w = rng.random((n + 1, n + 1))
        enter, first = rng.random(n), rng.random(n)
        brute = min(
            w[0, o[0] + 1] + first[o[0]] + sum(w[o[i - 1] + 1, o[i] + 1] + enter[o[i]] for i in range(1, n))
            for o in itertools.permutations(range(n))
        )
        assert least_path(w, enter, first) == pytest.approx(brute)
    assert least_path(np.zeros((1, 1)), np.zeros(0), np.zeros(0)) == 0.0


@pytest.mark.skipif(not planning_kernels.COMPILED, reason="numba not installed")
def test_compiled_least_path_is_the_numpy_one_to_the_bit(monkeypatch):
    """The compiled Held-Karp table gives the numpy form's value to the last bit, on random legs up to 12 nodes, on
    legs with many ties (small integers) and on the lower bounds' own legs (a box's vertices and faces' middles)."""
    rng = np.random.default_rng(11)
    cases = []
    for _ in range(150):
        n = int(rng.integers(1, 13))
        w = rng.random((n + 1, n + 1)) * rng.choice([1e-3, 1.0, 1e3])
        cases.append((w, rng.random(n), rng.random(n)))
        k = rng.integers(0, 4, (n + 1, n + 1)).astype(float)
        cases.append((k, rng.integers(0, 3, n).astype(float), np.zeros(n)))
    box = LIB["BOX01"]
    w = np.linalg.norm(box.vertices[:, None] - box.vertices[None], axis=2) * 7.3
    cases.append((w[:7, :7], arrival_costs(box, ALL)[1:7], np.zeros(6)))
    compiled = [least_path(w, e, f) for w, e, f in cases]
    monkeypatch.setattr(planning_kernels, "COMPILED", False)
    reference = [least_path(w, e, f) for w, e, f in cases]
    assert [float(x).hex() for x in compiled] == [float(x).hex() for x in reference]
