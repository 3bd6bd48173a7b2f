"""Record a probe carried out by another finger than the exploring one, for the rerun viewer, headless.

    .venv/bin/python scripts/record_finger_probe.py [--object BOX01P] [--seed 1] [--face 8] [--standoff 40]
                                                    [--length 60] [--out out/finger_probe.rrd]

The object rests on the table at the episode's pose for ``--seed`` (``haptic explore --object NAME --executor
physics --seed S`` places it so). The hand starts as an episode does (it lands on the object and measures a face),
then probes along a line ``--standoff`` mm out from the middle of model face ``--face``, toward it: the planner's
reach test (:func:`haptic.executor.placement.finger_probe`) picks the first finger whose pad it can put at the line's
start pointing along the line, clear of the object, and the executor carries the probe out with that finger. The
hypothesis the reach test is given is the truth (a right recognition's), read here by this script, never by the
executor. Prints what each finger's reach test and the probe did; open the recording with ``rerun OUT.rrd`` (the
``sim_time`` timeline shows the hand turning the finger to the line, closing, stroking, and back).

Seed 1 of BOX01P with face 8 is the side under the object's step, 20 mm in under a 35 mm-high overhang: the index
finger pointing down cannot come to it (its probe along that line is blocked), the thumb turned along the line can.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import build_episode
from haptic.errors import HapticError
from haptic.executor.placement import finger_probe
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import ProbeMove
from haptic.recording import EpisodeRecorder


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--object", default="BOX01P")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--face", type=int, default=8, help="model face to probe (its middle)")
    ap.add_argument("--standoff", type=float, default=40.0, help="line start out from the face [mm]")
    ap.add_argument("--length", type=float, default=60.0, help="line length [mm]")
    ap.add_argument("--out", default="out/finger_probe.rrd")
    args = ap.parse_args(argv)
    try:
        ep = build_episode(EpisodeSpec(model=args.object, seed=args.seed, executor="physics", verify="none"))
        poly, pose = ep.true_model, ep.world_from_model
        if not 0 <= args.face < poly.n_faces:
            raise HapticError(f"--face {args.face}: {args.object} has faces 0 to {poly.n_faces - 1}")
        n = pose.rotate(poly.face_normals[args.face])
        middle = pose.apply(poly.vertices[list(poly.faces[args.face])]).mean(axis=0)
        line = ProbeMove(middle + args.standoff / 1000.0 * n, -n, args.length / 1000.0)
        h = Hypothesis(model=args.object, poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
        recorder = EpisodeRecorder(args.out, name=f"{args.object} seed {args.seed}: a probe by another finger")
        recorder.on_start(poly, pose)
        first = ep.executor.start()
        recorder.on_move(0, first, 0)
        print(f"start: {first.status}")
        move = finger_probe(line, [h])
        if move is None:
            print("no finger reaches the line's start")
            recorder.close(keep=True)
            return 1
        print(f"reach test: {move.finger}, a path of {len(move.path)} configurations")
        res = ep.executor.execute(move)
        if res.ok:
            recorder.on_move(1, res, 0)
        else:
            recorder.on_failed_move(1, res)
        print(f"probe by the {res.info.get('finger', move.finger)}: {res.status} {res.reason}".rstrip())
        for c in res.components:
            err = np.degrees(np.arccos(np.clip(float(c.normal @ n), -1.0, 1.0)))
            print(f"  face component {c.id}: normal {np.round(c.normal, 3).tolist()}, {err:.2f}° from face {args.face}")
        path = recorder.close(keep=True)
        print(f"wrote {path}")
        return 0
    except HapticError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
