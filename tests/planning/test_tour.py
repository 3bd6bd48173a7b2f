"""The verification's tour (haptic.planning.tour): leg costs, the tour over the features still to measure, its
cost from wherever a move leaves the sensor, and the lower bound every verification's cost stays above."""

import itertools

import numpy as np
import pytest

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import load_library
from haptic.planning.config import PlannerConfig
from haptic.planning.tour import (
    VERTEX,
    LegCosts,
    arrival_costs,
    features,
    leg_matrix,
    plan_tour,
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
    record gives, and the record has the tour planned at the start."""
    seen = 0
    for k, name in enumerate(("BOX01", "PYR01", "WEDGE01", "TETRA01L", "LBLOCK01")):
        r = run_episode(EpisodeSpec(model=name, seed=100 + k, verify="full", moves=moves)).to_json()
        v = r["verified"]
        if "tour_bound" not in v:
            continue
        seen += 1
        assert v["cost"] >= v["tour_bound"] - 1e-6, (name, v["cost"], v["tour_bound"])
        assert v["tour_planned"] >= v["tour_bound"] - 1e-6
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
        # two vertices, the sensor at the first: the leg between them, two detections, one arrival
        d = float(np.linalg.norm(poly.vertices[1] - poly.vertices[0]))
        leg = min(legs.face_rate * d, legs.probe_fixed + legs.probe_rate * d) if legs.probes else legs.face_rate * d
        expected = leg + 2 * legs.vertex_event + min(arrive[0], arrive[1])
        assert tour_lower_bound(poly, poly.vertices[0], keys[:2], legs) == pytest.approx(expected)
