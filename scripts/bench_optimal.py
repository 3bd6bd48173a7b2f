"""Policies against the best possible on a small library: the hindsight optimum of each episode, the
cheapest recognising move sequence found by exhaustive search with knowledge of the truth (a lower bound for
every policy, and for the least expected cost).

    python scripts/bench_optimal.py --episodes 30 --seed 7
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from tqdm import tqdm

from haptic.bench.oracle import hindsight_optimum
from haptic.bench.runner import plan_sweep
from haptic.episode import run_episode
from haptic.geometry import load_library

SMALL = ["BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=30)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--depth", type=int, default=3, help="moves searched after the fixed sequence")
    ap.add_argument("--policies", default="planner,greedy,random")
    args = ap.parse_args(argv)
    library = {k: v for k, v in load_library().items() if k in SMALL}
    policies = args.policies.split(",")
    specs = plan_sweep(sorted(library), args.episodes, args.seed, policies)
    rows: dict[str, list] = {p: [] for p in policies}
    oracle: dict[int, object] = {}
    t0 = time.perf_counter()
    for s in tqdm(specs, desc="episodes", unit="ep"):
        r = run_episode(s, library=library)
        rows[s.policy].append(r)
        if s.seed not in oracle:
            oracle[s.seed] = hindsight_optimum(s, library=library, max_depth=args.depth)
    print(f"library: {', '.join(sorted(library))}; {args.episodes} episodes; seed {args.seed}; "
          f"hindsight search depth {args.depth} after the fixed sequence; {time.perf_counter() - t0:.0f} s")
    found = {k for k, o in oracle.items() if o.found}
    print(f"hindsight optimum found within the depth for {len(found)}/{len(oracle)} episodes; ratios below use those")
    print()
    print("| policy | correct | mean cost | median cost | mean moves | mean cost / hindsight optimum | "
          "episodes within 1.15x |")
    print("|---|---|---|---|---|---|---|")
    opt_cost = np.array([oracle[k].path_cost for k in sorted(found)])
    opt_moves = np.array([oracle[k].moves for k in sorted(found)])
    for p, rs in rows.items():
        by_seed = {r.seed: r for r in rs}
        c = np.array([by_seed[k].path_cost for k in sorted(found)])
        allc = np.array([r.path_cost for r in rs])
        within = np.mean(c <= 1.15 * opt_cost + 1e-9) * 100
        print(f"| {p} | {sum(r.correct for r in rs)}/{len(rs)} | {allc.mean():.1f} | {np.median(allc):.1f} | "
              f"{np.mean([r.moves for r in rs]):.2f} | {c.mean() / opt_cost.mean():.3f} | {within:.0f}% |")
    print(f"| hindsight optimum | - | {opt_cost.mean():.1f} | {np.median(opt_cost):.1f} | {opt_moves.mean():.2f} "
          "| 1.000 | - |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
