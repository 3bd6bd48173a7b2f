"""The Gymnasium environments: the API checks (Gymnasium's and Stable-Baselines3's, without warnings), the reward,
the mask, episode boundaries in vector environments, and the planner through the environment is the bench's
planner."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from haptic.bench.runner import plan_sweep, run_sweep
from haptic.env import GLOBALS, MOVE_COLUMNS, MOVE_FEATURES, ExploreEnv, PolicyAgent
from haptic.errors import HapticError
from haptic.geometry.library_cache import cached_library

COL = {name: i for i, name in enumerate(MOVE_COLUMNS)}


def run(env: gym.Env, act, **reset) -> tuple[float, float, dict]:
    """One episode: (its return, the cost at reset, the end's info)."""
    _, info = env.reset(**reset)
    at_reset, ret = info["path_cost"], 0.0
    while True:
        _, reward, terminated, truncated, info = env.step(act(env))
        ret += reward
        if terminated or truncated:
            return ret, at_reset, info


def candidates(obs: dict, env: ExploreEnv) -> np.ndarray:
    return obs["candidates"].reshape(env.n_candidates, MOVE_FEATURES)


def test_importing_registers_both_environments():
    ids = set(gym.registry)
    assert {"haptic/Explore-v0", "haptic/ExplorePhysics-v0"} <= ids
    assert gym.registry["haptic/ExplorePhysics-v0"].kwargs == {"executor": "physics"}


@pytest.mark.parametrize("observation", ["dict", "flat"])
def test_the_geometric_environment_passes_the_gymnasium_checks_without_warnings(small_library, observation):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(ExploreEnv(models=small_library, verify="none", observation=observation), skip_render_check=True)


@pytest.mark.parametrize("observation", ["dict", "flat"])
def test_stable_baselines3_checks_pass_without_warnings(small_library, observation):
    sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_checker.check_env(ExploreEnv(models=small_library, verify="none", observation=observation), warn=True)


@pytest.mark.slow
def test_the_physics_environment_passes_the_gymnasium_checks(small_library):
    """Short: at most 8 moves per episode (the opening sequence and a few decisions), a three-model library."""
    check_env(ExploreEnv(executor="physics", models=small_library, verify="none", max_moves=8), skip_render_check=True)


def test_the_planner_through_the_environment_is_the_bench_planner():
    """Same (model, seed) draws as ``haptic bench --seed 3 --episodes 4 --verify none --moves tracing``: the same
    path cost per episode; the rewards add up to minus the cost after the reset (every episode correct: no
    penalty), scaled. (``scripts/env_example.py`` compares more episodes, with verification.)"""
    specs = plan_sweep(sorted(cached_library()), 4, 3, ["planner"], verify="none", moves="tracing")
    bench = {(r["model"], r["seed"]): r["path_cost"] for r in run_sweep(specs)}
    env, agent = gym.make("haptic/Explore-v0", verify="none", reward_scale=0.01), PolicyAgent("planner")
    for s in specs:
        ret, at_reset, info = run(env, agent.act, options={"model": s.model, "seed": s.seed})
        assert info["record"]["path_cost"] == bench[(s.model, s.seed)]
        assert info["record"]["correct"]
        assert ret == pytest.approx(-0.01 * (info["record"]["path_cost"] - at_reset), abs=1e-7)


def test_masks_observations_and_random_actions(small_library):
    env = ExploreEnv(models=small_library, verify="none")
    rng = np.random.default_rng(0)
    obs, info = env.reset(seed=5)
    assert env.observation_space.contains(obs)
    decisions = telling = 0
    for _ in range(40):
        mask = env.action_masks()
        assert mask.shape == (env.action_space.n,) and mask.any()
        assert np.array_equal(mask, info["action_mask"])
        if env.context is not None:
            decisions += 1
            n = len(env.candidates)
            rows = candidates(obs, env)
            assert mask[n:].sum() == 0 and not rows[n:].any()  # padding: never admissible, zero rows
            assert np.array_equal(rows[:n, COL["admissible"]], mask[:n])
            if (rows[:n, COL["eliminated"]] > 0).any():  # the mask removes moves predicted to tell nothing
                telling += 1
                assert (rows[:n, COL["eliminated"]][mask[:n]] > 0).all()
                assert rows[:n, COL["efficiency"]].max() == pytest.approx(1.0)
            assert obs["globals"][GLOBALS.index("moves_left")] == pytest.approx(1 - env.context.moves / env.max_moves)
        obs, reward, terminated, truncated, info = env.step(int(rng.choice(np.flatnonzero(mask))))
        assert reward <= 0.0 and env.observation_space.contains(obs)
        if terminated or truncated:
            obs, info = env.reset()
    assert decisions and telling


def test_reset_with_a_seed_reproduces_the_trajectory(small_library):
    def play(seed: int) -> list[np.ndarray]:
        env, rng = ExploreEnv(models=small_library, verify="none", observation="flat"), np.random.default_rng(1)
        obs, info = env.reset(seed=seed)
        out = [obs]
        for _ in range(12):
            obs, _, terminated, truncated, info = env.step(int(rng.choice(np.flatnonzero(info["action_mask"]))))
            out.append(obs)
            if terminated or truncated:
                obs, info = env.reset()
        return out

    a, b = play(7), play(7)
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


def _repeat_one_move(env: gym.Env) -> int:
    """Ignore the mask and repeat a move that tells nothing: a vertex move when there is one (circling the same
    vertex), else the first candidate."""
    e = env.unwrapped
    kinds = [m.kind for m in e.candidates]
    return kinds.index("vertex") if "vertex" in kinds else 0


def test_repeating_a_move_that_tells_nothing_cannot_beat_the_planner():
    """On the same draws: every episode the repeating agent does not end correctly returns less than minus the
    budget, below every episode of the planner (all correct), so its mean return is below the planner's."""
    env = gym.make("haptic/Explore-v0", verify="none", max_moves=12)
    specs = plan_sweep(sorted(cached_library()), 6, 11, ["planner"], verify="none", moves="tracing")
    planner, repeat = PolicyAgent("planner"), []
    planned = []
    for s in specs:
        ret, _, info = run(env, planner.act, options={"model": s.model, "seed": s.seed})
        assert info["record"]["correct"] and ret > -600.0
        planned.append(ret)
        ret, _, info = run(env, _repeat_one_move, options={"model": s.model, "seed": s.seed})
        if not info["record"]["correct"]:
            assert ret < -600.0 < min(planned)
        repeat.append(ret)
    assert any(r < -600.0 for r in repeat)  # the repeating agent did fail some
    assert np.mean(repeat) < np.mean(planned)


def test_the_penalty_and_the_scale(small_library):
    """A failed episode's last step carries the penalty; the reward is scaled by ``reward_scale``."""
    kw = dict(models=small_library, verify="none", max_moves=3)
    ret1, c1, info1 = run(ExploreEnv(**kw, failure_penalty=50.0), _repeat_one_move, seed=2)
    ret2, c2, info2 = run(ExploreEnv(**kw, failure_penalty=50.0, reward_scale=0.5), _repeat_one_move, seed=2)
    assert info1["record"] == {**info2["record"], "wall_time_s": info1["record"]["wall_time_s"],
                               "decision_times_s": info1["record"]["decision_times_s"]}  # fmt: skip
    penalty = 0.0 if info1["record"]["correct"] else 50.0
    assert ret1 == pytest.approx(-(info1["record"]["path_cost"] - c1) - penalty, abs=1e-6)
    assert ret2 == pytest.approx(0.5 * ret1, abs=1e-6)


def test_shaping_adds_a_sum_fixed_by_the_first_decision():
    """Potential-based shaping: an episode's return with ``shaping=1`` exceeds the return without by log2(1 + k),
    k the pose classes at the first decision, whatever the moves."""
    env0 = gym.make("haptic/Explore-v0", verify="none")
    env1 = gym.make("haptic/Explore-v0", verify="none", shaping=1.0)
    agent = PolicyAgent("planner")
    for model, seed in (("WEDGE01", 4), ("LBLOCK01", 9)):
        ret0, _, info0 = run(env0, agent.act, options={"model": model, "seed": seed})
        env1.reset(options={"model": model, "seed": seed})
        k = env1.unwrapped._left()
        ret1, _, info1 = run(env1, agent.act, options={"model": model, "seed": seed})
        assert info0["record"]["path_cost"] == info1["record"]["path_cost"]
        assert ret1 - ret0 == pytest.approx(math.log2(1 + k), abs=1e-6)


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_a_vector_environment_counts_each_episode_once(small_library, mode):
    """``info["record"]`` comes on the step that ends an episode and on no other (not on the auto-reset steps),
    so the records counted are the episodes ended."""
    envs = gym.make_vec("haptic/Explore-v0", num_envs=2, vectorization_mode=mode,
                        models=small_library, verify="none", max_moves=6)  # fmt: skip
    rng = np.random.default_rng(3)
    _, info = envs.reset(seed=1)
    assert "record" not in info
    ended = records = 0
    for _ in range(40):
        masks = info["action_mask"]
        actions = np.array([int(rng.choice(np.flatnonzero(m))) for m in masks])
        _, _, terminated, truncated, info = envs.step(actions)
        done = terminated | truncated
        ended += int(done.sum())
        if "record" in info:
            got = info["_record"]
            assert np.array_equal(got, done)
            records += int(got.sum())
    envs.close()
    assert ended > 2 and records == ended


def test_the_agent_can_take_the_opening_decisions(small_library):
    """With ``opening="agent"`` the first decision comes before the data fix a pose; the episodes still end."""
    env = ExploreEnv(models=small_library, verify="none", opening="agent", max_moves=15)
    rng = np.random.default_rng(0)
    unposed = 0
    for seed in range(3):
        obs, info = env.reset(seed=seed)
        assert env.context is not None and obs["globals"][GLOBALS.index("posed")] == 0.0
        for _ in range(40):
            if env.context is not None and not env.context.hypotheses:
                unposed += 1
            obs, _, terminated, truncated, info = env.step(int(rng.choice(np.flatnonzero(info["action_mask"]))))
            if terminated or truncated:
                assert info["record"]["outcome"]
                break
        else:
            pytest.fail("the episode did not end within 40 steps")
    assert unposed >= 3


def test_bad_settings_are_refused(small_library):
    env = ExploreEnv(models=small_library)
    with pytest.raises(HapticError, match="unknown reset options"):
        env.reset(options={"modle": "BOX01"})
    with pytest.raises(HapticError, match="NOSUCH"):
        env.reset(options={"model": "NOSUCH"})
    with pytest.raises(HapticError, match="valid: geometric, physics"):
        ExploreEnv(executor="mujoco")
    with pytest.raises(HapticError, match="valid: loop, agent"):
        ExploreEnv(models=small_library, opening="planner")
    with pytest.raises(HapticError, match="valid: dict, flat"):
        ExploreEnv(models=small_library, observation="box")
    with pytest.raises(HapticError, match="reward_scale"):
        ExploreEnv(models=small_library, reward_scale=-1.0)
