"""Policies against the best possible on a small library, on the same episodes (geometric executor, default
noise):

- ``optimal``: the policy of least expected path cost to recognition (exhaustive search over move sequences,
  ``--depth`` moves, then planner roll-outs; :mod:`haptic.planning.optimal`);
- ``lookahead``: one move searched, each outcome valued by planner roll-outs (:class:`~haptic.planning.optimal.
  LookaheadPolicy`);
- the hindsight optimum of each episode: the cheapest recognising move sequence found by exhaustive search
  knowing the truth (``--hindsight-depth`` moves after the fixed sequence; :mod:`haptic.bench.oracle`), a
  lower bound for every policy.

    .venv/bin/python scripts/bench_optimal.py [--episodes 60] [--seed 7] [--moves tracing] [--jobs 2]
        [--policies optimal,lookahead,planner,greedy,random] [--json out/optimal.jsonl]

The table gives each policy's decision times (the policy's choices, wall time: on a loaded machine they grow).

``--moves`` sets the policies' admissible moves (as ``haptic bench --moves``) and the hindsight search's: with
``tracing`` it searches tracing moves after the seed's opening; with ``all`` (or ``probing``) it starts where the
episode's own opening leaves it and tries, at each node, the tracing moves and the best probes
(:func:`~haptic.bench.oracle.hindsight_optimum_probing`). ``--hindsight-depth 0`` leaves the hindsight optimum out.

``--reuse FILE`` takes the rows of an earlier ``--json FILE`` of the same episodes (``--episodes``, ``--seed``,
``--moves``) for the policies and the hindsight optimum it holds, and runs only the rest: a new policy is compared
on the same episodes without searching the hindsight optimum again. The reused rows are what the code of that run
gave.
"""

from __future__ import annotations

import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from tqdm import tqdm

from haptic.bench.runner import plan_sweep
from haptic.episode.spec import EpisodeSpec
from haptic.planning.moves import MOVE_SETS

SMALL = ["BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R"]


def _library():
    from haptic.geometry import load_library

    return {k: v for k, v in load_library().items() if k in SMALL}


def _policy_run(spec: EpisodeSpec, depth: int) -> dict:
    from haptic.episode.worlds import run_episode
    from haptic.planning.registry import make_policy

    options = {"depth": depth} if spec.policy == "optimal" else {}
    t0 = time.perf_counter()
    r = run_episode(spec, library=_library(), policy=make_policy(spec.policy, **options))
    return {"policy": spec.policy, "seed": spec.seed, "model": spec.model, "cost": r.path_cost, "moves": r.moves,
            "correct": r.correct, "wall_s": time.perf_counter() - t0, "decision_times_s": list(r.decision_times_s)}


def _hindsight_run(spec: EpisodeSpec, depth: int) -> dict:
    from haptic.bench.oracle import hindsight_optimum, hindsight_optimum_probing

    search = hindsight_optimum if spec.moves == "tracing" else hindsight_optimum_probing
    o = search(spec, library=_library(), max_depth=depth)
    return {"policy": "hindsight", "seed": spec.seed, "model": spec.model, "cost": o.path_cost if o.found else None,
            "moves": o.moves, "correct": o.found, "wall_s": None}


def _reused(path: str, policies: list[str], seeds: set[int]) -> list[dict]:
    """The rows of an earlier run's JSON lines for ``policies`` (the hindsight optimum as "hindsight") on the
    episodes of ``seeds``."""
    with open(path) as f:
        rows = [json.loads(line) for line in f if line.strip()]
    return [r for r in rows if r["policy"] in policies and r["seed"] in seeds]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=60)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--depth", type=int, default=2, help="moves searched exhaustively by the optimal policy")
    ap.add_argument("--hindsight-depth", type=int, default=3, help="moves after the fixed sequence, hindsight search")
    ap.add_argument("--policies", default="optimal,planner,greedy,random")
    ap.add_argument("--moves", choices=MOVE_SETS, default="tracing", help="admissible moves of the policies")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", help="write one JSON line per episode and policy here")
    ap.add_argument("--reuse", help="an earlier --json of the same episodes: its rows are not run again")
    args = ap.parse_args(argv)
    policies = args.policies.split(",")
    specs = plan_sweep(SMALL, args.episodes, args.seed, policies, moves=args.moves, verify="none")
    draws = {s.seed: s for s in specs} if args.hindsight_depth > 0 else {}
    t0 = time.perf_counter()
    rows = _reused(args.reuse, policies + ["hindsight"], {s.seed for s in specs}) if args.reuse else []
    done = {(r["policy"], r["seed"]) for r in rows}
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        futs = [pool.submit(_policy_run, s, args.depth) for s in specs if (s.policy, s.seed) not in done]
        hind = [s for s in draws.values() if ("hindsight", s.seed) not in done]
        futs += [pool.submit(_hindsight_run, s, args.hindsight_depth) for s in hind]
        for f in tqdm(futs, desc="episodes", unit="ep"):
            rows.append(f.result())
    wall = time.perf_counter() - t0
    if args.json:
        from haptic.geometry.io import atomic_write

        atomic_write(args.json, "".join(json.dumps(r) + "\n" for r in rows))

    by = {(r["policy"], r["seed"]): r for r in rows}
    seeds = sorted({s.seed for s in specs})
    hind_ok = [k for k in seeds if ("hindsight", k) in by and by[("hindsight", k)]["cost"] is not None]
    print(f"library: {', '.join(SMALL)}; {args.episodes} episodes, seed {args.seed}; --moves {args.moves}; optimal "
          f"search depth {args.depth}; hindsight depth {args.hindsight_depth} after the fixed sequence; {wall:.0f} s "
          f"wall, {args.jobs} jobs")
    print(f"hindsight optimum found for {len(hind_ok)}/{len(seeds)} episodes (its column uses those)")
    print()
    print("| policy | correct | mean cost | median cost | mean moves | median moves | wall s/episode | "
          "decision ms p50 / p90 / max | mean cost / optimal's | mean cost / hindsight optimum |")
    print("|---|---|---|---|---|---|---|---|---|---|")

    def mean_cost(p, ks):
        return float(np.mean([by[(p, k)]["cost"] for k in ks]))

    for p in policies + (["hindsight"] if hind_ok else []):
        ks = hind_ok if p == "hindsight" else seeds
        rs = [by[(p, k)] for k in ks]
        c = np.array([r["cost"] for r in rs])
        m = np.array([r["moves"] for r in rs])
        vs_opt = "-"
        if "optimal" in policies and p != "hindsight":
            vs_opt = f"{mean_cost(p, seeds) / mean_cost('optimal', seeds):.3f}"
        vs_hind = f"{mean_cost(p, hind_ok) / mean_cost('hindsight', hind_ok):.3f}" if hind_ok else "-"
        wall_ep = "-" if p == "hindsight" else f"{np.mean([r['wall_s'] for r in rs]):.2f}"
        correct = "-" if p == "hindsight" else f"{sum(r['correct'] for r in rs)}/{len(rs)}"
        times = [t * 1e3 for r in rs for t in r.get("decision_times_s") or []]
        decide = (f"{np.percentile(times, 50):.1f} / {np.percentile(times, 90):.1f} / {max(times):.0f}" if times
                  else "-")  # fmt: skip
        print(f"| {p} | {correct} | {c.mean():.2f} | {np.median(c):.2f} | {m.mean():.2f} | {np.median(m):.1f} | "
              f"{wall_ep} | {decide} | {vs_opt} | {vs_hind} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
