"""Candidate placements of several fingertips at once, predicted per pose class and scored like every move (seed §5).

The seed's last section names what it did not do: the hand's several fingers, "the matching part is essentially
unchanged, but the planning gets far more complicated", while "the set of admissible moves, and the cost and
efficiency measures ... should remain relevant". A placement (:class:`~haptic.planning.moves.PlacementMove`)
closes two to four fingertips in one approach of the hand, each along its own line onto a face, as a probe
(§1.1) does with one; each finger that touches yields a face component.

Candidates come from the hypotheses. Each finger's line is one of the candidate probe lines aimed at the pose
classes' faces (:func:`~haptic.planning.probe_lines.candidate_probes`, so with the probes' clearance from the
table and the finger above the pad), predicted per pose class as a probe is
(:func:`~haptic.planning.probe_prediction.predict_probes`). Lines are put together into one placement when one
hand can close on them together (:func:`compatible`): their closing directions within :attr:`PlacementConfig.
max_spread` of each other, their predicted contacts at least a finger's spacing apart and within the hand's
span, and on different faces in most of the hypotheses that predict both to touch. Placements grow greedily from
the most telling lines, one finger at a time, keeping the finger that makes the placement most efficient.

If hypothesis ``i`` is true, ``j`` is eliminated when any finger's outcome eliminates it
(:meth:`~haptic.planning.probe_prediction.ProbePrediction.eliminates`: a finger predicted to fail in either world
tells nothing); the relative positions of the fingers' contacts, which the matcher also tests, only add to that,
so the prediction errs toward fewer eliminations. The cost in ``i``'s world is
:meth:`~haptic.planning.moves.CostModel.placement_move` of the hand's travel there. Efficiency is expected pose
classes eliminated per unit cost (§4.1.1), as for face, edge and vertex moves and probes, so one planner ranks
them together.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from haptic.planning.efficiency import efficiency_of, expected_eliminated, move_score
from haptic.planning.handpath import LIFT, HandStart, safe_height
from haptic.planning.moves import CostModel, FingerApproach, PlacementMove, ProbeMove
from haptic.planning.probe_prediction import ProbePrediction

HAND_FINGERS = ("index", "middle", "ring", "thumb")
"""The hand's fingers in the order a placement assigns them (the simulated hand's ``haptic.sim.scene.FINGERS``)."""


@dataclass(frozen=True)
class PlacementConfig:
    """Options of placement candidate generation."""

    finger_spacing: float = 0.03
    """Least distance between two fingers' predicted contacts: the hand's pads are 24 mm across and its fingers'
    bases 40 mm apart [m]."""
    max_span: float = 0.15
    """Greatest distance between two fingers' predicted contacts: about what the hand's fingers and thumb span
    (its fingers are 40 mm apart at the base and some 90 mm long) [m]."""
    max_spread: float = np.deg2rad(90.0)
    """Greatest angle between two fingers' closing directions: the fingers of one palm flex toward its front
    [rad]."""
    min_hit_share: float = 0.5
    """A line joins a placement only when the hypotheses predict it to touch by at least this share of their
    weight: a placement's fingers aim at faces."""
    min_other_face: float = 0.5
    """Two lines are on different faces when, of the hypotheses' weight that predicts both to touch, at least
    this share has them touch different model faces."""
    seeds: int = 6
    """Placements grow from this many of the most telling lines (by expected eliminations)."""
    pool: int = 24
    """Each finger added is one of this many most telling lines."""
    max_tilt: float | None = None
    """Fingers close only along lines within this of straight down (None: any line). The simulated hand's
    (:data:`HAND_MAX_TILT`): its fingers point down, and a finger pointing across its line closes with its links
    ahead of its pad [rad]."""


HAND_MAX_TILT = np.deg2rad(30.0)
"""The simulated hand's :attr:`PlacementConfig.max_tilt` [rad]."""


