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

LEARNED_PREFIX = "learned:"
"""``learned:PATH`` names a policy trained on the Gymnasium environment, saved at PATH (``haptic.env.learned``, outside
the planning layer: the bench builds it)."""


def is_learned(name: str) -> bool:
    """Whether a policy name is a learned policy's (``learned:PATH``)."""
    return name.startswith(LEARNED_PREFIX)
