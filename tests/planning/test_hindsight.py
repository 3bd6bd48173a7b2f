"""The hindsight optimum over tracing moves and probes (:func:`haptic.bench.oracle.hindsight_optimum_probing`)."""

import pytest

from haptic.bench.oracle import hindsight_optimum_probing
from haptic.bench.runner import plan_sweep
from haptic.episode.worlds import run_episode
from haptic.geometry import load_library
from haptic.planning.registry import make_policy

pytestmark = pytest.mark.slow  # an exhaustive search per episode

SMALL = ["BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R"]
LIB = {k: v for k, v in load_library().items() if k in SMALL}


def test_the_search_starts_from_the_episodes_opening_and_probes_make_it_no_dearer():
    """With ``--moves all`` the search starts where the episode's own opening leaves every policy (the planner's
    episode passes through that cost), finds a recognising sequence, and with probes among its candidates is never
    dearer than with tracing moves alone, and cheaper on some episode."""
    searched, cheaper = 0, 0
    for spec in plan_sweep(["BOX01", "BOX01N", "BOX01P"], 4, seed=7, policies=["planner"], verify="none", moves="all"):
        with_probes = hindsight_optimum_probing(spec, library=LIB, max_depth=2)
        tracing = hindsight_optimum_probing(spec, library=LIB, max_depth=2, max_probes=0)
        assert with_probes.initial_cost == tracing.initial_cost
        record = run_episode(spec, library=LIB, policy=make_policy("planner"))
        assert any(abs(c - with_probes.initial_cost) < 1e-5 for c in record.to_json()["cum_cost"])
        if with_probes.nodes == 0:  # recognised in the opening
            assert with_probes.path_cost == pytest.approx(record.path_cost, abs=1e-5)
            continue
        searched += 1
        assert with_probes.found and with_probes.path_cost >= with_probes.initial_cost
        assert with_probes.path_cost <= tracing.path_cost + 1e-9
        cheaper += with_probes.path_cost < tracing.path_cost - 1e-9
    assert searched >= 2 and cheaper >= 1