@dataclass(frozen=True, eq=False)
class PlacementPrediction:
    """A candidate placement with every hypothesis's predicted outcome (one probe prediction per finger) and cost."""

    move: PlacementMove
    """The candidate."""
    lines: tuple[ProbePrediction, ...]
    """Each finger's line predicted as a probe, in the order of ``move.fingers``."""
    costs: np.ndarray
    """Predicted cost per hypothesis, shape (N,) [units]."""

    def eliminates(self) -> np.ndarray:
        """``D[i, j]``: hypothesis ``j`` eliminated if ``i`` is true, by any finger's outcome, shape (N, N)."""
        d = self.lines[0].eliminates().copy()
        for p in self.lines[1:]:
            d |= p.eliminates()
        return d

    def risk(self, weights: np.ndarray | None = None) -> float:
        """The mean over fingers of each finger's predicted failure risk (a failed finger fails alone)."""
        return float(np.mean([p.risk(weights) for p in self.lines]))

    def score(self, weights: np.ndarray | None = None) -> tuple[float, float, float]:
        """Efficiency, expected eliminations and expected cost, as :meth:`ProbePrediction.score` gives them."""
        return move_score(self.eliminates(), self.costs, weights)


def placement_costs(
    lines: Sequence[ProbePrediction], position: np.ndarray, costs: CostModel, hand: HandStart | None = None
) -> np.ndarray:
    """Each hypothesis's cost of closing the fingers of ``lines`` in one approach: the hand's travel is its way to
    the placement (the longest of the fingers' ways to their lines' starts: the hand carries them together) and
    the longest finger's closing, to contact or its line's end, and back from there when no finger touches;
    :meth:`~haptic.planning.moves.CostModel.placement_move` of it, with a stroke per contact on the hand (``hand``
    given; a point sensor has the normal at contact)."""
    starts = np.array([p.move.start for p in lines], dtype=float)
    dirs = np.array([p.move.direction for p in lines], dtype=float)
    lengths = np.array([p.move.length for p in lines], dtype=float)
    if hand is None:
        here = np.asarray(position, dtype=float)
        transfer = np.linalg.norm(starts - here, axis=1)
        back = np.linalg.norm(starts + lengths[:, None] * dirs - here, axis=1)
    else:
        transfer, back = hand.distances(starts, dirs, lengths)
    hit = np.array([p.hit for p in lines])  # (K, N)
    closing = np.where(hit, np.nan_to_num(np.array([p.distance for p in lines])), lengths[:, None])
    s = float(np.max(transfer)) + closing.max(axis=0) + np.where(hit.any(axis=0), 0.0, float(np.min(back)))
    contacts = hit.sum(axis=0)
    strokes = contacts if hand is not None else 0  # a point sensor has the normal at contact
    return np.asarray(costs.placement_move(s, len(lines), strokes), dtype=float)  # (the formula, elementwise)


