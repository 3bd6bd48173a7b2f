"""The Gymnasium environments: the API checks, and the planner through the environment is the bench's planner."""

from __future__ import annotations

import shutil

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from haptic.bench.runner import plan_sweep, run_sweep
from haptic.env import ExploreEnv, PolicyAgent
from haptic.errors import HapticError
from haptic.geometry.io import DEFAULT_LIBRARY
from haptic.geometry.library_cache import cached_library


@pytest.fixture(scope="module")
def small_library(tmp_path_factory):
    """Three seed models (a smaller tree keeps the checks quick)."""
    d = tmp_path_factory.mktemp("lib")
    for name in ("BOX01", "WEDGE01", "TETRA01L"):
        src = next(DEFAULT_LIBRARY.glob(f"{name}.*"))
        shutil.copy(src, d / src.name)
    return str(d)


def run(env: gym.Env, act, **reset) -> tuple[float, float, dict]:
    """One episode: (path cost reported at the end, cost at reset minus the rewards, the end's info)."""
    _, info = env.reset(**reset)
    spent = info["path_cost"]
    while True:
        _, reward, terminated, truncated, info = env.step(act(env))
        spent -= reward
        if terminated or truncated:
            return info["record"]["path_cost"], spent, info


def test_importing_registers_both_environments():
    ids = set(gym.registry)
    assert {"haptic/Explore-v0", "haptic/ExplorePhysics-v0"} <= ids
    assert gym.registry["haptic/ExplorePhysics-v0"].kwargs == {"executor": "physics"}


def test_the_geometric_environment_passes_the_gymnasium_checks(small_library):
    check_env(ExploreEnv(models=small_library, verify="none"), skip_render_check=True)


@pytest.mark.slow
def test_the_physics_environment_passes_the_gymnasium_checks(small_library):
    """Short: at most 8 moves per episode (the opening sequence and a few decisions), a three-model library."""
    check_env(ExploreEnv(executor="physics", models=small_library, verify="none", max_moves=8), skip_render_check=True)


def test_the_planner_through_the_environment_is_the_bench_planner():
    """Same (model, seed) draws as ``haptic bench --seed 3 --episodes 4 --verify none --moves tracing``: the same
    path cost per episode, hence the same mean; the rewards add up to it. (``scripts/env_example.py`` compares more
    episodes, with verification.)"""
    specs = plan_sweep(sorted(cached_library()), 4, 3, ["planner"], verify="none", moves="tracing")
    bench = {(r["model"], r["seed"]): r["path_cost"] for r in run_sweep(specs)}
    env, agent = gym.make("haptic/Explore-v0", verify="none"), PolicyAgent("planner")
    costs = []
    for s in specs:
        cost, spent, info = run(env, agent.act, options={"model": s.model, "seed": s.seed})
        assert cost == bench[(s.model, s.seed)]
        assert spent == pytest.approx(cost, abs=1e-5)
        assert info["record"]["outcome"] == "recognized"
        costs.append(cost)
    assert np.mean(costs) == pytest.approx(np.mean(list(bench.values())), abs=1e-9)


def test_masks_and_random_actions(small_library):
    env = ExploreEnv(models=small_library, verify="none")
    rng = np.random.default_rng(0)
    obs, info = env.reset(seed=5)
    assert env.observation_space.contains(obs)
    seen_decision = False
    for _ in range(30):
        mask = env.action_masks()
        assert mask.shape == (env.action_space.n,) and mask.any()
        assert np.array_equal(mask, info["action_mask"])
        if env.context is not None:
            seen_decision = True
            assert mask[len(env.candidates):].sum() == 0  # padding is never admissible
            assert np.array_equal(obs["candidates"][: len(env.candidates), 6], mask[: len(env.candidates)])
        obs, reward, terminated, truncated, info = env.step(int(rng.choice(np.flatnonzero(mask))))
        assert reward <= 0.0 and env.observation_space.contains(obs)
        if terminated or truncated:
            obs, info = env.reset()
    assert seen_decision


def test_bad_reset_options_are_refused(small_library):
    env = ExploreEnv(models=small_library)
    with pytest.raises(HapticError, match="unknown reset options"):
        env.reset(options={"modle": "BOX01"})
    with pytest.raises(HapticError, match="NOSUCH"):
        env.reset(options={"model": "NOSUCH"})
    with pytest.raises(HapticError, match="valid: geometric, physics"):
        ExploreEnv(executor="mujoco")
