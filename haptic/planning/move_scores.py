"""Scoring candidate moves for a policy: what a policy decides from (:class:`Context`), each fresh candidate's
predicted efficiency (seed §4.1), expected eliminations, cost and risk, and what a decision records.

Below the policies (:mod:`haptic.planning.policies`) and the look-ahead (:mod:`haptic.planning.search`), which
both score moves with it.
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex, SensorNoise
from haptic.matching.free_space import MIN_SPAN, position_span
from haptic.planning.bound import reduce_hypotheses
from haptic.planning.config import PlannerConfig
from haptic.planning.efficiency import class_weights, distinguishable, efficiency_of, expected_eliminated
from haptic.planning.handpath import HandStart
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import EdgeMove, FaceMove, Move, PlacementMove, ProbeMove, SensorState
from haptic.planning.placements import (
    HAND_MAX_TILT,
    PlacementConfig,
    PlacementPrediction,
    candidate_placements,
    placement_path_costs,
    same_placement,
)
from haptic.planning.predict import Prediction, candidate_moves, crossed_edge, predict_moves
from haptic.planning.probe_lines import ProbeConfig, candidate_probes
from haptic.planning.probe_prediction import ProbePrediction, predict_probes
from haptic.planning.simulate import circled_vertex
from haptic.planning.table import descent_risk, hand_trace

PROBE_RISK = 0.25
"""Probes the hand's pad is predicted to fail in this share of the hypotheses' weight or more are not offered
(:meth:`~haptic.planning.probe_prediction.ProbePrediction.risk`): a failed probe tells the matcher nothing, and the loop
then falls back to tracing moves; the rest are discounted by their risk."""


@dataclass(frozen=True, eq=False)
class Context:
    """What a policy decides from."""

    hypotheses: Sequence[Hypothesis]
    """Surviving pose classes."""
    state: SensorState
    """Where the sensor is."""
    components: Mapping[int, DataComponent]
    """Data components so far, by id (latest version of re-reported edges)."""
    noise: SensorNoise
    """Sensor-noise model (for outcome bounds)."""
    config: PlannerConfig = field(default_factory=PlannerConfig)
    """Candidate generation and cost options."""
    avoid: tuple[Move, ...] = ()
    """Moves that failed from the current state (they are not offered again until a move succeeds), and the
    probes carried out so far (a line probed again tells nothing new)."""
    tree: object | None = None
    """The matcher's interpretation tree (an ``InterpretationTree``), when a policy or a check wants to ask
    the matcher itself which hypotheses a predicted outcome would eliminate."""
    moves: int = 0
    """Moves carried out or failed so far in the episode (the start not counted)."""
    cost: float = 0.0
    """Path cost spent so far in the episode [units]."""


@dataclass(frozen=True, eq=False)
class Scored:
    """A candidate move with its score under the deciding policy."""

    move: Move
    score: float
    """Efficiency, expected eliminations, or negative expected cost, by policy."""
    expected_cost: float
    """Weighted mean predicted cost [units]."""
    expected_eliminated: float
    """Weighted mean pose classes eliminated."""
    risk: float = 0.0
    """Predicted chance that the executor cannot carry the move out (the table, a steep descent)."""


@dataclass(frozen=True, eq=False)
class Decision:
    """The chosen move and every candidate considered, for recording and analysis."""

    move: Move
    candidates: tuple[Scored, ...] = ()


_SCORES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""The scores of a decision (:func:`score_all`), per :class:`Context` object, with the data components they were
computed from."""


def score_all(ctx: Context) -> list[tuple[Prediction | ProbePrediction, float, float, float, float]]:
    """Efficiency, expected eliminations, expected cost and risk of every fresh, reliable candidate move; the
    eliminations come from comparing predicted outcome attributes (§4.1). With a table (``config.table_z``),
    moves the hypotheses predict to run into it are left out and the rest discounted by that risk.
    Free-space probes join them when ``config.moves`` admits them, scored in the same form
    (:meth:`ProbePrediction.score`, on the simulated hand discounted by :meth:`ProbePrediction.risk`), so one
    planner ranks every kind of move together; ``config.moves == "probing"`` leaves the tracing moves out. With
    ``config.fingers`` > 1, placements of several fingertips join them too (:func:`score_placements`).

    Computed once per decision: a context scored again (the observation of :mod:`haptic.env` and then the planner
    acting through it, at one decision) gets the same scores back while its data components are the same objects;
    everything else a context holds is fixed when it is made."""
    comps = tuple(ctx.components.values())
    hit = _SCORES.get(ctx)
    if hit is not None and len(hit[0]) == len(comps) and all(a is b for a, b in zip(hit[0], comps, strict=True)):
        return list(hit[1])
    out = _score_all(ctx)
    _SCORES[ctx] = (comps, tuple(out))
    return out


