"""Episodes on the simulated hand: the same loop as the geometric episodes, with the physics executor.

The scene is composed with the true object at a seeded random resting pose; the executor gets only a
:class:`~haptic.sim.RobotInterface`. Ground truth is read here, outside the executor, only to report the pose
and to score perception and recognition afterwards.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from haptic.bench.runner import EpisodeSpec
from haptic.episode import EpisodeObserver, EpisodeRecord, run_loop
from haptic.geometry import SE3, Polyhedron, load_library, resolve_model
from haptic.matching.components import SensorNoise
from haptic.planning.policies import Policy, make_policy
from haptic.planning.predict import PlannerConfig

STEEP_DESCENT_RISK = 0.5
"""Failure risk the planner charges a face move heading steeply down on the simulated hand (measured: such
moves often lose the surface rolling over the edge they meet)."""


def noise_models(level: float):
    """One noise level for the simulated hand: the simulated sensors' noise (PHYSICS_NOTES levels x ``level``),
    the segmenter's bounds (its σ x ``level``, the systematic floors unchanged), hence the matcher's bounds
    (the segmented components carry them), and the planner's outcome bounds (:class:`SensorNoise` x ``level``).
    The bounds do not shrink below the default level (``max(level, 1)``): the simulated contacts scatter by
    about that much with ideal sensors (contact discretisation, pad compliance; noiseless, normals beside a
    seam of the simulated pieces read 1.5° off), and a segmenter fitting with σ = 0 fails. Returns ``(sim
    noise, segment bounds, planner noise)``; ``level`` must be within
    :data:`~haptic.matching.components.NOISE_LEVELS`."""
    from haptic.executor.segment import SegmentBounds
    from haptic.matching.components import check_noise_level
    from haptic.sim import SensorNoise as SimNoise

    level = check_noise_level(level)
    n = SimNoise.from_notes()
    sim_noise = SimNoise(n.force_std * level, n.normal_std * level, n.point_std * level, n.joint_std * level)
    bounded = max(level, 1.0)
    bounds = SegmentBounds.from_noise(n.force_std, n.normal_std, n.point_std).scaled(bounded)
    return sim_noise, bounds, SensorNoise().scaled(bounded)


def run_physics_episode(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron] | None = None,
    observer: EpisodeObserver | None = None,
    config: PlannerConfig | None = None,
    policy: Policy | None = None,
) -> EpisodeRecord:
    """One episode on the simulated hand (the object rests on the table at a seeded random pose)."""
    from haptic.executor.evaluate import score_components
    from haptic.executor.physics import PhysicsExecutor
    from haptic.executor.primitives import TouchConfig
    from haptic.sim import RobotInterface, Simulation, compose_scene, random_object_pose
    from haptic.sim.scene import TABLE_TOP_Z, scene_object_from_polyhedron

    library = library if library is not None else load_library(spec.models, skip_invalid=spec.skip_invalid)
    true_model = resolve_model(spec.model, library)
    config = config or PlannerConfig()
    if config.table_z is None:  # the robot knows its workspace: where the table top is (never the object)
        config = replace(
            config, table_z=TABLE_TOP_Z, steep_descent_risk=STEEP_DESCENT_RISK,
            max_undercut=TouchConfig().max_undercut, touch_evidence=True,
        )
    root = np.random.SeedSequence(spec.seed)
    pose_rng, exec_rng, policy_rng, sim_seq = (np.random.default_rng(s) for s in root.spawn(4))
    obj = scene_object_from_polyhedron(true_model)
    pose = random_object_pose(obj, pose_rng)
    sim_noise, bounds, noise = noise_models(spec.noise)
    sim = Simulation(compose_scene(obj, pose), noise=sim_noise, seed=int(sim_seq.integers(2**31 - 1)))
    executor = PhysicsExecutor(RobotInterface(sim), bounds=bounds, costs=config.costs, rng=exec_rng)
    results = []
    execute, start = executor.execute, executor.start

    def logged_start():
        r = start()
        results.append(r)
        return r

    def logged_execute(move):
        r = execute(move)
        results.append(r)
        return r

    executor.start, executor.execute = logged_start, logged_execute  # keep the move results for scoring
    world_from_model = SE3(np.asarray(pose)[:3, :3], np.asarray(pose)[:3, 3])
    record = run_loop(
        spec, library, true_model, world_from_model, executor, noise, config,
        policy or make_policy(spec.policy), policy_rng, observer,
    )  # fmt: skip
    record.sim_time_s = round(float(sim.time), 4)
    truth = sim.ground_truth()
    score = score_components(executor.components, true_model, truth.world_from_object, results)
    record.perception = _jsonable(score.summary())
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
