"""Perception errors of the physics executor per seed object over random poses, move success, matcher
acceptance, and face-move throughput.

    .venv/bin/python scripts/perception_report.py [--poses 5] [--objects BOX01,WEDGE01,...] [--seed 0]

Each run: start, then the fixed sequence face, edge, vertex, edge, face, edge, vertex (random choices through
a seeded generator; a failed move is retried with another choice, up to 4 times; an edge move in the sense of
a vertex already reached is not asked). On objects with concave edges a *concave probe* follows: face moves
whose directions are chosen with the ground truth (an oracle standing in for the planner -- the executor is
as blind as ever) towards the nearest concave edge of the current face -- or, from a face without one, towards
the middle of the edge to a face that has one --, until one is reported or 6 moves are spent.

The components are scored against ground truth by ``haptic.episode.evaluate`` (outside the executor); every
component of every run is also fed, unchanged, to the interpretation-tree matcher, and the run counts as
accepted when the true model survives every one of them.

Move counts: ``ok/asked``; ``table`` counts failures because the move needed the part of the object next to
the table (an edge on the table, the finger meeting the table, a vertex circle that would put the pad on the
table), which the pad cannot touch; a vertex move across a face that failed so is not asked again from the
same state. The totals also give the success rate of the moves that did not fail for the table.
"""

from __future__ import annotations

import argparse
import time
from collections import Counter

import numpy as np

from haptic.episode.evaluate import score_components, score_face
from haptic.executor.physics import PhysicsExecutor
from haptic.geometry import SE3, load_library
from haptic.matching.tree import InterpretationTree
from haptic.planning.moves import EdgeMove, FaceMove, Move, VertexMove
from haptic.sim import RobotInterface, SimulatedSensorNoise, Simulation, compose_scene, random_object_pose
from haptic.sim.scene import scene_object_from_polyhedron

SEED_OBJECTS = ("BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R")
PLAN = ("face", "edge", "vertex", "edge", "face", "edge", "vertex")


def _edge_sense(ex: PhysicsExecutor, rng: np.random.Generator) -> int | None:
    """A random edge-move sense that does not start at a vertex already reached in that sense."""
    st = ex.state
    senses = [1, -1] if rng.random() < 0.5 else [-1, 1]
    rec = ex.segmenter.edges[st.edge]
    if st.vertex is not None and st.vertex in rec.vertices:
        lo, hi = rec.interval
        s_v = rec.vertices[st.vertex]
        senses = [s for s in senses if not ((s > 0 and s_v >= hi - 1e-9) or (s < 0 and s_v <= lo + 1e-9))]
    return senses[0] if senses else None


def _is_table(r) -> bool:
    return "table" in r.reason


def explore(poly, seed: int, plan=PLAN, retries: int = 4):
    """One exploration of ``poly`` at a random pose; returns (simulation, executor, results)."""
    obj = scene_object_from_polyhedron(poly)
    pose = random_object_pose(obj, np.random.default_rng(seed))
    sim = Simulation(compose_scene(obj, pose), noise=SimulatedSensorNoise.from_notes(), seed=seed)
    ex = PhysicsExecutor(RobotInterface(sim), rng=np.random.default_rng(seed))
    rng = np.random.default_rng(seed + 7919)
    results = [ex.start()]
    if not results[0].ok:
        return sim, ex, results
    for kind in plan:
        table_faces: set[int] = set()  # faces a vertex move from this state cannot circle (the table)
        for attempt in range(retries):
            st = ex.state
            if kind == "face":
                move: Move = ex.admissible_moves(rng, 1)[0]
            elif kind == "edge":
                sense = _edge_sense(ex, rng) if st.edge is not None else None
                if sense is None:
                    break
                move = EdgeMove(sense)
            else:
                faces = [f for f in st.edge_faces if f not in table_faces] if st.vertex is not None else []
                if not faces:
                    break
                move = VertexMove(faces[(attempt + int(rng.integers(2))) % len(faces)])
            r = ex.execute(move)
            results.append(r)
            if r.ok:
                break
            if kind == "vertex" and _is_table(r):
                table_faces.add(move.across_face)
    return sim, ex, results


