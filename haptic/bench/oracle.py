"""The best possible: the cheapest move sequence to recognition for one episode, found in hindsight.

Evaluation code, not a policy: it uses the true model and pose (through the geometric executor) to try every
sequence of candidate moves (the same discretised candidates the policies choose from) after the episode's
fixed initial sequence, up to ``max_depth`` moves, with branch and bound on the path cost. No policy can do
better on that episode with those candidates, so it is a lower bound on the planner's cost, and on the least
*expected* cost of any policy (the expectation of minima is at most the minimum of expectations).

Where the episode admits free-space probes (``spec.moves`` "all" or "probing"), the fixed sequence is the
episode's own opening, run by the episode loop up to the first decision a policy takes (it draws from the
episode's generators alone, so every policy's episode begins with it), and each node of the search tries the
tracing moves and the :data:`HINDSIGHT_PROBES` probes of highest planner efficiency there
(:func:`hindsight_optimum_probing`); every move booked as the episode books it (the free space a probe travelled
included).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from haptic.episode.opening import opening_move
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import GeometricWorld
from haptic.geometry import Polyhedron, load_library
from haptic.matching.recognition import RECOGNIZED, model_symmetries, recognize
from haptic.matching.tree import InterpretationTree
from haptic.planning.config import PlannerConfig
from haptic.planning.predict import candidate_moves


def _may_be_recognized(tree: InterpretationTree) -> bool:
    """Cheap necessary condition: one model left, with no more interpretations than one pose class can hold
    (one per symmetry of the model)."""
    alive = tree.models_alive()
    if len(alive) != 1:
        return False
    model = tree.library.models[tree.library.names.index(alive[0])]
    return tree.count <= len(model_symmetries(model))


@dataclass(frozen=True)
class OracleResult:
    """The hindsight optimum of one episode."""

    found: bool
    """A recognising sequence was found within the depth."""
    path_cost: float
    """Its total path cost, fixed initial sequence included (inf when not found) [units]."""
    moves: int
    """Its number of moves, fixed sequence included."""
    nodes: int
    """Search nodes expanded."""
    initial_cost: float
    """Cost of the start and the fixed initial sequence [units]."""


def hindsight_optimum(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron] | None = None,
    max_depth: int = 3,
    config: PlannerConfig | None = None,
    upper_bound: float = np.inf,
) -> OracleResult:
    """Search the cheapest recognising continuation of ``spec``'s episode (same pose, start and fixed moves)."""
    library = library if library is not None else load_library(spec.models)
    episode = GeometricWorld.build(spec, library, config)  # the same pose, start and noise as the episode's
    config, ex, policy_rng = episode.config, episode.executor, episode.policy_rng
    tree = InterpretationTree(library)
    comps: dict = {}
    first = ex.start()
    cost, n_moves = first.cost, 0
    for c in first.components:
        comps[c.id] = c
        tree.add(c)
    state = first.state
    for kind in ("face", "edge", "vertex"):
        if recognize(tree).status == RECOGNIZED:
            return OracleResult(True, cost, n_moves, 0, cost)
        move = opening_move(kind, state, comps, config, policy_rng)
        if move is None:
            continue
        res = ex.execute(move)
        n_moves += 1
        cost += res.cost
        if res.ok:
            for c in res.components:
                comps[c.id] = c
                tree.add(c)
            state = res.state
    initial = cost
    if recognize(tree).status == RECOGNIZED:
        return OracleResult(True, cost, n_moves, 0, initial)

    best = [upper_bound, -1]
    nodes = [0]

    def search(ex, tree, comps, state, spent: float, depth: int, moves: int) -> None:
        if depth == 0:
            return
        for move in candidate_moves(state, comps, config):
            ex2 = copy.deepcopy(ex)
            res = ex2.execute(move)
            nodes[0] += 1
            total = spent + res.cost
            if total >= best[0] or not res.ok:
                continue
            tree2 = tree.copy()
            comps2 = dict(comps)
            for c in res.components:
                comps2[c.id] = c
                tree2.add(c)
            if tree2.count == 0:
                continue
            if _may_be_recognized(tree2) and recognize(tree2).status == RECOGNIZED:
                best[0], best[1] = total, moves + 1
                continue
            search(ex2, tree2, comps2, res.state, total, depth - 1, moves + 1)

    search(ex, tree, comps, state, cost, max_depth, n_moves)
    found = best[1] >= 0
    return OracleResult(found, best[0] if found else float("inf"), best[1] if found else -1, nodes[0], initial)


