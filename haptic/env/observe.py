"""What an agent sees at a decision and which actions it may take: the observation, the action mask and the reward's
constants of :class:`~haptic.env.explore.ExploreEnv`, built from the policy's
:class:`~haptic.planning.move_scores.Context` alone (and the agent's own earlier decisions), so that a trained
policy acting in ``haptic bench`` (:mod:`haptic.env.learned`) sees exactly what it saw in training.

A decision's candidates are the tracing moves of :func:`~haptic.planning.predict.candidate_moves` (the action is an
index into them). The planner's scores of each (:func:`~haptic.planning.move_scores.score_all`, seed §4.1) are part
of the observation: its predicted pose classes eliminated, expected cost and efficiency.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from haptic.episode.loop import MAX_FAILED_MOVES, MAX_INTERPRETATIONS
from haptic.errors import HapticError
from haptic.matching.components import DataComponent, DataEdge, DataFace
from haptic.planning.move_scores import Context, bounded, same_move, score_all
from haptic.planning.moves import EdgeMove, FaceMove, Move, VertexMove
from haptic.planning.predict import candidate_moves

KINDS = ("face", "edge", "vertex")
MAX_COMPONENTS = 8
"""Data components in an observation (the latest ones)."""
COMPONENT_FEATURES = 10
"""Per component: kind one-hot (face, edge, vertex), unit vector (3), position from the sensor (3) [m], length [m]."""
MAX_EXTENT = 10.0
"""Bound of the component features: unit vectors, and positions and lengths [m] within the workspace."""
COST_UNIT = 10.0
"""Expected costs in an observation are in units of this many cost units (seed §3.1: 10 cm across a face)."""
MAX_COST_FEATURE = 10.0
"""Expected costs are clipped at this many :data:`COST_UNIT` (100 cost units: longer than any move of the shipped
models)."""
TRIED_RADIUS = 0.005
"""A candidate counts as tried before when the agent chose the same move (kind and parameter) at an earlier
decision of the episode with the sensor within this distance of where it is now [m]."""
MAX_TRIED = 3
"""Tries counted (the feature is tries / MAX_TRIED, at most 1)."""

GLOBALS = (
    "log_interpretations",
    "log_classes",
    "moves_left",
    "cost_left",
    "moves_so_far",
    "posed",
    "admissible",
    "failed_here",
)
"""The global features, in order: log(1 + interpretations) and log(1 + pose classes) over
log(1 + :data:`~haptic.episode.loop.MAX_INTERPRETATIONS`) (the classes are the interpretations while the data fix
no pose); the move budget left (1 − moves / max_moves) and the cost budget left (1 − path cost / budget), both
clipped at 0; moves so far / max_moves; 1 when the interpretations are grouped into pose classes; the fraction of
the candidates the mask admits; moves failed from here / :data:`~haptic.episode.loop.MAX_FAILED_MOVES`."""
MOVE_COLUMNS = (
    "face",
    "edge",
    "vertex",
    "dir_x",
    "dir_y",
    "dir_z",
    "admissible",
    "eliminated",
    "expected_cost",
    "efficiency",
    "risk",
    "scored",
    "tried",
)
"""The features of each candidate move, in order: kind one-hot; direction in the world (a face move's direction, an
edge move's direction along its edge, a vertex move's crossed face's normal); admissible (the mask); the planner's
expected pose classes eliminated over the pose classes left; expected cost / :data:`COST_UNIT` (clipped at
:data:`MAX_COST_FEATURE`); efficiency (eliminated per cost, seed §4.1) over the best candidate's (1: the planner's
choice, 0 when no candidate is predicted to eliminate anything); the predicted risk that the executor cannot carry
it out; 1 when the planner scores it (fresh and reliable: :func:`~haptic.planning.move_scores.score_all`); earlier
tries from here / :data:`MAX_TRIED` (:data:`TRIED_RADIUS`). Rows past the candidate list are zero."""
MOVE_FEATURES = len(MOVE_COLUMNS)
_COL = {name: i for i, name in enumerate(MOVE_COLUMNS)}
_LOG_MAX = float(np.log1p(MAX_INTERPRETATIONS))
_MOVE_LOW = np.array([0, 0, 0, -1, -1, -1, 0, 0, 0, 0, 0, 0, 0], np.float32)
_MOVE_HIGH = np.array([1, 1, 1, 1, 1, 1, 1, 1, MAX_COST_FEATURE, 1, 1, 1, 1], np.float32)


def observation_space(n_candidates: int, flat: bool = False) -> spaces.Space:
    """The observation space: a ``Dict`` of 1-D float32 arrays ``globals`` (:data:`GLOBALS`), ``candidates``
    (``n_candidates`` rows of :data:`MOVE_COLUMNS`, row-major) and ``components`` (:data:`MAX_COMPONENTS` rows of
    :data:`COMPONENT_FEATURES`), or with ``flat`` one ``Box``: the three concatenated in that order."""
    parts = {
        "globals": spaces.Box(0.0, 1.0, (len(GLOBALS),), np.float32),
        "candidates": spaces.Box(np.tile(_MOVE_LOW, n_candidates), np.tile(_MOVE_HIGH, n_candidates), dtype=np.float32),
        "components": spaces.Box(-MAX_EXTENT, MAX_EXTENT, (MAX_COMPONENTS * COMPONENT_FEATURES,), np.float32),
    }
    if not flat:
        return spaces.Dict(parts)
    low = np.concatenate([p.low for p in parts.values()])
    high = np.concatenate([p.high for p in parts.values()])
    return spaces.Box(low, high, dtype=np.float32)


@dataclass(frozen=True)
class Budgets:
    """The episode's budgets, as the observation scales them."""

    max_moves: int
    """Moves before the episode ends as "budget"."""
    budget: float
    """Path cost before the episode ends as "budget" [units]."""


