"""Resting probes on the simulated hand: another finger probing while the exploring pad rests, taken whenever the
planner offers one.

    .venv/bin/python scripts/bench_resting.py [--objects BOX01P,LBLOCK01] [--seeds 1,2,3] [--verify none]
                                              [--record R.rrd]

Each seed-library episode (physics, ``--fingers 4``) is run with the planner, except that at every decision where the
planner offers a resting probe (its lines the resting hand's reach test reached) that probe is taken, whether or not
it is the most efficient candidate: what the hand does with the resting probes the planner can offer, which in the
episodes it rarely ranks first. Per episode: the decisions that asked for resting lines, the lines within the
fingers' reach, those asked about and reached; per resting probe taken, the finger, how it ended and whether the face
it measured lies within its bounds of a true face (evaluation: the true pose is read here, never by the executor or
the planner). ``--record`` writes a rerun recording of the first episode that takes one.
"""

from __future__ import annotations

import argparse
import os
from collections import Counter

os.environ.setdefault("MUJOCO_GL", "disable")

import numpy as np  # noqa: E402

from haptic.episode.loop import EpisodeObserver, chain_observers  # noqa: E402
from haptic.episode.spec import EpisodeSpec  # noqa: E402
from haptic.episode.worlds import build_episode  # noqa: E402
from haptic.matching.components import DataFace  # noqa: E402
from haptic.planning.move_scores import Decision  # noqa: E402
from haptic.planning.registry import make_policy  # noqa: E402

SEED_OBJECTS = ("BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R", "HEXPRISM01", "LBLOCK01",
                "FRAME01")


class TakeResting:
    """The planner, but a resting probe it offers is taken."""

    def __init__(self, policy) -> None:
        self.policy, self.name = policy, policy.name
        self.offered: list[str] = []
        """Per resting probe offered: its efficiency, expected eliminations and cost against the planner's choice's."""

    def choose(self, ctx, rng):
        decision = self.policy.choose(ctx, rng)
        resting = [c for c in decision.candidates if getattr(c.move, "resting", False)]
        if not resting:
            return decision
        r = resting[0]
        best = next((c for c in decision.candidates if c.move is decision.move), None)
        mine = f"{r.score:.2f} classes/unit ({r.expected_eliminated:.2f} for {r.expected_cost:.2f})"
        theirs = "" if best is None else (f" against the planner's {best.move.kind} {best.score:.2f} "
                                          f"({best.expected_eliminated:.2f} for {best.expected_cost:.2f})")  # fmt: skip
        self.offered.append(f"offered: {mine}{theirs}")
        return Decision(r.move, decision.candidates)


def within_bounds(face: DataFace, ep) -> bool:
    """Whether a measured face lies within its bounds of some true face (its normal within its normal bound, its
    points within its position bound of that face's plane)."""
    poly, pose = ep.true_model, ep.world_from_model
    normals = pose.rotate(poly.face_normals)
    pts = np.atleast_2d(face.points)
    for f in range(poly.n_faces):
        if float(np.arccos(np.clip(normals[f] @ face.normal, -1.0, 1.0))) > face.normal_bound:
            continue
        p0 = pose.apply(poly.vertices[poly.faces[f][0]])
        if float(np.abs((pts - p0) @ normals[f]).mean()) <= face.position_bound:
            return True
    return False


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--objects", default=",".join(SEED_OBJECTS))
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--verify", default="none", choices=("none", "fast", "full"))
    ap.add_argument("--record", default=None, metavar="R.rrd")
    args = ap.parse_args()
    totals: Counter = Counter()
    outcomes: Counter = Counter()
    recorded = False
    for name in args.objects.split(","):
        for seed in (int(s) for s in args.seeds.split(",")):
            ep = build_episode(EpisodeSpec(model=name, seed=seed, executor="physics", verify=args.verify, fingers=4))
            taken: list = []

            def keep(n, result, *rest, taken=taken) -> None:
                if getattr(result.move, "resting", False):
                    taken.append(result)

            observer = EpisodeObserver(on_move=keep, on_failed_move=keep)
            recorder = None
            if args.record and not recorded:
                from haptic.recording import EpisodeRecorder

                recorder = EpisodeRecorder(args.record)
                observer = chain_observers(observer, recorder.observer())
            policy = TakeResting(make_policy("planner"))
            rec = ep.run(policy, observer)
            rows = list(policy.offered)
            if recorder is not None:
                recorded = bool(taken)
                recorder.close(keep=recorded)
            r = rec.resting_reach or {}
            for k in ("decisions", "lines", "asked", "reached"):
                totals[k] += r.get(k, 0)
            totals["episodes"] += 1
            totals["correct"] += rec.outcome == "recognized" and rec.correct
            for res in taken:
                totals["taken"] += 1
                status = res.info.get("finger_status") if res.ok else str(res.status)
                outcomes[status] += 1
                faces = [c for c in res.components if isinstance(c, DataFace)]
                inside = sum(within_bounds(c, ep) for c in faces)
                totals["faces"] += len(faces)
                totals["within"] += inside
                totals["ok"] += res.ok
                rows.append(f"{res.move.finger} {status}" + (f" ({res.reason})" if res.reason else "")
                            + (f", face within bounds {inside}/{len(faces)}" if faces else "")
                            + f", cost {res.cost:.2f}")  # fmt: skip
            print(f"{name:<11}{seed:>2} {rec.outcome:<11} moves {rec.moves:>2} cost {rec.path_cost:6.2f}; lines: "
                  f"{r.get('decisions', 0)} decisions, {r.get('lines', 0)} lines, {r.get('asked', 0)} asked, "
                  f"{r.get('reached', 0)} reached; taken {len(taken)}" + ("".join(f"\n    {x}" for x in rows)),
                  flush=True)  # fmt: skip
    t = totals
    print(f"\n{t['episodes']} episodes, {t['correct']} correct; resting lines: {t['decisions']} decisions asked, "
          f"{t['lines']} lines within the fingers' reach ({t['lines'] / max(1, t['decisions']):.1f} a decision), "
          f"{t['asked']} asked about, {t['reached']} reached; resting probes taken {t['taken']}, succeeded {t['ok']}, "
          f"faces measured {t['faces']}, within their bounds {t['within']}")  # fmt: skip
    for k, v in outcomes.most_common():
        print(f"  {v:>4}  {k}")


if __name__ == "__main__":
    main()
