"""A policy trained on :class:`~haptic.env.explore.ExploreEnv` (sb3-contrib's MaskablePPO, ``scripts/train_ppo.py``)
acting in episodes as any policy does: ``haptic bench --policy learned:PATH``.

At each of the planner's decisions it builds the observation and the mask the environment would
(:func:`~haptic.env.observe.choice_at`, from the decision's context and its own earlier decisions in the episode) and
takes the model's most likely admissible action (``deterministic=True``). The loop makes the start, the opening
sequence and the verification moves, as in the environment with ``opening="loop"``. Needs the ``[learn]`` extra
(``pip install -e '.[learn]'``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from haptic.env.observe import Budgets, choice_at
from haptic.errors import HapticError
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import Move
from haptic.planning.policies import Context, Decision, Policy
from haptic.planning.registry import LEARNED_PREFIX

_MODELS: dict[tuple[str, float], object] = {}


def learned_path(name: str) -> Path:
    """The model file a ``learned:PATH`` policy names; a :class:`~haptic.errors.HapticError` naming it when it is not
    a file."""
    path = Path(name[len(LEARNED_PREFIX) :]).expanduser()
    if not path.is_file():
        raise HapticError(f"--policy {name}: no model file {path} (a MaskablePPO .zip that scripts/train_ppo.py saves)")
    return path


def load_model(path: str | os.PathLike):
    """The MaskablePPO model saved at ``path`` (loaded once per process and file version)."""
    try:
        import torch
        from sb3_contrib import MaskablePPO
    except ImportError:
        raise HapticError("learned policies need the [learn] extra: pip install -e '.[learn]'") from None
    path = Path(path).resolve()
    key = (str(path), path.stat().st_mtime)
    if key not in _MODELS:
        torch.set_num_threads(1)  # one decision at a time: more threads only contend with the episode workers
        try:
            _MODELS[key] = MaskablePPO.load(str(path), device="cpu")
        except Exception as exc:  # a file of another kind: one line naming it
            raise HapticError(f"{path}: not a MaskablePPO model ({type(exc).__name__}: {exc})") from None
    return _MODELS[key]


class LearnedPolicy(Policy):
    """A trained MaskablePPO model choosing among the candidate moves (module docstring); one per episode (it keeps
    its own decisions, which the observation's "tried" feature counts)."""

    name = "learned"

    def __init__(self, path: str | os.PathLike, max_moves: int, budget: float, config: PlannerConfig | None = None):
        self.model = load_model(path)
        self.n_candidates = (config or PlannerConfig()).n_directions + 4
        n_actions = int(getattr(self.model.action_space, "n", -1))
        if n_actions != self.n_candidates:
            raise HapticError(f"{path}: the model chooses among {n_actions} actions; this planner offers "
                              f"{self.n_candidates} candidate moves")  # fmt: skip
        self.flat = not hasattr(self.model.observation_space, "spaces")
        self.budgets = Budgets(max_moves, budget)
        self.history: list[tuple[np.ndarray, Move]] = []

    def choose(self, ctx: Context, rng: np.random.Generator) -> Decision:
        choice = choice_at(ctx, self.n_candidates, self.budgets, self.history)
        action, _ = self.model.predict(choice.observation(self.flat), action_masks=choice.mask, deterministic=True)
        move = choice.moves[int(action) % len(choice.moves)]
        self.history.append((np.array(ctx.state.position, float), move))
        return Decision(move)


def learned_policy(name: str, max_moves: int, budget: float) -> LearnedPolicy:
    """The policy ``learned:PATH`` names, for an episode with these budgets."""
    return LearnedPolicy(learned_path(name), max_moves, budget)
