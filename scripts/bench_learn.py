"""Learning objects outside the library, and knowing them the next time.

The objects: the perturbed variants of every library model (those of ``scripts/bench_unknown.py``: a dimension
scaled, a vertex moved, an edge chamfered) and ``--hulls`` random convex hulls of ``haptic models generate``
(its ``hull`` family). Each is learned from one episode with ``--learn``: explored against the library until
``no-match``, then on to closure; the learned model is written into a copy of the library made for it. Scored
against the truth (evaluation only):

- V/E/F: the learned model has the object's counts of vertices, edges and faces;
- Hausdorff distance between the learned surface and the true one (posed as in the episode), from the vertices
  and ``--samples`` points drawn on each surface (trimesh), and the volume error;
- re-identification: ``--poses`` new episodes of the object against its library with the learned model in it,
  recognised as the learned model; and false recognitions: episodes of library objects (the model the variant
  was made from first, then others, ``--others`` in all, ``--poses-others`` poses each) recognised as the
  learned model.

    .venv/bin/python scripts/bench_learn.py --hulls 50 --workers 2
    .venv/bin/python scripts/bench_learn.py --executor physics --hulls 0 --models-only WEDGE01,PYR01 --variants \
        dim --poses 1 --others 0 --workers 1

``--executor physics`` learns on the simulated hand (the objects rest on the table at the episode's seeded pose)
and re-identifies there too; ``--variants`` keeps the perturbations of the kinds given (``dim``, ``v``, ``ch``).

Results: ``OUT/learn.jsonl`` (one line per object), the table by family in ``OUT/learn.md``. Wall times are
measured on whatever else runs on the machine.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from collections import defaultdict
from contextlib import closing
from pathlib import Path

import numpy as np
from tqdm import tqdm

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_unknown import _same_shape, variants  # noqa: E402

from haptic.bench.runner import run_sweep  # noqa: E402
from haptic.episode.spec import EpisodeSpec  # noqa: E402
from haptic.errors import HapticError, ModelError  # noqa: E402
from haptic.geometry import Polyhedron, load_library, load_model, model_files, save_model  # noqa: E402
from haptic.geometry.distance import point_triangle_distance  # noqa: E402
from haptic.geometry.generate import iter_library  # noqa: E402
from haptic.geometry.io import atomic_write  # noqa: E402
from haptic.geometry.se3 import quat_to_matrix  # noqa: E402

HAUSDORFF_GOAL_MM = 1.0
VOLUME_GOAL = 0.02


def surface_points(vertices: np.ndarray, triangles: np.ndarray, samples: int, rng: np.random.Generator) -> np.ndarray:
    """``samples`` points drawn uniformly (by area) on the triangles ``vertices[triangles]``, and the vertices."""
    tri = vertices[triangles]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    pick = rng.choice(len(tri), size=samples, p=area / area.sum())
    u, v = rng.random(samples), rng.random(samples)
    flip = u + v > 1
    u, v = np.where(flip, 1 - u, u), np.where(flip, 1 - v, v)
    t = tri[pick]
    pts = t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])
    return np.vstack([pts, vertices])


def surface_distance(a: Polyhedron, b: Polyhedron, b_pose: tuple[np.ndarray, np.ndarray], samples: int,
                     rng: np.random.Generator) -> float:
    """Hausdorff distance between the surface of ``a`` and that of ``b`` at ``b_pose`` (rotation, translation)
    [m]: over the vertices of each and ``samples`` points drawn uniformly on each, the largest distance to the
    other surface (the model's triangles posed as arrays: a posed model is not validated again)."""
    r, t = b_pose
    surfaces = [(np.asarray(a.vertices, float), a.triangles), (np.asarray(b.vertices, float) @ r.T + t, b.triangles)]
    worst = 0.0
    for (pv, pt), (qv, qt) in (surfaces, surfaces[::-1]):
        pts = surface_points(pv, pt, samples, rng)
        tris = qv[qt]
        for i in range(0, len(pts), 1000):
            worst = max(worst, float(point_triangle_distance(pts[i : i + 1000], tris).min(axis=1).max()))
    return worst


def objects(library: dict[str, Polyhedron], hulls: int, seed: int, out: Path,
            kinds: tuple[str, ...] | None = None) -> list[dict]:
    """The objects to learn, written as model files: ``{path, family, base}`` each; ``kinds`` keeps the
    variants whose name's tag starts with one of them (``dim``, ``v``, ``ch``; None: all)."""
    rng = np.random.default_rng(seed)
    items = []
    for name in sorted(library):
        for kind, size, poly in variants(library[name], np.random.default_rng(rng.integers(2**31))):
            if any(_same_shape(poly, m) for m in library.values()):
                continue
            tag = poly.name.rsplit("__", 1)[-1]
            if kinds is not None and not any(tag.startswith(k) and tag[len(k):][:1].isdigit() for k in kinds):
                continue
            family = kind if poly.is_convex else f"{kind}, non-convex"
            path = out / f"{poly.name}.json"
            save_model(poly, path)
            try:
                load_model(path)
            except ModelError as exc:  # the file's rounding broke it: not an object to explore
                print(f"{poly.name} left out: {exc}", file=sys.stderr)
                continue
            items.append({"path": str(path), "family": family, "size": size, "base": name})
    if hulls:
        count = int(np.ceil(hulls / 0.3)) + 1
        got = 0
        for poly in iter_library(count, seed):
            if got >= hulls:
                break
            if not poly.name.startswith("GEN_HULL"):
                continue
            path = out / f"{poly.name}.json"
            save_model(poly, path)
            items.append({"path": str(path), "family": "hull", "size": "-", "base": None})
            got += 1
    return items


def library_copy(src: str | None, dst: Path) -> Path:
    """A fresh copy of the library's model files (and its ``library.toml``) at ``dst``."""
    from haptic.geometry.io import DEFAULT_LIBRARY, LIBRARY_FILE

    where = Path(src) if src else DEFAULT_LIBRARY
    if dst.exists():
        shutil.rmtree(dst)
    dst.mkdir(parents=True)
    for f in model_files(where):
        shutil.copy2(f, dst / f.name)
    if (where / LIBRARY_FILE).is_file():
        shutil.copy2(where / LIBRARY_FILE, dst / LIBRARY_FILE)
    return dst


def sweep(specs: list[EpisodeSpec], workers: int, desc: str) -> list[dict]:
    out = []
    with tqdm(total=len(specs), unit="ep", desc=desc, file=sys.stderr, disable=None) as bar:
        with closing(run_sweep(specs, workers=workers)) as records:
            for rec in records:
                out.append(rec)
                bar.update(1)
    return out


def table(rows: list[dict]) -> str:
    """Markdown: per family, what was learned and how well."""
    groups: dict[str, list[dict]] = defaultdict(list)
    for r in rows:
        groups[r["family"]].append(r)
    groups["all"] = rows
    groups["all convex"] = [r for r in rows if "non-convex" not in r["family"]]
    head = ("| family | objects | closed | V/E/F right | Hausdorff mean / max [mm] | ≤ 1 mm | volume error mean / max "
            "[%] | within 2 % | learning moves | learning cost | learning wall [s] | re-identified | false "
            "recognitions |")
    lines = [head, "|" + "---|" * 13]
    for fam, rs in groups.items():
        n = len(rs)
        ok = [r for r in rs if r.get("learned_status") == "closed" and r.get("V") is not None]
        h = [r["hausdorff_mm"] for r in ok]
        v = [abs(r["volume_error"]) * 100 for r in ok]
        vef = sum(r["vef_right"] for r in ok)
        reid = sum(r["reid_recognized"] for r in rs)
        reid_n = sum(r["reid_episodes"] for r in rs)
        false = sum(r["false_recognitions"] for r in rs)
        false_n = sum(r["false_episodes"] for r in rs)

        def pct(k: int, d: int) -> str:  # rounded down: 443 of 445 is not 100 %
            return f"{k}/{d} ({int(100 * k // d)} %)" if d else "-"

        def mean(key: str, fmt: str, rs: list = rs) -> str:  # a family with no object (no convex one drawn): "-"
            return format(float(np.mean([r[key] for r in rs])), fmt) if rs else "-"

        lines.append(
            f"| {fam} | {n} | {pct(len(ok), n)} | {pct(vef, n)} | "
            + (f"{np.mean(h):.3f} / {np.max(h):.3f} | {pct(sum(x <= HAUSDORFF_GOAL_MM for x in h), n)} | "
               f"{np.mean(v):.2f} / {np.max(v):.2f} | {pct(sum(x <= VOLUME_GOAL * 100 for x in v), n)} | "
               if ok else "- | - | - | - | ")
            + f"{mean('learn_moves', '.1f')} | {mean('learn_cost', '.1f')} | {mean('learn_wall_s', '.2f')} | "
            f"{pct(reid, reid_n)} | {false}/{false_n} |"
        )  # fmt: skip
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--models", metavar="DIR", help="library directory (default: the shipped seed library)")
    ap.add_argument("--models-only", default="", help="comma-separated library models to perturb (default: all)")
    ap.add_argument("--no-variants", action="store_true", help="learn only the hulls")
    ap.add_argument("--hulls", type=int, default=50, help="random convex hulls of `haptic models generate`")
    ap.add_argument("--variants", default="",
                    help="comma-separated kinds of perturbation kept: dim, v, ch (default: all)")
    ap.add_argument("--executor", choices=("geometric", "physics"), default="geometric")
    ap.add_argument("--noise", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--poses", type=int, default=5, help="re-identification episodes per learned model")
    ap.add_argument("--others", type=int, default=3, help="library objects tried per learned model (false)")
    ap.add_argument("--poses-others", type=int, default=1, help="episodes per library object tried")
    ap.add_argument("--samples", type=int, default=5000, help="surface points per model for the Hausdorff distance")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="out/learn", help="output directory")
    args = ap.parse_args(argv)
    try:
        library = load_library(args.models)
        if args.models_only:
            keep = set(args.models_only.split(","))
            base_lib = {k: v for k, v in library.items() if k in keep}
        else:
            base_lib = {} if args.no_variants else library
        out = Path(args.out)
        (out / "objects").mkdir(parents=True, exist_ok=True)
        kinds = tuple(k for k in args.variants.split(",") if k) or None
        items = objects(base_lib, args.hulls, args.seed, out / "objects", kinds)
        rng = np.random.default_rng(args.seed + 1)
        t0 = time.perf_counter()
        specs = []
        for it in items:
            stem = Path(it["path"]).stem
            it["library"] = str(library_copy(args.models, out / "libraries" / stem).resolve())
            it["name"] = f"learned_{stem}"
            specs.append(EpisodeSpec(model=it["path"], seed=int(rng.integers(2**31 - 1)), noise=args.noise,
                                     models=args.models, learn=it["library"], learn_name=it["name"],
                                     executor=args.executor))  # fmt: skip
        for rec in sweep(specs, args.workers, "learning"):
            it = next(i for i in items if Path(i["path"]).name == rec["model"])
            it["record"] = rec
        # score what was learned against the truth
        rows = []
        reid_specs, false_specs = [], []
        for it in items:
            rec = it["record"]
            learned = rec.get("learned") or {}
            truth = load_model(it["path"])
            q, t = rec["pose"]["quat_wxyz"], rec["pose"]["translation_m"]
            pose = (quat_to_matrix(np.array(q)), np.array(t))
            row = {"object": Path(it["path"]).stem, "family": it["family"], "size": it["size"], "base": it["base"],
                   "seed": rec["seed"], "learn_detail": learned.get("detail") or rec["detail"],
                   "outcome": rec["outcome"], "learned_status": learned.get("status"),
                   "learn_moves": learned.get("moves", 0), "learn_cost": learned.get("path_cost", 0.0),
                   "learn_wall_s": learned.get("wall_time_s", 0.0), "episode_moves": rec["moves"],
                   "episode_cost": rec["path_cost"], "true_VEF": [truth.n_vertices, truth.n_edges, truth.n_faces],
                   "V": None, "vef_right": False, "reid_episodes": 0, "reid_recognized": 0, "reid_cost": [],
                   "reid_outcomes": [], "reid_seeds": [], "reid_missed": [], "false_seeds": [],
                   "false_episodes": 0, "false_recognitions": 0, "false_outcomes": []}  # fmt: skip
            if learned.get("status") == "closed" and learned.get("path"):
                try:
                    model = load_model(learned["path"])
                except ModelError as exc:
                    row["score_error"] = str(exc)
                    it["row"] = row
                    rows.append(row)
                    continue
                row.update(V=model.n_vertices, E=model.n_edges, F=model.n_faces,
                           vef_right=(model.n_vertices, model.n_edges, model.n_faces)
                           == (truth.n_vertices, truth.n_edges, truth.n_faces),
                           hausdorff_mm=1e3 * surface_distance(model, truth, pose, args.samples, rng),
                           volume_error=model.volume / truth.volume - 1.0)  # fmt: skip
                for _ in range(args.poses):
                    reid_specs.append((row, EpisodeSpec(model=it["path"], seed=int(rng.integers(2**31 - 1)),
                                                        noise=args.noise, models=it["library"],
                                                        executor=args.executor)))  # fmt: skip
                others = sorted(library, key=lambda n: (n != it["base"], rng.random()))[: args.others]
                for name in others:
                    for _ in range(args.poses_others):
                        false_specs.append((row, EpisodeSpec(model=name, seed=int(rng.integers(2**31 - 1)),
                                                             noise=args.noise, models=it["library"],
                                                             executor=args.executor)))  # fmt: skip
            it["row"] = row
            rows.append(row)
        learned_of = {it["library"]: it["name"] for it in items}
        keyed: dict[tuple, list[dict]] = defaultdict(list)
        for row, s in reid_specs + false_specs:
            keyed[(Path(s.model).name, s.seed, str(Path(s.models).resolve()))].append(row)
        pending = [s for _, s in reid_specs] + [s for _, s in false_specs]
        for rec in sweep(pending, args.workers, "re-identification"):
            lib = str(Path(rec["key"]["library"]))  # the library's directory name
            match = [k for k in keyed if k[0] == rec["model"] and k[1] == rec["seed"] and Path(k[2]).name == lib]
            row = keyed[match[0]][0]
            name = learned_of[match[0][2]]
            if rec["model"].endswith(".json"):
                row["reid_episodes"] += 1
                row["reid_recognized"] += int(rec["recognized"] == name)
                row["reid_cost"].append(rec["path_cost"])
                row["reid_outcomes"].append(rec["recognized"] or rec["outcome"])
                row["reid_seeds"].append(rec["seed"])
                if rec["recognized"] != name:
                    row["reid_missed"].append({"seed": rec["seed"], "outcome": rec["outcome"], "detail": rec["detail"]})
            else:
                row["false_episodes"] += 1
                row["false_recognitions"] += int(rec["recognized"] == name)
                row["false_outcomes"].append(rec["recognized"] or rec["outcome"])
                if rec["recognized"] == name:
                    row["false_seeds"].append({"model": rec["model"], "seed": rec["seed"]})
        wall = time.perf_counter() - t0
        for r in rows:
            r["reid_cost_mean"] = float(np.mean(r.pop("reid_cost"))) if r["reid_cost"] else None
        atomic_write(out / "learn.jsonl", "".join(json.dumps(r) + "\n" for r in rows))
        paired = [r for r in rows if r["reid_cost_mean"] is not None]
        text = (f"# Learning by touch: {len(rows)} objects, {args.executor} executor, noise {args.noise:g}\n\n"
                + table(rows)
                + "\nCost: the learning episode (recognition to no-match, then learning) against recognising the "
                "learned object afterwards (mean of its re-identification episodes): "
                + (f"{np.mean([r['episode_cost'] for r in paired]):.1f} vs "
                   f"{np.mean([r['reid_cost_mean'] for r in paired]):.1f} units over {len(paired)} objects\n"
                   if paired else "-\n"))  # fmt: skip
        atomic_write(out / "learn.md", text)
        print(text)
        print(f"{len(rows)} objects in {wall:.0f} s (machine shared); results: {out / 'learn.jsonl'}")
    except HapticError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
