"""Objects outside the library: perturbed variants of every library model, explored against the library.

Each model of the library gets these variants (:mod:`haptic.geometry.perturb`): one dimension (a model axis,
drawn per model) scaled by 0.97, 1.03, 1.05 and 1.10; one vertex (drawn per model) moved 2, 4 and 8 mm along its
outward normal; one convex edge (the longest that allows it) chamfered with 4 mm legs; a variant congruent to
a library model (a box made exactly as tall as another) is left out, and on the hand one the simulated scene cannot
hold (a convex piece thinner than it takes), each said on stderr. Each variant is written
as a model file and explored as ``--object FILE`` against the library: the right outcome is ``no-match``; a
``recognized`` outcome is a false recognition -- on the hand, unless the variant differs from the model it was
recognised as only within the band next to the table where the verification says it measured nothing (its
``table_band_mm``: a chamfer of an edge on the table, below the pad's reach), or only at vertices it took on trust in
the table's shadow and within its ``table_shadow_mm`` (``shadow_claim``), counted apart (``within_claim``, with the
highest point of the difference, ``difference_top_mm``). The table gives them by perturbation and size,
per verification mode; with ``--baseline N`` it also runs N library objects (the policy's usual episodes) per mode
and reports the mean path cost of each mode over that without verification. ``--policy`` sets every episode's
policy (default: the default policy).

    .venv/bin/python scripts/bench_unknown.py --verify none,fast,full --episodes 2 --workers 2
    .venv/bin/python scripts/bench_unknown.py --models assets/libraries/lookalike --episodes 1 --verify full \
        --baseline 100 --baseline-verify none,full
    .venv/bin/python scripts/bench_unknown.py --executor physics --episodes 1 --models-only BOX01,WEDGE01

Results (one JSON line per episode) go to ``OUT/<library>_<executor>.jsonl``, the table to the same name with
``.md``. Wall times are measured on whatever else runs on the machine.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from haptic.bench.runner import plan_sweep, run_sweep
from haptic.episode.spec import DEFAULT_POLICY, EpisodeSpec
from haptic.errors import HapticError, ModelError, SceneError
from haptic.geometry import Polyhedron, are_congruent, load_library, save_model
from haptic.geometry.io import atomic_write
from haptic.geometry.perturb import chamfer_edge, move_vertex, scale_dimension
from haptic.planning.moves import MOVE_SETS, CostModel, default_moves
from haptic.planning.registry import POLICY_NAMES
from haptic.sim.scene import scene_object_from_polyhedron

SCALES = (0.97, 1.03, 1.05, 1.10)
VERTEX_MM = (2.0, 4.0, 8.0)
CHAMFER_MM = 4.0


def variants(poly: Polyhedron, rng: np.random.Generator) -> list[tuple[str, str, Polyhedron]]:
    """``(kind, size label, variant)`` for one model (a variant the model cannot take is left out, said on
    stderr)."""
    out = []
    axis = int(rng.integers(3))
    for f in SCALES:
        out.append(("dimension", f"x{f:.2f}", scale_dimension(poly, axis, f, name=f"{poly.name}__dim{axis}_{f:.2f}")))
    for vertex in rng.permutation(poly.n_vertices):  # the first vertex that all three moves leave valid
        try:
            moved = [move_vertex(poly, int(vertex), mm * 1e-3, name=f"{poly.name}__v{vertex}_{mm:g}mm")
                     for mm in VERTEX_MM]  # fmt: skip
        except ModelError as exc:
            print(f"vertex {vertex} not moved: {exc}", file=sys.stderr)
            continue
        out.extend(("vertex", f"{mm:g} mm", m) for mm, m in zip(VERTEX_MM, moved, strict=True))
        break
    for e in np.argsort(-poly.edge_lengths):
        if poly.edge_convexity[e] <= 0:
            continue
        try:
            out.append(("chamfer", f"{CHAMFER_MM:g} mm",
                        chamfer_edge(poly, int(e), CHAMFER_MM * 1e-3, name=f"{poly.name}__ch{int(e)}")))  # fmt: skip
            break
        except ModelError:
            continue
    return out


def unsimulated(poly: Polyhedron) -> str | None:
    """Why the simulated scene cannot hold ``poly`` (as the physics world builds it: :func:`~haptic.sim.scene.
    scene_object_from_polyhedron`, convex pieces for a non-convex one), or None when it can. A variant
    may decompose into a piece too thin for the simulator (FRAME01 with a vertex moved 2 mm: a sliver of 0.1 mm^3);
    it is left out of a run on the hand, said on stderr, rather than ending the run."""
    try:
        scene_object_from_polyhedron(poly)
    except SceneError as exc:
        return str(exc)
    return None


def difference_top(variant: Polyhedron, base: Polyhedron, pose: dict, table_z: float, spacing: float = 1e-3,
                   tol: float = 3e-4) -> float | None:  # fmt: skip
    """How high above the table (``table_z``) the highest point lies where ``variant`` and ``base`` (one model
    frame) differ, at the variant's resting ``pose`` (a record's ``pose``): points of either surface farther than
    ``tol`` from the other's [m]; None where they do not differ."""
    from haptic.geometry.distance import surface_distance, surface_grid
    from haptic.geometry.se3 import quat_to_matrix

    rot = quat_to_matrix(np.asarray(pose["quat_wxyz"], dtype=float))
    t = np.asarray(pose["translation_m"], dtype=float)
    tops = []
    for a, b in ((variant, base), (base, variant)):
        p = surface_grid(a, spacing)
        off = p[surface_distance(b, p) > tol]
        if len(off):
            tops.append(float((off @ rot.T + t)[:, 2].max()) - table_z)
    return max(tops) if tops else None


