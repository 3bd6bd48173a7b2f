"""The worlds an episode runs in, built from its :class:`~haptic.episode.spec.EpisodeSpec` in one place.

:meth:`GeometricWorld.build` and :meth:`PhysicsWorld.build` are where an episode's seed is split into the
generators of the pose, the executor, the policy (and the simulation), where one noise level becomes every
noise model, and (on the simulated hand) where the planner learns its workspace. The object's true model and
pose are read here only to place it and, in :meth:`Episode.finish`, to score the outcome; the loop
(:func:`~haptic.episode.loop.run_loop`) sees the object only through the executor's data components.
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace

import numpy as np

from haptic.episode.loop import EpisodeObserver, EpisodeRecord, Executor, Observer, chain_observers, run_loop
from haptic.episode.spec import EpisodeSpec
from haptic.errors import HapticError
from haptic.executor.geometric import GeometricExecutor, GeometricSettings
from haptic.executor.segment import SegmentBounds
from haptic.geometry import SE3, Polyhedron, convex_decomposition, resolve_model
from haptic.geometry.library_cache import cached_library
from haptic.matching.components import NoiseModel, SensorNoise, check_noise_level
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import CostModel, MoveResult
from haptic.planning.policies import Policy
from haptic.planning.registry import make_policy

STEEP_DESCENT_RISK = 0.5
"""Failure risk the planner charges a face move heading steeply down on the simulated hand (measured: such
moves often lose the surface rolling over the edge they meet)."""


@dataclass
class Episode:
    """An episode built from its spec: what the loop needs, and what scores the record at the end."""

    spec: EpisodeSpec
    """What defines the episode."""
    library: dict[str, Polyhedron]
    """The models the matcher knows, by name."""
    true_model: Polyhedron
    """The object (evaluation only: the loop never reads it)."""
    world_from_model: SE3
    """The object's true pose (evaluation only)."""
    executor: Executor
    """Carries out moves."""
    noise: SensorNoise
    """The planner's outcome bounds."""
    config: PlannerConfig
    """The planner's settings (with the workspace, on the simulated hand)."""
    policy_rng: np.random.Generator
    """The policy's (and the opening sequence's) generator."""
    observer: EpisodeObserver | None = None
    """The world's own observer (on the simulated hand: it keeps the move results for scoring perception)."""
    finish: Callable[[EpisodeRecord], None] | None = field(default=None, repr=False)
    """Completes the record after the loop (simulated time, perception scored against the truth)."""

    def run(self, policy: Policy | None = None, observer: Observer | None = None) -> EpisodeRecord:
        """The closed loop over this episode, then :attr:`finish`."""
        record = run_loop(
            self.spec, self.library, self.true_model, self.world_from_model, self.executor, self.noise, self.config,
            policy or make_policy(self.spec.policy), self.policy_rng, chain_observers(observer, self.observer),
        )  # fmt: skip
        if self.finish is not None:
            self.finish(record)
        return record


def make_geometric_executor(
    model: Polyhedron, world_from_model: SE3, noise: SensorNoise, rng, costs: CostModel,
    settings: GeometricSettings | None = None,
):  # fmt: skip
    return GeometricExecutor(model, world_from_model, noise=noise, rng=rng, costs=costs, settings=settings)


def _setup(
    spec: EpisodeSpec, library: dict[str, Polyhedron] | None
) -> tuple[dict[str, Polyhedron], Polyhedron, list[np.random.Generator]]:
    """What every world starts from: the library (loaded once per process unless given), the true model, and
    the one split of the episode's seed into the generators of the pose, the executor, the policy and the
    simulator (children 0-3 of ``SeedSequence(spec.seed)``; a world uses those it needs)."""
    if library is None:
        library = cached_library(spec.models, skip_invalid=spec.skip_invalid, units=spec.units)
    rngs = [np.random.default_rng(s) for s in np.random.SeedSequence(spec.seed).spawn(4)]
    return library, resolve_model(spec.model, library, units=spec.units), rngs


