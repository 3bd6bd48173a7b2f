"""The closed loop of one episode: executor → matcher → planner until recognised, ambiguous, no-match, out of
budget, or failed.

Each turn the loop checks its ending conditions (:data:`ENDINGS`), then asks an ordered list of move sources
(:mod:`haptic.episode.sources`) for the next move, carries it out and books the result in the episode's state
(:class:`~haptic.episode.state.EpisodeState`). It owns the order, the budgets and the bookkeeping; which move comes
next is each source's rule.

The loop sees the object only through the executor's data components. The true model and pose are used
here only to place the object (for the geometric executor) and, at the end, to score the outcome.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable, Generator, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Protocol

import numpy as np

from haptic.episode.outcome import score_outcome
from haptic.episode.sources import DecisionPoint, MoveSource, episode_sources
from haptic.episode.spec import EpisodeSpec
from haptic.episode.state import EpisodeState, hypotheses_from
from haptic.errors import HapticError, PlanningError
from haptic.geometry import SE3, Polyhedron
from haptic.geometry.se3 import matrix_to_quat
from haptic.matching.acceptance import K_SIGMA, K_SIGMA_PHYSICS
from haptic.matching.components import SensorNoise
from haptic.matching.recognition import AMBIGUOUS, NO_MATCH, RECOGNIZED, Recognition
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import Move, MoveResult
from haptic.planning.policies import Decision, Policy
from haptic.planning.verify import Verifier

MAX_FAILED_MOVES = 4
"""Consecutive failed moves after which the episode ends as "failed"."""
MAX_INTERPRETATIONS = 200_000
"""Most interpretations the loop lets the tree hold: past it the episode ends as "failed" before another
component is added (the next add tests each interpretation against every model face and would need gigabytes;
probes that hit faces of few distinct normals can double the tree with every hit)."""


@dataclass
class EpisodeRecord:
    """What one episode did and how it scored (the JSON record of docs/design.md and the README, plus traces)."""

    model: str
    pose: dict
    outcome: str
    recognized: str | None
    correct: bool
    moves: int
    path_cost: float
    interpretations: list[int]
    classes: list[int]
    cum_cost: list[float]
    move_kinds: list[str]
    pose_error_mm: float | None
    pose_error_deg: float | None
    seed: int
    policy: str
    executor: str
    noise: float
    faces: int = 0
    edges: int = 0
    vertices: int = 0
    wall_time_s: float = 0.0
    decision_times_s: list[float] = field(default_factory=list)
    failed_moves: int = 0
    sim_time_s: float | None = None
    perception: dict | None = None
    detail: str = ""
    verify: str = "none"
    verified: dict | None = None
    move_set: str = "tracing"
    """Admissible kinds of move (``EpisodeSpec.moves``; a record written before it existed: "tracing")."""
    probes: int = 0
    """Free-space probes carried out."""
    probe_misses: int = 0
    """Of those, probes that met nothing (negative evidence)."""
    fingers: int = 1
    """Fingers the hand could use at once (``EpisodeSpec.fingers``; a record written before it existed: 1)."""
    placements: list[dict] = field(default_factory=list)
    """Each placement of several fingertips carried out or failed, in order: its ``status`` ("ok" or why it
    failed) and ``fingers``, per finger its name and ``status`` ("touched", "missed" or why it failed)."""
    placement_reach: dict | None = None
    """On the simulated hand with several fingers, the planner's reach test of placements
    (:class:`haptic.executor.placement.PlacementReach`): placements ``asked`` about, ``reached``, and why the others
    were not (``reasons``, by the solver's reason); None otherwise."""
    learned: dict | None = None
    """How learning the object went after ``no-match`` (``--learn DIR``: :mod:`haptic.episode.learning`; None:
    no learning)."""

    def to_json(self) -> dict:
        """The record as a dict of plain values (what :func:`dataclasses.asdict` gives: lists and dicts copied, at
        a fraction of its cost; every value is a number, string, bool, None, or a list, tuple or dict of them)."""
        return {f.name: _plain(getattr(self, f.name)) for f in _RECORD_FIELDS}


def _plain(value):
    """A copy of a JSON-like value: containers copied, immutable leaves shared."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return type(value)(_plain(v) for v in value)
    if isinstance(value, int | float | str | bool | None):
        return value
    return copy.deepcopy(value)


_RECORD_FIELDS = fields(EpisodeRecord)


@dataclass
class EpisodeObserver:
    """Hooks for recording (rerun) and progress; every hook is optional."""

    on_start: Callable[[Polyhedron, SE3], None] | None = None
    on_move: Callable[[int, MoveResult, int, Recognition | None], None] | None = None
    on_decision: Callable[[int, Decision], None] | None = None
    on_failed_move: Callable[[int, MoveResult], None] | None = None
    on_end: Callable[[EpisodeRecord], None] | None = None


class Executor(Protocol):
    """What carries out moves (the geometric executor, the simulated hand): each call returns a
    :class:`MoveResult` with the data components the move produced and, when it keeps them, its touches and
    contact trace."""

    def start(self) -> MoveResult:
        """Find the object and settle on a face (the episode's first data)."""
        ...

    def execute(self, move: Move) -> MoveResult:
        """Carry out ``move`` from the current sensor state."""
        ...


class Observer(Protocol):
    """What watches an episode (recordings, progress, scoring): it sees every move result through the loop's
    hooks, each of which may be None. :class:`EpisodeObserver` is one; :func:`chain_observers` joins several."""

    on_start: Callable[[Polyhedron, SE3], None] | None
    on_move: Callable[[int, MoveResult, int, Recognition | None], None] | None
    on_decision: Callable[[int, Decision], None] | None
    on_failed_move: Callable[[int, MoveResult], None] | None
    on_end: Callable[[EpisodeRecord], None] | None


def chain_observers(*observers: Observer | None) -> EpisodeObserver:
    """One observer whose every hook calls the hooks of ``observers`` in order (None entries are skipped)."""
    present = [o for o in observers if o is not None]

    def hook(name: str):
        fns = [getattr(o, name) for o in present if getattr(o, name) is not None]
        if not fns:
            return None

        def call(*args) -> None:
            for fn in fns:
                fn(*args)

        return call

    return EpisodeObserver(**{f.name: hook(f.name) for f in fields(EpisodeObserver)})


def run_loop(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron],
    true_model: Polyhedron,
    world_from_model: SE3,
    executor: Executor,
    noise: SensorNoise,
    config: PlannerConfig,
    policy: Policy,
    rng: np.random.Generator,
    observer: Observer | None = None,
) -> EpisodeRecord:
    """The closed loop over any executor with ``start()`` and ``execute(move)``, ``policy`` answering every
    :class:`DecisionPoint` of :func:`loop_steps`."""
    steps = loop_steps(spec, library, true_model, world_from_model, executor, noise, config, rng, observer)
    return drive(steps, lambda point: policy.choose(point.context, point.rng))


def drive(steps: Generator[DecisionPoint, Decision, EpisodeRecord], choose: Callable[[DecisionPoint], Decision]):
    """Run :func:`loop_steps` to its end, answering each decision point with ``choose`` (a
    :class:`~haptic.errors.HapticError` it raises ends the episode as failed); returns the record."""
    try:
        point = next(steps)
        while True:
            try:
                decision = choose(point)
            except HapticError as exc:
                point = steps.throw(exc)
            else:
                point = steps.send(decision)
    except StopIteration as end:
        return end.value


def loop_steps(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron],
    true_model: Polyhedron,
    world_from_model: SE3,
    executor: Executor,
    noise: SensorNoise,
    config: PlannerConfig,
    rng: np.random.Generator,
    observer: Observer | None = None,
    sources: Sequence[MoveSource] | None = None,
    endings: Sequence[Callable[[EpisodeState, EpisodeSpec], Ending | None]] | None = None,
) -> Generator[DecisionPoint, Decision, EpisodeRecord]:
    """The closed loop as a generator: it yields a :class:`DecisionPoint` whenever the policy is to choose
    and takes the :class:`Decision` sent back (a ``HapticError`` thrown in ends the episode as failed); it
    returns the :class:`EpisodeRecord`. The moves come from ``sources``, asked in order each turn (default:
    :func:`~haptic.episode.sources.episode_sources`, drawing from ``rng``: opening moves, verification moves and
    the random fallback when fewer than two pose classes are left are chosen inside). :func:`run_loop` drives it
    with a policy, :mod:`haptic.env` with the actions of an agent."""
    t0 = time.perf_counter()
    obs = observer or EpisodeObserver()
    if obs.on_start:
        obs.on_start(true_model, world_from_model)
    view = EpisodeState.begin(library, noise, config, _verifier(spec, noise, config, executor))
    sources = episode_sources(library, config, rng) if sources is None else sources
    end = _start(view, executor, obs)
    while end is None:
        end = ending(view, spec, endings)
        if end is None:
            end = yield from _turn(view, sources, executor, obs)
    record = _record(spec, library, true_model, world_from_model, view, end, time.perf_counter() - t0)
    if obs.on_end:
        obs.on_end(record)
    return record


