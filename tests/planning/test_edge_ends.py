"""Edge moves the hand cannot finish are predicted refused: toward an end where the pad on the ridge would meet
the table first, and (with ``concave_end_block``, the physics executor's setting) toward a concave edge's end
where no face blocks the pad -- only with a table, so the geometric setting is unchanged."""

from dataclasses import replace

import numpy as np
import pytest

from haptic.geometry import SE3, load_library
from haptic.matching.components import DataEdge
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import EdgeMove, SensorState
from haptic.planning.table import edge_end_on_table, hidden_concave_end, table_conflict

LIB = load_library()
TABLE_Z = 0.35
HAND = PlannerConfig(table_z=TABLE_Z, pad_radius=0.012, concave_end_block=0.2)


def _on_edge(name: str, pick):
    """Model ``name`` resting with model z = 0 on the table, the sensor on its first edge that ``pick(poly, e)``
    accepts, the data edge along the model edge (id 0): the true hypothesis, the state and the components."""
    poly = LIB[name]
    pose = SE3(np.eye(3), np.array([0.5, 0.0, TABLE_Z]))
    e = next(e for e in range(poly.n_edges) if pick(poly, e))
    p, b, length = poly.edge_points[e], poly.edge_directions[e], float(poly.edge_lengths[e])
    edge = DataEdge(0, pose.rotate(b), pose.apply(p), length, 1e-3, 1e-3, 1e-3)
    h = Hypothesis(name, poly, pose, {}, {0: e}, {})
    state = SensorState(pose.apply(p + 0.5 * length * b), face=1, edge=0, edge_faces=(1, 2))
    return h, state, {0: edge}, e


def _sense_toward(h: Hypothesis, e: int, up: bool) -> int:
    """The data sense (+1/-1) of an edge move along model edge ``e`` toward its higher (``up``) or lower end."""
    z = h.poly.vertices[h.poly.edges[e], 2]
    return 1 if (z[1] > z[0]) == up else -1


def test_an_edge_move_down_to_a_vertex_on_the_table_is_refused_and_up_is_not():
    h, state, comps, e = _on_edge("BOX01", lambda p, e: abs(p.edge_directions[e][2]) > 0.99)
    down, up = EdgeMove(_sense_toward(h, e, False)), EdgeMove(_sense_toward(h, e, True))
    assert edge_end_on_table(h, down, state, comps, HAND)
    assert not edge_end_on_table(h, up, state, comps, HAND)
    assert table_conflict(h, down, state, comps, HAND) == 1.0
    assert table_conflict(h, up, state, comps, HAND) == 0.0
    # without a table (the geometric setting) nothing is refused
    assert table_conflict(h, down, state, comps, PlannerConfig()) == 0.0


@pytest.mark.parametrize("name", ["BOX01N"])
def test_an_edge_move_toward_a_concave_ends_open_side_is_refused_only_for_the_hand(name):
    # a concave edge lying level, above the table: each end opens onto an end face (the surface falls away)
    h, state, comps, e = _on_edge(name, lambda p, e: p.edge_convexity[e] < 0 and abs(p.edge_directions[e][2]) < 1e-6)
    for sense in (1, -1):
        move = EdgeMove(sense)
        assert hidden_concave_end(h, move, state, comps, HAND)
        assert not edge_end_on_table(h, move, state, comps, HAND)
        assert table_conflict(h, move, state, comps, HAND) == 1.0
        assert not hidden_concave_end(h, move, state, comps, replace(HAND, concave_end_block=None))


def test_a_convex_edge_is_never_taken_for_a_hidden_concave_end():
    h, state, comps, e = _on_edge("BOX01N", lambda p, e: p.edge_convexity[e] > 0 and abs(p.edge_directions[e][2]) < 1e-6
                                  and p.vertices[p.edges[e], 2].min() > 0.01)  # fmt: skip
    for sense in (1, -1):
        assert not hidden_concave_end(h, EdgeMove(sense), state, comps, HAND)
        assert table_conflict(h, EdgeMove(sense), state, comps, HAND) == 0.0