HINDSIGHT_PROBES = 6
"""Free-space probes the hindsight search tries at each node (:func:`hindsight_optimum_probing`): those of highest
planner efficiency. There are up to 64 probe candidates a node; trying each at each of three levels is more than a
benchmark can wait for."""


class _Peek:
    """A move source that proposes nothing and keeps the episode's state: the hindsight search starts from it."""

    name = "peek"

    def __init__(self) -> None:
        self.view = None

    def propose(self, view):
        self.view = view
        return None

    def on_result(self, view, move, result) -> None:
        return None


def _copy_view(view):
    """An independent copy of an episode's state (the tree copied, every list and dict of it new)."""
    from dataclasses import fields, replace

    new = {f.name: copy.copy(getattr(view, f.name)) for f in fields(view)
           if isinstance(getattr(view, f.name), list | dict)}  # fmt: skip
    return replace(view, tree=view.tree.copy(), **new)


def hindsight_optimum_probing(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron] | None = None,
    max_depth: int = 3,
    config: PlannerConfig | None = None,
    upper_bound: float = np.inf,
    max_probes: int = HINDSIGHT_PROBES,
) -> OracleResult:
    """The hindsight optimum of ``spec``'s episode over tracing moves and probes (module docstring): from the
    episode's state at its first decision, every sequence of up to ``max_depth`` moves of the node's tracing
    candidates (``spec.moves`` not "probing") and its ``max_probes`` best probes, branch and bound on the path
    cost."""
    from haptic.episode.loop import loop_steps
    from haptic.episode.sources import decision_context, episode_sources
    from haptic.planning.move_scores import score_all
    from haptic.planning.probe_prediction import ProbePrediction

    library = library if library is not None else load_library(spec.models)
    episode = GeometricWorld.build(spec, library, config)
    config, ex = episode.config, episode.executor
    peek = _Peek()
    sources = [peek, *episode_sources(library, config, episode.policy_rng)]
    steps = loop_steps(spec, library, episode.true_model, episode.world_from_model, ex, episode.noise, config,
                       episode.policy_rng, sources=sources)  # fmt: skip
    try:
        next(steps)
    except StopIteration as end:  # ended before any decision
        record = end.value
        return OracleResult(bool(record.recognized), record.path_cost, record.moves, 0, record.path_cost)
    steps.close()
    view = peek.view
    initial = view.cost
    best = [upper_bound, -1]
    nodes = [0]

    def candidates(view) -> list:
        moves = [] if config.moves == "probing" else list(candidate_moves(view.sensor, view.components, config))
        if config.moves == "tracing" or not view.posed:
            return moves
        ctx = decision_context(view)
        if ctx.config.moves == "tracing":
            return moves
        scored = [c for c in score_all(ctx) if isinstance(c[0], ProbePrediction)]
        scored.sort(key=lambda c: -c[1])
        return moves + [c[0].move for c in scored[:max_probes]]

    def search(ex, view, depth: int) -> None:
        if depth == 0:
            return
        for move in candidates(view):
            ex2 = copy.deepcopy(ex)
            res = ex2.execute(move)
            nodes[0] += 1
            total = view.cost + res.cost
            if total >= best[0] or not res.ok:
                continue
            view2 = _copy_view(view)
            view2.moves += 1
            view2.took(res)
            if view2.tree.count == 0:
                continue
            if view2.rec is not None and view2.rec.status == RECOGNIZED:
                best[0], best[1] = total, view2.moves
                continue
            search(ex2, view2, depth - 1)

    search(ex, view, max_depth)
    found = best[1] >= 0
    return OracleResult(found, best[0] if found else float("inf"), best[1] if found else -1, nodes[0], initial)