def _start(view: EpisodeState, executor: Executor, obs: Observer) -> Ending | None:
    """The executor finds the object: its first data are booked (an ending when it cannot)."""
    first = executor.start()
    if not first.ok:
        return Ending("failed", f"start: {first.status}" + (f" ({first.reason})" if first.reason else ""))
    view.took(first)
    if obs.on_move:
        obs.on_move(0, first, view.tree.count, view.rec)
    return None


def _turn(
    view: EpisodeState, sources: Sequence[MoveSource], executor: Executor, obs: Observer
) -> Generator[DecisionPoint, Decision, Ending | None]:
    """One move: the first proposal of ``sources``, carried out and booked; every source hears the result. An
    ending when no move can be had (a :class:`~haptic.errors.HapticError` from a source or the driver)."""
    try:
        move = yield from _next_move(view, sources, obs)
    except HapticError as exc:
        return Ending("failed", f"no move: {exc}")
    result = executor.execute(move)
    view.moves += 1
    if result.ok:
        view.took(result)
        if obs.on_move:
            obs.on_move(view.moves, result, view.tree.count, view.rec)
    else:
        view.failed(move, result)
        if obs.on_failed_move:
            obs.on_failed_move(view.moves, result)
    for source in sources:
        source.on_result(view, move, result)
    return None


