"""One episode: executor → matcher → planner until recognised, ambiguous, no-match, out of budget, or failed.

The loop sees the object only through the executor's data components. The true model and pose are used
here only to place the object (for the geometric executor) and, at the end, to score the outcome.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from haptic.bench.runner import EpisodeSpec
from haptic.errors import HapticError
from haptic.geometry import SE3, Polyhedron, library_twin, resolve_model
from haptic.geometry.library_cache import cached_library
from haptic.geometry.se3 import matrix_to_quat, rotation_angle
from haptic.matching.components import DataComponent, SensorNoise, check_noise_level
from haptic.matching.recognition import AMBIGUOUS, EXPLORING, NO_MATCH, RECOGNIZED, Recognition, recognize
from haptic.matching.tree import InterpretationTree
from haptic.planning.moves import CostModel, Move, MoveResult
from haptic.planning.policies import Context, Decision, Policy, RandomPolicy, make_policy
from haptic.planning.predict import (
    Hypothesis,
    PlannerConfig,
    candidate_moves,
    pose_fixed_by,
    rests_on_table,
    table_safe_moves,
    vertex_sweep_off_table,
)

MAX_POSED = 400
"""Largest number of interpretations whose poses are computed to group them into pose classes."""
MAX_FAILED_MOVES = 4
"""Consecutive failed moves after which the episode ends as "failed"."""
CORRECT_POSE_MM, CORRECT_POSE_DEG = 5.0, 5.0
"""A recognition is correct when the model is right and the pose within these of the truth."""


@dataclass
class EpisodeRecord:
    """What one episode did and how it scored (the JSON record of DESIGN.md, plus traces)."""

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


def pose_error(model: Polyhedron, truth: SE3, estimate: SE3) -> tuple[float, float]:
    """Pose error up to the model's symmetry: centroid displacement [mm] and rotation angle [deg]."""
    from haptic.matching.recognition import model_symmetries

    c = model.centroid
    dist = float(np.linalg.norm(truth.apply(c) - estimate.apply(c))) * 1e3
    ang = min(rotation_angle(truth.rotation.T @ (estimate @ s).rotation) for s in model_symmetries(model))
    return dist, float(np.degrees(ang))


TOUCH_PHASES = ("face", "circle")
"""Trace phases whose contacts count: the pad sliding on one face (rolling over an edge, or resting on an edge
or a vertex, it may touch two faces at once, and the sensed point is their mean)."""
TOUCH_CONE = np.deg2rad(8.0)
"""Within a phase, rows whose sensed normal is farther than this from the phase's median normal are not on
the face slid on (the pad in a corner, or turning at an edge) and do not count [rad]."""


def touched_points(result: MoveResult, config: PlannerConfig) -> tuple[np.ndarray, np.ndarray]:
    """The contact points and sensed normals of a move's trace (the physics executor's sensing, in
    ``result.info["trace"]``) while sliding on a face, thinned to one per ``config.touch_spacing`` of the
    trace, none within the pad's radius of the table (where the pad may touch the table and the object at
    once); shapes (P, 3), (P, 3), with P = 0 when the executor keeps no trace."""
    from haptic.executor.primitives import PHASES

    none = (np.zeros((0, 3)), np.zeros((0, 3)))
    trace = result.info.get("trace") if isinstance(result.info, dict) else None
    if trace is None or not len(trace):
        return none
    pts, nrm = [], []
    for ph in TOUCH_PHASES:
        ok = trace.in_contact & (trace.phase == PHASES.index(ph))
        p, n = trace.point_in_world[ok], trace.normal_in_world[ok]
        if config.table_z is not None:
            high = p[:, 2] > config.table_z + config.pad_radius
            p, n = p[high], n[high]
        if not len(p):
            continue
        med = np.median(n, axis=0)
        on = n @ (med / np.linalg.norm(med)) > np.cos(TOUCH_CONE)
        last = None
        for q, m in zip(p[on], n[on], strict=True):
            if last is None or float(np.linalg.norm(q - last)) >= config.touch_spacing:
                pts.append(q)
                nrm.append(m)
                last = q
    return (np.array(pts), np.array(nrm)) if pts else none


def _fits_touches(c, touched: tuple[np.ndarray, np.ndarray], config: PlannerConfig) -> bool:
    """Whether pose class ``c`` has every touched point on a face of its sensed normal (but a few strays)."""
    from haptic.planning.reach import touch_distance

    d = touch_distance(c.model, c.world_from_model, *touched)
    return int((d > config.touch_tol).sum()) < config.touch_outliers


