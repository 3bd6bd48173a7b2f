"""The policies by name, on top of the planning layer: ``make_policy("planner")``."""

from __future__ import annotations

from collections.abc import Callable

from haptic.errors import PlanningError
from haptic.planning.optimal import LookaheadPolicy, OptimalPolicy
from haptic.planning.policies import GreedyPolicy, PlannerPolicy, Policy, RandomPolicy

POLICIES: dict[str, Callable[..., Policy]] = {
    "planner": PlannerPolicy,
    "greedy": GreedyPolicy,
    "random": RandomPolicy,
    "optimal": OptimalPolicy,
    "lookahead": LookaheadPolicy,
}


def make_policy(name: str, **options) -> Policy:
    """A policy by name: planner, greedy, random, optimal, lookahead."""
    try:
        return POLICIES[name](**options)
    except KeyError:
        raise PlanningError(f"unknown policy {name!r}; valid: {', '.join(POLICIES)}") from None


POLICY_NAMES = tuple(POLICIES)
