"""Benchmark of the interpretation-tree matcher with the geometric executor (not a timed test).

Prints: the median time of one tree update with the full library; the interpretation counts along one walk;
and, per seed object over random poses and random walks, how many data faces and edges it took until the
object was recognised (the seed reports 3–4 faces and 2–3 edges for hand-chosen data, §2.5), and the pose
error at recognition.

    .venv/bin/python scripts/bench_matcher.py [--trials 20] [--seed 0] [--noise 1.0] [--max-moves 150]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from haptic.executor.geometric import GeometricExecutor
from haptic.geometry import SE3, load_library
from haptic.matching.components import SensorNoise
from haptic.matching.library import LibraryArrays
from haptic.matching.pose import pose_error
from haptic.matching.recognition import model_symmetries, recognize
from haptic.matching.tree import InterpretationTree


def episode(model, arrays, rng, noise, max_moves, timings=None, trace=None):
    """Random walk until recognised; returns (status, recognised model, faces, edges, vertices, moves, pose)."""
    truth = SE3.random(rng, 0.2)
    ex = GeometricExecutor(model, truth, noise, rng)
    tree = InterpretationTree(arrays)
    counts = {"face": 0, "edge": 0, "vertex": 0}
    seen: set[int] = set()

    def feed(components):
        for c in components:
            t0 = time.perf_counter()
            n = tree.add(c)
            if timings is not None:
                timings.append(time.perf_counter() - t0)
            if c.id not in seen:
                counts[c.kind] += 1
                seen.add(c.id)
            if trace is not None:
                trace.append((f"{c.kind[0].upper()}{c.id}", n))

    feed(ex.start().components)
    rec = recognize(tree)
    moves = 0
    while rec.status == "exploring" and moves < max_moves:
        options = ex.admissible_moves(rng, n_directions=1)
        res = ex.execute(options[int(rng.integers(len(options)))])
        if res.ok:
            moves += 1
            feed(res.components)
            rec = recognize(tree)
    err = None
    if rec.status == "recognized" and rec.model == model.name:
        err = pose_error(rec.world_from_model, truth, model, model_symmetries(model))
    return rec.status, rec.model, counts["face"], counts["edge"], counts["vertex"], moves, err


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--trials", type=int, default=20, help="random poses and walks per object")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--noise", type=float, default=1.0, help="noise level (multiple of the default σ's)")
    ap.add_argument("--max-moves", type=int, default=150)
    args = ap.parse_args()

    lib = load_library()
    arrays = LibraryArrays.build(lib)
    noise = SensorNoise().scaled(args.noise)
    rng = np.random.default_rng(args.seed)
    n_f, n_e, n_v = (sum(getattr(m, k) for m in lib.values()) for k in ("n_faces", "n_edges", "n_vertices"))
    print(f"library: {len(lib)} models, {n_f} faces, {n_e} edges, {n_v} vertices")

    trace: list[tuple[str, int]] = []
    episode(lib["WEDGE01"], arrays, np.random.default_rng(args.seed), noise, 40, trace=trace)
    print("interpretation counts along a WEDGE01 walk:", " ".join(f"{k}:{n}" for k, n in trace))

    timings: list[float] = []
    print(
        f"\n{'object':<11} {'recognised':>10} {'faces med [min-max]':>20} {'edges med [min-max]':>20} "
        f"{'moves med':>9} {'pose mm (max)':>14} {'pose deg (max)':>15}"
    )
    for name, model in lib.items():
        rows = [episode(model, arrays, rng, noise, args.max_moves, timings) for _ in range(args.trials)]
        ok = [r for r in rows if r[0] == "recognized" and r[1] == name]
        wrong = [r for r in rows if r[0] == "recognized" and r[1] != name]
        faces = np.array([r[2] for r in ok]) if ok else np.zeros(1)
        edges = np.array([r[3] for r in ok]) if ok else np.zeros(1)
        moves = np.array([r[5] for r in ok]) if ok else np.zeros(1)
        errs = np.array([r[6] for r in ok]) if ok else np.zeros((1, 2))
        print(
            f"{name:<11} {len(ok):>4}/{len(rows):<3}{'' if not wrong else f' ({len(wrong)} WRONG)'}  "
            f"{np.median(faces):>6.1f} [{faces.min()}-{faces.max()}]{'':>7} "
            f"{np.median(edges):>6.1f} [{edges.min()}-{edges.max()}]{'':>7} {np.median(moves):>9.1f} "
            f"{np.median(errs[:, 0]) * 1e3:>6.2f} ({errs[:, 0].max() * 1e3:.2f}) "
            f"{np.degrees(np.median(errs[:, 1])):>7.2f} ({np.degrees(errs[:, 1].max()):.2f})"
        )
    t = np.array(timings) * 1e3
    print(
        f"\ntree update with the full library: median {np.median(t):.2f} ms, 90th pct {np.percentile(t, 90):.2f} ms,"
        f" max {t.max():.2f} ms over {len(t)} updates"
    )


if __name__ == "__main__":
    main()
