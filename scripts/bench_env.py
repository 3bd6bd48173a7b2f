"""Steps and resets per second of the Gymnasium environments, per core, for a random agent over the admissible actions.

    .venv/bin/python scripts/bench_env.py [--env geometric,physics] [--verify none,full] [--seconds 30]
                                          [--min-steps 1] [--agent random|planner] [--seed 1] [--models DIR]
                                          [--json out.json]

For each environment and verification mode the script plays episodes (``reset`` without options: the model and the
episode seed drawn from the environment's generator) with actions drawn uniformly from ``info["action_mask"]``
(``--agent planner``: the planner's through :class:`~haptic.env.PolicyAgent`, whose scores of the candidates the
observation has already computed) until ``--seconds`` of this process's CPU time are spent and ``--min-steps`` steps
made (at least one reset and one step), and prints the steps per second (the time in ``step`` alone, the agent's
choice not counted) and the resets per second (the time in ``reset`` alone), both in CPU time of this process (one
core: what other processes on the machine take does not count) and in wall time, the agent's CPU time per step
(its choices; 0 for the random agent), and the machine's load average over the last minute when each row ends
(other processes share the caches and the memory bus even so).
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from haptic.env import ExploreEnv, PolicyAgent
from haptic.geometry.io import atomic_write
from haptic.matching.acceptance import VERIFY_MODES


def measure(
    executor: str, verify: str, seconds: float, seed: int, models: str | None, min_steps: int = 1, agent: str = "random"
) -> dict:
    """Play episodes for ``seconds`` of CPU time and at least ``min_steps`` steps; the counts and the CPU and wall
    time in step and reset."""
    env = ExploreEnv(executor=executor, models=models, verify=verify)
    rng = np.random.default_rng(seed)
    planner = PolicyAgent("planner") if agent == "planner" else None
    cpu = {"step": 0.0, "reset": 0.0, "act": 0.0}
    wall = {"step": 0.0, "reset": 0.0, "act": 0.0}
    n = {"step": 0, "reset": 0, "act": 0}

    def timed(kind: str, fn):
        c, w = time.process_time(), time.perf_counter()
        out = fn()
        cpu[kind] += time.process_time() - c
        wall[kind] += time.perf_counter() - w
        n[kind] += 1
        return out

    _, info = timed("reset", lambda: env.reset(seed=seed))
    while n["step"] < max(1, min_steps) or cpu["step"] + cpu["reset"] < seconds:
        if planner is not None:
            action = timed("act", lambda: planner.act(env))
        else:
            action = int(rng.choice(np.flatnonzero(info["action_mask"])))
        _, _, terminated, truncated, info = timed("step", lambda a=action: env.step(a))
        if terminated or truncated:
            _, info = timed("reset", env.reset)
    env.close()
    return {
        "env": "haptic/Explore-v0" if executor == "geometric" else "haptic/ExplorePhysics-v0",
        "verify": verify,
        "agent": agent,
        "steps": n["step"],
        "resets": n["reset"],
        "steps_per_s_cpu": n["step"] / cpu["step"],
        "resets_per_s_cpu": n["reset"] / cpu["reset"],
        "steps_per_s_wall": n["step"] / wall["step"],
        "resets_per_s_wall": n["reset"] / wall["reset"],
        "agent_ms_per_step_cpu": 1000.0 * cpu["act"] / n["step"],
        "load_1min": os.getloadavg()[0],
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env", default="geometric,physics", help="executors, comma-separated: geometric, physics")
    ap.add_argument("--verify", default="none,full", help=f"modes, comma-separated: {', '.join(VERIFY_MODES)}")
    ap.add_argument("--seconds", type=float, default=30.0, help="CPU seconds per environment and mode")
    ap.add_argument("--min-steps", type=int, default=1, help="steps per environment and mode at least")
    ap.add_argument("--agent", choices=("random", "planner"), default="random",
                    help="random: uniform over the mask; planner: the planner's choice (PolicyAgent)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--models", default=None)
    ap.add_argument("--json", default=None, help="also write the rows to this file")
    args = ap.parse_args(argv)
    rows = []
    print(f"{'environment':26s} {'verify':6s} {'steps':>6s} {'resets':>6s} {'steps/s cpu':>11s} {'resets/s cpu':>12s} "
          f"{'steps/s wall':>12s} {'resets/s wall':>13s} {'agent ms':>8s} {'load':>5s}")  # fmt: skip
    for executor in args.env.split(","):
        for verify in args.verify.split(","):
            r = measure(executor, verify, args.seconds, args.seed, args.models, args.min_steps, args.agent)
            rows.append(r)
            print(f"{r['env']:26s} {r['verify']:6s} {r['steps']:6d} {r['resets']:6d} {r['steps_per_s_cpu']:11.1f} "
                  f"{r['resets_per_s_cpu']:12.2f} {r['steps_per_s_wall']:12.1f} {r['resets_per_s_wall']:13.2f} "
                  f"{r['agent_ms_per_step_cpu']:8.2f} {r['load_1min']:5.1f}",
                  flush=True)  # fmt: skip
    if args.json:
        atomic_write(args.json, json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
