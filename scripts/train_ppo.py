"""Train a MaskablePPO policy (sb3-contrib) on ``haptic/Explore-v0``, saved for ``haptic bench --policy learned:PATH``.

    pip install -e '.[learn]'
    .venv/bin/python scripts/train_ppo.py [--minutes 30] [--timesteps N] [--envs 2] [--seed 1] [--verify none]
                                          [--models DIR] [--reward-scale 0.01] [--shaping 0] [--out out/learn/ppo.zip]
                                          [--eval-episodes 50]

Training runs ``--envs`` environments in worker processes (one per core) with the flat observation
(``observation="flat"``, for SB3's default ``MlpPolicy``) until ``--timesteps`` steps or ``--minutes`` of wall time,
whichever comes first, and saves the model (written atomically). It then plays ``--eval-episodes`` draws that
training never saw (``haptic bench``'s draws for ``--seed`` + 1000) through the environment with the trained policy
(its most likely admissible action) and with a random agent over the same mask, and prints the success rate and
mean path cost of both. ``haptic bench --policy planner,random,learned:PATH --moves tracing`` compares it with the
other policies on the bench's draws.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from haptic.env import ExploreEnv
from haptic.geometry.library_cache import cached_library


def make_env(args: argparse.Namespace, rank: int):
    def build():
        from stable_baselines3.common.monitor import Monitor

        env = ExploreEnv(models=args.models, verify=args.verify, max_moves=args.max_moves,
                         reward_scale=args.reward_scale, shaping=args.shaping, observation="flat")  # fmt: skip
        env.reset(seed=args.seed * 1000 + rank)
        return Monitor(env)

    return build


def evaluate(model, args: argparse.Namespace) -> dict[str, dict]:
    """Success rate and mean path cost of the trained policy and of a random agent over the mask, on the same
    draws (not the training's)."""
    from haptic.bench.runner import plan_sweep

    specs = plan_sweep(sorted(cached_library(args.models)), args.eval_episodes, args.seed + 1000, ["agent"],
                       verify=args.verify, models=args.models, moves="tracing")  # fmt: skip
    env = ExploreEnv(models=args.models, verify=args.verify, max_moves=args.max_moves, observation="flat")
    rng = np.random.default_rng(args.seed)
    agents = {
        "learned": lambda obs, mask: int(model.predict(obs, action_masks=mask, deterministic=True)[0]),
        "random (masked)": lambda obs, mask: int(rng.choice(np.flatnonzero(mask))),
    }
    out = {}
    for name, act in agents.items():
        recs = []
        for s in specs:
            obs, info = env.reset(options={"model": s.model, "seed": s.seed})
            while True:
                obs, _, terminated, truncated, info = env.step(act(obs, info["action_mask"]))
                if terminated or truncated:
                    recs.append(info["record"])
                    break
        out[name] = {
            "success": float(np.mean([r["correct"] for r in recs])),
            "mean_path_cost": float(np.mean([r["path_cost"] for r in recs])),
            "mean_moves": float(np.mean([r["moves"] for r in recs])),
        }
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=30.0, help="wall-time limit of the training")
    ap.add_argument("--timesteps", type=int, default=1_000_000, help="environment steps (decisions) at most")
    ap.add_argument("--envs", type=int, default=2, help="environments, each in a worker process")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--verify", default="none")
    ap.add_argument("--models", default=None)
    ap.add_argument("--max-moves", type=int, default=40)
    ap.add_argument("--reward-scale", type=float, default=0.01, help="reward per cost unit (1 cost unit = 0.01)")
    ap.add_argument("--shaping", type=float, default=0.0, help="potential-based shaping by eliminated pose classes")
    ap.add_argument("--n-steps", type=int, default=256, help="steps per environment between updates")
    ap.add_argument("--out", default="out/learn/ppo.zip")
    ap.add_argument("--eval-episodes", type=int, default=50)
    args = ap.parse_args(argv)

    import torch
    from sb3_contrib import MaskablePPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    torch.set_num_threads(1)
    fns = [make_env(args, i) for i in range(args.envs)]
    venv = SubprocVecEnv(fns) if args.envs > 1 else DummyVecEnv(fns)

    class WallClock(BaseCallback):
        def __init__(self, seconds: float) -> None:
            super().__init__()
            self.deadline = time.monotonic() + seconds

        def _on_step(self) -> bool:
            return time.monotonic() < self.deadline

    model = MaskablePPO(
        "MlpPolicy", venv, n_steps=args.n_steps, batch_size=64, n_epochs=5, gamma=0.99, learning_rate=3e-4,
        ent_coef=0.01, seed=args.seed, verbose=0, device="cpu", policy_kwargs={"net_arch": [128, 128]},
    )  # fmt: skip
    t0 = time.monotonic()
    model.learn(total_timesteps=args.timesteps, callback=WallClock(60 * args.minutes))
    train_s = time.monotonic() - t0
    venv.close()
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=out.parent, suffix=".zip")
    os.close(fd)
    model.save(tmp)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp's file is private; the model is an ordinary output file
    os.replace(tmp, out)
    print(f"trained {model.num_timesteps} steps in {train_s / 60:.1f} min ({model.num_timesteps / train_s:.0f} steps/s "
          f"over {args.envs} environments); saved {out}")  # fmt: skip
    for name, r in evaluate(model, args).items():
        print(f"{name:16s} success {100 * r['success']:.0f}%  mean path cost {r['mean_path_cost']:.2f}  "
              f"mean moves {r['mean_moves']:.2f}  ({args.eval_episodes} draws)")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