def placement_path_costs(
    lines: Sequence[ProbePrediction], move: PlacementMove, position: np.ndarray, costs: CostModel,
    hand: HandStart | None = None,
) -> np.ndarray:
    """Each hypothesis's cost of the placement ``move`` along the way the hand's reach test found for it
    (``move.travel`` and ``move.home``; :func:`placement_costs` without them), the fingers closing along
    ``lines``: the exploring pad lifts off its face, rises to the safe height and goes over to its place at the
    path's start (``home``); the fingers' pads go along the path (``travel``, the farthest of them) to their lines'
    starts and close, the longest to contact or its line's end; then the fingers retract, the hand rises straight
    up to the height it went over at (the safe height, or the path's start where higher: the way back to the
    tracing posture) and its exploring pad goes over and down to the first face a finger touched (when none did,
    to the face it left). :meth:`~haptic.planning.moves.CostModel.placement_move` of that way, with a stroke
    per contact on the hand."""
    if move.travel is None or move.home is None:
        return placement_costs(lines, position, costs, hand)
    starts = np.array([p.move.start for p in lines], dtype=float)
    dirs = np.array([p.move.direction for p in lines], dtype=float)
    lengths = np.array([p.move.length for p in lines], dtype=float)
    home = np.asarray(move.home, dtype=float)
    if hand is None:
        here, r, top = np.asarray(position, dtype=float), 0.0, float(np.asarray(position)[2])
        lifted = here
    else:
        here, r, top = hand.tip, hand.pad_radius, hand.highest
        lifted = hand.tip + LIFT * np.asarray(hand.normal, dtype=float)
    c0 = starts - r * dirs
    z_safe = max(float(np.max(safe_height(top, r, c0, here))), float(home[2]))
    to_home = (float(np.linalg.norm(lifted - here)) + (z_safe - float(lifted[2]))
               + float(np.linalg.norm(home - np.array([lifted[0], lifted[1], z_safe]))))  # fmt: skip
    hit = np.array([p.hit for p in lines])  # (K, N)
    depth = np.nan_to_num(np.array([p.distance for p in lines]))
    closing = np.where(hit, depth, lengths[:, None])  # (K, N)
    # back: the fingers retract and the hand rises straight up to the safe height; the exploring pad goes over,
    # from above the fingers' contacts, and down to the first face touched (else to the face it left)
    ends = c0[:, None, :] + closing[..., None] * dirs[:, None, :]  # (K, N, 3) each pad's place at its closing's end
    first = np.argmax(hit, axis=0)  # (N,) the first finger touching in each world (0 when none)
    touched = np.where(hit.any(axis=0)[:, None], ends[first, np.arange(hit.shape[1])], lifted[None])  # (N, 3)
    low = ends[..., 2].min(axis=0)  # (N,)
    over = np.linalg.norm(ends.mean(axis=0)[:, :2] - touched[:, :2], axis=1)
    back = LIFT + (z_safe - low) + over + (z_safe - touched[:, 2])
    s = to_home + move.travel + closing.max(axis=0) + back
    strokes = hit.sum(axis=0) if hand is not None else 0
    return np.asarray(costs.placement_move(s, len(lines), strokes), dtype=float)


def _contact_points(lines: Sequence[ProbePrediction], weights: np.ndarray) -> np.ndarray:
    """Each line's weighted mean predicted contact over the hypotheses predicting one, (L, 3) (NaN: none do)."""
    out = np.full((len(lines), 3), np.nan)
    for k, p in enumerate(lines):
        if p.hit.any():
            w = weights[p.hit] / weights[p.hit].sum()
            t = float(np.nan_to_num(p.distance[p.hit]) @ w)
            out[k] = np.asarray(p.move.start) + t * np.asarray(p.move.direction)
    return out


def compatibility(lines: Sequence[ProbePrediction], weights: np.ndarray, config: PlacementConfig) -> np.ndarray:
    """``ok[a, b]``: whether one hand can close two fingers along lines ``a`` and ``b`` together (module
    docstring), shape (L, L) bool, False on the diagonal."""
    u = np.array([p.move.direction for p in lines], dtype=float)
    spread = u @ u.T >= np.cos(config.max_spread)
    c = _contact_points(lines, weights)
    gap = np.linalg.norm(c[:, None] - c[None], axis=2)
    with np.errstate(invalid="ignore"):
        apart = (gap >= config.finger_spacing) & (gap <= config.max_span)
    hit = np.array([p.hit for p in lines], dtype=float)  # (L, N)
    face = np.array([p.face for p in lines])
    both = hit * weights[None] @ hit.T  # weight predicting both to touch
    same = np.einsum("an,bn,abn,n->ab", hit, hit, face[:, None] == face[None], weights)
    with np.errstate(invalid="ignore", divide="ignore"):
        other = (both - same) / both
    ok = spread & apart & (both > 0) & (np.nan_to_num(other) >= config.min_other_face)
    np.fill_diagonal(ok, False)
    return ok


