"""Benchmark of matching and planning against the size of the model library (a benchmark, not a timed test).

For generated libraries (``haptic models generate``) of each size: the library build time (loading and
validating the files; building the matcher's arrays), the peak memory of a worker, the decision time — the
matcher update after a move (its components added to the interpretation tree, then the verdict) plus the
policy's choice of the next move (pose classes to hypotheses, scoring) — as median and 95th percentile over
every decision the loop makes (``fallback_decisions`` counts those it leaves to a random move because the
matcher has no pose classes yet: more than ``haptic.episode.state.MAX_GROUPED_INTERPRETATIONS`` interpretations, or
poses undetermined), the episode wall time, episodes per minute on the workers, and the outcomes.
Wall-clock and CPU time of the deciding process are both reported: on a shared machine the wall clock counts
the time other processes held the core.

Writes ``OUT/scale.json`` (every figure), ``OUT/scale.md`` (the table) and ``OUT/scale.png`` (decision time
against library size, log-log, with the fitted growth exponent); prints the table.

    .venv/bin/python scripts/bench_scale.py [--sizes 10,30,100,300,1000] [--episodes 200] [--workers 2]
        [--seed 1] [--library-seed 0] [--libraries out/bench_scale/libraries] [--out out/bench_scale]
        [--compare-bound SIZE] [--bound N] [--max-grouped N] [--policy planner] [--moves tracing]

It also prints the policy's choice alone (CPU time of each decision, the matcher update left out) as 50th, 90th
and 99th percentiles.

``--compare-bound SIZE`` runs the episodes of library SIZE a second time with no bound on the planner's
hypotheses (``PlannerConfig.max_hypotheses=None``) and reports the change in path cost and outcomes; ``--bound N``
sets the bound of the first runs (default: ``PlannerConfig``'s); ``--max-grouped N`` sets the largest number of
interpretations the loop groups into pose classes (``haptic.episode.state.MAX_GROUPED_INTERPRETATIONS``; above
it, a random move).
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from haptic.planning.moves import MOVE_SETS

_TIMES: dict = {}


def _clock() -> tuple[float, float]:
    return time.perf_counter(), time.process_time()


class _TimedExecutor:
    """The episode's executor, noting when each move's result is back (the matcher update starts then)."""

    def __init__(self, inner) -> None:
        self.inner = inner

    def start(self):
        out = self.inner.start()
        _TIMES["returned"] = _clock()
        return out

    def execute(self, move):
        out = self.inner.execute(move)
        _TIMES["returned"] = _clock()
        return out


def _init_worker(max_grouped: int | None = None) -> None:
    import haptic.episode.state as state
    import haptic.episode.worlds as worlds

    if max_grouped is not None:
        state.MAX_GROUPED_INTERPRETATIONS = max_grouped
    make = worlds.make_geometric_executor
    worlds.make_geometric_executor = lambda *a, **k: _TimedExecutor(make(*a, **k))


def _episode(task: dict) -> dict:
    """One episode with timings: per policy decision, (update wall, update cpu, decide wall, decide cpu)."""
    from haptic.episode.loop import EpisodeObserver
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import run_episode
    from haptic.planning.config import PlannerConfig

    decisions: list[tuple[float, float, float, float]] = []
    fallback = [0]  # decisions taken by the loop's random fallback (no pose classes yet: too many or unposed)
    state = {"update": (0.0, 0.0), "last": _clock()}

    def on_move(n, result, count, rec):
        now = _clock()
        back = _TIMES.get("returned", now)
        state["update"] = (now[0] - back[0], now[1] - back[1])
        state["last"] = now

    def on_failed(n, result):
        state["update"] = (0.0, 0.0)
        state["last"] = _clock()

    def on_decision(n, decision):
        now = _clock()
        fallback[0] += not decision.candidates
        last = state["last"]
        decisions.append((*state["update"], now[0] - last[0], now[1] - last[1]))
        state["update"] = (0.0, 0.0)
        state["last"] = now

    config = PlannerConfig(max_hypotheses=task["bound"])
    t0 = _clock()
    rec = run_episode(
        EpisodeSpec(**task["spec"]),
        observer=EpisodeObserver(on_move=on_move, on_failed_move=on_failed, on_decision=on_decision),
        config=config,
    ).to_json()
    t1 = _clock()
    return {
        "model": rec["model"], "outcome": rec["outcome"], "correct": rec["correct"], "recognized": rec["recognized"],
        "moves": rec["moves"], "path_cost": rec["path_cost"], "seed": rec["seed"],
        "wall_s": t1[0] - t0[0], "cpu_s": t1[1] - t0[1], "decisions": decisions, "fallback": fallback[0],
        "max_interpretations": max(rec["interpretations"]) if rec["interpretations"] else 0,
        "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }  # fmt: skip


def _library(size: int, seed: int, root: Path) -> Path:
    from haptic.geometry.generate import iter_library, write_library

    d = root / f"gen{size}_s{seed}"
    if not d.exists():
        write_library(iter_library(size, seed), d)
    return d


def _build_times(directory: Path) -> dict:
    """Loading and validating the files, and building the matcher's arrays, in a fresh process."""
    code = (
        "import time, json, resource\n"
        "from haptic.geometry import load_library\n"
        "from haptic.matching.library import LibraryArrays\n"
        "t0 = time.perf_counter()\n"
        f"lib = load_library({str(directory)!r})\n"
        "t1 = time.perf_counter()\n"
        "a = LibraryArrays.build(lib)\n"
        "t2 = time.perf_counter()\n"
        "print(json.dumps({'load_s': t1 - t0, 'arrays_s': t2 - t1, 'faces': a.count(0), 'edges': a.count(1),"
        " 'vertices': a.count(2), 'rss_mib': resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))\n"
    )
    import subprocess

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _run(
    specs: list[dict], workers: int, bound: int | None, max_grouped: int | None = None
) -> tuple[list[dict], float]:
    tasks = [{"spec": s, "bound": bound} for s in specs]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=workers, initializer=_init_worker, initargs=(max_grouped,)) as pool:
        results = list(pool.map(_episode, tasks, chunksize=1))
    return results, time.perf_counter() - t0