def moved_vertices(variant: Polyhedron, base: Polyhedron, tol: float = 1e-6) -> frozenset[int]:
    """The vertices of ``base`` that ``variant`` (one model frame) does not keep where they are: a moved vertex, a
    chamfered edge's two ends."""
    d = np.linalg.norm(np.asarray(base.vertices)[:, None, :] - np.asarray(variant.vertices)[None, :, :], axis=2)
    return frozenset(int(i) for i in np.flatnonzero(d.min(axis=1) > tol))


SAME_PLACE = 3e-3
"""A vertex the variant moves is one the verification took on trust when it lies this near one of them, the variant
at its pose and the model at the fitted one [m] (the fitted pose is off by about 1 mm; a symmetric model's fitted
interpretation numbers its vertices otherwise)."""


def _at_shadowed(rec: dict, base: Polyhedron, moved: frozenset[int]) -> bool:
    """Whether every vertex of ``base`` in ``moved``, at the record's pose, lies where the verification took a vertex
    on trust in the table's shadow (``verified.shadowed_at_mm``, world, at the fitted pose)."""
    from haptic.geometry.se3 import quat_to_matrix

    at = np.asarray((rec.get("verified") or {}).get("shadowed_at_mm") or [], dtype=float).reshape(-1, 3) / 1000.0
    if not moved or not len(at):
        return False
    rot = quat_to_matrix(np.asarray(rec["pose"]["quat_wxyz"], dtype=float))
    p = np.asarray(base.vertices)[sorted(moved)] @ rot.T + np.asarray(rec["pose"]["translation_m"], dtype=float)
    return bool(np.all(np.linalg.norm(p[:, None, :] - at[None, :, :], axis=2).min(axis=1) <= SAME_PLACE))


def within_claim(rec: dict, variant: Polyhedron, base: Polyhedron, table_z: float) -> bool:
    """Whether a variant recognised as its base model differs from it only where the verification says it measured
    nothing: within its ``table_band_mm`` of the table (the hand's pad cannot touch lower on the faces rising from
    the table), or at the vertices it took on trust in the table's shadow (every vertex the variant moves lies
    where one of them does, ``verified.shadowed_at_mm``) within its ``table_shadow_mm``. Any other recognition of a
    variant is false. Sets ``shadow_claim`` when the claim relied on was the shadow's rather than the band's."""
    v = rec.get("verified") or {}
    band, shadow = v.get("table_band_mm") or 0.0, v.get("table_shadow_mm") or 0.0
    if rec["outcome"] != "recognized" or rec["recognized"] != base.name or not (band or shadow):
        return False
    top = difference_top(variant, base, rec["pose"], table_z)
    rec["difference_top_mm"] = None if top is None else round(top * 1000.0, 2)
    if top is None:
        return False
    if top * 1000.0 <= band:
        return True
    rec["shadow_claim"] = bool(top * 1000.0 <= shadow and _at_shadowed(rec, base, moved_vertices(variant, base)))
    return rec["shadow_claim"]


def _same_shape(a: Polyhedron, b: Polyhedron) -> bool:
    """Whether two models are congruent (the variant is in the library after all)."""
    if (a.n_vertices, a.n_edges, a.n_faces) != (b.n_vertices, b.n_edges, b.n_faces):
        return False
    return are_congruent(a, b)