def compatible(a: ProbePrediction, b: ProbePrediction, weights: np.ndarray, config: PlacementConfig) -> bool:
    """Whether one hand can close two fingers along ``a``'s and ``b``'s lines together (:func:`compatibility`)."""
    return bool(compatibility([a, b], np.asarray(weights, dtype=float) / np.sum(weights), config)[0, 1])


def candidate_placements(
    lines: Sequence[ProbePrediction],
    weights: np.ndarray,
    fingers: int,
    position: np.ndarray,
    costs: CostModel,
    hand: HandStart | None = None,
    config: PlacementConfig | None = None,
    avoid: Sequence[PlacementMove] = (),
) -> list[PlacementPrediction]:
    """Placements of 2 to ``fingers`` fingertips over the predicted probe ``lines`` (module docstring), each
    predicted and costed, less those in ``avoid`` (:func:`same_placement`); none when ``fingers`` < 2."""
    config = config or PlacementConfig()
    w = np.asarray(weights, dtype=float) / np.sum(weights)
    if fingers < 2 or len(lines) < 2:
        return []
    useful = [p for p in lines if float(w[p.hit].sum()) >= config.min_hit_share]
    if config.max_tilt is not None:
        useful = [p for p in useful if float(p.move.direction[2]) <= -np.cos(config.max_tilt)]
    if len(useful) < 2:
        return []
    elim = np.array([expected_eliminated(p.eliminates(), w) for p in useful])
    order = np.argsort(-elim, kind="stable")
    pool = [useful[i] for i in order[: config.pool]]
    ok = compatibility(pool, w, config)
    out: list[PlacementPrediction] = []
    for seed in range(min(config.seeds, len(pool))):
        chosen = [seed]
        d = pool[seed].eliminates()
        while len(chosen) < min(fingers, len(HAND_FINGERS)):
            best, best_eff = None, -np.inf
            for k in np.flatnonzero(ok[chosen].all(axis=0)):
                cand = [pool[i] for i in (*chosen, k)]
                eff, _ = efficiency_of(d | pool[k].eliminates(), placement_costs(cand, position, costs, hand), w)
                if eff > best_eff:
                    best, best_eff = int(k), eff
            if best is None:
                break
            chosen.append(best)
            d = d | pool[best].eliminates()
            pred = _placement([pool[i] for i in chosen], position, costs, hand)
            if not any(same_placement(pred, q) for q in (*out, *avoid)):
                out.append(pred)
    return out


def _placement(
    lines: Sequence[ProbePrediction], position: np.ndarray, costs: CostModel, hand: HandStart | None
) -> PlacementPrediction:
    fingers = tuple(
        FingerApproach(name, np.asarray(p.move.start), np.asarray(p.move.direction), float(p.move.length))
        for name, p in zip(HAND_FINGERS, lines, strict=False)
    )
    return PlacementPrediction(PlacementMove(fingers), tuple(lines), placement_costs(lines, position, costs, hand))


def same_placement(a: PlacementMove | PlacementPrediction, b: PlacementMove | PlacementPrediction) -> bool:
    """Two placements are the same when their fingers' lines are the same set (as probes, :data:`SAME_LINE`)."""
    a = a.move if isinstance(a, PlacementPrediction) else a
    b = b.move if isinstance(b, PlacementPrediction) else b
    if len(a.fingers) != len(b.fingers):
        return False
    return all(any(_same_line(f.line, g.line) for g in b.fingers) for f in a.fingers)


SAME_LINE = 0.01
"""Two fingers' lines are one when of nearly one direction with starts closer than this [m] (a probe target's
spacing)."""


def _same_line(a: ProbeMove, b: ProbeMove) -> bool:
    return float(np.dot(a.direction, b.direction)) > 0.99 and float(np.linalg.norm(a.start - b.start)) < SAME_LINE


__all__ = [
    "HAND_FINGERS",
    "HAND_MAX_TILT",
    "SAME_LINE",
    "PlacementConfig",
    "PlacementPrediction",
    "candidate_placements",
    "compatibility",
    "compatible",
    "placement_costs",
    "placement_path_costs",
    "same_placement",
]
