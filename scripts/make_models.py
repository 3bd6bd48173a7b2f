"""Write the shipped model library ``assets/models/`` as native JSON, from the dimensions in its README.

    python scripts/make_models.py            # rewrite assets/models
    python scripts/make_models.py --check    # exit 1 if the files differ from what this script makes
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from haptic.geometry import Polyhedron, save_model
from haptic.geometry.io import to_native
from haptic.geometry.shapes import box, extrusion_xz, frame, prism, pyramid, regular_prism, tetrahedron

OUT = Path(__file__).resolve().parents[1] / "assets" / "models"

# BOX01 and its notched / bumped variants share one box: 100 x 80 x 60 mm.
L, W, H = 0.100, 0.080, 0.060
NOTCH_X0, NOTCH_X1, NOTCH_D = 0.035, 0.065, 0.020  # a 30 mm wide, 20 mm deep slot across the top (along y)


def seed_models() -> list[Polyhedron]:
    tetra = tetrahedron((0, 0, 0), (0.100, 0, 0), (0.025, 0.080, 0), (0.035, 0.025, 0.070), name="TETRA01L")
    return [
        box(L, W, H, name="BOX01"),
        extrusion_xz([(0, 0), (0.100, 0), (0.0, 0.060)], 0.080, name="WEDGE01"),
        extrusion_xz(
            [(0, 0), (L, 0), (L, H), (NOTCH_X1, H), (NOTCH_X1, H - NOTCH_D), (NOTCH_X0, H - NOTCH_D), (NOTCH_X0, H),
             (0, H)],
            W,
            name="BOX01N",
        ),
        extrusion_xz(
            [(0, 0), (L, 0), (L, H), (NOTCH_X1, H), (NOTCH_X1, H + NOTCH_D), (NOTCH_X0, H + NOTCH_D), (NOTCH_X0, H),
             (0, H)],
            W,
            name="BOX01P",
        ),
        pyramid(0.100, 0.080, 0.070, name="PYR01"),
        tetra,
        tetra.mirrored(name="TETRA01R"),
    ]


def extra_models() -> list[Polyhedron]:
    return [
        regular_prism(6, 0.040, 0.060, name="HEXPRISM01"),
        prism([(0, 0), (0.100, 0), (0.100, 0.035), (0.035, 0.035), (0.035, 0.080), (0, 0.080)], 0.050, name="LBLOCK01"),
        frame(0.060, 0.030, 0.030, 0.016, name="FRAME01"),
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="compare instead of writing")
    args = ap.parse_args(argv)
    stale = []
    for m in seed_models() + extra_models():
        path = OUT / f"{m.name}.json"
        if args.check:
            if not path.exists() or path.read_text() != to_native(m):
                stale.append(path.name)
        else:
            save_model(m, path)
            print(f"wrote {path.relative_to(OUT.parents[1])}: V={m.n_vertices} E={m.n_edges} F={m.n_faces}")
    if stale:
        print("out of date: " + ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
