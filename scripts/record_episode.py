"""Record one episode for the rerun viewer, headless, and list what the recording holds; or measure what
recording costs.

    .venv/bin/python scripts/record_episode.py [--object WEDGE01] [--seed 3] [--executor geometric|physics]
                                               [--policy planner] [--out episode.rrd] [--spawn]
    .venv/bin/python scripts/record_episode.py --executor physics --seed 1 --overhead 3

Copy and adapt: the recorder is an episode observer, so any loop that calls ``run_episode`` can record. Open the
result with ``rerun episode.rrd``: a physics recording opens on the ``sim_time`` timeline with its eye on the
object and a second view following the fingertip; the ``move`` timeline steps through the moves; toggle
``world/truth`` to hide the ground truth. The recording is written only when the episode ends: a crash leaves
no file behind.

``--overhead N`` runs the same episode N times without and N times with the recorder (alternating, so both
see the same load on the machine) and prints the median wall times, the time recording adds (it includes
closing the file and checking it reads back) and the recording's size.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from dataclasses import fields
from pathlib import Path

from haptic.episode.loop import EpisodeObserver
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.errors import HapticError
from haptic.recording import EpisodeRecorder, load_recording


def _timed(observer: EpisodeObserver, spent: list[float]) -> EpisodeObserver:
    """``observer`` with the time spent in each of its hooks added to ``spent``."""

    def timed(hook):
        if hook is None:
            return None

        def call(*args):
            t0 = time.perf_counter()
            try:
                return hook(*args)
            finally:
                spent.append(time.perf_counter() - t0)

        return call

    return EpisodeObserver(**{f.name: timed(getattr(observer, f.name)) for f in fields(EpisodeObserver)})


def overhead(spec: EpisodeSpec, repeats: int) -> int:
    """Print the wall time of ``spec`` without and with recording (medians of ``repeats`` runs each)."""
    plain, recorded, inside, sizes, outcomes = [], [], [], [], set()
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeats):
            t0 = time.perf_counter()
            a = run_episode(spec)
            plain.append(time.perf_counter() - t0)
            out = Path(tmp) / f"run{k}.rrd"
            t0 = time.perf_counter()
            recorder = EpisodeRecorder(out)
            spent = [time.perf_counter() - t0]
            b = run_episode(spec, observer=_timed(recorder.observer(), spent))
            t1 = time.perf_counter()
            recorder.close()
            spent.append(time.perf_counter() - t1)
            recorded.append(time.perf_counter() - t0)
            inside.append(sum(spent))
            sizes.append(out.stat().st_size / 1e6)
            outcomes.add((a.outcome, a.moves, tuple(a.interpretations)))
            outcomes.add((b.outcome, b.moves, tuple(b.interpretations)))
            print(f"run {k}: without {plain[-1]:.2f} s, with {recorded[-1]:.2f} s (in the recorder "
                  f"{inside[-1]:.3f} s), {sizes[-1]:.2f} MB")  # fmt: skip
    p, r, i = statistics.median(plain), statistics.median(recorded), statistics.median(inside)
    print(f"{spec.model} seed {spec.seed} ({spec.executor}): {a.outcome} after {a.moves} moves"
          + ("" if len(outcomes) == 1 else " (runs differ!)"))  # fmt: skip
    print(f"median wall time without recording {p:.2f} s, with {r:.2f} s: recording adds {r - p:+.2f} s "
          f"({100 * (r - p) / p:+.1f} %); recording {statistics.median(sizes):.2f} MB")
    print(f"time spent in the recorder (opening, its hooks, closing and checking the file): median {i:.3f} s, "
          f"{100 * i / (r - i):.1f} % of the episode's own wall time")
    return 0 if len(outcomes) == 1 else 1


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--object", default="WEDGE01")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--executor", choices=("geometric", "physics"), default="geometric")
    ap.add_argument("--policy", default="planner")
    ap.add_argument("--out", default="episode.rrd")
    ap.add_argument("--spawn", action="store_true", help="also open the viewer (where one can start)")
    ap.add_argument("--overhead", type=int, metavar="N", help="measure: N runs without and N with recording")
    args = ap.parse_args(argv)

    spec = EpisodeSpec(model=args.object, seed=args.seed, policy=args.policy, executor=args.executor)
    try:
        if args.overhead:
            return overhead(spec, args.overhead)
        with EpisodeRecorder(args.out, spawn=args.spawn) as recorder:
            record = run_episode(spec, observer=recorder.observer())
    except HapticError as exc:
        print(f"record_episode: error: {exc}", file=sys.stderr)
        return 1
    print(f"{record.model}: {record.outcome} ({record.recognized}) after {record.moves} moves, "
          f"interpretations {' -> '.join(map(str, record.interpretations))}")  # fmt: skip
    print(f"wrote {args.out} ({Path(args.out).stat().st_size / 1e6:.2f} MB); it holds:")
    for path, ent in load_recording(args.out).items():
        if not path.startswith("__"):
            print(f"  /{path:<40} {ent.rows:>5} rows  {', '.join(sorted(ent.timelines)) or 'static'}")
    print(f"open it with: rerun {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
