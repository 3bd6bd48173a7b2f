"""Benchmark of the admissible kinds of move: tracing moves alone, free-space probes alone (``--moves probing``)
and both ranked together (``--moves all``), on the same draws, the last two at several values of the probe's
constant cost (not a timed test).

Geometric executor, one policy, no verification. The draws are those of ``haptic bench --seed S --episodes N``
(:func:`~haptic.bench.runner.plan_sweep`), so ``--c-p 2`` (the default :class:`~haptic.planning.moves.CostModel`)
gives the figures ``haptic bench --moves tracing`` and ``--moves all`` give. Prints one markdown row per setting:
correct %, mean and median path cost and moves of the recognised episodes, probes used (in how many episodes),
misses, outcomes and wall time, then the ratio of ``all`` to the better of the other two (means of the
recognised episodes' path cost, per ``c_p``).

    .venv/bin/python scripts/bench_moves.py [--episodes 200] [--seed 0] [--models DIR] [--policy planner]
        [--c-p 0.5,2,5] [--workers 2]
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from functools import partial

import numpy as np

from haptic.bench.runner import library_name, plan_sweep
from haptic.episode.worlds import run_episode
from haptic.geometry.library_cache import cached_library
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import CostModel

COLUMNS = ("library", "setting", "episodes", "correct %", "cost mean", "cost median", "moves mean", "moves median",
           "probes", "with a probe", "misses", "outcomes", "wall s")  # fmt: skip


def _episode(spec, models: str | None, c_p: float):
    return run_episode(spec, cached_library(models), config=PlannerConfig(costs=CostModel(c_p=c_p)))


def run(episodes: int = 200, seed: int = 0, models: str | None = None, policy: str = "planner",
        probe_costs: tuple[float, ...] = (0.5, 2.0, 5.0), workers: int = 1) -> list[dict]:  # fmt: skip
    """One row per setting: tracing, then ``probing`` and ``all`` at each probe constant ``c_p`` [units per
    probe]; ``workers`` processes run the episodes."""
    lib = cached_library(models)
    settings = [("tracing", "tracing", CostModel().c_p)]
    settings += [(f"probing, c_p {c:g}", "probing", c) for c in probe_costs]
    settings += [(f"all, c_p {c:g}", "all", c) for c in probe_costs]
    rows = []
    pool = ProcessPoolExecutor(workers) if workers > 1 else None
    try:
        for label, moves, c_p in settings:
            specs = plan_sweep(sorted(lib), episodes, seed, [policy], models=models, verify="none", moves=moves)
            t0 = time.perf_counter()
            run_one = partial(_episode, models=models, c_p=c_p)
            recs = list(pool.map(run_one, specs)) if pool else [run_one(s) for s in specs]
            rows.append(_row(library_name(models), label, moves, c_p, recs, time.perf_counter() - t0))
    finally:
        if pool:
            pool.shutdown()
    return rows


def _row(library: str, label: str, moves: str, c_p: float, recs, wall: float) -> dict:
    ok = [r for r in recs if r.outcome == "recognized"]
    cost = np.array([r.path_cost for r in ok])
    moves_n = np.array([r.moves for r in ok])
    probes = np.array([r.probes for r in recs])
    outcomes = {o: sum(r.outcome == o for r in recs) for o in sorted({r.outcome for r in recs})}
    return {
        "library": library, "setting": label, "moves": moves, "c_p": c_p, "episodes": len(recs),
        "correct %": 100.0 * float(np.mean([r.correct for r in recs])),
        "cost mean": float(cost.mean()) if len(ok) else float("nan"),
        "cost median": float(np.median(cost)) if len(ok) else float("nan"),
        "moves mean": float(moves_n.mean()) if len(ok) else float("nan"),
        "moves median": float(np.median(moves_n)) if len(ok) else float("nan"),
        "probes": int(probes.sum()), "with a probe": int((probes > 0).sum()),
        "misses": int(sum(r.probe_misses for r in recs)),
        "outcomes": ", ".join(f"{k} {v}" for k, v in outcomes.items()),
        "wall s": wall,
    }  # fmt: skip


def ratios(rows: list[dict]) -> list[str]:
    """Per ``c_p``: mean path cost of ``all`` over the better (lower) of ``tracing`` and ``probing`` at it."""
    tracing = next(r["cost mean"] for r in rows if r["moves"] == "tracing")
    out = []
    for r in rows:
        if r["moves"] != "all":
            continue
        probing = next((p["cost mean"] for p in rows if p["moves"] == "probing" and p["c_p"] == r["c_p"]), np.inf)
        best = min(tracing, probing)
        out.append(f"c_p {r['c_p']:g}: all / better of tracing and probing = {r['cost mean']:.2f} / {best:.2f} "
                   f"= {r['cost mean'] / best:.3f}")  # fmt: skip
    return out


def markdown(rows: list[dict]) -> str:
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "|".join("---" for _ in COLUMNS) + "|"]
    for r in rows:
        vals = [f"{r[c]:.2f}" if isinstance(r[c], float) else str(r[c]) for c in COLUMNS]
        lines.append("| " + " | ".join(vals) + " |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--models", default=None, help="library directory (default: the shipped one)")
    ap.add_argument("--policy", default="planner", choices=("planner", "greedy", "random"))
    ap.add_argument("--c-p", default="0.5,2,5", help="comma-separated probe constants [units per probe]")
    ap.add_argument("--workers", type=int, default=1, help="processes running episodes")
    args = ap.parse_args()
    if args.episodes < 1:
        ap.error("--episodes must be at least 1")
    try:
        costs = tuple(float(x) for x in args.c_p.split(","))
    except ValueError:
        ap.error(f"--c-p {args.c_p!r}: expected comma-separated numbers, such as 0.5,2,5")
    if not all(np.isfinite(c) and c >= 0 for c in costs):
        ap.error(f"--c-p {args.c_p!r}: every probe constant must be a finite number >= 0")
    if args.workers < 1:
        ap.error("--workers must be at least 1")
    rows = run(args.episodes, args.seed, args.models, args.policy, costs, args.workers)
    print(markdown(rows))
    print("\n".join(ratios(rows)))


if __name__ == "__main__":
    main()