class GeometricWorld:
    """The ideal sensor: the object floats at a random pose; moves are computed from the true model, with noise."""

    name = "geometric"

    @staticmethod
    def build(
        spec: EpisodeSpec,
        library: dict[str, Polyhedron] | None = None,
        config: PlannerConfig | None = None,
    ) -> Episode:
        library, true_model, (pose_rng, exec_rng, policy_rng, _) = _setup(spec, library)
        config = replace(config or PlannerConfig(), moves=spec.moves, fingers=spec.fingers)
        world_from_model = SE3.random(pose_rng, translation_scale=0.1)
        noise = NoiseModel(check_noise_level(spec.noise)).fitted
        settings = GeometricSettings()
        executor = make_geometric_executor(true_model, world_from_model, noise, exec_rng, config.costs, settings)
        config = replace(config, vertex_radius=settings.vertex_radius)  # the circle the executor makes
        return Episode(spec, library, true_model, world_from_model, executor, noise, config, policy_rng)


BOUND_FLOOR = 1.0
"""On the simulated hand the bounds do not shrink below this noise level: the simulated contacts scatter by
about that much with ideal sensors (contact discretisation, pad compliance; noiseless, normals beside a seam of
the simulated pieces read 1.5° off), and a segmenter fitting with σ = 0 fails."""


def noise_models(noise: NoiseModel):
    """One noise model for the simulated hand: the simulated sensors' noise (its per-sample σ at its level),
    the segmenter's bounds (the same σ, the systematic floors unchanged), hence the matcher's bounds (the
    segmented components carry them), and the planner's outcome bounds (its fitted σ); the bounds at no less
    than :data:`BOUND_FLOOR`. Returns ``(sim noise, segment bounds, planner noise)``."""
    from haptic.sim import SimulatedSensorNoise  # MuJoCo loads only for the simulated hand's episodes

    bounded = noise.at_least(BOUND_FLOOR)
    return SimulatedSensorNoise.from_model(noise), SegmentBounds.from_model(bounded), bounded.fitted


class PhysicsWorld:
    """The simulated hand: the object rests on the table at a seeded random pose; the executor gets only a
    :class:`~haptic.sim.RobotInterface`. Ground truth is read here, outside the executor, only to report the
    pose and to score perception and recognition afterwards."""

    name = "physics"

    @staticmethod
    def build(
        spec: EpisodeSpec,
        library: dict[str, Polyhedron] | None = None,
        config: PlannerConfig | None = None,
    ) -> Episode:
        # MuJoCo and the physics executor load only for physics episodes (geometric sweeps never import them)
        from haptic.episode.evaluate import score_components
        from haptic.executor.physics import PhysicsExecutor, PhysicsSettings
        from haptic.executor.placement import finger_reach
        from haptic.executor.touch_config import TouchConfig
        from haptic.sim import RobotInterface, Simulation, compose_scene, random_object_pose
        from haptic.sim.scene import scene_object_from_polyhedron

        library, true_model, (pose_rng, exec_rng, policy_rng, sim_seq) = _setup(spec, library)
        config = replace(config or PlannerConfig(), moves=spec.moves, fingers=spec.fingers)
        obj = scene_object_from_polyhedron(true_model)
        pose = random_object_pose(obj, pose_rng)
        scene = compose_scene(obj, pose)
        if config.table_z is None:  # the robot knows its workspace from the scene (never the object)
            ws = scene.workspace
            config = replace(
                config, table_z=ws.table_top_z, pad_radius=ws.pad_radius, steep_descent_risk=STEEP_DESCENT_RISK,
                max_undercut=TouchConfig().reach_undercut, touch_evidence=True,
                felt_edge=TouchConfig().edge_angle,
            )  # fmt: skip
        if config.fingers > 1 and config.placement_reach is None:  # placements the reach solver reaches alone
            from haptic.executor.placement import PlacementReach

            config = replace(config, placement_reach=PlacementReach())
        if config.finger_reach is None:  # probes by another finger: the reach solver with the hypothesis at its pose
            config = replace(config, finger_reach=finger_reach())
        sim_noise, bounds, noise = noise_models(NoiseModel(check_noise_level(spec.noise)))
        sim = Simulation(scene, noise=sim_noise, seed=int(sim_seq.integers(2**31 - 1)))
        settings = PhysicsSettings()
        executor = PhysicsExecutor(RobotInterface(sim), bounds=bounds, costs=config.costs, rng=exec_rng,
                                   settings=settings)  # fmt: skip
        # the circle the executor makes; the concave edges' ends it can tell; no move from a concave vertex
        clearance = max(config.min_vertex_clearance, settings.crossing_clearance)
        config = replace(config, vertex_radius=settings.vertex_radius, min_vertex_clearance=clearance,
                         edge_reentry=settings.edge_reentry if config.edge_reentry is None else config.edge_reentry,
                         concave_end_block=(settings.min_block_cos if config.concave_end_block is None
                                            else config.concave_end_block),
                         leave_concave_vertices=False)  # fmt: skip
        results: list[MoveResult] = []  # every move's result, for scoring perception

        def keep(*args) -> None:
            results.append(args[1])

        def finish(record: EpisodeRecord) -> None:
            record.sim_time_s = round(float(sim.time), 4)
            truth = sim.ground_truth()
            score = score_components(executor.components, true_model, SE3.from_matrix(truth.world_from_object), results)
            record.perception = _jsonable(score.summary())
            reach = config.placement_reach
            if reach is not None and hasattr(reach, "asked"):
                record.placement_reach = {"asked": reach.asked, "reached": reach.reached,
                                          "reasons": dict(reach.reasons)}  # fmt: skip

        world_from_model = SE3.from_matrix(pose)
        return Episode(
            spec, library, true_model, world_from_model, executor, noise, config, policy_rng,
            observer=EpisodeObserver(on_move=keep, on_failed_move=keep), finish=finish,
        )  # fmt: skip


