"""A random agent and the planner through the Gymnasium environment; their mean path cost, and the bench's.

    .venv/bin/python scripts/env_example.py [--episodes 20] [--seed 1] [--executor geometric|physics]
                                            [--verify none|fast|full] [--models DIR]

Both agents play the same (model, episode seed) draws as ``haptic bench --episodes N --seed S``. The random agent
picks uniformly among the admissible actions (``info["action_mask"]``) with its own generator; the planner acts
through :class:`haptic.env.PolicyAgent` and must give the path costs of ``haptic bench --policy planner`` (the
script runs that sweep too and prints both means).
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import haptic.env  # noqa: F401 -- registers the environments
from haptic.bench.runner import plan_sweep, run_sweep
from haptic.env import PolicyAgent
from haptic.geometry.library_cache import cached_library
from haptic.matching.acceptance import DEFAULT_VERIFY, VERIFY_MODES


def play(env: gym.Env, act, model: str, seed: int) -> dict:
    """One episode through the environment; its JSON record."""
    env.reset(options={"model": model, "seed": seed})
    while True:
        _, _, terminated, truncated, info = env.step(act(env))
        if terminated or truncated:
            return info["record"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--executor", choices=("geometric", "physics"), default="geometric")
    ap.add_argument("--verify", choices=VERIFY_MODES, default=DEFAULT_VERIFY)
    ap.add_argument("--models", default=None)
    args = ap.parse_args(argv)

    env_id = "haptic/Explore-v0" if args.executor == "geometric" else "haptic/ExplorePhysics-v0"
    env = gym.make(env_id, models=args.models, verify=args.verify)
    specs = plan_sweep(sorted(cached_library(args.models)), args.episodes, args.seed, ["planner"],
                       executor=args.executor, verify=args.verify, models=args.models, moves="tracing")  # fmt: skip
    rng = np.random.default_rng(args.seed)
    planner = PolicyAgent("planner")
    agents = {
        "random": lambda e: int(rng.choice(np.flatnonzero(e.unwrapped.action_masks()))),
        "planner": planner.act,
    }
    for name, act in agents.items():
        t0 = time.perf_counter()
        recs = [play(env, act, s.model, s.seed) for s in specs]
        outcomes = {o: sum(r["outcome"] == o for r in recs) for o in sorted({r["outcome"] for r in recs})}
        print(f"{name:8s} through {env_id}: mean path cost {np.mean([r['path_cost'] for r in recs]):.3f} over "
              f"{len(recs)} episodes, mean moves {np.mean([r['moves'] for r in recs]):.2f}, outcomes {outcomes} "
              f"({time.perf_counter() - t0:.0f} s)")  # fmt: skip
    bench = list(run_sweep(specs))
    print(f"haptic bench --policy planner (same draws): mean path cost {np.mean([r['path_cost'] for r in bench]):.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