def _score_all(ctx: Context) -> list[tuple[Prediction | ProbePrediction | PlacementPrediction, float, float, float,
                                           float]]:
    weights = class_weights([h.model for h in ctx.hypotheses])
    out: list = []
    if ctx.config.moves != "probing":
        preds = predict_moves(ctx.hypotheses, fresh_moves(ctx), ctx.state, ctx.components, ctx.noise, ctx.config)
        preds = [p for p in preds if p.reliable(ctx.config)] or preds
        preds = [replace(p, outcomes=np.full_like(p.outcomes, np.nan)) if remeasures(ctx, p.move) else p
                 for p in preds]  # fmt: skip
        refused = [(p, refusal(p, ctx.config)) for p in preds]
        refused = [(p, r) for p, r in refused if r < ctx.config.table_risk] or refused
        out = [(pred, *score_prediction(pred, weights, r, ctx.config)) for pred, r in refused]
    lines = weak_probes(ctx, predict_probe_moves(ctx))
    probes = [s for s in (score_probe(pred, weights) for pred in lines) if s is not None]
    others = (*out, *probes)
    beat = (max((c[1] for c in others), default=-np.inf), max((c[2] for c in others), default=-np.inf))
    return out + probes + score_placements(ctx, weights, lines if ctx.config.moves != "tracing" else None, beat)


def alone_data_edges(components: Mapping[int, DataComponent]) -> frozenset[int]:
    """The data edges the hand reported alone: met from one face, the next face out of the pad's reach (leaning
    under, or the table's), no data face adjacent to it. Crossing such an edge again the pad meets it again out of
    reach."""
    listed = {int(a) for c in components.values() if isinstance(c, DataFace) for a in c.adjacent}
    return frozenset(int(d) for d, c in components.items() if isinstance(c, DataEdge) and int(d) not in listed)


def alone_edges(h: Hypothesis, alone: frozenset[int]) -> frozenset[int]:
    """The model edges ``h`` pairs with the data edges ``alone`` (those the hand reported alone:
    :func:`alone_data_edges`)."""
    return frozenset(int(m) for d, m in h.edges.items() if d in alone)


def remeasures(ctx: Context, move: Move) -> bool:
    """Whether ``move`` is predicted, in every hypothesis's world, to measure again what that hypothesis has
    already paired with data: an edge move running to a model vertex paired with a data vertex, a face move
    crossing a model edge paired with a data edge onto a model face paired with a data face, or over a model edge
    paired with a data edge the hand reported alone (:func:`alone_data_edges`: the hypotheses that predict the pad
    steps onto the next face there would be told apart by its angle, and none is, the hand meeting the edge alone
    again; on the public polyhedra at 30 mm, metabiaugmented_hexagonal_prism seed 1 made face moves from one face
    over such edges 9 times in a row with four pose classes left, to the move budget). Each hypothesis has
    been fitted to those data, so what the move measures again can differ between them only by their fit's
    residuals, which the matcher has already let pass: the predicted outcomes tell nothing apart (else, at two
    hypotheses that fit every measurement, a vertex moved 2 mm from its model's place, the planner measured the
    same vertex round and round to the episode's budget)."""
    from haptic.geometry.tracing import trace_edge

    if not ctx.hypotheses or not isinstance(move, FaceMove | EdgeMove):
        return False
    state = ctx.state
    alone = None  # the data edges reported alone, found when first asked
    for h in ctx.hypotheses:
        if h.world_from_model is None:
            return False
        if isinstance(move, EdgeMove):
            e_m = h.edges.get(state.edge) if state.edge is not None else None
            data_edge = ctx.components.get(state.edge) if state.edge is not None else None
            if e_m is None or not isinstance(data_edge, DataEdge):
                return False
            b_world = h.world_from_model.rotate(h.poly.edge_directions[e_m])
            sense = move.sense if b_world @ data_edge.direction > 0 else -move.sense
            hit = trace_edge(h.poly, e_m, h.model_from_world.apply(state.position), sense)
            if hit.vertex not in set(h.vertices.values()):
                return False
        else:
            tr = hand_trace(h, move, state, ctx.config)
            if tr is None or tr.hit.edge not in set(h.edges.values()):
                return False
            if tr.hit.next_face not in set(h.faces.values()):
                alone = alone_data_edges(ctx.components) if alone is None else alone
                if tr.hit.edge not in alone_edges(h, alone):
                    return False
    return True