def table(records: list[dict]) -> str:
    """Markdown: per (verify mode, perturbation, size): episodes, false recognitions, no-match, ambiguous,
    budget, failed, mean path cost."""
    groups: dict[tuple, list[dict]] = defaultdict(list)
    for r in records:
        groups[(r["verify"], r["perturbation"], r["size"])].append(r)
    order = {k: i for i, k in enumerate(["dimension", "vertex", "chamfer", "library"])}
    lines = ["| verify | perturbation | size | episodes | false recognitions | recognised, differing only within the "
             "table band | ... only within the table's shadow | no-match | ambiguous | budget | failed | mean path "
             "cost |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for (v, kind, size), rs in sorted(groups.items(), key=lambda kv: (kv[0][0], order.get(kv[0][1], 9), kv[0][2])):
        n = len(rs)

        def count(o: str, rs=rs) -> int:
            return sum(r["outcome"] == o for r in rs)

        cost = float(np.mean([r["path_cost"] for r in rs]))
        claimed = sum(bool(r.get("within_claim")) for r in rs)
        shadow = sum(bool(r.get("within_claim")) and bool(r.get("shadow_claim")) for r in rs)
        false = count("recognized") - claimed if kind != "library" else sum(
            r["outcome"] == "recognized" and not r["correct"] for r in rs)  # fmt: skip
        lines.append(f"| {v} | {kind} | {size} | {n} | {false} | {claimed - shadow} | {shadow} | {count('no-match')} | "
                     f"{count('ambiguous')} | {count('budget')} | {count('failed')} | {cost:.1f} |")  # fmt: skip
    return "\n".join(lines) + "\n"


def vertex_tour_bound(poly: Polyhedron, costs: CostModel | None = None) -> float:
    """A lower bound of the path cost of any episode that measures every vertex of ``poly`` [units]: a vertex is
    measured only by an edge move that ends at it (seed §4), so the sensor's path passes through every vertex;
    that path is at least the minimum spanning tree of the vertices (straight lines are no longer than paths on
    the surface), at the cheapest rate of any move (``c_f``, a face), plus ``c_k`` per vertex detected (§3.1)."""
    from scipy.sparse.csgraph import minimum_spanning_tree
    from scipy.spatial.distance import cdist

    costs = costs or CostModel()
    mst = float(minimum_spanning_tree(cdist(poly.vertices, poly.vertices)).sum())
    return costs.c_f * mst + poly.n_vertices * costs.c_k


def cost_ratios(records: list[dict], library: dict[str, Polyhedron] | None = None) -> str:
    """Mean path cost of the library episodes per mode, over that of "none" (same episodes); with ``library``,
    also the least ratio any mode that measures every vertex can reach: an episode costs at least what it costs
    to recognise (its path without verification) and at least :func:`vertex_tour_bound`."""
    lib = [r for r in records if r["perturbation"] == "library"]
    by = defaultdict(list)
    for r in lib:
        by[r["verify"]].append(r["path_cost"])
    if "none" not in by:
        return ""
    base = float(np.mean(by["none"]))
    lines = ["| verify | library episodes | mean path cost | over none | correct % |", "|---|---|---|---|---|"]
    for v in sorted(by):
        rs = [r for r in lib if r["verify"] == v]
        ok = 100.0 * sum(r["correct"] for r in rs) / len(rs)
        lines.append(f"| {v} | {len(by[v])} | {np.mean(by[v]):.1f} | {np.mean(by[v]) / base:.2f}x | {ok:.1f} |")
    if library:
        bound = {n: vertex_tour_bound(p) for n, p in library.items()}
        least = [max(r["path_cost"], bound[r["model"]]) for r in lib if r["verify"] == "none" and r["model"] in bound]
        if least:
            lines.append(f"| every vertex, lower bound | {len(least)} | {np.mean(least):.1f} | "
                         f"{np.mean(least) / base:.2f}x | - |")  # fmt: skip
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--models", metavar="DIR", help="library directory (default: the shipped seed library)")
    ap.add_argument("--models-only", default="", help="comma-separated model names to perturb (default: all)")
    ap.add_argument("--executor", choices=("geometric", "physics"), default="geometric")
    ap.add_argument("--verify", default="none,fast,full", help="comma-separated verification modes")
    ap.add_argument("--sizes", default="", help="comma-separated size labels to run (e.g. x0.97,4 mm; default: all)")
    ap.add_argument("--episodes", type=int, default=2, help="episodes (random poses) per variant")
    ap.add_argument("--baseline", type=int, default=0, help="library episodes per mode for the cost of verification")
    ap.add_argument("--baseline-verify", default="", help="modes of the library episodes (default: those of --verify)")
    ap.add_argument("--noise", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--max-moves", type=int, default=40)
    ap.add_argument("--moves", choices=MOVE_SETS, default=None,
                    help="admissible kinds of move (default: the command line's for the executor)")
    ap.add_argument("--policy", default=DEFAULT_POLICY, choices=POLICY_NAMES, help="the policy of every episode")
    ap.add_argument("--out", default="out/unknown", help="output directory")
    args = ap.parse_args(argv)
    moves = args.moves or default_moves(args.executor)
    try:
        library = load_library(args.models)
        lib_name = Path(args.models).name if args.models else "seed"
        names = [n for n in args.models_only.split(",") if n] or sorted(library)
        modes = [m for m in args.verify.split(",") if m]
        sizes = {x.strip() for x in args.sizes.split(",") if x.strip()}
        out = Path(args.out)
        vdir = out / "variants" / lib_name
        rng = np.random.default_rng(args.seed)
        specs, meta = [], []
        shapes: dict[str, Polyhedron] = {}  # variant file name -> variant
        for name in names:
            for kind, size, poly in variants(library[name], np.random.default_rng(rng.integers(2**31))):
                if sizes and size not in sizes:
                    continue
                twin = next((m.name for m in library.values() if _same_shape(poly, m)), None)
                if twin is not None:  # e.g. a box 60 mm high made 66 mm: a model of the library
                    print(f"{poly.name} is library model {twin}: left out", file=sys.stderr)
                    continue
                why = unsimulated(poly) if args.executor == "physics" else None
                if why is not None:
                    print(f"{poly.name} left out: the simulated hand cannot explore it ({why})", file=sys.stderr)
                    continue
                path = vdir / f"{poly.name}.json"
                save_model(poly, path)
                shapes[path.name] = poly
                seeds = rng.integers(2**31 - 1, size=args.episodes)
                for mode in modes:
                    for s in seeds:
                        specs.append(EpisodeSpec(
                            model=str(path), seed=int(s), executor=args.executor, noise=args.noise,
                            models=args.models, max_moves=args.max_moves, verify=mode, moves=moves,
                            policy=args.policy,
                        ))  # fmt: skip
                        meta.append((name, kind, size))
        if args.baseline:
            for mode in [m for m in args.baseline_verify.split(",") if m] or modes:
                for s in plan_sweep(names, args.baseline, args.seed + 1, [args.policy], (args.noise,),
                                    executor=args.executor, models=args.models, max_moves=args.max_moves,
                                    verify=mode, moves=moves):  # fmt: skip
                    specs.append(s)
                    meta.append((s.model, "library", "-"))
        results = out / f"{lib_name}_{args.executor}.jsonl"
        out.mkdir(parents=True, exist_ok=True)
        records = []
        t0 = time.perf_counter()
        keyed = {(Path(s.model).name, s.seed, s.verify): m for s, m in zip(specs, meta, strict=True)}
        lines = []
        for rec in run_sweep(specs, workers=args.workers):
            base, kind, size = keyed[(rec["model"], rec["seed"], rec["verify"])]
            rec.update(base_model=base, perturbation=kind, size=size, library=lib_name)
            if kind != "library" and args.executor == "physics":
                from haptic.sim.scene import TABLE_TOP_Z

                rec["within_claim"] = within_claim(rec, shapes[rec["model"]], library[base], TABLE_TOP_Z)
            records.append(rec)
            lines.append(json.dumps(rec))
            if len(records) % 20 == 0:
                print(f"{len(records)}/{len(specs)} episodes", file=sys.stderr, flush=True)
                atomic_write(results, "\n".join(lines) + "\n")
        atomic_write(results, "\n".join(lines) + "\n")
        wall = time.perf_counter() - t0
        text = (f"# {lib_name} library, {args.executor} executor, --moves {moves}, noise {args.noise:g}\n\n"
                + table(records) + "\n"
                + cost_ratios(records, library))  # fmt: skip
        atomic_write(results.with_suffix(".md"), text)
        print(text)
        print(f"{len(records)} episodes in {wall:.0f} s (machine shared); results: {results}")
    except HapticError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
