"""Write the corpus of third-party-like model files, and optionally check every file imports as its formula says.

    python scripts/make_corpus.py out/corpus            # out/corpus/{obj6,objmm3,stl,objtri}/ + manifest.json
    python scripts/make_corpus.py out/corpus --check    # also import each file: V/E/F and symmetry order
    python scripts/make_corpus.py out/sized --sizes 30:150 --encodings obj6   # each solid at a drawn size

``--sizes MIN:MAX`` scales each solid so that its size (largest vertex-to-vertex distance) is drawn uniformly
from MIN to MAX mm (seeded), for exploring objects of many sizes on the hand; the formulas' counts do not change.

The table printed by ``--check`` counts, per family and encoding, the files whose V/E/F (and symmetry order)
match the formula, out of the total. Exit 1 when any does not.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import defaultdict

import numpy as np

from haptic.errors import HapticError
from haptic.geometry import Polyhedron, load_model, symmetry_group
from haptic.geometry.corpus import ENCODINGS, corpus_solids, write_corpus


def sized(solids, lo: float, hi: float, rng: np.random.Generator):
    """Each solid scaled about its centroid so that its size (the largest distance between two of its vertices,
    whatever its pose) is drawn uniformly from ``lo`` to ``hi`` [m]."""
    out = []
    for spec, poly in solids:
        v = poly.vertices
        extent = float(np.linalg.norm(v[:, None] - v[None], axis=2).max())
        k = rng.uniform(lo, hi) / extent
        c = poly.centroid
        out.append((spec, Polyhedron.from_faces(c + k * (poly.vertices - c), poly.faces, name=poly.name)))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="directory to write the corpus into")
    ap.add_argument("--seed", type=int, default=0, help="seed of the poses and random hulls (default 0)")
    ap.add_argument("--check", action="store_true", help="import every file and compare with the formula")
    ap.add_argument("--sizes", default=None, metavar="MIN:MAX",
                    help="scale each solid to a size (largest vertex distance) drawn from MIN to MAX mm "
                    "(default: as the formulas)")
    ap.add_argument("--encodings", default=",".join(ENCODINGS), help=f"comma-separated, of {', '.join(ENCODINGS)}")
    args = ap.parse_args(argv)
    encodings = tuple(e for e in args.encodings.split(",") if e)
    bad = [e for e in encodings if e not in ENCODINGS]
    if bad or not encodings:
        ap.error(f"--encodings: {', '.join(bad) or 'none given'}; valid: {', '.join(ENCODINGS)}")
    solids = corpus_solids(seed=args.seed)
    if args.sizes:
        try:
            lo, hi = (float(x) for x in args.sizes.split(":"))
        except ValueError:
            ap.error(f"--sizes: expected MIN:MAX in mm (e.g. 30:150), got {args.sizes!r}")
        if not 0 < lo <= hi:
            ap.error(f"--sizes: expected 0 < MIN <= MAX, got {args.sizes!r}")
        solids = sized(solids, lo / 1000.0, hi / 1000.0, np.random.default_rng(args.seed))
    dirs = write_corpus(args.out, seed=args.seed, solids=solids, encodings=encodings)
    print(f"{len(solids)} solids x {len(dirs)} encodings written under {args.out}")
    if not args.check:
        return 0
    right = defaultdict(lambda: [0, 0, 0])  # (family, encoding) -> [V/E/F right, symmetry right, total]
    t0 = time.perf_counter()
    for enc, d in dirs.items():
        for spec, _ in solids:
            row = right[(spec.family, enc)]
            row[2] += 1
            path = next(d.glob(f"{spec.name}.*"))
            try:
                m = load_model(path)
                order = len(symmetry_group(m))
            except HapticError as exc:
                print(f"  {path}: {exc}", file=sys.stderr)
                continue
            vef = (m.n_vertices, m.n_edges, m.n_faces) == (spec.V, spec.E, spec.F)
            row[0] += vef
            row[1] += order == spec.symmetry
            if not vef or order != spec.symmetry:
                print(f"  {path}: V/E/F {m.n_vertices}/{m.n_edges}/{m.n_faces} symmetry {order}; formula "
                      f"{spec.V}/{spec.E}/{spec.F} symmetry {spec.symmetry}", file=sys.stderr)
    families = sorted({f for f, _ in right})
    print(f"\n| family | {' | '.join(f'{e} V/E/F | {e} sym' for e in ENCODINGS if e in dirs)} |")
    print("|---|" + "---|" * (2 * len(dirs)))
    total = [0, 0, 0]
    for fam in families:
        cells = []
        for enc in dirs:
            r = right[(fam, enc)]
            cells += [f"{r[0]}/{r[2]}", f"{r[1]}/{r[2]}"]
            total = [total[0] + r[0], total[1] + r[1], total[2] + r[2]]
        print(f"| {fam} | {' | '.join(cells)} |")
    print(f"\nall: V/E/F {total[0]}/{total[2]}, symmetry {total[1]}/{total[2]} "
          f"({time.perf_counter() - t0:.1f} s to import and find every symmetry group)")
    return 0 if total[0] == total[1] == total[2] else 1


if __name__ == "__main__":
    raise SystemExit(main())
