"""Every model of a library explored as itself, with the default budgets: how many the verification confirms.

Each model gets ``--poses`` episodes (random poses, seeded), the planner, the geometric executor, the library's
own models as the library; the table counts the outcomes and the verification's statuses, with the verification's
moves against its move budget and the path cost against the episode's budget, and lists every episode that did
not end confirmed and correct, largest models first.

    .venv/bin/python scripts/make_corpus.py out/corpus --encodings obj6
    .venv/bin/python scripts/confirm_library.py --models out/corpus/obj6 --workers 1
    .venv/bin/haptic models generate --count 100 --seed 0 --out out/gen100
    .venv/bin/python scripts/confirm_library.py --models out/gen100 --workers 1

Results (one JSON line per episode) go to ``--out`` (default ``out/confirm/<library>.jsonl``).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from haptic.bench.runner import run_sweep
from haptic.episode.spec import DEFAULT_BUDGET, EpisodeSpec
from haptic.errors import HapticError
from haptic.geometry import load_library
from haptic.geometry.io import atomic_write
from haptic.matching.acceptance import DEFAULT_VERIFY, VERIFY_MODES
from haptic.planning.moves import MOVE_SETS


def summary(records: list[dict], sizes: dict[str, int]) -> str:
    """Markdown: outcomes, statuses, the verification's moves over its budget and the path cost, and the episodes
    that were not confirmed and correct (``sizes``: vertices per model)."""
    n = len(records)
    ok = [r for r in records if r["outcome"] == "recognized" and r["correct"]]
    wrong = [r for r in records if r["outcome"] == "recognized" and not r["correct"]]
    outcomes = Counter(r["outcome"] for r in records)
    statuses = Counter((r.get("verified") or {}).get("status", "-") for r in records)
    # the budget is for the vertices (verify_move_budget); the faces' middles are probed once each after them
    use = [(r["verified"]["moves"] - r["verified"].get("middles_probed", 0)) / r["verified"]["move_budget"]
           for r in records if (r.get("verified") or {}).get("move_budget")]  # fmt: skip
    lines = [
        f"episodes: {n}; confirmed and correct: {len(ok)} ({100.0 * len(ok) / max(n, 1):.1f} %); wrong: {len(wrong)}",
        f"outcomes: {', '.join(f'{k} {v}' for k, v in outcomes.most_common())}",
        f"verification statuses: {', '.join(f'{k} {v}' for k, v in statuses.most_common())}",
        f"path cost: mean {np.mean([r['path_cost'] for r in records]):.1f}, "
        f"max {max(r['path_cost'] for r in records):.1f} (budget {DEFAULT_BUDGET:g})",
    ]
    if use:
        lines.append(f"verification moves before the faces' middles / move budget: median {np.median(use):.2f}, "
                     f"max {max(use):.2f}")
    big = sorted(records, key=lambda r: -sizes.get(r["model"], 0))[:3]
    lines.append("largest models: " + "; ".join(
        f"{r['model']} ({sizes.get(r['model'], 0)} vertices): {r['outcome']}, {r['moves']} moves, "
        f"path cost {r['path_cost']:.1f}" for r in big))  # fmt: skip
    bad = sorted((r for r in records if r not in ok), key=lambda r: -sizes.get(r["model"], 0))
    for r in bad:
        lines.append(f"  not confirmed: {r['model']} ({sizes.get(r['model'], 0)} vertices) seed {r['seed']}: "
                     f"{r['outcome']}, {r['detail']}")  # fmt: skip
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--models", metavar="DIR", help="library directory (default: the shipped seed library)")
    ap.add_argument("--poses", type=int, default=1, help="episodes (random poses) per model")
    ap.add_argument("--verify", choices=VERIFY_MODES, default=DEFAULT_VERIFY)
    ap.add_argument("--moves", choices=MOVE_SETS, default="all")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--out", default=None, help="results file (default out/confirm/<library>.jsonl)")
    args = ap.parse_args(argv)
    try:
        library = load_library(args.models)
        name = Path(args.models).name if args.models else "seed"
        out = Path(args.out or f"out/confirm/{name}.jsonl")
        rng = np.random.default_rng(args.seed)
        specs = [EpisodeSpec(model=m, seed=int(s), models=args.models, verify=args.verify, moves=args.moves)
                 for m in sorted(library) for s in rng.integers(2**31 - 1, size=args.poses)]  # fmt: skip
        records, lines = [], []
        out.parent.mkdir(parents=True, exist_ok=True)
        for rec in run_sweep(specs, workers=args.workers):
            records.append(rec)
            lines.append(json.dumps(rec))
            if len(records) % 20 == 0:
                print(f"{len(records)}/{len(specs)} episodes", file=sys.stderr, flush=True)
                atomic_write(out, "\n".join(lines) + "\n")
        atomic_write(out, "\n".join(lines) + "\n")
        sizes = {m: p.n_vertices for m, p in library.items()}
        text = f"# {name}: {len(library)} models, --verify {args.verify}, --moves {args.moves}\n\n" + summary(
            records, sizes)  # fmt: skip
        atomic_write(out.with_suffix(".md"), text)
        print(text)
    except HapticError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
