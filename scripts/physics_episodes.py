"""Physics episodes on every object of the seed library at a few random resting poses, headless: outcome,
moves, path cost, wall and simulated time, pose error and perception errors per episode, then a summary per object.

    .venv/bin/python scripts/physics_episodes.py [--poses 3] [--first-seed 1] [--objects BOX01,WEDGE01]
                                                 [--policy planner] [--moves tracing|all]
                                                 [--verify none|fast|full] [--jobs 2] [--json episodes.json]

Pose ``k`` of an object is episode seed ``first-seed + k`` (the seed places the object and drives the planner's
random choices), so any row can be replayed with ``haptic explore --object NAME --executor physics --seed S``
(and ``--moves all`` for free-space probes too: the probes used, those that missed and those that failed are
counted per episode).
Copy and adapt: one episode is ``run_episode(EpisodeSpec(model=..., seed=..., executor="physics"))``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from haptic.episode.loop import EpisodeObserver
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.errors import HapticError
from haptic.geometry.io import atomic_write

SEED_OBJECTS = ("BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R", "HEXPRISM01", "LBLOCK01",
                "FRAME01")


def one(model: str, seed: int, policy: str, moves: str = "tracing", verify: str = "none") -> dict:
    """One physics episode's record as JSON (an ``error`` entry when it could not run), with the probes that
    failed (``probes_failed``) and why (``probe_failures``)."""
    failed: list[str] = []

    def on_failed(n, result) -> None:
        if result.move is not None and result.move.kind == "probe":
            failed.append(f"{result.status}: {result.info.get('reason', '')}")

    try:
        spec = EpisodeSpec(model=model, seed=seed, policy=policy, executor="physics", moves=moves, verify=verify)
        rec = run_episode(spec, observer=EpisodeObserver(on_failed_move=on_failed)).to_json()
    except HapticError as exc:
        return {"model": model, "seed": seed, "outcome": "error", "correct": False, "detail": str(exc)}
    rec.update(probes_failed=len(failed), probe_failures=failed)
    return rec


def _f(x, fmt: str = ".1f") -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, fmt)


def _perception(r: dict) -> str:
    p = r.get("perception") or {}
    if not p:
        return "-"
    med = lambda k: p.get(k, {}).get("median")  # noqa: E731
    return (f"n {_f(med('face_normal_deg'), '.2f')}° e {_f(med('edge_direction_deg'), '.2f')}° "
            f"ep {_f(med('edge_position_mm'), '.2f')} vp {_f(med('vertex_position_mm'), '.2f')} mm "
            f"sp {p.get('spurious', '-')} mi {p.get('missed', '-')}")  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=3, help="random resting poses (episodes) per object")
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--objects", default=",".join(SEED_OBJECTS))
    ap.add_argument("--policy", default="planner")
    ap.add_argument("--moves", default="tracing", choices=("tracing", "all"), help="admissible kinds of move")
    ap.add_argument("--verify", default="none", choices=("none", "fast", "full"),
                    help="verification before recognition (default none: the matcher's verdict)")
    ap.add_argument("--jobs", type=int, default=1, help="episodes run in parallel (processes)")
    ap.add_argument("--json", default=None, help="write every episode record here")
    args = ap.parse_args(argv)

    objects = [o for o in args.objects.split(",") if o]
    jobs = [(o, args.first_seed + k, args.policy, args.moves, args.verify) for o in objects for k in range(args.poses)]
    t0 = time.perf_counter()
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            records = list(pool.map(one, *zip(*jobs, strict=True)))
    else:
        records = [one(*j) for j in jobs]

    print(f"{'object':<10} {'seed':>4} {'outcome':<10} {'ok':<3} {'moves':>5} {'fail':>4} {'probes':>6} "
          f"{'cost':>6} {'wall s':>6} {'sim s':>6} {'err mm':>6} {'err °':>5}  perception (medians)")  # fmt: skip
    for r in records:
        probes = f"{r.get('probes', 0)}/{r.get('probe_misses', 0)}/{r.get('probes_failed', 0)}"
        print(f"{r['model']:<10} {r['seed']:>4} {r['outcome']:<10} {'yes' if r['correct'] else 'no':<3} "
              f"{r.get('moves', 0):>5} {r.get('failed_moves', 0):>4} {probes:>6} {_f(r.get('path_cost')):>6} "
              f"{_f(r.get('wall_time_s')):>6} {_f(r.get('sim_time_s')):>6} {_f(r.get('pose_error_mm'), '.2f'):>6} "
              f"{_f(r.get('pose_error_deg'), '.2f'):>5}  {_perception(r)}")  # fmt: skip
        if r["outcome"] not in ("recognized",) and r.get("detail"):
            print(f"{'':<16}{r['detail']}")

    print()
    print(f"{'object':<10} {'correct':>7} {'wrong':>5} {'moves':>6} {'cost':>6} {'wall s':>6} {'sim s':>6} "
          f"{'err mm':>6}  (medians over the correctly recognised episodes; probes: used/missed/failed)")  # fmt: skip
    wrong_total = 0
    for o in objects:
        rs = [r for r in records if r["model"] == o]
        good = [r for r in rs if r["correct"]]
        wrong = [r for r in rs if r["outcome"] == "recognized" and not r["correct"]]
        wrong_total += len(wrong)

        def med(k: str, good=good) -> float | None:
            v = [r[k] for r in good if r.get(k) is not None]
            return float(np.median(v)) if v else None

        print(f"{o:<10} {len(good):>3}/{len(rs):<3} {len(wrong):>5} {_f(med('moves')):>6} "
              f"{_f(med('path_cost')):>6} {_f(med('wall_time_s')):>6} {_f(med('sim_time_s')):>6} "
              f"{_f(med('pose_error_mm'), '.2f'):>6}")  # fmt: skip
    good = [r for r in records if r["correct"]]
    walls = [r["wall_time_s"] for r in good]
    print()
    outcomes = Counter(r["outcome"] for r in records)
    print(f"correct {len(good)}/{len(records)}, wrong recognitions {wrong_total}; outcomes: "
          f"{', '.join(f'{k} {v}' for k, v in sorted(outcomes.items()))}; median wall time to recognition "
          f"{_f(float(np.median(walls)) if walls else None)} s; total {time.perf_counter() - t0:.0f} s")  # fmt: skip
    if args.json:
        atomic_write(args.json, json.dumps(records, indent=1))
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
