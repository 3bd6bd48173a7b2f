"""The local and the Ray backend on the same sweep: identical records (timings aside), episodes per minute.

Runs one sweep with ``--workers`` local worker processes, then on a Ray started here with as many CPUs (or
the cluster named by RAY_ADDRESS), and compares the records episode by episode. Ray's start-up is timed
apart from the sweep. Needs the Ray extra: ``pip install -e '.[ray]'``.

    .venv/bin/python scripts/bench_backends.py                  # 40 episodes, planner, 2 workers
    .venv/bin/python scripts/bench_backends.py --episodes 4
    .venv/bin/python scripts/bench_backends.py --kill-a-worker   # SIGKILL a Ray worker running an episode
"""

from __future__ import annotations

import argparse
import os
import signal
import threading
import time
from pathlib import Path

from haptic.bench.runner import key_id, plan_sweep, run_sweep, start_ray
from haptic.geometry import load_library

TIMINGS = ("wall_time_s", "decision_times_s")
"""Record fields that measure time and so differ between runs."""


def by_key(records: list[dict]) -> dict[str, dict]:
    return {key_id(r["key"]): {k: v for k, v in r.items() if k not in TIMINGS} for r in records}


def kill_a_ray_worker(stop: threading.Event, killed: list[int]) -> None:
    """SIGKILL the first Ray worker seen running an episode (its title is ``ray::_run``)."""
    while not stop.is_set():
        for p in Path("/proc").iterdir():
            try:
                if p.name.isdigit() and (p / "cmdline").read_bytes().startswith(b"ray::_run"):
                    time.sleep(0.2)  # well into its episode
                    os.kill(int(p.name), signal.SIGKILL)
                    killed.append(int(p.name))
                    return
            except OSError:
                continue
        time.sleep(0.05)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=40)
    ap.add_argument("--policy", default="planner")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--kill-a-worker", action="store_true", help="SIGKILL one Ray worker during the sweep")
    args = ap.parse_args(argv)
    import ray

    specs = plan_sweep(sorted(load_library(None)), args.episodes, args.seed, args.policy.split(","),
                       verify="none", moves="tracing")
    t0 = time.perf_counter()
    local = list(run_sweep(specs, workers=args.workers))
    local_s = time.perf_counter() - t0

    t0 = time.perf_counter()
    started = start_ray(args.workers)
    start_s = time.perf_counter() - t0
    try:
        stop, killed = threading.Event(), []
        if args.kill_a_worker:
            threading.Thread(target=kill_a_ray_worker, args=(stop, killed), daemon=True).start()
        t0 = time.perf_counter()
        remote = list(run_sweep(specs, workers=args.workers, backend="ray"))
        ray_s = time.perf_counter() - t0
        stop.set()
    finally:
        if started:
            ray.shutdown()
    a, b = by_key(local), by_key(remote)
    same = sum(a[k] == b.get(k) for k in a)
    print(f"{len(specs)} episodes ({args.policy}, seed {args.seed}); {args.workers} local workers vs Ray with "
          f"{args.workers} CPUs")
    print("| backend | episodes | sweep [s] | episodes/min | start-up [s] |")
    print("|---|---|---|---|---|")
    print(f"| local | {len(local)} | {local_s:.1f} | {60 * len(local) / local_s:.0f} | - |")
    print(f"| ray | {len(remote)} | {ray_s:.1f} | {60 * len(remote) / ray_s:.0f} | {start_s:.1f} |")
    if args.kill_a_worker:
        print(f"Ray workers killed during the sweep: {len(killed)} (pid {', '.join(map(str, killed)) or '-'})")
    print(f"records identical (timings aside): {same} of {len(a)}; only local: {len(set(a) - set(b))}, "
          f"only Ray: {len(set(b) - set(a))}, Ray lines: {len(remote)}")
    return 0 if same == len(a) == len(b) == len(remote) else 1


if __name__ == "__main__":
    raise SystemExit(main())
