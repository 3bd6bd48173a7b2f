"""``haptic bench``: a sweep of episodes, a results file, a summary table and a plot."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from haptic.errors import BenchError


def add_parser(sub: argparse._SubParsersAction) -> None:
    from haptic.matching.verify import DEFAULT_VERIFY, VERIFY_MODES
    from haptic.planning.policies import POLICY_NAMES

    p = sub.add_parser(
        "bench",
        help="run many episodes; write one JSON line per episode, a summary table and a plot",
        description="Models x random poses x noise levels x policies. Every policy runs on the same "
        "(model, pose) draws. Writes OUT (JSON lines, one per episode as it ends), OUT with .md (summary "
        "table) and .png (pose classes remaining vs path cost).",
    )
    p.add_argument("--models", metavar="DIR", help="library directory (default: the shipped assets/models)")
    p.add_argument("--executor", choices=("geometric", "physics"), default="geometric")
    p.add_argument(
        "--policy", default="planner,random", help=f"comma-separated policies from {', '.join(POLICY_NAMES)}"
    )
    p.add_argument("--episodes", type=int, default=50, help="random (model, pose) draws (default 50)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--noise", default="1", help="comma-separated sensor-noise levels (x default sigma, 0 to 10)")
    p.add_argument(
        "--verify", choices=VERIFY_MODES, default=DEFAULT_VERIFY,
        help=f"verification before recognition (default {DEFAULT_VERIFY}): none, fast or full",
    )
    p.add_argument("--out", default="out/bench/results.jsonl", help="results file (JSON lines)")
    p.add_argument("--workers", type=int, default=1, help="worker processes (local backend)")
    p.add_argument("--backend", choices=("local", "ray"), default="local")
    p.add_argument("--max-moves", type=int, default=40)
    p.add_argument("--no-plot", action="store_true", help="skip the PNG plot")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from haptic.bench.results import ResultsWriter
    from haptic.bench.runner import plan_sweep, run_sweep
    from haptic.bench.summary import markdown_table, plot_interpretations_vs_cost, summary_rows
    from haptic.geometry import load_library
    from haptic.geometry.io import atomic_write
    from haptic.matching.components import check_noise_level
    from haptic.planning.policies import POLICY_NAMES

    policies = [p.strip() for p in args.policy.split(",") if p.strip()]
    bad = [p for p in policies if p not in POLICY_NAMES]
    if bad or not policies:
        raise BenchError(f"unknown policy {', '.join(bad) or '(none)'}; valid: {', '.join(POLICY_NAMES)}")
    noises = [check_noise_level(x) for x in args.noise.split(",")]
    if args.episodes < 1:
        raise BenchError(f"--episodes must be at least 1, got {args.episodes}")
    library = load_library(args.models)
    lib_name = Path(args.models).name if args.models else "seed"
    specs = plan_sweep(
        sorted(library), args.episodes, args.seed, policies, noises,
        executor=args.executor, models=args.models, max_moves=args.max_moves, verify=args.verify,
    )
    out = Path(args.out)
    records = []
    t0 = time.perf_counter()
    with ResultsWriter(out) as writer:
        bar = tqdm(total=len(specs), unit="ep", desc="bench", disable=None, file=sys.stderr)
        for rec in run_sweep(specs, workers=args.workers, backend=args.backend):
            rec["library"] = lib_name
            writer.write(rec)
            records.append(rec)
            bar.update(1)
        bar.close()
    wall = time.perf_counter() - t0
    table = markdown_table(summary_rows(records, ("library", "executor", "noise", "verify", "policy")))
    atomic_write(out.with_suffix(".md"), table)
    print(table, end="")
    print(f"{len(records)} episodes in {wall:.1f} s ({60 * len(records) / wall:.0f} episodes/min); results: {out}")
    if not args.no_plot:
        png = plot_interpretations_vs_cost(records, out.with_suffix(".png"), title=f"{lib_name} library")
        print(f"plot: {png}")
    return 0