@dataclass(frozen=True, eq=False)
class Choice:
    """What the agent may choose from at one decision: the candidate moves (in action order), the mask and the
    observation's arrays."""

    moves: tuple[Move, ...]
    """The candidate moves; the action is an index into them."""
    mask: np.ndarray
    """Admissible actions, shape (n_candidates,) bool."""
    globals: np.ndarray
    """:data:`GLOBALS`, shape (len(GLOBALS),) float32."""
    candidates: np.ndarray
    """:data:`MOVE_COLUMNS` per candidate, shape (n_candidates, MOVE_FEATURES) float32."""
    components: np.ndarray
    """The latest data components, shape (MAX_COMPONENTS, COMPONENT_FEATURES) float32."""

    def observation(self, flat: bool = False) -> dict | np.ndarray:
        """The observation as :func:`observation_space` describes it."""
        parts = {"globals": self.globals.copy(), "candidates": self.candidates.flatten(),
                 "components": self.components.flatten()}  # fmt: skip
        return np.concatenate(list(parts.values())) if flat else parts


def empty_choice(n_candidates: int, counts: tuple[int, int] = (0, 0)) -> Choice:
    """The observation when the episode has ended (no decision): the last counts, action 0 alone admissible."""
    g = np.zeros(len(GLOBALS), np.float32)
    g[0], g[1] = (min(1.0, np.log1p(c) / _LOG_MAX) for c in counts)
    mask = np.zeros(n_candidates, bool)
    mask[0] = True
    return Choice((), mask, g, np.zeros((n_candidates, MOVE_FEATURES), np.float32),
                  np.zeros((MAX_COMPONENTS, COMPONENT_FEATURES), np.float32))  # fmt: skip


