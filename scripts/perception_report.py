"""Perception of the simulated hand: every data component's error in units of its own bound, over physics
episodes; or (``--fixed-plan``) errors per seed object over a fixed sequence of moves.

    .venv/bin/python scripts/perception_report.py --out out/perception/seed.jsonl [--models DIR | --corpus]
        [--sizes 30,90,150] [--objects A,B] [--poses 2] [--first-seed 1] [--verify full] [--noise 1]
        [--workers 2] [--resume] [--plot hist.png] [--worst 10]
    .venv/bin/python scripts/perception_report.py --summarize A.jsonl [B.jsonl ...] [--plot hist.png]
    .venv/bin/python scripts/perception_report.py --fixed-plan [--poses 5] [--objects BOX01,WEDGE01,...] [--seed 0]

**Episodes** (the default): the real ``haptic explore --executor physics`` episodes (``EpisodeSpec`` with the
command line's defaults but those given), each object of the library (``--objects``: some of them) at
``--poses`` random resting poses (episode seeds ``first-seed``, ``first-seed + 1``, ...), on ``--workers``
processes. ``--sizes`` (mm) scales every model so that its largest extent is that size, one library per size,
written under ``--libraries`` (the objects are recognised within the library at their size); ``--corpus`` is
the formula corpus of ``scripts/make_corpus.py`` instead of the seed library. Each record is appended to
``--out`` as it ends (``--resume`` skips the episodes already there). Each record's ``perception`` holds every
component's quantities in units of their bounds, scored against the truth outside the executor
(:func:`haptic.episode.evaluate.bound_ratios`): the report prints the distribution per quantity, the counts of
components and episodes outside their bounds, the outcomes (wrong recognitions, no-match), the worst cases with
the command that replays each, and with ``--plot`` a histogram of the ratios per quantity.

**Fixed plan**: start, then the fixed sequence face, edge, vertex, edge, face, edge, vertex (random choices
through a seeded generator; a failed move is retried with another choice, up to 4 times; an edge move in the
sense of a vertex already reached is not asked). On objects with concave edges a *concave probe* follows: face
moves whose directions are chosen with the ground truth (an oracle standing in for the planner -- the executor
is as blind as ever) towards the nearest concave edge of the current face -- or, from a face without one,
towards the middle of the edge to a face that has one --, until one is reported or 6 moves are spent.

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
import math
import time
from collections import Counter
from pathlib import Path

import numpy as np

from haptic.episode.evaluate import score_components, score_face
from haptic.episode.spec import EpisodeSpec
from haptic.executor.physics import PhysicsExecutor
from haptic.geometry import SE3, load_library
from haptic.geometry.io import save_model
from haptic.geometry.perturb import scaled_to
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


def fixed_plan(args: argparse.Namespace) -> int:
    """Errors per seed object over the fixed sequence of moves (module doc)."""
    lib = load_library()
    all_rates = []
    totals: Counter = Counter()
    print(f"{'object':9} {'face ok':>8} {'edge ok':>8} {'vtx ok':>8} {'table':>5} {'normal°':>13} {'edge dir°':>13} "
          f"{'edge pos mm':>13} {'vertex mm':>13} {'spur':>4} {'miss':>4} {'concave':>7} {'matcher':>7}")  # fmt: skip
    for name in (args.objects or ",".join(SEED_OBJECTS)).split(","):
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


# -- episodes: error / bound per quantity -------------------------------------------------------------------

DEFAULT_LIBRARIES = "out/perception/libraries"
"""Where the scaled libraries are written (``--libraries``)."""


def write_library(models: dict, out: Path, size_mm: float | None) -> Path:
    """``models`` (name -> Polyhedron) as native model files in ``out``, each scaled so that its largest
    extent is ``size_mm`` (None: as they are); the directory is written once and reused."""
    if out.is_dir() and any(out.glob("*.json")):
        return out
    out.mkdir(parents=True, exist_ok=True)
    for name, poly in models.items():
        save_model(poly if size_mm is None else scaled_to(poly, size_mm * 1e-3, name), out / f"{name}.json")
    return out


def libraries(args: argparse.Namespace) -> list[Path | None]:
    """The library directories of the sweep: one per size, or the library as it is (None: the seed one)."""
    if args.corpus:
        from haptic.geometry.corpus import corpus_solids

        models, base = {s.name: p for s, p in corpus_solids()}, "corpus"
    elif args.models:
        models, base = load_library(args.models), Path(args.models).resolve().name
    else:
        models, base = load_library(), "seed"
    if not args.sizes:
        return [write_library(models, Path(args.libraries) / base, None) if args.corpus else args.models]
    root = Path(args.libraries)
    return [write_library(models, root / f"{base}_{float(s):03.0f}mm", float(s)) for s in args.sizes.split(",")]


def plan(args: argparse.Namespace) -> list[EpisodeSpec]:
    """The episodes: every object (or ``--objects``, or ``--per-library`` drawn from ``--first-seed``) of each
    library at ``--poses`` seeds."""
    specs = []
    for lib_dir in libraries(args):
        names = sorted(load_library(lib_dir))
        if args.objects:
            names = [n for n in names if n in args.objects.split(",")]
        if args.per_library and args.per_library < len(names):
            rng = np.random.default_rng(args.first_seed)
            names = sorted(rng.choice(names, size=args.per_library, replace=False).tolist())
        settings = {"executor": "physics", "verify": args.verify, "noise": args.noise}
        if lib_dir is not None:
            settings["models"] = str(lib_dir)
        specs += [EpisodeSpec(model=n, seed=args.first_seed + k, **settings)
                  for k in range(args.poses) for n in names]  # fmt: skip
    return specs


def run_episodes(args: argparse.Namespace) -> None:
    """Run the planned episodes not yet in ``--out``, appending each record as it ends."""
    from contextlib import closing

    from haptic.bench.results import ResultsWriter, drop_partial_line, read_results
    from haptic.bench.runner import episode_key, key_id, run_sweep

    out = Path(args.out)
    if out.exists() and out.stat().st_size and not args.resume:
        raise SystemExit(f"perception_report: {out} holds records; --resume to add the missing episodes to it")
    drop_partial_line(out)
    done = {key_id(r["key"]) for r in read_results(out)} if out.exists() else set()
    todo = [s for s in plan(args) if key_id(episode_key(s)) not in done]
    print(f"{len(todo)} episodes to run ({len(done)} already in {out}) on {args.workers} workers", flush=True)
    t0 = time.time()
    with ResultsWriter(out) as writer, closing(run_sweep(todo, workers=args.workers)) as records:
        for i, r in enumerate(records, 1):
            writer.write(r)
            worst = _worst_ratio(r)
            print(f"  {i}/{len(todo)} {r['library']} {r['model']} seed {r['seed']}: {r['outcome']}"
                  f"{'' if r['correct'] else ' (wrong)' if r['recognized'] else ''}, largest ratio "
                  f"{worst:.2f}, {time.time() - t0:.0f} s", flush=True)  # fmt: skip


def _worst_ratio(r: dict) -> float:
    rows = (r.get("perception") or {}).get("ratios") or []
    return max((x[2] for x in rows), default=0.0)


def replay(r: dict, libraries: str = DEFAULT_LIBRARIES) -> str:
    """The command that replays a record's episode (a library other than the seed one: the directory of that
    name under ``libraries``)."""
    parts = [f"haptic explore --executor physics --object {r['model']} --seed {r['seed']}"]
    if r.get("library", "seed") != "seed":
        parts.append(f"--models {Path(libraries) / r['library']}")
    if r.get("verify", "full") != "full":
        parts.append(f"--verify {r['verify']}")
    if r.get("noise", 1.0) != 1.0:
        parts.append(f"--noise {r['noise']:g}")
    return " ".join(parts)


def summarize(records: list[dict], worst: int = 10, plot: str | None = None, libraries: str = DEFAULT_LIBRARIES) -> int:
    """Print the error / bound distribution per quantity, the counts outside bounds, the outcomes and the worst
    cases; with ``plot``, write a histogram of the ratios per quantity. Returns the components outside bounds."""
    from haptic.episode.evaluate import BOUND_QUANTITIES

    rows = []  # (ratio, what, data id, record)
    for r in records:
        for cid, what, ratio, _ in (r.get("perception") or {}).get("ratios") or []:
            rows.append((float(ratio), what, int(cid), r))
    libs = Counter(r["library"] for r in records)
    print(f"{len(records)} episodes ({', '.join(f'{k} {v}' for k, v in sorted(libs.items()))})")
    print(f"{'quantity':15} {'n':>5} {'median':>7} {'p90':>7} {'p99':>7} {'max':>7} {'> 1':>5}")
    for what in BOUND_QUANTITIES:
        a = np.array([x for x, w, _, _ in rows if w == what])
        if not len(a):
            continue
        q = np.quantile(a, [0.5, 0.9, 0.99])
        print(f"{what:15} {len(a):5d} {q[0]:7.2f} {q[1]:7.2f} {q[2]:7.2f} {a.max():7.2f} {int((a > 1).sum()):5d}")
    outside = {(id(r), cid) for x, _, cid, r in rows if x > 1.0}
    n_comp = len({(id(r), cid) for _, _, cid, r in rows})
    eps = {id(r) for x, _, _, r in rows if x > 1.0}
    print(f"components outside their bounds: {len(outside)} of {n_comp}, in {len(eps)} of {len(records)} episodes")
    missed = sum((r.get("perception") or {}).get("missed", 0) for r in records)
    spurious = sum((r.get("perception") or {}).get("spurious", 0) for r in records)
    print(f"components farther than 5° or 3 mm from every true feature (spurious): {spurious}; moves that met "
          f"another feature than the one they reported (missed): {missed}")  # fmt: skip
    out = Counter(r["outcome"] for r in records)
    wrong = [r for r in records if r["recognized"] and not r["correct"]]
    print("outcomes: " + ", ".join(f"{k} {v}" for k, v in sorted(out.items()))
          + f"; wrong recognitions {len(wrong)}")  # fmt: skip
    for r in wrong:
        print(f"  wrong: {r['library']} {r['model']} seed {r['seed']} as {r['recognized']} "
              f"({r['pose_error_mm']} mm, {r['pose_error_deg']} deg)")  # fmt: skip
    for r in records:
        if r["outcome"] == "no-match":
            print(f"  no-match: {r['library']} {r['model']} seed {r['seed']}: {r['detail']}")
    _hand_summary(records)
    _wrist_summary(records)
    print(f"worst {worst}:")
    for ratio, what, cid, r in sorted(rows, key=lambda x: -x[0])[:worst]:
        print(f"  {ratio:6.2f} {what:14} component {cid:2d}  {r['library']} {r['model']} seed {r['seed']}: "
              f"{replay(r, libraries)}")  # fmt: skip
    if plot:
        _plot(rows, plot)
    return len(outside)


def _hand_summary(records: list[dict]) -> None:
    """The contacts of links other than the exploring pad (``perception.hand``): in how many episodes and moves, on
    which links, their points' distance from the true surface in units of the link's bound, and the components
    reported by the moves that had them, in units of their own bounds."""
    hands = [(r, (r.get("perception") or {}).get("hand") or {}) for r in records]
    hands = [(r, h) for r, h in hands if h.get("moves")]
    if not hands:
        print("contacts of links other than the pad: none")
        return
    links = Counter(link for _, h in hands for link in h["links"])
    comp = [h["component_ratio_max"] for _, h in hands if h.get("component_ratio_max") is not None]
    worst = max(hands, key=lambda rh: rh[1]["point_ratio_max"])
    print(f"contacts of links other than the pad: {len(hands)} episodes, {sum(h['moves'] for _, h in hands)} moves, "
          f"{sum(h['points'] for _, h in hands)} points ({', '.join(f'{k} {v}' for k, v in links.most_common())}); "
          f"largest point off the surface {max(h['point_mm_max'] for _, h in hands):.2f} mm, "
          f"{worst[1]['point_ratio_max']:.3f} of its link's bound ({worst[0]['model']} seed {worst[0]['seed']}); "
          f"{sum(h['components'] for _, h in hands)} components from those moves, the largest "
          f"{max(comp) if comp else 0.0:.2f} of its bound")  # fmt: skip


def _wrist_summary(records: list[dict]) -> None:
    """The wrist force sensor's watch (``perception.wrist``): ticks watched with the pad free, how many of those
    with a link's contact the wrist felt, the ticks and moves with a force neither the pad nor a link reports, and
    the largest force off the hand's weight with nothing touching."""
    ws = [w for w in ((r.get("perception") or {}).get("wrist") or {} for r in records) if w.get("watched")]
    if not ws:
        print("wrist force sensor: not watched")
        return
    total = {k: sum(w[k] for w in ws) for k in ("watched", "links", "links_felt", "unexplained", "unexplained_moves")}
    print(f"wrist force sensor, pad free: {total['watched']} ticks watched in {len(ws)} episodes; with a link's "
          f"contact {total['links']}, the wrist felt {total['links_felt']}; a force no link nor the pad reports: "
          f"{total['unexplained']} ticks in {total['unexplained_moves']} moves; nothing touching, the force off the "
          f"hand's weight at most {max(w['free_max'] for w in ws):.2f} N")  # fmt: skip