def _summary(size: int, results: list[dict], wall: float, workers: int, build: dict) -> dict:
    d = np.array([x for r in results for x in r["decisions"]], dtype=float).reshape(-1, 4)
    total_wall, total_cpu = d[:, 0] + d[:, 2], d[:, 1] + d[:, 3]
    q = (lambda a, p: float(np.percentile(a, p)) if len(a) else float("nan"))  # noqa: E731
    n = len(results)
    wrong = sum(1 for r in results if r["outcome"] == "recognized" and not r["correct"])
    return {
        "models": size, "faces": build["faces"], "edges": build["edges"],
        "load_s": build["load_s"], "arrays_s": build["arrays_s"],
        "episodes": n, "correct_pct": 100.0 * sum(r["correct"] for r in results) / n, "wrong": wrong,
        "outcomes": {o: sum(r["outcome"] == o for r in results) for o in sorted({r["outcome"] for r in results})},
        "decisions": len(d), "fallback_decisions": sum(r["fallback"] for r in results),
        "decision_median_s": q(total_wall, 50), "decision_p95_s": q(total_wall, 95),
        "decision_cpu_median_s": q(total_cpu, 50), "decision_cpu_p95_s": q(total_cpu, 95),
        "update_median_s": q(d[:, 0], 50), "update_p95_s": q(d[:, 0], 95),
        "choose_median_s": q(d[:, 2], 50), "choose_p95_s": q(d[:, 2], 95),
        "choose_cpu_p50_s": q(d[:, 3], 50), "choose_cpu_p90_s": q(d[:, 3], 90), "choose_cpu_p99_s": q(d[:, 3], 99),
        "episode_wall_median_s": q([r["wall_s"] for r in results], 50),
        "episode_wall_p95_s": q([r["wall_s"] for r in results], 95),
        "episodes_per_min": 60.0 * n / wall, "workers": workers, "sweep_wall_s": wall,
        "peak_rss_mib_per_worker": max(r["peak_rss_mib"] for r in results),
        "path_cost_mean": float(np.mean([r["path_cost"] for r in results])),
        "moves_mean": float(np.mean([r["moves"] for r in results])),
    }  # fmt: skip


def _fit(sizes, values) -> tuple[float, float]:
    """Exponent and prefactor of ``value ≈ c · size^k`` by least squares in log-log."""
    k, logc = np.polyfit(np.log(sizes), np.log(values), 1)
    return float(k), float(np.exp(logc))


