"""Gymnasium environments over the episode loop, for learned exploration policies.

Importing this package registers ``haptic/Explore-v0`` (the geometric executor) and ``haptic/ExplorePhysics-v0``
(the simulated hand), both :class:`~haptic.env.explore.ExploreEnv`: the environment and its reward
(:mod:`haptic.env.explore`), the observation and the action mask (:mod:`haptic.env.observe`), and a trained policy
acting in ``haptic bench --policy learned:PATH`` (:mod:`haptic.env.learned`, with the ``[learn]`` extra).
"""

from __future__ import annotations

from gymnasium.envs.registration import register

from haptic.env.explore import ENDED, OBSERVATIONS, OPENINGS, REWARD_SCALE, AgentDecisions, ExploreEnv, PolicyAgent
from haptic.env.observe import (
    COMPONENT_FEATURES,
    GLOBALS,
    MAX_COMPONENTS,
    MOVE_COLUMNS,
    MOVE_FEATURES,
    choice_at,
    observation_space,
)

register(id="haptic/Explore-v0", entry_point="haptic.env.explore:ExploreEnv", kwargs={"executor": "geometric"})
register(id="haptic/ExplorePhysics-v0", entry_point="haptic.env.explore:ExploreEnv", kwargs={"executor": "physics"})

__all__ = [
    "COMPONENT_FEATURES",
    "ENDED",
    "GLOBALS",
    "MAX_COMPONENTS",
    "MOVE_COLUMNS",
    "MOVE_FEATURES",
    "OBSERVATIONS",
    "OPENINGS",
    "REWARD_SCALE",
    "AgentDecisions",
    "ExploreEnv",
    "PolicyAgent",
    "choice_at",
    "observation_space",
]