def concave_probe(sim: Simulation, ex: PhysicsExecutor, poly, results: list, max_moves: int = 6) -> None:
    """Face moves towards the nearest concave edge, directions from the ground truth (an oracle planner)."""
    gt = sim.ground_truth().world_from_object
    rot, trans = gt[:3, :3], gt[:3, 3]
    concave = np.flatnonzero(poly.edge_convexity < 0)
    if not len(concave) or ex.state is None:
        return
    a_w = poly.vertices[poly.edges[concave, 0]] @ rot.T + trans
    b_w = poly.vertices[poly.edges[concave, 1]] @ rot.T + trans
    for _ in range(max_moves):
        st = ex.state
        face = ex.segmenter.faces[st.face].component
        x = st.position
        ab = b_w - a_w
        s = np.clip(np.einsum("ij,ij->i", x - a_w, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
        near = a_w + s[:, None] * ab
        # aim at the nearest concave edge of the current face (true face by the evaluator); on a face without
        # one, at the middle of its nearest edge towards a face that has one (crossing there), else at the
        # nearest concave edge
        true_face = score_face(face, poly, rot, trans, _tol()).true_id
        own = [i for i, e in enumerate(concave) if true_face in poly.edge_faces(int(e))]
        bordering = {f for e in concave for f in poly.edge_faces(int(e))}
        edges_here = poly.face_edges[true_face] if true_face is not None else ()
        gates = [int(e) for e in edges_here if set(poly.edge_faces(int(e))) & bordering]
        if own or not gates:
            pick = own if own else list(range(len(concave)))
            k = min(pick, key=lambda i: float(np.linalg.norm(near[i] - x)))
            target = near[k]
        else:
            mids = [0.5 * (poly.vertices[poly.edges[e, 0]] + poly.vertices[poly.edges[e, 1]]) @ rot.T + trans
                    for e in gates]  # fmt: skip
            target = min(mids, key=lambda m: float(np.linalg.norm(m - x)))
        d = target - x
        d = d - (d @ face.normal) * face.normal
        if np.linalg.norm(d) < 1e-4:
            break
        r = ex.execute(FaceMove(d / np.linalg.norm(d)))
        r.info["probe"] = True
        results.append(r)
        if r.ok and r.info.get("kind") == "concave":
            break
        if not r.ok and len(results) > 1 and not results[-2].ok and results[-2].info.get("probe"):
            break  # the same failure twice: the oracle direction does not work from here


def _tol():
    from haptic.episode.evaluate import EvaluationTolerances

    return EvaluationTolerances()


def matcher_accepts(poly, components, library) -> tuple[bool, str]:
    """Feed every component to a fresh interpretation tree; the true model must survive each one."""
    tree = InterpretationTree(library)
    for c in components:
        tree.add(c)
        if poly.name not in tree.models_alive():
            return False, f"{poly.name} pruned at {c.kind} {c.id}"
    return True, ""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=5)
    ap.add_argument("--objects", default=",".join(SEED_OBJECTS))
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    lib = load_library()
    all_rates = []
    totals: Counter = Counter()
    print(f"{'object':9} {'face ok':>8} {'edge ok':>8} {'vtx ok':>8} {'table':>5} {'normal°':>13} {'edge dir°':>13} "
          f"{'edge pos mm':>13} {'vertex mm':>13} {'spur':>4} {'miss':>4} {'concave':>7} {'matcher':>7}")  # fmt: skip
    for name in args.objects.split(","):
        poly = lib[name]
        faces, dirs, epos, verts = [], [], [], []
        c: Counter = Counter()
        for k in range(args.poses):
            sim, ex, results = explore(poly, args.seed + 1000 * k + 17)
            if (poly.edge_convexity < 0).any():
                concave_probe(sim, ex, poly, results)
            for r in results[1:]:
                if r.status == "invalid":
                    continue
                if r.move.kind == "face" and r.ok:
                    all_rates.append((r.sim_time, r.wall_time))
                c[f"{r.move.kind}_asked"] += 1
                c[f"{r.move.kind}_ok"] += r.ok
                c["table"] += (not r.ok) and _is_table(r)
                c[f"{r.move.kind}_table"] += (not r.ok) and _is_table(r)
            c["start_ok"] += results[0].ok
            gt = sim.ground_truth()
            score = score_components(ex.components, poly, SE3.from_matrix(gt.world_from_object), results)
            faces.extend(score.errors("face", "angle"))
            dirs.extend(score.errors("edge", "angle"))
            epos.extend(score.errors("edge", "position"))
            verts.extend(score.errors("vertex", "position"))
            c["spurious"] += score.spurious
            c["missed"] += score.missed
            c["concave"] += score.concave_edges_found
            ok, why = matcher_accepts(poly, ex.components, lib)
            c["accepted"] += ok
            if not ok:
                print(f"  matcher: {why} (pose {k})")
        totals.update(c)

        def cell(a) -> str:
            return f"{np.median(a):5.2f} ({np.max(a):5.2f})" if len(a) else "      -      "

        def ratio(kind: str, c: Counter = c) -> str:
            return f"{c[kind + '_ok']}/{c[kind + '_asked']}"

        print(f"{name:9} {ratio('face'):>8} {ratio('edge'):>8} {ratio('vertex'):>8} {c['table']:5d} {cell(faces):>13} "
              f"{cell(dirs):>13} {cell(epos):>13} {cell(verts):>13} {c['spurious']:4d} {c['missed']:4d} "
              f"{c['concave']:7d} {c['accepted']:3d}/{args.poses:<3d}")  # fmt: skip
    for kind in ("face", "edge", "vertex"):
        asked, ok, tab = totals[kind + "_asked"], totals[kind + "_ok"], totals[kind + "_table"]
        feasible = asked - tab
        print(f"{kind} moves: {ok}/{asked} ok ({100 * ok / max(asked, 1):.0f} %; {100 * ok / max(feasible, 1):.0f} % "
              f"of the {feasible} not failing for the table)", end="; ")
    print(f"failures needing the table side: {totals['table']}")
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
