"""The Gymnasium environment over the episode loop: one touch-exploration episode per reset, the agent choosing the
moves the policy would.

An environment step is one decision of the episode's policy in :func:`~haptic.episode.loop.loop_steps`: the same
loop as ``haptic explore`` and ``haptic bench``, with the agent in the policy's place. The start, verification moves
and the random fallback (fewer than two pose classes left) are the loop's; the opening sequence (seed §4.1) is the
loop's too unless ``opening="agent"``, when the agent takes those decisions as well (every decision while the data
fix no pose, and then while two or more pose classes are left).

- ``reset(seed, options)`` draws the model (uniformly from the library) and the episode seed from the environment's
  generator, or takes them from ``options`` (``{"model": name, "seed": episode_seed}``), and runs the loop to its
  first decision. ``info["path_cost"]`` is the cost spent so far (the start, and the opening moves).
- The observation (:mod:`haptic.env.observe`): a ``Dict`` of 1-D float32 arrays ``globals`` (counts on a log
  scale, the budgets left, moves so far, ...), ``candidates`` (per candidate move: kind, direction, admissible,
  the planner's predicted eliminations, expected cost and efficiency, risk, tried before) and ``components`` (the
  latest data components); with ``observation="flat"`` one ``Box``, the three concatenated, which the default
  policies of Stable-Baselines3 take as they are.
- The action is the index of a candidate move (``Discrete``); ``info["action_mask"]`` and
  :meth:`ExploreEnv.action_masks` (what sb3-contrib's MaskablePPO calls) mark the admissible ones: moves the planner
  scores (not one that failed from here) and predicts to eliminate at least one pose class, when there are such
  (:func:`~haptic.env.observe.choice_at`). An index past the candidate list is taken modulo its length.
- The reward states the task: ``reward_scale`` × (− the path cost the step spent (the chosen move, and the moves
  the loop makes before the next decision: verification, the random fallback) − :attr:`ExploreEnv.failure_penalty`
  on the step that ends the episode without a correct recognition (budget, failed, wrong model or pose, ambiguous,
  no-match)) [cost units of seed §3.1 × ``reward_scale``]. The penalty defaults to the cost budget: an episode that
  fails returns less than any that recognises the object correctly within the budget, so spending moves that tell
  nothing until the budget runs out never pays. With ``shaping`` > 0 each step adds
  ``reward_scale × shaping × (log2(1 + k) − log2(1 + k'))``, k and k' the pose classes (the interpretations while
  there are none) before and after it, and the episode's last step ``reward_scale × shaping × log2(1 + k)``: a
  potential-based shaping (Ng, Harada & Russell 1999) that rewards eliminations at once and leaves the order of
  policies by return unchanged (its sum over an episode is fixed by the first decision).
- ``terminated`` when the episode ends recognised, ambiguous, no-match or failed; ``truncated`` when it runs out of
  budget (``max_moves`` moves or ``budget`` cost). ``info["record"]`` is the episode's JSON record on the step that
  ends it, and on no other step nor in a reset's info, so a vector environment counts an episode once. An episode
  that ends before its first decision (recognised by the opening moves) ends at the first step, whatever the
  action, with no path cost (the opening's is in the reset's ``info["path_cost"]``).
"""

from __future__ import annotations

import math
from collections.abc import Generator

import gymnasium as gym
import numpy as np

from haptic.env.observe import Budgets, Choice, choice_at, empty_choice, observation_space, same_parameters
from haptic.episode.loop import DecisionPoint, EpisodeObserver, EpisodeRecord, chain_observers, loop_steps
from haptic.episode.sources import (
    MoveSource,
    RandomFallback,
    VerificationMoves,
    decision_context,
    episode_sources,
)
from haptic.episode.spec import EpisodeSpec
from haptic.episode.state import EpisodeState
from haptic.episode.worlds import Episode, build_episode
from haptic.errors import HapticError
from haptic.geometry import load_library
from haptic.geometry.library_cache import cached_library
from haptic.matching.acceptance import DEFAULT_VERIFY
from haptic.matching.recognition import AMBIGUOUS, NO_MATCH, RECOGNIZED
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import Move, MoveResult
from haptic.planning.policies import Decision, Policy
from haptic.planning.registry import make_policy

ENDED = (RECOGNIZED, AMBIGUOUS, NO_MATCH, "failed")
"""Outcomes that terminate an episode; "budget" truncates it."""
REWARD_SCALE = 1.0
"""Default factor from cost units to reward: 1, the reward is minus the path cost."""
OPENINGS = ("loop", "agent")
"""Who takes the opening's decisions: the loop (the seed's opening sequence) or the agent."""
OBSERVATIONS = ("dict", "flat")
"""Observation layouts: a ``Dict`` of 1-D arrays, or one flat ``Box``."""


class AgentDecisions(MoveSource):
    """With ``opening="agent"``: every decision while the data fix no pose, then while two or more pose classes are
    left, and no verification is under way, goes to the loop's driver (a :class:`DecisionPoint`)."""

    name = "agent"

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng = rng

    def propose(self, view: EpisodeState) -> DecisionPoint | None:
        if view.verifying or (view.posed and len(view.hypotheses()) < 2):
            return None
        return DecisionPoint(decision_context(view), self.rng)


