"""Where look-alike hypotheses disagree: a move toward the vertex that tells them apart.

Two models that are the same shape but for a vertex moved a few millimetres (a library model and an object learned
from one of its variants), each posed to fit the data, predict every move's outcome alike within the outcomes'
bounds: the one-move scores eliminate nothing, and the look-ahead, whose last move each hypothesis has already been
fitted to, predicts eliminations that never come (at a box with a corner moved 4 mm it went round the same four
moves to the episode's budget). What tells them apart is the vertex where they differ: its measured position is off
one model's by more than the bounds allow. So when no candidate move is expected to eliminate anything and the
hypotheses left are look-alikes (:func:`look_alikes`), the planner heads for the nearest unmeasured vertex of one of
them with no counterpart within :data:`DISAGREE` bounds in another (:func:`disagreeing_vertices`), by the
verification's moves toward a missing vertex (:func:`~haptic.planning.verify.plan_verification_move`).
"""

from __future__ import annotations

import numpy as np

from haptic.planning.hypothesis import Hypothesis
from haptic.planning.move_scores import Context
from haptic.planning.moves import Move

DISAGREE = 2.0
"""A vertex of one hypothesis is where it disagrees with another when the other's nearest vertex is farther than
this many position bounds (the data's and both models' learned bounds in quadrature): each posed model's vertex is
off by its pose's fit too [-]."""
MOST = 0.5
"""Two hypotheses are look-alikes when more than this share of each one's vertices has a counterpart within
:data:`DISAGREE` bounds in the other [-]."""


def _bound(ctx: Context, a: Hypothesis, b: Hypothesis) -> float:
    """:data:`DISAGREE` position bounds of a vertex of ``a`` against one of ``b`` [m]."""
    own = [h.poly.learned_bounds.position if h.poly.learned_bounds is not None else 0.0 for h in (a, b)]
    data = ctx.noise.k * ctx.noise.position_sigma
    return DISAGREE * float(np.sqrt(data**2 + own[0] ** 2 + own[1] ** 2))


def _far(ctx: Context, hyps: list[Hypothesis]) -> list[np.ndarray]:
    """For each posed hypothesis, per hypothesis, which of its vertices (world) have no counterpart in the other
    within :func:`_bound`: ``far[i][j]`` a bool array over ``i``'s vertices (``far[i][i]`` all False)."""
    pts = [h.world_from_model.apply(h.poly.vertices) for h in hyps]
    out = []
    for i, a in enumerate(hyps):
        row = []
        for j, b in enumerate(hyps):
            if i == j:
                row.append(np.zeros(len(pts[i]), dtype=bool))
                continue
            nearest = np.linalg.norm(pts[i][:, None, :] - pts[j][None, :, :], axis=2).min(axis=1)
            row.append(nearest > _bound(ctx, a, b))
        out.append(row)
    return out


def look_alikes(ctx: Context) -> bool:
    """Whether two or more hypotheses are left, every one posed, and every two are look-alikes (:data:`MOST`)."""
    hyps = list(ctx.hypotheses)
    if len(hyps) < 2 or any(h.world_from_model is None for h in hyps):
        return False
    return _alike(_far(ctx, hyps))


def _alike(far: list[list[np.ndarray]]) -> bool:
    """Whether every two hypotheses are look-alikes, from their :func:`_far` table."""
    n = len(far)
    return all(1.0 - far[i][j].mean() > MOST for i in range(n) for j in range(n) if i != j)


def disagreeing_vertices(ctx: Context, far: list[list[np.ndarray]] | None = None
                         ) -> list[tuple[Hypothesis, frozenset[int]]]:  # fmt: skip
    """For each hypothesis of ``ctx`` (every one posed), the model vertices not paired with data that have no
    counterpart within :data:`DISAGREE` bounds in at least one other hypothesis; on the table, only those the
    verification can measure (:func:`~haptic.planning.verify.reachable_features`). Hypotheses with none are left
    out. ``far``: their :func:`_far` table, when already computed."""
    from haptic.planning.verify import reachable_features

    hyps = list(ctx.hypotheses)
    far = _far(ctx, hyps) if far is None else far
    out = []
    for i, h in enumerate(hyps):
        paired = set(h.vertices.values())
        where = np.logical_or.reduce(far[i])
        ids = {int(v) for v in np.flatnonzero(where) if int(v) not in paired}
        if ids and ctx.config.table_z is not None:
            ids &= set(reachable_features(h.poly, h.world_from_model, ctx.config)[2])
        if ids:
            out.append((h, frozenset(ids)))
    return out


def disagreement_move(ctx: Context) -> Move | None:
    """Toward the cheapest-reached vertex where look-alike hypotheses disagree: of each hypothesis's
    :func:`disagreeing_vertices`, the verification's next move (in that hypothesis's world) of the least tour cost
    from here; None when the hypotheses are not look-alikes (:func:`look_alikes`) or none has such a vertex or a
    move toward it."""
    from haptic.planning.verify import plan_verification_move

    hyps = list(ctx.hypotheses)
    if len(hyps) < 2 or any(h.world_from_model is None for h in hyps):
        return None
    far = _far(ctx, hyps)
    if not _alike(far):
        return None
    best, best_cost = None, np.inf
    for h, ids in disagreeing_vertices(ctx, far):
        missing = (frozenset(), frozenset(), ids)
        move, _, cost = plan_verification_move(h, ctx.state, ctx.components, missing, ctx.noise, ctx.config,
                                               ctx.avoid)  # fmt: skip
        if move is not None and cost < best_cost:
            best, best_cost = move, cost
    return best