def score_placements(ctx: Context, weights: np.ndarray, lines: Sequence[ProbePrediction] | None = None,
                     beat: tuple[float, float] = (-np.inf, -np.inf)) -> list[tuple]:
    """Placements of several fingertips (``config.fingers`` > 1, every hypothesis posed), scored as
    :func:`score_all` scores moves, ``(pred, efficiency, eliminations, cost, risk)``: their fingers' lines are
    the candidate probe lines (``lines``, the probes' predictions when the move set has them, else
    :func:`placement_lines`) and a finger predicted to fail tells nothing
    (:class:`~haptic.planning.placements.PlacementPrediction`). With the hand's reach test
    (``config.placement_reach``) only the first placement it reaches is offered, of those beating the best other
    candidate's efficiency or expected eliminations (``beat``: the only ones a policy scoring either could
    choose), costed along the way the test found (:func:`~haptic.planning.placements.placement_path_costs`)."""
    if ctx.config.fingers < 2 or not ctx.hypotheses or any(h.world_from_model is None for h in ctx.hypotheses):
        return []
    lines = placement_lines(ctx) if lines is None else lines
    lines = [p for p in lines if p.risk(weights) < PROBE_RISK]
    avoid = [m for m in ctx.avoid if isinstance(m, PlacementMove)]
    # on the hand without its reach test, fingers close only along lines near straight down; with it, the test
    # decides (each finger pointing along its line)
    tilted = ctx.config.table_z is not None and ctx.config.placement_reach is None
    cfg = PlacementConfig(max_tilt=HAND_MAX_TILT) if tilted else PlacementConfig()
    preds = candidate_placements(lines, weights, ctx.config.fingers, ctx.state.position, ctx.config.costs,
                                 hand_start(ctx), cfg, avoid)  # fmt: skip
    scored = [(p, *p.score(weights), p.risk(weights)) for p in preds]
    reach = ctx.config.placement_reach
    if reach is None:
        return scored
    # one notion of reachability: the hand's own test, asked for the most efficient first; the first reached is
    # offered (with the fingers that reach it), none that it cannot reach
    likely = [ctx.hypotheses[k] for k in np.argsort(-weights, kind="stable")]
    better = [c for c in scored if c[1] > beat[0] or c[2] > beat[1]]
    for item in sorted(better, key=lambda c: -c[1])[: ctx.config.placement_checks]:
        move = reach(item[0].move, likely)
        if move is not None:  # costed along the way the test found (the hand's way there and back)
            costs = placement_path_costs(item[0].lines, move, ctx.state.position, ctx.config.costs, hand_start(ctx))
            pred = replace(item[0], move=move, costs=costs)
            return [(pred, *pred.score(weights), pred.risk(weights))]
    return []


def placement_lines(ctx: Context) -> list[ProbePrediction]:
    """The lines a placement's fingers may close along: the candidate probe lines
    (:func:`~haptic.planning.probe_lines.candidate_probes`), predicted in every hypothesis."""
    cfg = probe_config(ctx.config)
    moves = candidate_probes(ctx.hypotheses, cfg)
    return weak_probes(ctx, predict_probe_moves(ctx, moves))


def score_probe(pred: ProbePrediction, weights: np.ndarray) -> tuple | None:
    """A probe scored as :func:`score_all` scores it, ``(pred, efficiency, eliminations, cost, risk)``, both
    discounted by the risk that the hand's pad touches what the line-cast does not predict (0: a point sensor);
    None when that risk is :data:`PROBE_RISK` or more."""
    eff, elim, cost = pred.score(weights)
    risk = pred.risk(weights)
    if risk >= PROBE_RISK:
        return None
    return pred, eff * (1.0 - risk), elim * (1.0 - risk), cost, risk


def probe_moves(ctx: Context) -> list[ProbeMove]:
    """Candidate free-space probes (:func:`~haptic.planning.probe_lines.candidate_probes`) when the configuration admits
    them (``config.moves``) and every hypothesis has a pose to predict from, less those that failed from here."""
    if ctx.config.moves == "tracing" or not ctx.hypotheses or any(h.world_from_model is None for h in ctx.hypotheses):
        return []
    cfg = probe_config(ctx.config)
    return [m for m in candidate_probes(ctx.hypotheses, cfg) if not any(same_move(m, bad) for bad in ctx.avoid)]


