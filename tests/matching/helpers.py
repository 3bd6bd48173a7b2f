"""Shared helpers for the matcher tests: run executor data through a tree and find the true interpretation."""

from __future__ import annotations

import numpy as np

from haptic.executor.geometric import GeometricExecutor
from haptic.matching.library import KIND_INDEX
from haptic.matching.tree import InterpretationTree


def true_leaves(tree: InterpretationTree, ex: GeometricExecutor) -> np.ndarray:
    """Leaves whose pairing is the executor's ground truth (senses equal or not yet known)."""
    lib = tree.library
    mi = lib.names.index(ex.model.name)
    assign, sense = tree.assignments, tree.senses
    ok = tree.model_indices == mi
    for d in range(assign.shape[1]):
        kind, local = ex.truth[d]
        k = KIND_INDEX[kind]
        ok &= assign[:, d] == local + lib.offsets[k, mi]
        if kind == "edge":
            ok &= (sense[:, d] == 0) | (sense[:, d] == ex.edge_senses[d])
    return np.flatnonzero(ok)


def feed(tree: InterpretationTree, ex: GeometricExecutor) -> list[int]:
    """Add every component the executor reported; the counts after each."""
    return [tree.add(c) for c in ex.components]