def _on_the_table(
    rec: Recognition,
    tree: InterpretationTree,
    components,
    config: PlannerConfig,
    touched: tuple[np.ndarray, np.ndarray] | None = None,
) -> Recognition:
    """The matcher's verdict with the workspace prior that the object rests on the table (``config.table_z``):
    once the data fix the poses, pose classes that would put the model through the table or float it above
    it are set aside, and the verdict is taken again over the rest (left as it is when that would leave no
    class: the prior is then doubted, not the data). With ``touched`` points (every contact sensed so far),
    classes that leave some of them off their faces are set aside too. A few classes left that differ only
    where the fingertip
    cannot reach (:func:`~haptic.planning.reach.indistinguishable`: their difference faces the table) are
    ambiguous."""
    from haptic.matching.recognition import PoseTolerance, same_solid
    from haptic.planning.reach import indistinguishable

    if not rec.classes or not pose_fixed_by(components):
        return rec
    keep = tuple(c for c in rec.classes if rests_on_table(c.model, c.world_from_model, config)) or rec.classes
    if touched is not None and len(touched[0]) and len(keep) <= MAX_TOUCH_CHECK:
        keep = tuple(c for c in keep if _fits_touches(c, touched, config)) or keep
    if len(keep) == len(rec.classes) and rec.status != EXPLORING:
        return rec
    models = tuple(sorted({c.name for c in keep}))
    if len(keep) == 1:
        return Recognition(RECOGNIZED, keep[0].name, keep[0].world_from_model, keep, rec.count, models)
    tol = PoseTolerance.from_data(tree.data)
    status = AMBIGUOUS if all(same_solid(keep[0], c, tol) for c in keep[1:]) else EXPLORING
    if status == EXPLORING and len(keep) <= MAX_HIDDEN_CHECK and all(
        indistinguishable(keep[0].model, keep[0].world_from_model, c.model, c.world_from_model, config)
        for c in keep[1:]
    ):
        status = AMBIGUOUS
    return Recognition(status, None, None, keep, rec.count, models)


MAX_HIDDEN_CHECK = 4
"""Pose classes up to which an episode on the table checks whether what tells them apart is out of reach."""
MAX_TOUCH_CHECK = 24
"""Pose classes up to which the touched points are checked against each class's surface."""


def _fixed_move(
    kind: str,
    state,
    components,
    config: PlannerConfig,
    rng: np.random.Generator,
    avoid: tuple = (),
    hypotheses: tuple = (),
) -> Move | None:
    """The seed's initial sequence (§4.1): a face move, an edge move, a vertex move, each in a random
    admissible direction (not one that already failed from here). With a table (``config.table_z``), away
    from it: not a move the data or the hypotheses predict to run into it, and among the rest those heading
    up rather than down (face and edge moves) or whose vertex circle stays clear of it."""
    from haptic.planning.policies import same_move

    moves = [
        m for m in candidate_moves(state, components, config)
        if m.kind == kind and not any(same_move(m, bad) for bad in avoid)
    ]
    if not moves:
        return None
    if config.table_z is not None:
        moves = _away_from_table(table_safe_moves(moves, hypotheses, state, components, config), state,
                                 components, config)  # fmt: skip
    return moves[int(rng.integers(len(moves)))]


def _away_from_table(moves: list[Move], state, components, config: PlannerConfig) -> list[Move]:
    """The moves of ``moves`` that head away from the table: face moves and edge moves not heading down by
    more than ~12°; vertex moves whose circle can sweep half a turn off the table (else the widest sweep)."""
    if not moves:
        return moves
    if moves[0].kind == "vertex":
        sweep = np.array([vertex_sweep_off_table(state, components, m.across_face, config) for m in moves])
        keep = sweep >= np.pi if (sweep >= np.pi).any() else sweep >= sweep.max() - 1e-9
        return [m for m, k in zip(moves, keep, strict=True) if k]
    if moves[0].kind == "face":
        up = np.array([float(m.direction[2]) for m in moves])
    else:
        b = components[state.edge].direction
        up = np.array([m.sense * float(b[2]) for m in moves])
    keep = up >= -0.2 if (up >= -0.2).any() else up >= up.max() - 1e-9
    return [m for m, k in zip(moves, keep, strict=True) if k]


def make_geometric_executor(model: Polyhedron, world_from_model: SE3, noise: SensorNoise, rng, costs: CostModel):
    from haptic.executor.geometric import GeometricExecutor

    return GeometricExecutor(model, world_from_model, noise=noise, rng=rng, costs=costs)


