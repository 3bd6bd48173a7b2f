"""Efficiency of a candidate move: expected hypotheses eliminated per expected unit of cost (seed §4.1).

Each hypothesis predicts the move's outcome as a vector of attributes (for an edge move the distance to the
vertex; for vertex and face moves the distance or swept angle, then the new edge's angle, then the new face's
angle, §4.1.2–4.1.3). If hypothesis ``i`` is true, hypothesis ``j`` is eliminated when *any* attribute of its
prediction differs from ``i``'s by more than that attribute's error bound: the tie-breaks of §4.1.2–4.1.3
("if two interpretations are not distinguishable by the edge angle, check the face angle") amount to this.

The paper averages over interpretations with equal weight. Here the hypotheses are *pose classes* (one per
model pose up to the model's symmetry, since symmetric interpretations can never be told apart) and each can
carry a prior weight; :func:`class_weights` gives every surviving model the same total weight, shared among
its pose classes, so that a symmetric model or a model with many look-alike poses does not dominate. The
number eliminated is counted in pose classes.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from haptic.matching import kernels


def distinguishable(outcomes: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """``D[i, j]`` is True when hypothesis ``j``'s outcome differs from ``i``'s beyond the error bounds.

    ``outcomes`` has shape (N, A) (A attributes per hypothesis; NaN = no prediction, never distinguishable on
    that attribute); ``bounds`` has shape (A,).
    """
    o = np.asarray(outcomes, dtype=float)
    if o.ndim == 1:
        o = o[:, None]
    b = np.broadcast_to(np.asarray(bounds, dtype=float), (o.shape[1],))
    if kernels.COMPILED:
        return kernels.distinguishable(np.ascontiguousarray(o), np.ascontiguousarray(b))
    diff = np.abs(o[:, None, :] - o[None, :, :])  # (N, N, A)
    with np.errstate(invalid="ignore"):
        beyond = diff > b[None, None, :] * (1 + 1e-9) + 1e-12
    beyond &= ~np.isnan(diff)
    return beyond.any(axis=2)


def move_efficiency(
    outcomes: np.ndarray,
    bounds: np.ndarray | Sequence[float],
    costs: np.ndarray | Sequence[float],
    weights: np.ndarray | Sequence[float] | None = None,
) -> tuple[float, np.ndarray]:
    """Efficiency of one move and the per-hypothesis efficiencies (seed §4.1.1).

    Per hypothesis ``i``: (number of hypotheses eliminated if ``i`` is true) / (cost if ``i`` is true).
    The move's efficiency is the weighted mean over hypotheses (the plain mean when ``weights`` is None).
    """
    return efficiency_of(distinguishable(outcomes, np.asarray(bounds, dtype=float)), costs, weights)


def efficiency_of(
    eliminates: np.ndarray, costs: np.ndarray | Sequence[float], weights: np.ndarray | Sequence[float] | None = None
) -> tuple[float, np.ndarray]:
    """:func:`move_efficiency` from ``eliminates[i, j]``: whether hypothesis ``j`` is eliminated if ``i`` is
    true."""
    eliminated = np.asarray(eliminates).sum(axis=1).astype(float)
    per = eliminated / np.maximum(np.asarray(costs, dtype=float), 1e-12)
    return float(per @ _normalised(weights, len(per))), per


def expected_eliminations(outcomes: np.ndarray, bounds, weights=None) -> float:
    """Expected number of hypotheses eliminated, ignoring cost (the greedy policy's score)."""
    return expected_eliminated(distinguishable(outcomes, np.asarray(bounds, dtype=float)), weights)


def expected_eliminated(eliminates: np.ndarray, weights=None) -> float:
    """:func:`expected_eliminations` from ``eliminates[i, j]`` (see :func:`efficiency_of`)."""
    d = np.asarray(eliminates)
    return float(d.sum(axis=1) @ _normalised(weights, len(d)))


def move_score(eliminates: np.ndarray, costs: np.ndarray, weights=None) -> tuple[float, float, float]:
    """A candidate's efficiency (:func:`efficiency_of`), expected eliminations (:func:`expected_eliminated`) and
    expected cost (``costs`` per hypothesis, weighted by ``weights``; equal when None)."""
    eff, _ = efficiency_of(eliminates, costs, weights)
    return eff, expected_eliminated(eliminates, weights), float(costs @ _normalised(weights, len(costs)))


def _normalised(weights, n: int) -> np.ndarray:
    return np.full(n, 1.0 / n) if weights is None else np.asarray(weights, dtype=float) / np.sum(weights)


def outcome_groups(outcomes: np.ndarray, bounds) -> list[np.ndarray]:
    """Partition hypotheses into groups that one outcome cannot separate (transitive closure of
    'indistinguishable'); used by the exhaustive search to branch on what the data could show."""
    d = ~distinguishable(outcomes, np.asarray(bounds, dtype=float))
    n = len(d)
    label = -np.ones(n, dtype=int)
    g = 0
    for i in range(n):
        if label[i] >= 0:
            continue
        stack = [i]
        label[i] = g
        while stack:
            k = stack.pop()
            for j in np.flatnonzero(d[k] & (label < 0)):
                label[j] = g
                stack.append(j)
        g += 1
    return [np.flatnonzero(label == k) for k in range(g)]


def class_weights(models: Sequence[str]) -> np.ndarray:
    """Prior weight of each pose class: every model alive gets the same total, shared by its classes."""
    names, counts = np.unique(np.asarray(models), return_counts=True)
    per_model = dict(zip(names.tolist(), counts.tolist(), strict=True))
    w = np.array([1.0 / per_model[m] for m in models])
    return w / w.sum()
