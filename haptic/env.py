"""Gymnasium environments over the episode loop, for learned exploration policies.

Importing this module registers ``haptic/Explore-v0`` (the geometric executor) and ``haptic/ExplorePhysics-v0``
(the simulated hand). An environment step is one decision of the episode's policy in
:func:`~haptic.episode.loop.loop_steps`: the same loop as ``haptic explore`` and ``haptic bench``, with the
agent in the policy's place. The start, the opening sequence (seed §4.1), verification moves and the random
fallback (fewer than two pose classes left) are chosen by the loop, as in every episode.

- ``reset(seed, options)`` draws the model (uniformly from the library) and the episode seed from the
  environment's generator, or takes them from ``options`` (``{"model": name, "seed": episode_seed}``), and runs
  the loop to its first decision. ``info["path_cost"]`` is the cost spent so far (start and opening moves).
- The observation is a fixed-size ``Dict`` of float32 arrays: ``counts`` (interpretations, pose classes),
  ``components`` (the last :data:`MAX_COMPONENTS` data components: kind one-hot, unit normal or direction,
  position relative to the sensor [m], edge length [m]; zero rows before the first) and ``candidates`` (per
  candidate move: kind one-hot, direction in the world, admissible flag; zero rows past the list).
- The action is the index of a candidate move (``Discrete``); ``info["action_mask"]`` and
  :meth:`ExploreEnv.action_masks` (what sb3-contrib's MaskablePPO calls) mark the admissible ones (not a move
  that already failed from here). An index past the candidate list is taken modulo its length.
- The reward is minus the path cost the step spent (the chosen move, and any moves the loop makes before the
  next decision: verification, the random fallback) [cost units, seed §3.1].
- ``terminated`` when the episode ends recognised, ambiguous, no-match or failed; ``truncated`` when it runs
  out of budget (``max_moves`` moves or ``budget`` cost). ``info`` then holds the episode's JSON ``record``.
  An episode that ends before its first decision (recognised by the opening moves) ends at the first step,
  whatever the action, with reward 0.
"""

from __future__ import annotations

from collections.abc import Generator

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.envs.registration import register

from haptic.episode.loop import DecisionPoint, EpisodeObserver, EpisodeRecord, chain_observers, loop_steps
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import Episode, build_episode
from haptic.errors import HapticError
from haptic.geometry import load_library
from haptic.geometry.library_cache import cached_library
from haptic.matching.acceptance import DEFAULT_VERIFY
from haptic.matching.components import DataComponent, DataEdge, DataFace
from haptic.matching.recognition import AMBIGUOUS, NO_MATCH, RECOGNIZED
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import EdgeMove, FaceMove, Move, MoveResult, VertexMove
from haptic.planning.policies import Decision, Policy, same_move
from haptic.planning.predict import candidate_moves
from haptic.planning.registry import make_policy

MAX_COMPONENTS = 8
"""Data components in an observation (the latest ones)."""
COMPONENT_FEATURES = 10
"""Per component: kind one-hot (face, edge, vertex), unit vector (3), position from the sensor (3) [m], length [m]."""
MOVE_FEATURES = 7
"""Per candidate move: kind one-hot (face, edge, vertex), direction in the world (3), admissible (0/1)."""
MAX_COUNT = 1e12
"""Bound of the interpretation count in an observation (the matcher's tree stays far below)."""
MAX_EXTENT = 10.0
"""Bound of the component features: unit vectors, and positions and lengths [m] within the workspace."""
KINDS = ("face", "edge", "vertex")
ENDED = (RECOGNIZED, AMBIGUOUS, NO_MATCH, "failed")
"""Outcomes that terminate an episode; "budget" truncates it."""


