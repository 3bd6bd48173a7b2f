"""The closed loop of one episode: executor → matcher → planner until recognised, ambiguous, no-match, out of
budget, or failed.

The loop sees the object only through the executor's data components. The true model and pose are used
here only to place the object (for the geometric executor) and, at the end, to score the outcome.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Generator
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Protocol

import numpy as np

from haptic.episode.opening import (
    cheaper_opening,
    edge_run_of,
    opening_move,
    opening_probe,
    tracing_remainder,
)
from haptic.episode.outcome import score_outcome
from haptic.episode.perception import on_the_table, touched_points
from haptic.episode.spec import EpisodeSpec
from haptic.errors import HapticError
from haptic.geometry import SE3, Polyhedron
from haptic.geometry.se3 import matrix_to_quat
from haptic.matching.acceptance import K_SIGMA, K_SIGMA_PHYSICS
from haptic.matching.components import DataComponent, SensorNoise
from haptic.matching.free_space import MAX_POSED as PROBES_MAX_POSED
from haptic.matching.free_space import FreeSegment, apply_probes
from haptic.matching.recognition import AMBIGUOUS, EXPLORING, NO_MATCH, RECOGNIZED, Recognition, recognize
from haptic.matching.tree import InterpretationTree
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import Move, MoveResult
from haptic.planning.opening_probes import LibraryExtent
from haptic.planning.policies import Context, Decision, Policy, RandomPolicy
from haptic.planning.verify import Verifier

MAX_POSED = 4000
"""Largest number of interpretations whose poses are computed to group them into pose classes (all of them in one
batch); above it the loop takes a random move."""
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

    def to_json(self) -> dict:
        return asdict(self)


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


def hypotheses_from(tree: InterpretationTree, rec: Recognition) -> list[Hypothesis]:
    """One hypothesis per pose class, from the class's first interpretation."""
    out = []
    for c in rec.classes:
        it = tree.interpretation(c.leaves[0], with_pose=True, refine=True)
        out.append(
            Hypothesis(
                model=c.name,
                poly=c.model,
                world_from_model=it.world_from_model or c.world_from_model,
                faces=it.faces,
                edges=it.edges,
                vertices=it.vertices,
                size=len(c.leaves),
                leaves=tuple(c.leaves),
            )
        )
    return out


