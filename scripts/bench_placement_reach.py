"""How many of the planner's candidate placements the simulated hand could take up: the reach solver asked for
every finger's pad at its line's start, on the seed library resting on the table.

    .venv/bin/python scripts/bench_placement_reach.py [--seed 1] [--fingers 2]

Each seed object rests on the table at a pose drawn as the physics episodes draw theirs (``random_object_pose``,
from ``--seed``); its true pose is the one hypothesis the planner generates placements from
(``haptic.planning.placements``, over the lines of the simulated hand: the table, the pad, the faces the pad can
press on). For each candidate the reach solver (``haptic.sim.reach``, on the robot and table alone) is asked for
each finger's pad centre at its line's start, each finger pointing along its line within 10°, 30° or 60°, or
pointing anywhere, trying every assignment of the hand's fingers to the lines. Prints per setting how many
candidates it reaches and why not (the last assignment's reason).
"""

from __future__ import annotations

import argparse
import os
from collections import Counter
from itertools import permutations

os.environ.setdefault("MUJOCO_GL", "disable")

import numpy as np  # noqa: E402

from haptic.executor.touch_config import TouchConfig  # noqa: E402
from haptic.geometry import SE3, load_library  # noqa: E402
from haptic.matching.components import SensorNoise  # noqa: E402
from haptic.planning.config import PlannerConfig  # noqa: E402
from haptic.planning.efficiency import class_weights  # noqa: E402
from haptic.planning.hypothesis import Hypothesis  # noqa: E402
from haptic.planning.move_scores import probe_config  # noqa: E402
from haptic.planning.placements import HAND_MAX_TILT, PlacementConfig, candidate_placements  # noqa: E402
from haptic.planning.probe_lines import candidate_probes  # noqa: E402
from haptic.planning.probe_prediction import predict_probes  # noqa: E402
from haptic.sim import compose_scene, random_object_pose  # noqa: E402
from haptic.sim.reach import FingertipTarget, ReachSettings, ReachSolver  # noqa: E402
from haptic.sim.scene import FINGERS, PAD_RADIUS, scene_object_from_polyhedron  # noqa: E402

TOLERANCES = (10.0, 30.0, 60.0, None)
"""The pointing tolerances asked for [deg] (None: the finger may point anywhere)."""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1, help="seed of the objects' poses")
    ap.add_argument("--fingers", type=int, default=2, choices=(2, 4), help="most fingers a placement takes")
    ap.add_argument("--any-line", action="store_true",
                    help="placements over every line of the hand's probes, not only those within HAND_MAX_TILT of "
                    "straight down")
    args = ap.parse_args()
    scene = compose_scene(None)
    solvers = {tol: ReachSolver(scene, ReachSettings(approach_tol=np.deg2rad(tol if tol is not None else 180.0)))
               for tol in TOLERANCES}  # fmt: skip
    ws = scene.workspace
    config = PlannerConfig(table_z=ws.table_top_z, pad_radius=ws.pad_radius, max_undercut=TouchConfig().max_undercut,
                           fingers=args.fingers)  # fmt: skip
    reached = Counter()
    reasons: dict[object, Counter] = {tol: Counter() for tol in TOLERANCES}
    total = 0
    for name, poly in load_library().items():
        obj = scene_object_from_polyhedron(poly)
        pose = random_object_pose(obj, np.random.default_rng(args.seed))
        world_from_model = SE3.from_matrix(pose)
        h = Hypothesis(model=name, poly=poly, world_from_model=world_from_model, faces={}, edges={}, vertices={})
        lines = candidate_probes([h], probe_config(config))
        if not lines:
            continue
        preds = predict_probes([h], lines, world_from_model.apply(poly.centroid), [], SensorNoise(), config.costs)
        weights = class_weights([name])
        cands = candidate_placements(preds, weights, args.fingers, world_from_model.apply(poly.centroid),
                                     config.costs, config=PlacementConfig(max_tilt=None if args.any_line
                                                                          else HAND_MAX_TILT))  # fmt: skip
        n_here = Counter()
        for c in cands:
            total += 1
            for tol in TOLERANCES:
                r = None
                for names in permutations(FINGERS, len(c.move.fingers)):  # any finger for any line
                    targets = [FingertipTarget(name, np.asarray(f.start) - PAD_RADIUS * np.asarray(f.direction),
                                               None if tol is None else np.asarray(f.direction))
                               for name, f in zip(names, c.move.fingers, strict=True)]  # fmt: skip
                    r = solvers[tol].solve(targets)
                    if r.ok:
                        break
                reached[tol] += r.ok
                n_here[tol] += r.ok
                if not r.ok:
                    reasons[tol][str(r.reason)] += 1
        print(f"{name:<12} {len(cands):>3} candidates; reached " +
              ", ".join(f"{'any' if t is None else f'{t:.0f}°'}: {n_here[t]}" for t in TOLERANCES))
    print(f"\n| finger pointing along its line | reached of {total} | why not |\n|---|---|---|")
    for tol in TOLERANCES:
        why = ", ".join(f"{k}: {v}" for k, v in reasons[tol].most_common()) or "-"
        print(f"| {'anywhere' if tol is None else f'within {tol:.0f}°'} | {reached[tol]} | {why} |")


if __name__ == "__main__":
    main()
