"""Perception errors of the physics executor per seed object over random poses, and face-move throughput.

    .venv/bin/python scripts/perception_report.py [--poses 5] [--objects BOX01,WEDGE01,...] [--seed 0]

Each run: start, then a face move, an edge move, a vertex move, an edge move and a face move (random choices
through a seeded generator; a failed move is retried with another choice, up to 6 times). The components are
scored against ground truth by ``haptic.executor.evaluate`` (outside the executor).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from haptic.executor.evaluate import score_components
from haptic.executor.physics import PhysicsExecutor
from haptic.geometry import load_library
from haptic.planning.moves import EdgeMove, Move, VertexMove
from haptic.sim import RobotInterface, SensorNoise, Simulation, compose_scene, random_object_pose
from haptic.sim.scene import scene_object_from_polyhedron

SEED_OBJECTS = ("BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R")
PLAN = ("face", "edge", "vertex", "edge", "face")


def explore(poly, seed: int, plan=PLAN, retries: int = 6):
    """One exploration of ``poly`` at a random pose; returns (simulation, executor, results, face-move rates)."""
    obj = scene_object_from_polyhedron(poly)
    pose = random_object_pose(obj, np.random.default_rng(seed))
    sim = Simulation(compose_scene(obj, pose), noise=SensorNoise.from_notes(), seed=seed)
    ex = PhysicsExecutor(RobotInterface(sim), rng=np.random.default_rng(seed))
    rng = np.random.default_rng(seed + 7919)
    results = [ex.start()]
    rates = []
    if not results[0].ok:
        return sim, ex, results, rates
    for kind in plan:
        for attempt in range(retries):
            st = ex.state
            if kind == "face":
                move: Move = ex.admissible_moves(rng, 1)[0]
            elif kind == "edge":
                if st.edge is None:
                    break
                move = EdgeMove(int(rng.choice([-1, 1])))
            else:
                if st.vertex is None:
                    break
                move = VertexMove(st.edge_faces[attempt % 2])
            r = ex.execute(move)
            results.append(r)
            if kind == "face" and r.ok:
                rates.append((r.info["sim_time"], r.info["wall_time"]))
            if r.ok:
                break
    return sim, ex, results, rates


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=5)
    ap.add_argument("--objects", default=",".join(SEED_OBJECTS))
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    lib = load_library()
    all_rates = []
    print(f"{'object':9} {'runs':>4} {'moves ok':>9} {'normal°':>13} {'edge dir°':>13} {'edge pos mm':>13} "
          f"{'vertex mm':>13} {'spur':>4} {'miss':>4} {'concave':>7}")  # fmt: skip
    for name in args.objects.split(","):
        poly = lib[name]
        faces, dirs, epos, verts = [], [], [], []
        spurious = missed = concave = ok_moves = n_moves = 0
        for k in range(args.poses):
            sim, ex, results, rates = explore(poly, args.seed + 1000 * k + 17)
            all_rates.extend(rates)
            gt = sim.ground_truth()
            score = score_components(ex.components, poly, gt.world_from_object, results)
            faces.extend(score.errors("face", "angle"))
            dirs.extend(score.errors("edge", "angle"))
            epos.extend(score.errors("edge", "position"))
            verts.extend(score.errors("vertex", "position"))
            spurious += score.spurious
            missed += score.missed
            concave += score.concave_edges_found
            ok_moves += sum(r.ok for r in results)
            n_moves += len(results)

        def cell(a) -> str:
            return f"{np.median(a):5.2f} ({np.max(a):5.2f})" if len(a) else "      -      "

        print(f"{name:9} {args.poses:4d} {ok_moves:4d}/{n_moves:<4d} {cell(faces):>13} {cell(dirs):>13} "
              f"{cell(epos):>13} {cell(verts):>13} {spurious:4d} {missed:4d} {concave:7d}")  # fmt: skip
    if all_rates:
        sim_t = sum(s for s, _ in all_rates)
        wall_t = sum(w for _, w in all_rates)
        print(f"face move throughput: {sim_t / wall_t:.1f} simulated s per wall s over {len(all_rates)} face moves "
              f"(mean {sim_t / len(all_rates):.2f} s simulated each)")  # fmt: skip
    return 0


if __name__ == "__main__":
    t0 = time.time()
    rc = main()
    print(f"wall time {time.time() - t0:.0f} s")
    raise SystemExit(rc)
