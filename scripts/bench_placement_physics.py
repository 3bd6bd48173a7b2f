"""Placements carried out by the simulated hand: every candidate placement the hand's reach test offers, on the seed
library resting on the table, executed and its fingers' faces scored against the truth.

    .venv/bin/python scripts/bench_placement_physics.py [--seeds 1,2,3] [--fingers 2] [--objects A,B]
        [--tip-clearance MM|none] [--hold-clearance MM|none] [--record R.rrd --objects A --seeds S]

Each object rests at the pose of the physics episode of that seed (``EpisodeSpec(model, seed, executor="physics")``);
the benchmark, not the executor, reads it: the true pose is the one hypothesis the planner generates placements from
(``haptic.planning.placements``, as ``scripts/bench_placement_reach.py``), and the hand's reach test
(``haptic.executor.placement.PlacementReach``, the reach solver with that model at that pose) decides which are
offered, with which fingers (``--tip-clearance``: the placement's fingertips' least distance from the table there,
in mm, or ``none`` for the 20 mm of every other link; ``--hold-clearance``: how far within its clearances the path
may come, in mm, or ``none`` for as near as touching). After the episode's start (the landing), every offered
placement is carried out in turn (``PhysicsExecutor.execute``). Prints, per object and seed, the candidates, those
offered, and each placement's outcome, its cost and the hand's way (to the lines, closing, back); then the placements
that succeeded (at least one finger measured a face or free space), each finger's outcome by reason, and the faces
measured within their bounds of the true face (normal and plane). ``--record`` writes a rerun recording of the start
and the placements (one object and seed): each fingertip's contacts in its own colour.
"""

from __future__ import annotations

import argparse
import os
import time
from collections import Counter
from dataclasses import replace

os.environ.setdefault("MUJOCO_GL", "disable")

import numpy as np  # noqa: E402

from haptic.episode.spec import EpisodeSpec  # noqa: E402
from haptic.episode.worlds import build_episode  # noqa: E402
from haptic.executor.placement import (  # noqa: E402
    HOLD_CLEARANCE,
    REACH_CLEARANCE,
    TIP_TABLE_CLEARANCE,
    PlacementReach,
)
from haptic.geometry import load_library  # noqa: E402
from haptic.matching.components import DataFace, SensorNoise  # noqa: E402
from haptic.planning.efficiency import class_weights  # noqa: E402
from haptic.planning.handpath import HandStart  # noqa: E402
from haptic.planning.hypothesis import Hypothesis  # noqa: E402
from haptic.planning.move_scores import probe_config  # noqa: E402
from haptic.planning.placements import PlacementConfig, candidate_placements, placement_path_costs  # noqa: E402
from haptic.planning.probe_lines import candidate_probes  # noqa: E402
from haptic.planning.probe_prediction import predict_probes  # noqa: E402