def probe_config(config: PlannerConfig) -> ProbeConfig:
    """The probe lines' options for a planner configuration: its table, and the simulated hand's pad when there is
    a table (a point sensor without one)."""
    pad = config.pad_radius if config.table_z is not None else 0.0
    return ProbeConfig(table_z=config.table_z, table_clearance=config.table_clearance, pad_radius=pad,
                       max_undercut=config.max_undercut)  # fmt: skip


def predict_probe_moves(ctx: Context, moves: Sequence[ProbeMove] | None = None) -> list[ProbePrediction]:
    """Every hypothesis's predicted outcome of each candidate probe (:func:`probe_moves`, or ``moves``), its cost
    along the simulated hand's path (:func:`hand_start`) when the configuration has a pad and a table."""
    moves = probe_moves(ctx) if moves is None else list(moves)
    return predict_probes(ctx.hypotheses, moves, ctx.state.position, ctx.components, ctx.noise, ctx.config.costs,
                          hand_start(ctx))  # fmt: skip


def weak_probes(ctx: Context, preds: list[ProbePrediction]) -> list[ProbePrediction]:
    """``preds`` as the matcher will take their outcomes: while the data fix a position too weakly for it to test
    probe data against posed hypotheses (:func:`~haptic.matching.free_space.position_span` below
    :data:`~haptic.matching.free_space.MIN_SPAN`), a probe's miss, or where it hits, eliminates none of them
    (predicted to, probe after probe missed a re-identified L-block's three pose classes to the episode's
    budget)."""
    if not preds or position_span(list(ctx.components.values())) >= MIN_SPAN:
        return preds
    none = np.zeros((len(ctx.hypotheses), len(ctx.hypotheses)), dtype=bool)
    return [replace(p, known=none) for p in preds]


def hand_start(ctx: Context) -> HandStart | None:
    """Where the simulated hand's pad is, from the data (:class:`~haptic.planning.handpath.HandStart`): touching
    the sensor's position on its face (that face's normal), below the highest contact point of the data
    components; None without a pad and a table (a point sensor)."""
    c = ctx.config
    face = ctx.components.get(ctx.state.face)
    if c.table_z is None or c.pad_radius <= 0.0 or not isinstance(face, DataFace):
        return None
    points = [np.atleast_2d(ctx.state.position)]
    for comp in ctx.components.values():
        if isinstance(comp, DataFace):
            points.append(np.atleast_2d(comp.points))
        elif isinstance(comp, DataEdge):
            points.append(np.atleast_2d(comp.point))
        elif isinstance(comp, DataVertex):
            points.append(np.atleast_2d(comp.position))
    return HandStart.at(ctx.state.position, face.normal, np.concatenate(points), c.pad_radius, c.max_undercut)


def score_prediction(
    pred: Prediction, weights: np.ndarray, refused: float, config: PlannerConfig
) -> tuple[float, float, float, float]:
    """Efficiency and expected eliminations of one predicted move, both discounted by its risk (``refused``,
    :func:`refusal`, and a steep descent), its expected cost and that risk; ``weights`` sum to 1."""
    d = eliminates(pred, config)
    eff, _ = efficiency_of(d, pred.costs, weights)
    elim = expected_eliminated(d, weights)
    ok = (1.0 - refused) * (1.0 - descent_risk(pred.move, config))
    return eff * ok, elim * ok, float(pred.costs @ weights), 1.0 - ok


def _failing(pred: Prediction, config: PlannerConfig) -> np.ndarray | None:
    """Hypotheses in which the face move fails for the table (or a face out of reach) after touching its
    face some way, when touched points count as evidence; None when there are none."""
    if not config.touch_evidence or pred.reach is None or pred.table is None:
        return None
    fails = pred.table == 1
    return fails if fails.any() else None


def refusal(pred: Prediction, config: PlannerConfig) -> float:
    """Predicted chance that the move is refused or aborted for the table before it tells anything: with
    touched points as evidence, a face move failing after a trace of at least ``config.min_face_travel`` has
    told how far its face reaches."""
    fails = _failing(pred, config)
    if fails is None:
        return pred.table_risk
    t = np.where(fails & (pred.reach >= config.min_face_travel), 0.0, pred.table)
    return 0.0 if np.isnan(t).all() else float(np.nanmean(t))


