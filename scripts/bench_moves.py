"""Benchmark of the admissible kinds of move: tracing moves alone against tracing moves and free-space probes
ranked together (``--moves all``), on the same draws, at several values of the probe's constant cost (not a timed
test).

Geometric executor, one policy, no verification. The draws are those of ``haptic bench --seed S --episodes N``
(:func:`~haptic.bench.runner.plan_sweep`), so ``--c-p 2`` (the default :class:`~haptic.planning.moves.CostModel`)
gives the figures ``haptic bench --moves tracing`` and ``--moves all`` give. Prints one markdown row per setting:
correct %, mean and median path cost and moves of the recognised episodes, probes used (in how many episodes),
misses, outcomes and wall time.

    .venv/bin/python scripts/bench_moves.py [--episodes 200] [--seed 0] [--models DIR] [--policy planner]
        [--c-p 0.5,2,5]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from haptic.bench.runner import library_name, plan_sweep
from haptic.episode.worlds import run_episode
from haptic.geometry.library_cache import cached_library
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import CostModel

COLUMNS = ("library", "setting", "episodes", "correct %", "cost mean", "cost median", "moves mean", "moves median",
           "probes", "with a probe", "misses", "outcomes", "wall s")  # fmt: skip


def run(episodes: int = 200, seed: int = 0, models: str | None = None, policy: str = "planner",
        probe_costs: tuple[float, ...] = (0.5, 2.0, 5.0)) -> list[dict]:  # fmt: skip
    """One row per setting: tracing, then ``all`` at each probe constant ``c_p`` [units per probe]."""
    lib = cached_library(models)
    settings = [("tracing", "tracing", CostModel())]
    settings += [(f"all, c_p {c:g}", "all", CostModel(c_p=c)) for c in probe_costs]
    rows = []
    for label, moves, costs in settings:
        specs = plan_sweep(sorted(lib), episodes, seed, [policy], models=models, verify="none", moves=moves)
        t0 = time.perf_counter()
        recs = [run_episode(s, lib, config=PlannerConfig(costs=costs)) for s in specs]
        ok = [r for r in recs if r.outcome == "recognized"]
        cost = np.array([r.path_cost for r in ok])
        moves_n = np.array([r.moves for r in ok])
        probes = np.array([r.probes for r in recs])
        outcomes = {o: sum(r.outcome == o for r in recs) for o in sorted({r.outcome for r in recs})}
        rows.append({
            "library": library_name(models), "setting": label, "episodes": len(recs),
            "correct %": 100.0 * float(np.mean([r.correct for r in recs])),
            "cost mean": float(cost.mean()) if len(ok) else float("nan"),
            "cost median": float(np.median(cost)) if len(ok) else float("nan"),
            "moves mean": float(moves_n.mean()) if len(ok) else float("nan"),
            "moves median": float(np.median(moves_n)) if len(ok) else float("nan"),
            "probes": int(probes.sum()), "with a probe": int((probes > 0).sum()),
            "misses": int(sum(r.probe_misses for r in recs)),
            "outcomes": ", ".join(f"{k} {v}" for k, v in outcomes.items()),
            "wall s": time.perf_counter() - t0,
        })  # fmt: skip
    return rows


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
    args = ap.parse_args()
    if args.episodes < 1:
        ap.error("--episodes must be at least 1")
    try:
        costs = tuple(float(x) for x in args.c_p.split(","))
    except ValueError:
        ap.error(f"--c-p {args.c_p!r}: expected comma-separated numbers, such as 0.5,2,5")
    if not all(np.isfinite(c) and c >= 0 for c in costs):
        ap.error(f"--c-p {args.c_p!r}: every probe constant must be a finite number >= 0")
    print(markdown(run(args.episodes, args.seed, args.models, args.policy, costs)))


if __name__ == "__main__":
    main()