def _plot(rows: list[dict], path: Path) -> dict:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sizes = np.array([r["models"] for r in rows], dtype=float)
    fits = {}
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for key, label, style in (
        ("decision_median_s", "median (wall)", "o-"),
        ("decision_p95_s", "95th percentile (wall)", "s--"),
        ("decision_cpu_median_s", "median (CPU)", "^:"),
    ):
        v = np.array([r[key] for r in rows], dtype=float)
        k, c = _fit(sizes, v)
        fits[key] = k
        ax.loglog(sizes, v, style, label=f"{label}: exponent {k:.2f}")
        ax.loglog(sizes, c * sizes**k, color="0.7", lw=0.8)
    ax.set_xlabel("models in the library")
    ax.set_ylabel("decision time: matcher update + planner [s]")
    ax.set_title("Decision time against library size (log-log)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return fits


def _table(rows: list[dict], fits: dict) -> str:
    head = (
        "| models | faces | edges | load s | arrays s | episodes | correct % | wrong | decisions | decision median ms "
        "| p95 ms | CPU median ms | CPU p95 ms | update median ms | episode wall median s | episodes/min | "
        "peak MiB/worker | cost mean |\n" + "|---" * 18 + "|\n"
    )
    lines = [
        f"| {r['models']} | {r['faces']} | {r['edges']} | {r['load_s']:.2f} | {r['arrays_s']:.3f} | {r['episodes']} | "
        f"{r['correct_pct']:.1f} | {r['wrong']} | {r['decisions']} | {1e3 * r['decision_median_s']:.1f} | "
        f"{1e3 * r['decision_p95_s']:.1f} | {1e3 * r['decision_cpu_median_s']:.1f} | "
        f"{1e3 * r['decision_cpu_p95_s']:.1f} | {1e3 * r['update_median_s']:.1f} | "
        f"{r['episode_wall_median_s']:.2f} | {r['episodes_per_min']:.0f} | {r['peak_rss_mib_per_worker']:.0f} | "
        f"{r['path_cost_mean']:.1f} |"
        for r in rows
    ]
    fit = ", ".join(f"{k}: {v:.2f}" for k, v in fits.items())
    return head + "\n".join(lines) + f"\n\nfitted exponents of decision time against library size: {fit}\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="10,30,100,300,1000")
    ap.add_argument("--episodes", type=int, default=200)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1, help="seed of the sweep (models and poses)")
    ap.add_argument("--library-seed", type=int, default=0, help="seed of the generated libraries")
    ap.add_argument("--policy", default="planner")
    ap.add_argument("--moves", choices=MOVE_SETS, default="tracing", help="admissible moves of the episodes")
    ap.add_argument("--libraries", default="out/bench_scale/libraries")
    ap.add_argument("--out", default="out/bench_scale")
    ap.add_argument("--compare-bound", type=int, default=None, metavar="SIZE")
    ap.add_argument("--bound", type=int, default=None, help="PlannerConfig.max_hypotheses (default: its default)")
    ap.add_argument(
        "--max-grouped",
        type=int,
        default=None,
        help="haptic.episode.state.MAX_GROUPED_INTERPRETATIONS in the workers (default: its value)",
    )
    args = ap.parse_args(argv)
    if args.bound is None:
        from haptic.planning.config import PlannerConfig

        args.bound = PlannerConfig().max_hypotheses

    from haptic.bench.runner import plan_sweep
    from haptic.geometry import load_library
    from haptic.geometry.io import atomic_write

    sizes = [int(s) for s in args.sizes.split(",")]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows, compare = [], None
    for size in sizes:
        lib_dir = _library(size, args.library_seed, Path(args.libraries))
        build = _build_times(lib_dir)
        names = sorted(load_library(lib_dir))
        specs = [
            {"model": s.model, "seed": s.seed, "policy": s.policy, "models": str(lib_dir), "verify": "none",
             "moves": args.moves}  # tracing by default: the seed's episodes, what the figures were measured with
            for s in plan_sweep(names, args.episodes, args.seed, [args.policy])
        ]
        results, wall = _run(specs, args.workers, args.bound, args.max_grouped)
        row = _summary(size, results, wall, args.workers, build)
        rows.append(row)
        print(json.dumps(row), flush=True)
        print(f"{size} models, --policy {args.policy} --moves {args.moves}: the policy's choice, CPU ms p50 / p90 / "
              f"p99 over {row['decisions']} decisions: {1e3 * row['choose_cpu_p50_s']:.1f} / "
              f"{1e3 * row['choose_cpu_p90_s']:.1f} / {1e3 * row['choose_cpu_p99_s']:.1f}", flush=True)
        if args.compare_bound == size:
            free, wall_free = _run(specs, args.workers, None, args.max_grouped)
            paired = [(a, b) for a, b in zip(results, free, strict=True)]
            compare = {
                "models": size,
                "bound": args.bound,
                "episodes": len(paired),
                "bounded_cost_mean": float(np.mean([a["path_cost"] for a, _ in paired])),
                "unbounded_cost_mean": float(np.mean([b["path_cost"] for _, b in paired])),
                "bounded_correct": sum(a["correct"] for a, _ in paired),
                "unbounded_correct": sum(b["correct"] for _, b in paired),
                "episodes_differing": sum(a["path_cost"] != b["path_cost"] for a, b in paired),
                "unbounded": _summary(size, free, wall_free, args.workers, build),
            }
            print(json.dumps({"compare_bound": compare}), flush=True)
    fits = _plot(rows, out / "scale.png") if len(rows) >= 2 else {}
    table = _table(rows, fits)
    atomic_write(out / "scale.json", json.dumps({"rows": rows, "fits": fits, "compare_bound": compare}, indent=1))
    atomic_write(out / "scale.md", table)
    print(table, end="")
    if compare:
        print(
            f"bound of {compare['bound']} hypotheses, {compare['models']} models, {compare['episodes']} episodes: mean "
            f"path cost {compare['bounded_cost_mean']:.2f} bounded vs {compare['unbounded_cost_mean']:.2f} unbounded; "
            f"correct {compare['bounded_correct']} vs {compare['unbounded_correct']}; "
            f"{compare['episodes_differing']} episodes differ"
        )
    print(f"plot: {out / 'scale.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