def choice_at(
    ctx: Context, n_candidates: int, budgets: Budgets, history: Sequence[tuple[np.ndarray, Move]] = ()
) -> Choice:
    """The candidates, mask and observation at the decision ``ctx``; ``history``: the agent's earlier decisions of
    the episode, as (sensor position [m], move chosen).

    The mask admits the candidates the planner scores (fresh, reliable: not one that failed from here, nor a vertex
    move every pose class says circles back to an explored edge) that are predicted to eliminate at least one pose
    class; when none is, every scored candidate; when none is scored, every candidate that has not failed from
    here; failing that, all of them."""
    moves = tuple(candidate_moves(ctx.state, ctx.components, ctx.config))
    if len(moves) > n_candidates:
        raise HapticError(f"{len(moves)} candidate moves; the action space holds 1 to {n_candidates}")
    cands = np.zeros((n_candidates, MOVE_FEATURES), np.float32)
    n_classes = len(ctx.hypotheses)
    scored = score_all(bounded(ctx)) if n_classes else []
    for pred, eff, elim, cost, risk in scored:
        i = _index_of(pred.move, moves)
        if i is None:
            continue
        row = cands[i]
        row[_COL["scored"]] = 1.0
        row[_COL["eliminated"]] = elim / n_classes
        row[_COL["expected_cost"]] = min(cost / COST_UNIT, MAX_COST_FEATURE) if np.isfinite(cost) else MAX_COST_FEATURE
        row[_COL["efficiency"]] = max(eff, 0.0)
        row[_COL["risk"]] = risk
    best = cands[:, _COL["efficiency"]].max()
    cands[:, _COL["efficiency"]] = cands[:, _COL["efficiency"]] / best if best > 0 else 0.0
    for i, m in enumerate(moves):
        cands[i, KINDS.index(m.kind)] = 1.0
        cands[i, 3:6] = move_direction(m, ctx)
        tries = sum(
            1 for at, prev in history if same_move(m, prev) and np.linalg.norm(at - ctx.state.position) <= TRIED_RADIUS
        )
        cands[i, _COL["tried"]] = min(tries, MAX_TRIED) / MAX_TRIED
    np.nan_to_num(cands, copy=False)  # a score the planner could not form counts as none
    mask = _mask(moves, cands, ctx, n_candidates)
    cands[: len(moves), _COL["admissible"]] = mask[: len(moves)]
    g = np.zeros(len(GLOBALS), np.float32)
    count = ctx.tree.count if ctx.tree is not None else n_classes
    g[0] = np.log1p(count) / _LOG_MAX
    g[1] = np.log1p(n_classes or count) / _LOG_MAX
    g[2] = max(0.0, 1.0 - ctx.moves / budgets.max_moves)
    g[3] = max(0.0, 1.0 - ctx.cost / budgets.budget)
    g[4] = min(1.0, ctx.moves / budgets.max_moves)
    g[5] = float(n_classes > 0)
    g[6] = mask.sum() / n_candidates
    g[7] = min(1.0, sum(1 for m in ctx.avoid if m.kind in KINDS) / MAX_FAILED_MOVES)
    np.clip(g, 0.0, 1.0, out=g)
    comps = np.zeros((MAX_COMPONENTS, COMPONENT_FEATURES), np.float32)
    latest = list(ctx.components.values())[-MAX_COMPONENTS:]
    for row, c in zip(comps, latest, strict=False):
        row[:] = np.clip(component_features(c, ctx.state.position), -MAX_EXTENT, MAX_EXTENT)
    return Choice(moves, mask, g, cands, comps)


def _mask(moves: Sequence[Move], cands: np.ndarray, ctx: Context, n_candidates: int) -> np.ndarray:
    n = len(moves)
    scored = cands[:n, _COL["scored"]] > 0
    telling = scored & (cands[:n, _COL["eliminated"]] > 0)
    fresh = np.array([not any(same_move(m, bad) for bad in ctx.avoid) for m in moves], bool)
    mask = np.zeros(n_candidates, bool)
    for admit in (telling, scored, fresh, np.ones(n, bool)):
        if admit.any():
            mask[:n] = admit
            return mask
    mask[0] = True  # no candidate at all (the loop's candidate list is never empty at a decision)
    return mask


def _index_of(move: Move, moves: Sequence[Move]) -> int | None:
    for i, m in enumerate(moves):
        if same_parameters(m, move):
            return i
    return None


def same_parameters(a: Move, b: Move) -> bool:
    """Two tracing moves of one kind with exactly the same parameter."""
    if a.kind != b.kind:
        return False
    if isinstance(a, FaceMove):
        return bool(np.array_equal(a.direction, b.direction))
    if isinstance(a, EdgeMove):
        return a.sense == b.sense
    return a.across_face == b.across_face


def component_features(c: DataComponent, sensor: np.ndarray) -> np.ndarray:
    """A data component's row of the observation: kind one-hot, unit normal or direction, position from the
    sensor [m] (a face's mean touched point, an edge's midpoint, a vertex), edge length [m]."""
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


def move_direction(m: Move, ctx: Context) -> np.ndarray:
    """A face move's direction, an edge move's direction along its edge, a vertex move's crossed face's normal."""
    if isinstance(m, FaceMove):
        return np.asarray(m.direction, float)
    if isinstance(m, EdgeMove):
        return m.sense * np.asarray(ctx.components[ctx.state.edge].direction, float)
    assert isinstance(m, VertexMove)
    return np.asarray(ctx.components[m.across_face].normal, float)