def _convex_pieces(poly: Polyhedron) -> list[np.ndarray]:
    """:func:`~haptic.geometry.convex_decomposition` of ``poly``, by a name another process finds (a worker of
    :func:`preload_physics`)."""
    return convex_decomposition(poly)


def preload_physics(models: Iterable[Polyhedron] = (), jobs: int = 1) -> None:
    """Import now what a physics episode loads on first use (MuJoCo, the simulated hand, its executor, the
    scoring of perception), parse the scene and split the non-convex ``models`` into convex pieces
    (:func:`~haptic.sim.scene.preload_scenes`): a process about to fork workers hands it to them done, where each
    would do it again.

    The non-convex models are split in up to ``jobs`` processes forked first, while this one imports and parses
    the scene: a model of many faces takes as long as those (FRAME01: 0.6 s of CPU), and a process about to fork
    its workers does it before any of them starts."""
    models = list(models)
    apart = [poly for poly in models if not poly.is_convex]
    pool = split = None
    if apart:
        pool = ProcessPoolExecutor(max(1, min(jobs, len(apart))), mp_context=multiprocessing.get_context("fork"))
        split = pool.map(_convex_pieces, apart)
    from haptic import sim  # noqa: F401
    from haptic.episode import evaluate  # noqa: F401
    from haptic.executor import physics, touch_config  # noqa: F401
    from haptic.sim.scene import preload_scenes

    pieces = {}
    if pool is not None:
        with pool:
            pieces = dict(zip(apart, split, strict=True))
    preload_scenes(models, pieces)


WORLDS = {w.name: w for w in (GeometricWorld, PhysicsWorld)}
"""The worlds by executor name (``EpisodeSpec.executor``)."""


def build_episode(
    spec: EpisodeSpec, library: dict[str, Polyhedron] | None = None, config: PlannerConfig | None = None
) -> Episode:
    """The episode ``spec`` defines, in the world of its executor."""
    world = WORLDS.get(spec.executor)
    if world is None:
        raise HapticError(f"unknown executor {spec.executor!r}; valid: {', '.join(WORLDS)}")
    return world.build(spec, library, config)


def run_episode(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron] | None = None,
    observer: Observer | None = None,
    config: PlannerConfig | None = None,
    policy: Policy | None = None,
) -> EpisodeRecord:
    """Run one episode: built in its world (:func:`build_episode`), then the closed loop; with ``spec.learn``, on
    after ``no-match`` until the object is learned (:func:`haptic.episode.learning.run_learning`)."""
    episode = build_episode(spec, library, config)
    if spec.learn is None:
        return episode.run(policy, observer)
    from haptic.episode.learning import LearnSettings, run_learning

    record, _ = run_learning(episode, LearnSettings(spec.learn, spec.learn_name), policy, observer)
    return record


def _jsonable(x):
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, float | np.floating):
        v = float(x)
        return None if not np.isfinite(v) else round(v, 6)
    if isinstance(x, np.integer):
        return int(x)
    return x