def offered(ep, fingers: int, reach: PlacementReach):
    """The candidate placements from the true pose (the one hypothesis), and those the reach test offers (each with
    its candidate)."""
    poly, pose, name = ep.true_model, ep.world_from_model, ep.true_model.name
    h = Hypothesis(model=name, poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
    lines = candidate_probes([h], probe_config(ep.config))
    if not lines:
        return [], []
    centre = pose.apply(poly.centroid)
    preds = predict_probes([h], lines, centre, [], SensorNoise(), ep.config.costs)
    cands = candidate_placements(preds, class_weights([name]), fingers, centre, ep.config.costs,
                                 config=PlacementConfig())  # fmt: skip
    moves = [(c, reach(c.move, [h])) for c in cands]
    return cands, [(c, m) for c, m in moves if m is not None]


def hand_start(ex, first) -> HandStart | None:
    """Where the hand's pad is after the start, as the planner knows it (the face it landed on)."""
    face = next((c for c in first.components if isinstance(c, DataFace) and c.id == ex.state.face), None)
    if face is None:
        return None
    return HandStart.at(ex.state.position, face.normal, np.atleast_2d(face.points), ex.toucher.pad_radius)


def within_bounds(face: DataFace, ep) -> bool:
    """Whether a measured face lies within its bounds of some true face: normal within its normal bound and its
    points within its position bound (plus the points' own spread) of that face's plane."""
    poly, pose = ep.true_model, ep.world_from_model
    normals = pose.rotate(poly.face_normals)
    pts = np.atleast_2d(face.points)
    for f in range(poly.n_faces):
        ang = float(np.arccos(np.clip(normals[f] @ face.normal, -1.0, 1.0)))
        if ang > face.normal_bound:
            continue
        p0 = pose.apply(poly.vertices[poly.faces[f][0]])
        if float(np.abs((pts - p0) @ normals[f]).mean()) <= face.position_bound:
            return True
    return False


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1,2,3", help="episode seeds (the objects' resting poses)")
    ap.add_argument("--fingers", type=int, default=2, choices=(2, 4), help="most fingers a placement takes")
    ap.add_argument("--objects", default=None, help="comma-separated model names (default: the seed library)")
    ap.add_argument("--tip-clearance", default=f"{TIP_TABLE_CLEARANCE * 1000:g}", metavar="MM|none",
                    help="the fingertips' least distance from the table in the reach test [mm]")
    ap.add_argument("--hold-clearance", default=f"{HOLD_CLEARANCE * 1000:g}", metavar="MM|none",
                    help="how far within its clearances the reach test's path may come [mm]")
    ap.add_argument("--record", default=None, metavar="R.rrd", help="record the start and the placements here")
    args = ap.parse_args()
    objects = args.objects.split(",") if args.objects else sorted(load_library())
    seeds = [int(s) for s in args.seeds.split(",")]
    mm = {}
    for name in ("tip_clearance", "hold_clearance"):
        value = getattr(args, name)
        try:
            mm[name] = None if value == "none" else float(value) / 1000.0
        except ValueError:
            ap.error(f"--{name.replace('_', '-')} {value!r}: give millimetres (such as 8) or none")
    reach = PlacementReach(replace(REACH_CLEARANCE, tip_table_clearance=mm["tip_clearance"],
                                   hold_clearance=mm["hold_clearance"]))  # fmt: skip
    outcomes: Counter = Counter()
    fingers: Counter = Counter()
    faces = [0, 0]  # within bounds, measured
    walls: list[float] = []
    costs: list[tuple[float, float]] = []  # predicted (along the reach test's way), as carried out
    n_cands = n_offered = 0
    recorder = None
    for name in objects:
        for seed in seeds:
            ep = build_episode(EpisodeSpec(model=name, seed=seed, executor="physics", verify="none",
                                           fingers=args.fingers))  # fmt: skip
            cands, moves = offered(ep, args.fingers, reach)
            n_cands += len(cands)
            n_offered += len(moves)
            print(f"{name:<12} {seed:>2}: {len(cands):>2} candidates, {len(moves)} offered", flush=True)
            if not moves:
                continue
            if args.record and recorder is None:
                from haptic.recording import EpisodeRecorder

                recorder = EpisodeRecorder(args.record)
                recorder.on_start(ep.true_model, ep.world_from_model)
            ex = ep.executor
            first = ex.start()
            if recorder is not None:
                recorder.on_move(0, first, 0)
            if not first.ok:
                print(f"    start failed: {first.reason}")
                continue
            hand = hand_start(ex, first)
            for i, (cand, m) in enumerate(moves, start=1):
                predicted = float(placement_path_costs(cand.lines, m, ex.state.position, ep.config.costs, hand)[0])
                t0 = time.perf_counter()
                res = ex.execute(m)
                walls.append(time.perf_counter() - t0)
                outcomes[str(res.status)] += 1
                told = []
                for info in res.info.get("fingers", ()):
                    fingers[(info["status"], info.get("reason", ""))] += 1
                    told.append(f"{info['finger']} {info['status']}" + (f" ({info['reason']})" if info.get("reason")
                                                                         else ""))  # fmt: skip
                for c in res.components:
                    faces[1] += 1
                    faces[0] += within_bounds(c, ep)
                print(f"    placement {i}: {res.status}{': ' + res.reason if res.reason else ''}; {', '.join(told)}; "
                      f"cost {res.cost:.1f} (predicted {predicted:.1f}; way {res.info.get('travel')}), "
                      f"{walls[-1]:.1f} s", flush=True)  # fmt: skip
                if res.ok:
                    costs.append((predicted, float(res.cost)))
                if recorder is not None:
                    (recorder.on_move(i, res, 0) if res.ok else recorder.on_failed_move(i, res))
            if recorder is not None:
                recorder.close(keep=True)
                print(f"wrote {args.record}")
                return
    print(f"\ncandidates {n_cands}, offered {n_offered} (the reach test: asked {reach.asked}, reached {reach.reached}; "
          f"why not: {dict(reach.reasons)})")  # fmt: skip
    total = sum(outcomes.values())
    print(f"placements carried out {total}: " + ", ".join(f"{k} {v}" for k, v in outcomes.most_common())
          + (f"; median wall time {np.median(walls):.1f} s" if walls else ""))
    print("fingers:")
    for (status, why), n in fingers.most_common():
        print(f"  {n:>4}  {status}" + (f": {why}" if why else ""))
    print(f"faces measured {faces[1]}, within their bounds of a true face {faces[0]}")
    if costs:
        pred, act = np.array(costs).T
        print(f"cost of the placements that succeeded: median {np.median(act):.1f} (range {act.min():.1f}–"
              f"{act.max():.1f}); predicted along the reach test's way median {np.median(pred):.1f}, actual − "
              f"predicted median {np.median(act - pred):+.1f} (range {np.min(act - pred):+.1f}…"
              f"{np.max(act - pred):+.1f})")  # fmt: skip


if __name__ == "__main__":
    main()