def _next_move(
    view: EpisodeState, sources: Sequence[MoveSource], obs: Observer
) -> Generator[DecisionPoint, Decision, Move]:
    """The first move a source proposes; a decision point goes to the driver, and a policy's decision (the
    driver's or one taken inside a source) is timed and shown to the observer."""
    for source in sources:
        t = time.perf_counter()
        proposal = source.propose(view)
        if isinstance(proposal, DecisionPoint):
            proposal = yield proposal
        if isinstance(proposal, Decision):
            view.decision_times.append(time.perf_counter() - t)
            if obs.on_decision:
                obs.on_decision(view.moves + 1, proposal)
            return proposal.move
        if proposal is not None:
            return proposal
    raise PlanningError(f"no move source proposed a move (asked: {', '.join(s.name for s in sources)})")


def _verifier(spec: EpisodeSpec, noise: SensorNoise, config: PlannerConfig, executor: Executor | None = None
              ) -> Verifier | None:  # fmt: skip
    """The episode's verification stage (None with ``spec.verify`` "none"), its bounds by executor: an executor
    whose bounds hold systematic floors says how (``bound_floors``,
    :class:`~haptic.matching.acceptance.BoundFloors`)."""
    if spec.verify == "none":
        return None
    return Verifier(spec.verify, noise, config, K_SIGMA_PHYSICS if spec.executor == "physics" else K_SIGMA,
                    getattr(executor, "bound_floors", None))  # fmt: skip


@dataclass(frozen=True)
class Ending:
    """How an episode ends."""

    outcome: str
    """"recognized", "ambiguous", "no-match", "budget" or "failed"."""
    detail: str = ""
    """Why, in words ("" when the outcome says it)."""


def failed_in_a_row(view: EpisodeState, spec: EpisodeSpec) -> Ending | None:
    """Failed: :data:`MAX_FAILED_MOVES` moves failed in a row -- while recognising. A verification is bounded by
    its own rule instead (:data:`~haptic.planning.verify.STALL_MOVES` moves that measure nothing missing end it
    as incomplete, saying what was not measured): each failed verification move is one it does not ask again from
    there, and the next may measure what it needs."""
    if view.failed_in_a_row < MAX_FAILED_MOVES or view.verifying:
        return None
    return Ending("failed", f"{view.failed_in_a_row} failed moves in a row (last: {view.last_failure})")


def verdict(view: EpisodeState, spec: EpisodeSpec) -> Ending | None:
    """The matcher's verdict when final (recognised, ambiguous, no-match); with verification on, a recognition
    is final only when the verifier's verdict is (:meth:`~haptic.planning.verify.Verifier.verdict`)."""
    if view.verifying:
        v = view.verifier
        return None if v.verdict(view.tree, view.rec, view.cost) == "verifying" else Ending(v.outcome(), v.detail())
    if view.rec is not None and view.rec.status in (RECOGNIZED, AMBIGUOUS, NO_MATCH):
        return Ending(view.rec.status, ambiguity(view.rec) if view.rec.status == AMBIGUOUS else "")
    return None


