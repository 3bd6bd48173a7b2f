"""A bound on the hypotheses a policy scores a move against, so that its cost stays bounded with the library.

Scoring a candidate move predicts its outcome under every hypothesis (pose class) and compares the predictions
pairwise (seed §4.1): the cost grows with the number of hypotheses N as N (prediction) and N² (comparison).
With a library of hundreds of models the first moves may leave hundreds of pose classes. When more than
``PlannerConfig.max_hypotheses`` remain, the policy scores against a *reduced* set:

- the classes are grouped by model, and taken model by model in turns (the first class of every model, then
  the second of every model, ...) until the bound is reached, so that every surviving model keeps at least one
  class while the bound allows, and no model's many look-alike poses crowd the others out;
- when more models survive than the bound, an evenly spaced selection of the models (in library order) keeps
  one class each.

The prior weights (:func:`~haptic.planning.efficiency.class_weights`) are recomputed over the kept classes, so
every kept model keeps an equal share. Expected eliminations are then counted among the kept classes: a move
that separates models is still found, but the planner may miss the move that best splits the many poses of one
model. The effect on path cost is measured by ``scripts/bench_scale.py --compare-bound``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from haptic.planning.hypothesis import Hypothesis


def reduce_hypotheses(hypotheses: Sequence[Hypothesis], bound: int | None) -> list[Hypothesis]:
    """At most ``bound`` of ``hypotheses`` (all of them, in order, when there are not more; None: no bound),
    chosen model by model in turns, in their order (see the module docstring)."""
    hyps = list(hypotheses)
    if bound is None or len(hyps) <= bound:
        return hyps
    if bound < 1:
        raise ValueError(f"the hypothesis bound must be at least 1, got {bound}")
    by_model: dict[str, list[int]] = {}
    for i, h in enumerate(hyps):
        by_model.setdefault(h.model, []).append(i)
    groups = list(by_model.values())
    if len(groups) >= bound:
        pick = np.unique(np.linspace(0, len(groups) - 1, bound).round().astype(int))
        return [hyps[groups[int(k)][0]] for k in pick]
    keep: list[int] = []
    depth = 0
    while len(keep) < bound:
        for g in groups:
            if depth < len(g):
                keep.append(g[depth])
                if len(keep) == bound:
                    break
        depth += 1
    return [hyps[i] for i in sorted(keep)]