class ExploreEnv(gym.Env):
    """One touch-exploration episode per reset; the agent chooses the moves the policy would (module docstring)."""

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
        reward_scale: float = REWARD_SCALE,
        failure_penalty: float | None = None,
        shaping: float = 0.0,
        opening: str = "loop",
        observation: str = "dict",
    ) -> None:
        if executor not in ("geometric", "physics"):
            raise HapticError(f"unknown executor {executor!r}; valid: geometric, physics")
        if opening not in OPENINGS:
            raise HapticError(f"opening={opening!r} is not valid; valid: {', '.join(OPENINGS)}")
        if observation not in OBSERVATIONS:
            raise HapticError(f"observation={observation!r} is not valid; valid: {', '.join(OBSERVATIONS)}")
        for name, value in (("reward_scale", reward_scale), ("shaping", shaping), ("failure_penalty", failure_penalty)):
            if value is not None and not (math.isfinite(value) and value >= 0):
                raise HapticError(f"{name}={value!r} is not valid: a finite number >= 0")
        self.executor = executor
        self.models = models
        self.noise, self.verify, self.max_moves, self.budget = noise, verify, max_moves, budget
        self.config = config
        self.reward_scale, self.shaping = float(reward_scale), float(shaping)
        self.failure_penalty = float(budget if failure_penalty is None else failure_penalty)
        """Cost charged on the step that ends an episode without a correct recognition [units] (default: the
        cost budget)."""
        self.opening, self.flat = opening, observation == "flat"
        self.library = cached_library(models) if executor == "geometric" else load_library(models)
        self.names = sorted(self.library)
        self.n_candidates = (config or PlannerConfig()).n_directions + 4  # face directions, 2 edge, 2 vertex moves
        self.budgets = Budgets(max_moves, budget)
        self.action_space = gym.spaces.Discrete(self.n_candidates)
        self.observation_space = observation_space(self.n_candidates, self.flat)
        self.episode: Episode | None = None
        self.record: EpisodeRecord | None = None
        self._steps: Generator[DecisionPoint, Decision, EpisodeRecord] | None = None
        self._point: DecisionPoint | None = None
        self._choice: Choice = empty_choice(self.n_candidates)
        self._history: list[tuple[np.ndarray, Move]] = []
        self._cost = 0.0
        self._remaining = 0
        self._ended = False

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
        self.record, self._cost, self._history, self._ended = None, 0.0, [], False
        costs = EpisodeObserver(on_move=self._spent, on_failed_move=self._spent)
        ep = self.episode
        sources = None
        if self.opening == "agent":
            sources = [VerificationMoves(), AgentDecisions(ep.policy_rng), RandomFallback(ep.policy_rng)]
        else:
            sources = episode_sources(ep.library, ep.config, ep.policy_rng)
        self._steps = loop_steps(
            spec, ep.library, ep.true_model, ep.world_from_model, ep.executor, ep.noise, ep.config, ep.policy_rng,
            chain_observers(costs, ep.observer), sources,
        )  # fmt: skip
        self._advance(lambda: next(self._steps))
        self._remaining = self._left()
        return self._observation(), {"action_mask": self.action_masks(), "path_cost": round(self._cost, 6)}

    def step(self, action):
        if self._ended:
            raise HapticError("step() after the episode ended; call reset() first")
        cost, before = self._cost, self._remaining
        if self.record is None:
            move = self._choice.moves[int(action) % len(self._choice.moves)]
            self._history.append((np.array(self._point.context.state.position, float), move))
            self._advance(lambda: self._steps.send(Decision(move)))
        outcome = self.record.outcome if self.record is not None else None
        terminated, truncated = outcome in ENDED, outcome == "budget"
        spent = self._cost - cost
        reward = -spent
        if self.shaping:
            self._remaining = self._left()
            after = 0.0 if self.record is not None else math.log2(1 + self._remaining)
            reward += self.shaping * (math.log2(1 + before) - after)
        info = {"action_mask": self.action_masks(), "path_cost": round(self._cost, 6)}
        if self.record is not None:
            self._ended = True
            if not self.record.correct:
                reward -= self.failure_penalty
            info["record"] = self.record.to_json()
        return self._observation(), self.reward_scale * reward, terminated, truncated, info

    def action_masks(self) -> np.ndarray:
        """The admissible actions (n_candidates,) bool (:func:`~haptic.env.observe.choice_at`). With no decision
        left (the episode ended), action 0 only."""
        return self._choice.mask.copy()

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
        return list(self._choice.moves)

    def action_of(self, move: Move) -> int:
        """The action index of ``move`` (one of :attr:`candidates`, compared by kind and parameter)."""
        for i, m in enumerate(self._choice.moves):
            if same_parameters(m, move):
                return i
        raise HapticError(f"move {move!r} is not one of the {len(self._choice.moves)} candidate moves")

    # ------------------------------------------------------------------------------------------ internals
    def _spent(self, n: int, result: MoveResult, *rest) -> None:
        self._cost += result.cost

    def _left(self) -> int:
        """Pose classes left (the interpretations while there are none)."""
        ctx = self.context
        if ctx is None:
            return self.record.classes[-1] if self.record is not None and self.record.classes else 0
        return len(ctx.hypotheses) or (ctx.tree.count if ctx.tree is not None else 0)

    def _advance(self, resume) -> None:
        """Run the loop to its next decision point, or to its end (then finish and keep the record)."""
        try:
            self._point = resume()
        except StopIteration as end:
            self._point = None
            self.record = end.value
            if self.episode.finish is not None:
                self.episode.finish(self.record)
            counts = (self.record.interpretations[-1], self.record.classes[-1]) if self.record.classes else (0, 0)
            self._choice = empty_choice(self.n_candidates, counts)
            return
        self._choice = choice_at(self._point.context, self.n_candidates, self.budgets, self._history)

    def _observation(self):
        return self._choice.observation(self.flat)


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