class ExploreEnv(gym.Env):
    """One touch-exploration episode per reset; the agent chooses the moves the policy would."""

    metadata = {"render_modes": []}

    def __init__(
        self,
        executor: str = "geometric",
        models: str | None = None,
        noise: float = 1.0,
        verify: str = DEFAULT_VERIFY,
        max_moves: int = 40,
        budget: float = 600.0,
        config: PlannerConfig | None = None,
    ) -> None:
        if executor not in ("geometric", "physics"):
            raise HapticError(f"unknown executor {executor!r}; valid: geometric, physics")
        self.executor = executor
        self.models = models
        self.noise, self.verify, self.max_moves, self.budget = noise, verify, max_moves, budget
        self.config = config
        self.library = cached_library(models) if executor == "geometric" else load_library(models)
        self.names = sorted(self.library)
        self.n_candidates = (config or PlannerConfig()).n_directions + 4  # face directions, 2 edge, 2 vertex moves
        self.action_space = spaces.Discrete(self.n_candidates)
        self.observation_space = spaces.Dict({
            "counts": spaces.Box(0.0, MAX_COUNT, (2,), np.float32),
            "components": spaces.Box(-MAX_EXTENT, MAX_EXTENT, (MAX_COMPONENTS, COMPONENT_FEATURES), np.float32),
            "candidates": spaces.Box(-1.0, 1.0, (self.n_candidates, MOVE_FEATURES), np.float32),
        })  # fmt: skip
        self.episode: Episode | None = None
        self.record: EpisodeRecord | None = None
        self._steps: Generator[DecisionPoint, Decision, EpisodeRecord] | None = None
        self._point: DecisionPoint | None = None
        self._moves: list[Move] = []
        self._cost = 0.0

    # ------------------------------------------------------------------------------------------ gymnasium
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        options = dict(options or {})
        model = options.pop("model", None)
        if model is None:
            model = self.names[int(self.np_random.integers(len(self.names)))]
        episode_seed = options.pop("seed", None)
        if episode_seed is None:
            episode_seed = int(self.np_random.integers(2**31 - 1))
        if options:
            raise HapticError(f"unknown reset options {sorted(options)}; valid: model, seed")
        spec = EpisodeSpec(
            model=model, seed=int(episode_seed), policy="agent", executor=self.executor, noise=self.noise,
            models=self.models, budget=self.budget, max_moves=self.max_moves, verify=self.verify,
            moves="tracing",  # the actions index tracing moves (candidate_moves)
        )  # fmt: skip
        self.episode = build_episode(spec, self.library, self.config)
        self.record, self._cost = None, 0.0
        costs = EpisodeObserver(on_move=self._spent, on_failed_move=self._spent)
        ep = self.episode
        self._steps = loop_steps(
            spec, ep.library, ep.true_model, ep.world_from_model, ep.executor, ep.noise, ep.config, ep.policy_rng,
            chain_observers(costs, ep.observer),
        )  # fmt: skip
        self._advance(lambda: next(self._steps))
        return self._observation(), self._info()

    def step(self, action):
        cost = self._cost
        if self.record is None:
            move = self._moves[int(action) % len(self._moves)]
            self._advance(lambda: self._steps.send(Decision(move)))
        outcome = self.record.outcome if self.record is not None else None
        terminated, truncated = outcome in ENDED, outcome == "budget"
        return self._observation(), -(self._cost - cost), terminated, truncated, self._info()

    def action_masks(self) -> np.ndarray:
        """The admissible actions (n_candidates,) bool: a candidate move that has not failed from here. With no
        decision left (the episode ended), action 0 only."""
        mask = np.zeros(self.n_candidates, dtype=bool)
        if self._point is None:
            mask[0] = True
            return mask
        avoid = self._point.context.avoid
        ok = [not any(same_move(m, bad) for bad in avoid) for m in self._moves]
        mask[: len(ok)] = ok if any(ok) else True
        return mask

    # ------------------------------------------------------------------------------------------ for agents
    @property
    def context(self):
        """What the policy would decide from now (:class:`~haptic.planning.policies.Context`); None at the end."""
        return self._point.context if self._point is not None else None

    @property
    def decision_rng(self) -> np.random.Generator | None:
        """The episode's policy generator (a policy acting through :class:`PolicyAgent` draws from it, as in
        :func:`~haptic.episode.loop.run_loop`)."""
        return self._point.rng if self._point is not None else None

    @property
    def candidates(self) -> list[Move]:
        """The candidate moves, in action order."""
        return list(self._moves)

    def action_of(self, move: Move) -> int:
        """The action index of ``move`` (one of :attr:`candidates`, compared by kind and parameter)."""
        for i, m in enumerate(self._moves):
            if _same_parameters(m, move):
                return i
        raise HapticError(f"move {move!r} is not one of the {len(self._moves)} candidate moves")

    # ------------------------------------------------------------------------------------------ internals
    def _spent(self, n: int, result: MoveResult, *rest) -> None:
        self._cost += result.cost

    def _advance(self, resume) -> None:
        """Run the loop to its next decision point, or to its end (then finish and keep the record)."""
        try:
            self._point = resume()
        except StopIteration as end:
            self._point, self._moves = None, []
            self.record = end.value
            if self.episode.finish is not None:
                self.episode.finish(self.record)
            return
        ctx = self._point.context
        self._moves = candidate_moves(ctx.state, ctx.components, ctx.config)
        if not 0 < len(self._moves) <= self.n_candidates:
            raise HapticError(f"{len(self._moves)} candidate moves; the action space holds 1 to {self.n_candidates}")

    def _info(self) -> dict:
        info = {"action_mask": self.action_masks(), "path_cost": round(self._cost, 6)}
        if self.record is not None:
            info["record"] = self.record.to_json()
        return info

    def _observation(self) -> dict:
        counts = np.zeros(2, np.float32)
        comps = np.zeros((MAX_COMPONENTS, COMPONENT_FEATURES), np.float32)
        cands = np.zeros((self.n_candidates, MOVE_FEATURES), np.float32)
        if self._point is None:
            if self.record is not None and self.record.interpretations:
                counts[:] = self.record.interpretations[-1], self.record.classes[-1]
            return {"counts": counts, "components": comps, "candidates": cands}
        ctx = self._point.context
        counts[:] = ctx.tree.count if ctx.tree is not None else 0, len(ctx.hypotheses)
        latest = list(ctx.components.values())[-MAX_COMPONENTS:]
        for row, c in zip(comps, latest, strict=False):
            row[:] = _component_features(c, ctx.state.position)
        mask = self.action_masks()
        for i, m in enumerate(self._moves):
            cands[i, KINDS.index(m.kind)] = 1.0
            cands[i, 3:6] = _move_direction(m, ctx)
            cands[i, 6] = float(mask[i])
        return {"counts": counts, "components": comps, "candidates": cands}


