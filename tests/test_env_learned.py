"""A policy trained on the environment acting in ``haptic bench --policy learned:PATH``: it plays the episodes the
trained model plays through the environment, and the command line names what is wrong in one line. Needs the
``[learn]`` extra (skipped without it)."""

from __future__ import annotations

import pytest

from haptic.bench.results import read_results
from haptic.bench.runner import plan_sweep
from haptic.cli import main
from haptic.env import ExploreEnv
from haptic.geometry.library_cache import cached_library

sb3_contrib = pytest.importorskip("sb3_contrib")


@pytest.fixture(scope="module")
def model_path(tmp_path_factory):
    """A MaskablePPO model after a few updates (what it learned does not matter here, only that it acts)."""
    env = ExploreEnv(verify="none", observation="flat", max_moves=10)
    env.reset(seed=0)
    model = sb3_contrib.MaskablePPO("MlpPolicy", env, n_steps=32, batch_size=16, n_epochs=1, seed=0, device="cpu")
    model.learn(total_timesteps=32)
    path = tmp_path_factory.mktemp("learned") / "ppo.zip"
    model.save(str(path))
    return path


def test_the_bench_plays_the_learned_policy_as_the_environment_does(model_path, tmp_path):
    out = tmp_path / "r.jsonl"
    args = ["bench", "--episodes", "3", "--seed", "4", "--verify", "none", "--moves", "tracing", "--max-moves", "10",
            "--policy", f"random,learned:{model_path}", "--no-plot", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    records = [r for r in read_results(out) if r["policy"].startswith("learned:")]
    assert len(records) == 3
    model = sb3_contrib.MaskablePPO.load(str(model_path), device="cpu")
    env = ExploreEnv(verify="none", observation="flat", max_moves=10)
    specs = plan_sweep(sorted(cached_library()), 3, 4, ["learned"], verify="none", moves="tracing", max_moves=10)
    by_draw = {(r["model"], r["seed"]): r for r in records}
    for s in specs:
        obs, info = env.reset(options={"model": s.model, "seed": s.seed})
        while True:
            action = int(model.predict(obs, action_masks=info["action_mask"], deterministic=True)[0])
            obs, _, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                break
        bench = by_draw[(s.model, s.seed)]
        for field in ("path_cost", "outcome", "moves", "move_kinds", "interpretations"):
            assert info["record"][field] == bench[field], field


def test_bad_learned_policies_are_named_in_one_line(model_path, tmp_path, capsys):
    out = str(tmp_path / "x.jsonl")
    base = ["bench", "--episodes", "1", "--verify", "none", "--out", out]
    assert main([*base, "--moves", "tracing", "--policy", "learned:/no/such/model.zip"]) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "/no/such/model.zip" in err
    assert main([*base, "--policy", f"learned:{model_path}"]) != 0  # the default move set has probes
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--moves tracing" in err
    not_a_model = tmp_path / "notes.zip"
    not_a_model.write_text("not a model")
    assert main([*base, "--moves", "tracing", "--policy", f"learned:{not_a_model}"]) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "notes.zip" in err and "Traceback" not in err