@dataclass(frozen=True, eq=False)
class DecisionPoint:
    """Where the loop asks its policy for the next move (:func:`loop_steps` yields one)."""

    context: Context
    """What the policy decides from: two or more pose classes left, no verification under way."""
    rng: np.random.Generator
    """The episode's policy generator (the one the opening moves draw from too)."""


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
) -> Generator[DecisionPoint, Decision, EpisodeRecord]:
    """The closed loop as a generator: it yields a :class:`DecisionPoint` whenever the policy is to choose
    and takes the :class:`Decision` sent back (a ``HapticError`` thrown in ends the episode as failed); it
    returns the :class:`EpisodeRecord`. Opening moves, verification moves and the random fallback (fewer than
    two pose classes) are chosen inside. :func:`run_loop` drives it with a policy, :mod:`haptic.env` with
    the actions of an agent."""
    t0 = time.perf_counter()
    obs = observer or EpisodeObserver()
    if obs.on_start:
        obs.on_start(true_model, world_from_model)
    tree = InterpretationTree(library)
    components: dict[int, DataComponent] = {}
    counts: list[int] = []
    n_classes: list[int] = []
    cum_cost: list[float] = []
    kinds: list[str] = []
    decision_times: list[float] = []
    cost = 0.0
    failed_in_a_row = failed_total = 0
    failed_here: list[Move] = []
    rec: Recognition | None = None
    outcome, detail = EXPLORING, ""
    fallback = RandomPolicy()
    verifier = None
    if spec.verify != "none":
        verifier = Verifier(spec.verify, noise, config, K_SIGMA_PHYSICS if spec.executor == "physics" else K_SIGMA)

    touched: list[tuple[np.ndarray, np.ndarray]] = []
    free: list[FreeSegment] = []  # free space the probes travelled (a miss's line, a hit's approach)
    probe_faces: list[int] = []  # data ids of the faces probes hit
    probed: list[Move] = []  # probes carried out or failed: the same line again would tell nothing new (or fail again)

    def assess() -> Recognition:
        """The verdict on the data so far (with the table and the touched points, when known)."""
        r = recognize(tree, max_interpretations=MAX_POSED)
        if config.table_z is None:
            return r
        if not touched:
            return on_the_table(r, tree, components, config)
        both = (np.concatenate([p for p, _ in touched]), np.concatenate([n for _, n in touched]))
        return on_the_table(r, tree, components, config, both)

    def absorb(result: MoveResult) -> None:
        nonlocal cost, rec
        for c in result.components:
            components[c.id] = c
            tree.add(c)
        free.extend(result.free_space)
        if result.move is not None and result.move.kind == "probe":
            probe_faces.extend(c.id for c in result.components)
            probed.append(result.move)
        if free:  # after every add: poses tighten, and leaves unposed or too many before become testable
            apply_probes(tree, free, probe_faces)
        if config.touch_evidence:
            touched.append(touched_points(result, config))
        cost += result.cost
        rec = assess()
        counts.append(tree.count)
        n_classes.append(len(rec.classes) if rec.classes else tree.count)
        cum_cost.append(cost)
        kinds.append(result.move.kind if result.move is not None else "start")

    n_moves = 0
    first = executor.start()
    if not first.ok:
        outcome, detail = "failed", f"start: {first.status}"
    else:
        absorb(first)
        state = first.state
        if obs.on_move:
            obs.on_move(0, first, tree.count, rec)
        probing = config.moves == "probing"  # probes until the hypotheses have poses: the opening is probes
        # each new face of the opening by a tracing move or a probe; the simulated hand (a table) keeps the seed's
        # tracing opening: its probes cost more than predicted, and failed ones more again
        choosing = config.moves == "all" and config.table_z is None
        fixed = [] if probing else ["face", "edge", "vertex"]
        extent = LibraryExtent.of(library.values()) if probing or choosing else None
        while True:
            verifying = verifier is not None and rec is not None and rec.status == RECOGNIZED
            if verifying:
                verdict = verifier.verdict(tree, rec, cost)
                if verdict != "verifying":
                    outcome, detail = verifier.outcome(), verifier.detail()
                    break
            elif rec is not None and rec.status in (RECOGNIZED, AMBIGUOUS, NO_MATCH):
                outcome = rec.status
                break
            if cost > spec.budget or n_moves - (verifier.moves if verifier else 0) >= spec.max_moves:
                outcome = "budget"
                break
            if tree.count > MAX_INTERPRETATIONS:
                outcome = "failed"
                detail = f"{tree.count} interpretations, more than the matcher holds ({MAX_INTERPRETATIONS})"
                break
            move = None
            if verifying:
                move = verifier.choose(hypotheses_from(tree, rec)[0], state, components, tuple(failed_here), probed)
            posed = rec is not None and bool(rec.classes)
            probe_failed = any(m.kind == "probe" for m in failed_here)
            if choosing and move is None and not posed and not verifying:
                # the tracing opening from where the sensor is, or a probe when it measures the next face for less
                # (not after a probe failed from here: probes aimed at the same region would fail the same way)
                fixed = tracing_remainder(state)
                if not probe_failed:
                    run = edge_run_of(tree, state.edge) if state.edge is not None else None
                    move = cheaper_opening(fixed, state, components, extent, config, rng, (*failed_here, *probed), run)
                if move is not None:
                    fixed = []
            if fixed and move is None:
                hyps = (
                    tuple(hypotheses_from(tree, rec))
                    if config.table_z is not None and rec is not None and rec.classes else ()
                )  # fmt: skip
                move = opening_move(fixed.pop(0), state, components, config, rng, tuple(failed_here), hyps)
            if probing and move is None and not verifying and (not posed or tree.count > PROBES_MAX_POSED):
                move = opening_probe(components, extent, config, rng, (*failed_here, *probed), unmeasured=posed)
            if move is None:
                t_dec = time.perf_counter()
                hyps = hypotheses_from(tree, rec) if rec is not None and rec.classes else []
                # after a probe failed from here (the hand could not get along its line), tracing moves until one
                # succeeds: probes aimed at the same region would fail the same way
                cfg = replace(config, moves="tracing") if config.moves == "all" and probe_failed else config
                ctx = Context(hyps, state, components, noise, cfg, avoid=(*failed_here, *probed), tree=tree)
                try:
                    if len(hyps) >= 2 and not verifying:
                        decision = yield DecisionPoint(ctx, rng)
                    else:
                        decision = fallback.choose(ctx, rng)
                except HapticError as exc:
                    outcome, detail = "failed", f"no move: {exc}"
                    break
                move = decision.move
                decision_times.append(time.perf_counter() - t_dec)
                if obs.on_decision:
                    obs.on_decision(n_moves + 1, decision)
            result = executor.execute(move)
            n_moves += 1
            if not result.ok:
                failed_total += 1
                failed_in_a_row += 1
                failed_here.append(move)
                if move.kind == "probe":  # its line is where it is, whatever the state: not offered again
                    probed.append(move)
                cost += result.cost
                if obs.on_failed_move:
                    obs.on_failed_move(n_moves, result)
                if result.state is not None:
                    state = result.state
                if config.touch_evidence and rec is not None:
                    touched.append(touched_points(result, config))
                    before = len(rec.classes)
                    rec = assess()
                    if len(rec.classes) < before:  # the failed move's touches told something
                        failed_in_a_row = 0
                if failed_in_a_row >= MAX_FAILED_MOVES:
                    outcome, detail = "failed", f"{failed_in_a_row} failed moves in a row (last: {result.status})"
                    break
                continue
            failed_in_a_row = 0
            failed_here.clear()
            absorb(result)
            state = result.state
            if obs.on_move:
                obs.on_move(n_moves, result, tree.count, rec)

    if verifier is not None and outcome == NO_MATCH and verifier.status == "verifying":
        verifier.status = "mismatch"  # the matcher itself left no interpretation during the verification
    recognized = rec.model if rec is not None and outcome == RECOGNIZED else None
    in_library = spec.model in library
    err_mm, err_deg, correct = score_outcome(spec, library, true_model, world_from_model, outcome, rec)
    n_by_kind = {k: sum(1 for c in components.values() if c.kind == k) for k in ("face", "edge", "vertex")}
    n_probes = kinds.count("probe")
    record = EpisodeRecord(
        model=true_model.name if in_library else str(Path(spec.model).name),
        pose={
            "quat_wxyz": [round(float(x), 9) for x in matrix_to_quat(world_from_model.rotation)],
            "translation_m": [round(float(x), 9) for x in world_from_model.translation],
        },
        outcome=outcome,
        recognized=recognized,
        correct=bool(correct),
        moves=n_moves,
        path_cost=round(cost, 6),
        interpretations=counts,
        classes=n_classes,
        cum_cost=[round(c, 6) for c in cum_cost],
        move_kinds=kinds,
        pose_error_mm=err_mm,
        pose_error_deg=err_deg,
        seed=spec.seed,
        policy=spec.policy,
        executor=spec.executor,
        noise=spec.noise,
        faces=n_by_kind["face"],
        edges=n_by_kind["edge"],
        vertices=n_by_kind["vertex"],
        wall_time_s=round(time.perf_counter() - t0, 4),
        decision_times_s=[round(t, 6) for t in decision_times],
        failed_moves=failed_total,
        detail=detail,
        verify=spec.verify,
        verified=verifier.record(cost) if verifier is not None else None,
        move_set=spec.moves,
        probes=n_probes,
        probe_misses=n_probes - len(probe_faces),
    )
    if obs.on_end:
        obs.on_end(record)
    return record
