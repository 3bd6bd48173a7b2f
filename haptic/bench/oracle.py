"""The best possible: the cheapest move sequence to recognition for one episode, found in hindsight.

Evaluation code, not a policy: it uses the true model and pose (through the geometric executor) to try every
sequence of candidate moves (the same discretised candidates the policies choose from) after the episode's
fixed initial sequence, up to ``max_depth`` moves, with branch and bound on the path cost. No policy can do
better on that episode with those candidates, so it is a lower bound on the planner's cost, and on the least
*expected* cost of any policy (the expectation of minima is at most the minimum of expectations).
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