class PolicyAgent:
    """A policy of :mod:`haptic.planning` acting through an :class:`ExploreEnv`: it decides from the
    environment's context with the episode's generator, exactly as :func:`~haptic.episode.loop.run_loop` would
    (the same draws, hence the same episode), and returns the action of its move."""

    def __init__(self, policy: Policy | str = "planner") -> None:
        self.policy = make_policy(policy) if isinstance(policy, str) else policy

    def act(self, env: gym.Env) -> int:
        e = env.unwrapped
        if e.context is None:
            return 0
        return e.action_of(self.policy.choose(e.context, e.decision_rng).move)


def _same_parameters(a: Move, b: Move) -> bool:
    if a.kind != b.kind:
        return False
    if isinstance(a, FaceMove):
        return bool(np.array_equal(a.direction, b.direction))
    if isinstance(a, EdgeMove):
        return a.sense == b.sense
    return a.across_face == b.across_face


def _component_features(c: DataComponent, sensor: np.ndarray) -> np.ndarray:
    f = np.zeros(COMPONENT_FEATURES)
    f[KINDS.index(c.kind)] = 1.0
    if isinstance(c, DataFace):
        f[3:6], at = c.normal, np.mean(c.points, axis=0)
    elif isinstance(c, DataEdge):
        f[3:6], at, f[9] = c.direction, c.point + 0.5 * c.length * c.direction, c.length
    else:
        at = c.position
    f[6:9] = at - sensor
    return f


def _move_direction(m: Move, ctx) -> np.ndarray:
    """A face move's direction, an edge move's direction along its edge, a vertex move's crossed face's normal."""
    if isinstance(m, FaceMove):
        return np.asarray(m.direction, float)
    if isinstance(m, EdgeMove):
        return m.sense * np.asarray(ctx.components[ctx.state.edge].direction, float)
    assert isinstance(m, VertexMove)
    return np.asarray(ctx.components[m.across_face].normal, float)


register(id="haptic/Explore-v0", entry_point="haptic.env:ExploreEnv", kwargs={"executor": "geometric"})
register(id="haptic/ExplorePhysics-v0", entry_point="haptic.env:ExploreEnv", kwargs={"executor": "physics"})