def ambiguity(rec: Recognition) -> str:
    """Why an ambiguous verdict is final, in words: the pose classes left place solids alike wherever a finger
    can touch (congruent models, or poses that differ only toward the table)."""
    names = sorted({c.name for c in rec.classes})
    if len(names) == 1:
        return (f"{len(rec.classes)} poses of {names[0]} left that differ only where no finger reaches: no move tells "
                "them apart")  # fmt: skip
    return (f"{len(rec.classes)} pose classes of the models {', '.join(names)} left, alike wherever a finger "
            "reaches: no move tells them apart")  # fmt: skip


def out_of_budget(view: EpisodeState, spec: EpisodeSpec) -> Ending | None:
    """Budget: the path cost is over ``spec.budget``, or ``spec.max_moves`` moves are made (verification moves
    not counted)."""
    exempt = view.verifier.moves if view.verifier is not None else 0
    return Ending("budget") if view.cost > spec.budget or view.moves - exempt >= spec.max_moves else None


def too_many_interpretations(view: EpisodeState, spec: EpisodeSpec) -> Ending | None:
    """Failed: the tree holds more than :data:`MAX_INTERPRETATIONS` interpretations."""
    if view.tree.count <= MAX_INTERPRETATIONS:
        return None
    return Ending("failed", f"{view.tree.count} interpretations, more than the matcher holds ({MAX_INTERPRETATIONS})")


ENDINGS = (failed_in_a_row, verdict, out_of_budget, too_many_interpretations)
"""The ending conditions, checked in this order before every move."""


def ending(view: EpisodeState, spec: EpisodeSpec, endings: Sequence | None = None) -> Ending | None:
    """The first of ``endings`` (default :data:`ENDINGS`) that ends the episode now, or None."""
    for check in ENDINGS if endings is None else endings:
        end = check(view, spec)
        if end is not None:
            return end
    return None


def _record(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron],
    true_model: Polyhedron,
    world_from_model: SE3,
    view: EpisodeState,
    end: Ending,
    wall_time: float,
) -> EpisodeRecord:
    """The episode's record: what the loop booked, and the outcome scored against the truth."""
    verifier, rec, outcome = view.verifier, view.rec, end.outcome
    if verifier is not None and outcome == NO_MATCH and verifier.status == "verifying":
        verifier.status = "mismatch"  # the matcher itself left no interpretation during the verification
    err_mm, err_deg, correct = score_outcome(spec, library, true_model, world_from_model, outcome, rec)
    n_by_kind = {k: sum(1 for c in view.components.values() if c.kind == k) for k in ("face", "edge", "vertex")}
    n_probes = view.kinds.count("probe")
    return EpisodeRecord(
        model=true_model.name if spec.model in library else str(Path(spec.model).name),
        pose={
            "quat_wxyz": [round(float(x), 9) for x in matrix_to_quat(world_from_model.rotation)],
            "translation_m": [round(float(x), 9) for x in world_from_model.translation],
        },
        outcome=outcome,
        recognized=rec.model if rec is not None and outcome == RECOGNIZED else None,
        correct=bool(correct),
        moves=view.moves,
        path_cost=round(view.cost, 6),
        interpretations=view.counts,
        classes=view.classes,
        cum_cost=[round(c, 6) for c in view.cum_cost],
        move_kinds=view.kinds,
        pose_error_mm=err_mm,
        pose_error_deg=err_deg,
        seed=spec.seed,
        policy=spec.policy,
        executor=spec.executor,
        noise=spec.noise,
        faces=n_by_kind["face"],
        edges=n_by_kind["edge"],
        vertices=n_by_kind["vertex"],
        wall_time_s=round(wall_time, 4),
        decision_times_s=[round(t, 6) for t in view.decision_times],
        failed_moves=view.failed_total,
        detail=end.detail,
        verify=spec.verify,
        verified=verifier.record(view.cost) if verifier is not None else None,
        move_set=spec.moves,
        probes=n_probes,
        probe_misses=n_probes - (len(view.probe_faces) - view.placement_faces),
        fingers=spec.fingers,
        placements=list(view.placements),
    )


__all__ = [
    "ENDINGS",
    "MAX_FAILED_MOVES",
    "MAX_INTERPRETATIONS",
    "DecisionPoint",
    "Ending",
    "EpisodeObserver",
    "EpisodeRecord",
    "Executor",
    "Observer",
    "chain_observers",
    "drive",
    "ending",
    "hypotheses_from",
    "loop_steps",
    "run_loop",
]