def run_episode(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron] | None = None,
    observer: EpisodeObserver | None = None,
    config: PlannerConfig | None = None,
    policy: Policy | None = None,
) -> EpisodeRecord:
    """Run one episode with the geometric executor (the physics executor: :mod:`haptic.episode_physics`)."""
    if spec.executor == "physics":
        from haptic.episode_physics import run_physics_episode

        return run_physics_episode(spec, library=library, observer=observer, config=config, policy=policy)
    if spec.executor != "geometric":
        raise HapticError(f"unknown executor {spec.executor!r}; valid: geometric, physics")
    library = library if library is not None else cached_library(spec.models, skip_invalid=spec.skip_invalid)
    true_model = resolve_model(spec.model, library)
    config = config or PlannerConfig()
    root = np.random.SeedSequence(spec.seed)
    pose_rng, exec_rng, policy_rng = (np.random.default_rng(s) for s in root.spawn(3))
    world_from_model = SE3.random(pose_rng, translation_scale=0.1)
    noise = SensorNoise().scaled(check_noise_level(spec.noise))
    executor = make_geometric_executor(true_model, world_from_model, noise, exec_rng, config.costs)
    return run_loop(
        spec, library, true_model, world_from_model, executor, noise, config,
        policy or make_policy(spec.policy), policy_rng, observer,
    )


def run_loop(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron],
    true_model: Polyhedron,
    world_from_model: SE3,
    executor,
    noise: SensorNoise,
    config: PlannerConfig,
    policy: Policy,
    rng: np.random.Generator,
    observer: EpisodeObserver | None = None,
) -> EpisodeRecord:
    """The closed loop over any executor with ``start()`` and ``execute(move)``."""
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
        from haptic.matching.verify import K_SIGMA, K_SIGMA_PHYSICS
        from haptic.planning.verify import Verifier

        verifier = Verifier(spec.verify, noise, config, K_SIGMA_PHYSICS if spec.executor == "physics" else K_SIGMA)

    touched: list[tuple[np.ndarray, np.ndarray]] = []

    def assess() -> Recognition:
        """The verdict on the data so far (with the table and the touched points, when known)."""
        r = recognize(tree, max_interpretations=MAX_POSED)
        if config.table_z is None:
            return r
        if not touched:
            return _on_the_table(r, tree, components, config)
        both = (np.concatenate([p for p, _ in touched]), np.concatenate([n for _, n in touched]))
        return _on_the_table(r, tree, components, config, both)

    def absorb(result: MoveResult) -> None:
        nonlocal cost, rec
        for c in result.components:
            components[c.id] = c
            tree.add(c)
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
        fixed = ["face", "edge", "vertex"]
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
            move = None
            if verifying:
                move = verifier.choose(hypotheses_from(tree, rec)[0], state, components, tuple(failed_here))
            if fixed and move is None:
                hyps = (
                    tuple(hypotheses_from(tree, rec))
                    if config.table_z is not None and rec is not None and rec.classes else ()
                )  # fmt: skip
                move = _fixed_move(fixed.pop(0), state, components, config, rng, tuple(failed_here), hyps)
            if move is None:
                t_dec = time.perf_counter()
                hyps = hypotheses_from(tree, rec) if rec is not None and rec.classes else []
                ctx = Context(hyps, state, components, noise, config, avoid=tuple(failed_here), tree=tree)
                chooser = policy if len(hyps) >= 2 and not verifying else fallback
                try:
                    decision = chooser.choose(ctx, rng)
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
    err_mm = err_deg = None
    in_library = spec.model in library
    # the library model the object is (evaluation only): by name, or for a file by congruence with one
    twin = (spec.model, SE3.identity()) if in_library else library_twin(true_model, library)
    correct = False
    if outcome == RECOGNIZED and rec.world_from_model is not None:
        if twin is not None and recognized == twin[0]:
            # the library model's pose in the world: the object's pose after the map of the model onto it
            err_mm, err_deg = pose_error(library[twin[0]], world_from_model @ twin[1], rec.world_from_model)
            correct = err_mm < CORRECT_POSE_MM and err_deg < CORRECT_POSE_DEG
    elif outcome == NO_MATCH:
        correct = twin is None
    n_by_kind = {k: sum(1 for c in components.values() if c.kind == k) for k in ("face", "edge", "vertex")}
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
    )
    if obs.on_end:
        obs.on_end(record)
    return record
