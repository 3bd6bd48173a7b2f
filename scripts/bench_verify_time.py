"""The verification's decision time: percentiles of the time each verification move's choice takes, over the draws
``haptic bench`` makes, and the CPU time per episode.

    .venv/bin/python scripts/bench_verify_time.py [--episodes 50] [--seed 0] [--policy planner,random]
                                                  [--verify full] [--moves all] [--models DIR] [--json out.json]
                                                  [--records records.json]

The episodes are those of ``haptic bench`` with the same options (:func:`~haptic.bench.runner.plan_sweep`), run one
after another in this process. Each verification move's choice (:meth:`~haptic.planning.verify.Verifier.choose`) is
timed in wall and CPU time (its own ``decision_times`` are wall time); the script prints the 50th, 90th and 99th
percentile and the largest, in milliseconds, the number of choices, and the CPU seconds per episode with the
machine's load average over the last minute when it ends. ``--records`` writes the episodes' records (a JSON list),
to compare two runs with ``scripts/compare_records.py``.
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from haptic.bench.runner import plan_sweep
from haptic.episode.worlds import run_episode
from haptic.geometry import load_library
from haptic.geometry.io import atomic_write
from haptic.planning import verify


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=50)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--policy", default="planner,random")
    ap.add_argument("--verify", default="full")
    ap.add_argument("--moves", default="all")
    ap.add_argument("--models", default=None)
    ap.add_argument("--json", default=None, help="also write the figures to this file")
    ap.add_argument("--records", default=None, help="also write the episodes' records (a JSON list) to this file")
    args = ap.parse_args(argv)
    wall: list[float] = []
    cpu: list[float] = []
    choose = verify.Verifier.choose

    def timed_choose(self, *a, **k):
        c, w = time.process_time(), time.perf_counter()
        try:
            return choose(self, *a, **k)
        finally:
            cpu.append(time.process_time() - c)
            wall.append(time.perf_counter() - w)

    verify.Verifier.choose = timed_choose  # every verification move's choice, timed
    names = sorted(load_library(args.models))
    specs = plan_sweep(names, args.episodes, args.seed, args.policy.split(","), verify=args.verify,
                       moves=args.moves, models=args.models)  # fmt: skip
    c0 = time.process_time()
    records = [run_episode(spec).to_json() for spec in specs]
    per_episode = (time.process_time() - c0) / len(specs)
    out = {"episodes": len(specs), "choices": len(wall), "cpu_s_per_episode": per_episode,
           "load_1min": os.getloadavg()[0]}  # fmt: skip
    for name, xs in (("wall_ms", wall), ("cpu_ms", cpu)):
        if xs:
            ms = 1e3 * np.asarray(xs)
            out[name] = {f"p{q}": float(np.percentile(ms, q)) for q in (50, 90, 99)} | {"max": float(ms.max())}
    print(f"{out['episodes']} episodes, {out['choices']} verification choices, {per_episode:.3f} s CPU per episode, "
          f"load {out['load_1min']:.1f}")  # fmt: skip
    for name in ("wall_ms", "cpu_ms"):
        if name in out:
            print(f"  {name}: " + ", ".join(f"{k} {v:.1f}" for k, v in out[name].items()))
    if args.json:
        atomic_write(args.json, json.dumps(out, indent=1))
    if args.records:
        atomic_write(args.records, json.dumps(records, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
