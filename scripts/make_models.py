"""Write the shipped model libraries as native JSON, from the dimensions in their READMEs.

    python scripts/make_models.py            # rewrite assets/models and assets/libraries/lookalike
    python scripts/make_models.py --check    # exit 1 if the files differ from what this script makes

``assets/models`` holds the source paper's objects and three more; ``assets/libraries/lookalike`` holds
objects made to be hard to tell apart: boxes and prisms of close dimensions, mirror pairs, notch and bump
variants.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from haptic.geometry import Polyhedron, save_model
from haptic.geometry.io import to_native
from haptic.geometry.shapes import box, extrusion_xz, frame, prism, pyramid, regular_prism, tetrahedron

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "assets" / "models"
LOOKALIKE = ROOT / "assets" / "libraries" / "lookalike"

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


def _notched(name: str, x0: float, x1: float, depth: float, size=(L, W, H)) -> Polyhedron:
    """A box with a slot across its top (depth > 0) or a block standing on it (depth < 0), along y."""
    lx, ly, lz = size
    z = lz - depth
    profile = [(0, 0), (lx, 0), (lx, lz), (x1, lz), (x1, z), (x0, z), (x0, lz), (0, lz)]
    return extrusion_xz(profile, ly, name=name)


def lookalike_models() -> list[Polyhedron]:
    mm = 1e-3
    out: list[Polyhedron] = []
    for dims in [(100, 80, 60), (100, 80, 66), (100, 86, 60), (94, 80, 60), (100, 74, 60), (106, 80, 60),
                 (100, 80, 54), (80, 80, 60)]:
        out.append(box(*(d * mm for d in dims), name="LA_BOX_{}x{}x{}".format(*dims)))
    for base, height, depth in [(100, 60, 80), (100, 54, 80), (94, 60, 80), (100, 60, 74)]:
        profile = [(0, 0), (base * mm, 0), (0, height * mm)]
        out.append(extrusion_xz(profile, depth * mm, name=f"LA_WEDGE_{base}x{height}x{depth}"))
    out += [
        regular_prism(5, 0.045, 0.060, name="LA_PENTPRISM_r45h60"),
        regular_prism(6, 0.040, 0.060, name="LA_HEXPRISM_r40h60"),
        regular_prism(6, 0.045, 0.060, name="LA_HEXPRISM_r45h60"),
        regular_prism(6, 0.040, 0.054, name="LA_HEXPRISM_r40h54"),
    ]
    for k, apex in enumerate([(35, 25, 70), (30, 30, 70), (35, 25, 62)]):
        t = tetrahedron((0, 0, 0), (0.100, 0, 0), (0.025, 0.080, 0), tuple(a * mm for a in apex), name=f"LA_TETRA{k}L")
        out += [t, t.mirrored(name=f"LA_TETRA{k}R")]
    for name, x0, x1, depth in [("LA_NOTCH_30x20", 35, 65, 20), ("LA_NOTCH_20x20", 40, 60, 20),
                                ("LA_NOTCH_30x12", 35, 65, 12), ("LA_BUMP_30x20", 35, 65, -20),
                                ("LA_BUMP_20x20", 40, 60, -20), ("LA_NOTCH_OFF_30x20", 20, 50, 20)]:
        out.append(_notched(name, x0 * mm, x1 * mm, depth * mm))
    for name, apex in [("LA_PYR_h70", (0, 0)), ("LA_PYR_h70_off", (12, 8))]:
        out.append(pyramid(0.100, 0.080, 0.070, apex_xy=(apex[0] * mm, apex[1] * mm), name=name))
    off = out[-1]
    out.append(off.mirrored(name="LA_PYR_h70_offM"))
    out.append(pyramid(0.100, 0.080, 0.062, name="LA_PYR_h62"))
    out.append(
        prism([(0, 0), (0.100, 0), (0.100, 0.035), (0.035, 0.035), (0.035, 0.080), (0, 0.080)], 0.050, name="LA_L_35")
    )
    out.append(
        prism([(0, 0), (0.100, 0), (0.100, 0.029), (0.029, 0.029), (0.029, 0.080), (0, 0.080)], 0.050, name="LA_L_29")
    )
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="compare instead of writing")
    args = ap.parse_args(argv)
    stale = []
    todo = [(OUT, m) for m in seed_models() + extra_models()] + [(LOOKALIKE, m) for m in lookalike_models()]
    for folder, m in todo:
        path = folder / f"{m.name}.json"
        if args.check:
            if not path.exists() or path.read_text() != to_native(m):
                stale.append(path.name)
        else:
            save_model(m, path)
            print(f"wrote {path.relative_to(ROOT)}: V={m.n_vertices} E={m.n_edges} F={m.n_faces}")
    if stale:
        print("out of date: " + ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