def _plot(rows: list, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from haptic.episode.evaluate import BOUND_QUANTITIES

    fig, axes = plt.subplots(2, 4, figsize=(16, 6), sharex=True)
    for ax in axes.ravel()[len(BOUND_QUANTITIES) :]:
        ax.axis("off")
    # every ratio shows: zeros (an edge's extent within its explored interval) are counted in the title, not drawn
    # at the left edge, and the range reaches the largest ratio
    top = max([1.5] + [math.ceil(10 * math.log10(x)) / 10 + 0.1 for x, _, _, _ in rows if x > 0])
    bins = np.linspace(-3, top, int(round(10 * (top + 3))) + 1)
    for ax, what in zip(axes.ravel()[: len(BOUND_QUANTITIES)], BOUND_QUANTITIES, strict=True):
        a = np.array([x for x, w, _, _ in rows if w == what])
        pos = a[a > 0]
        ax.hist(np.clip(np.log10(pos), bins[0], bins[-1]), bins=bins, color="tab:blue")
        ax.axvline(0.0, color="tab:red", lw=1)
        ax.set_yscale("log")
        ax.set_title(f"{what} (n {len(a)}, {len(a) - len(pos)} zero, {int((a > 1).sum())} > 1)", fontsize=10)
    for ax in axes[-1]:
        ax.set_xlabel("log10 (error / bound)")
    fig.tight_layout()
    tmp = Path(path).with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=110)
    tmp.replace(path)
    print(f"histogram: {path}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fixed-plan", action="store_true", help="errors per seed object over a fixed plan of moves")
    ap.add_argument("--summarize", nargs="+", default=None, metavar="JSONL", help="report on records already run")
    ap.add_argument("--poses", type=int, default=None, help="poses per object (default 2; fixed plan: 5)")
    ap.add_argument("--objects", default=None, help="comma-separated model names (default: all)")
    ap.add_argument("--seed", type=int, default=0, help="fixed plan: seed of the poses")
    ap.add_argument("--out", default="out/perception/records.jsonl", help="episode records (JSON lines)")
    ap.add_argument("--resume", action="store_true", help="run only the episodes not yet in --out")
    ap.add_argument("--models", default=None, help="library directory (default: the seed library)")
    ap.add_argument("--corpus", action="store_true", help="the formula corpus (scripts/make_corpus.py) instead")
    ap.add_argument("--sizes", default=None, help="comma-separated largest extents [mm]: one library per size")
    ap.add_argument("--libraries", default=DEFAULT_LIBRARIES, help="where scaled libraries are written")
    ap.add_argument("--per-library", type=int, default=None, help="objects drawn per library (default: all)")
    ap.add_argument("--first-seed", type=int, default=1, help="episode seed of the first pose")
    ap.add_argument("--verify", default="full", choices=("none", "fast", "full"))
    ap.add_argument("--noise", type=float, default=1.0, help="sensor-noise level")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--worst", type=int, default=10, help="worst cases listed")
    ap.add_argument("--plot", default=None, help="histogram of error / bound per quantity (PNG)")
    args = ap.parse_args(argv)
    if args.fixed_plan:
        args.poses = args.poses or 5
        return fixed_plan(args)
    if args.summarize:
        from haptic.bench.results import read_results

        records = [r for p in args.summarize for r in read_results(p)]
    else:
        args.poses = args.poses or 2
        run_episodes(args)
        from haptic.bench.results import read_results

        records = read_results(args.out)
    summarize(records, args.worst, args.plot, args.libraries)
    return 0


if __name__ == "__main__":
    t0 = time.time()
    rc = main()
    print(f"wall time {time.time() - t0:.0f} s")
    raise SystemExit(rc)
