"""Efficiency of moves (seed §4.1)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from haptic.planning.efficiency import (
    class_weights,
    distinguishable,
    expected_eliminations,
    move_efficiency,
    outcome_groups,
)
from haptic.planning.moves import CostModel


def test_worked_example_of_section_4_1_1():
    """Distances 1.0, 2.8, 3.0, 3.2, 5.0; bound ±0.2; c_e 2.0, c_k 0.4 → 1.67, 0.5, 0.31, 0.44, 0.38; 0.66."""
    d = np.array([1.0, 2.8, 3.0, 3.2, 5.0])
    costs = CostModel(c_e=2.0, c_k=0.4)
    c = np.array([costs.edge_move(s) for s in d])
    assert np.allclose(c, [2.4, 6.0, 6.4, 6.8, 10.4])
    eliminated = distinguishable(d, [0.2]).sum(axis=1)
    assert eliminated.tolist() == [4, 3, 2, 3, 4]
    eff, per = move_efficiency(d, [0.2], c)
    assert np.allclose(per.round(2), [1.67, 0.5, 0.31, 0.44, 0.38])
    assert round(eff, 2) == 0.66


def test_second_attribute_breaks_ties():
    # same distance, different edge angle: the tie-break of §4.1.2 separates them
    o = np.array([[1.0, 0.5], [1.0, 0.9], [1.0, 0.52]])
    d = distinguishable(o, [0.1, 0.05])
    assert d[0, 1] and not d[0, 2] and d[1, 2]


def test_nan_never_distinguishes():
    o = np.array([[1.0], [np.nan], [3.0]])
    d = distinguishable(o, [0.1])
    assert not d[0, 1] and not d[1, 2] and d[0, 2]


def test_class_weights_share_each_models_weight():
    w = class_weights(["A", "A", "A", "B"])
    assert np.allclose(w, [1 / 6, 1 / 6, 1 / 6, 1 / 2])


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(0, 10, allow_nan=False), min_size=1, max_size=12), st.floats(0.01, 2))
def test_groups_partition_and_no_group_is_split_by_the_bound(values, bound):
    o = np.array(values)[:, None]
    groups = outcome_groups(o, [bound])
    assert sorted(np.concatenate(groups).tolist()) == list(range(len(values)))
    for g in groups:
        for i in g:
            # within a group every member has a chain of indistinguishable neighbours; across groups none
            others = np.setdiff1d(np.arange(len(values)), g)
            assert (np.abs(o[others, 0] - o[i, 0]) > bound).all()
    assert expected_eliminations(o, [bound]) <= len(values) - 1 + 1e-9