def eliminates(pred: Prediction, config: PlannerConfig) -> np.ndarray:
    """``D[i, j]``: hypothesis ``j`` eliminated if ``i`` is true. By the predicted attributes (§4.1); where the
    face move ends at its edge in ``i``'s world, the next face out of reach, by the edge's distance and angle
    alone; where it fails in ``i``'s world, only the hypotheses whose face ends sooner than ``i``'s trace (it
    touches points beyond their edge)."""
    d = distinguishable(pred.outcomes, pred.bounds)
    if pred.edge_only is not None and (pred.edge_only == 1).any():
        d_edge = distinguishable(pred.outcomes[:, :2], pred.bounds[:2])
        d = np.where((pred.edge_only == 1)[:, None], d_edge, d)
    fails = _failing(pred, config)
    if fails is None:
        return d
    with np.errstate(invalid="ignore"):
        beyond = pred.reach[:, None] - pred.outcomes[None, :, 0] > max(pred.bounds[0], config.touch_margin)
    return np.where(fails[:, None], beyond, d)


_BOUNDED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
""":func:`bounded` per :class:`Context` object (its hypotheses are fixed when it is made)."""


def bounded(ctx: Context) -> Context:
    """``ctx`` with at most ``config.max_hypotheses`` hypotheses (:mod:`haptic.planning.bound`); the same object for
    the same ``ctx`` (so that its scores are computed once: :func:`score_all`)."""
    if ctx in _BOUNDED:
        return _BOUNDED[ctx]
    kept = reduce_hypotheses(ctx.hypotheses, ctx.config.max_hypotheses)
    out = ctx if len(kept) == len(ctx.hypotheses) else replace(ctx, hypotheses=tuple(kept))
    if out is not ctx:  # (the context itself needs no entry: bounded already)
        _BOUNDED[ctx] = out
    return out


def fresh_moves(ctx: Context) -> list[Move]:
    """Candidate moves, less vertex moves that every hypothesis says circle back to an explored edge (or to one
    the hand reported alone, :func:`alone_data_edges`), and
    (while others remain) face moves that the hypotheses, by at least half their weight, say cross the edge a face
    move that failed from here was to cross: the pad did not get over it, and at another angle seldom does."""
    out, again = [], []
    failed_face = [bad for bad in ctx.avoid if isinstance(bad, FaceMove)]
    alone = alone_data_edges(ctx.components)
    for move in candidate_moves(ctx.state, ctx.components, ctx.config):
        if any(same_move(move, bad) for bad in ctx.avoid):
            continue
        if move.kind == "vertex" and ctx.hypotheses and all(
            (hit := circled_vertex(h, move, ctx.state, ctx.config)) is None
            or hit.edge in alone_edges(h, alone)
            for h in ctx.hypotheses
        ):
            continue
        if isinstance(move, FaceMove) and any(_same_crossing(move, bad, ctx) for bad in failed_face):
            again.append(move)
            continue
        out.append(move)
    return out or again


def _same_crossing(a: FaceMove, b: FaceMove, ctx: Context) -> bool:
    """Whether the hypotheses that can say, by at least half their weight, predict face moves ``a`` and ``b``
    to cross the same edge."""
    weights = class_weights([h.model for h in ctx.hypotheses])
    same = differ = 0.0
    for h, w in zip(ctx.hypotheses, weights, strict=True):
        ea, eb = crossed_edge(h, a, ctx.state, ctx.config), crossed_edge(h, b, ctx.state, ctx.config)
        if ea is None or eb is None:
            continue
        if ea == eb:
            same += w
        else:
            differ += w
    return same > 0.0 and same >= differ


def same_move(a: Move, b: Move) -> bool:
    """Two moves are the same when of one kind with the same parameter (face directions within ~8°; probes along
    nearly one line)."""
    if a.kind != b.kind:
        return False
    if a.kind == "face":
        return float(np.dot(a.direction, b.direction)) > 0.99
    if a.kind == "edge":
        return a.sense == b.sense
    if a.kind == "placement":
        return same_placement(a, b)
    if a.kind == "probe":  # one line: the same direction, starts within a probe target's spacing
        return (
            float(np.dot(a.direction, b.direction)) > 0.99
            and float(np.linalg.norm(np.asarray(a.start) - np.asarray(b.start))) < ProbeConfig.target_spacing
        )
    return a.across_face == b.across_face
