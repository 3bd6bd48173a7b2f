"""Record one episode for the rerun viewer, headless, and list what the recording holds.

    .venv/bin/python scripts/record_episode.py [--object WEDGE01] [--seed 3] [--executor geometric|physics]
                                               [--policy planner] [--out episode.rrd] [--spawn]

Copy and adapt: the recorder is an episode observer, so any loop that calls ``run_episode`` can record. Open the
result with ``rerun episode.rrd`` (the ``move`` timeline steps through the moves; toggle ``world/truth`` to hide
the ground truth). The recording is written only when the episode ends: a crash leaves no file behind.
"""

from __future__ import annotations

import argparse
import sys

from haptic.bench.runner import EpisodeSpec
from haptic.episode import run_episode
from haptic.errors import HapticError
from haptic.recording import EpisodeRecorder, load_recording


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--object", default="WEDGE01")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--executor", choices=("geometric", "physics"), default="geometric")
    ap.add_argument("--policy", default="planner")
    ap.add_argument("--out", default="episode.rrd")
    ap.add_argument("--spawn", action="store_true", help="also open the viewer (where one can start)")
    args = ap.parse_args(argv)

    spec = EpisodeSpec(model=args.object, seed=args.seed, policy=args.policy, executor=args.executor)
    try:
        with EpisodeRecorder(args.out, spawn=args.spawn) as recorder:
            record = run_episode(spec, observer=recorder.observer())
    except HapticError as exc:
        print(f"record_episode: error: {exc}", file=sys.stderr)
        return 1
    print(f"{record.model}: {record.outcome} ({record.recognized}) after {record.moves} moves, "
          f"interpretations {' -> '.join(map(str, record.interpretations))}")  # fmt: skip
    print(f"wrote {args.out}; it holds:")
    for path, ent in load_recording(args.out).items():
        if not path.startswith("__"):
            print(f"  /{path:<28} {ent.rows:>5} rows  {', '.join(sorted(ent.timelines)) or 'static'}")
    print(f"open it with: rerun {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
