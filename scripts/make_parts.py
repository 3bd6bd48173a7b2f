"""Write a library of small machined parts as a CAD tool would export them: triangulated binary STL files in metres,
each an outline drawn on a sketch plane and extruded (a box, an L bracket, a T block, a U channel, a block with one
edge chamfered, a hexagonal prism, a small stepped block, a bar with a roof-shaped top), 15-90 mm.

    python scripts/make_parts.py out/parts            # out/parts/*.stl
    haptic explore --executor physics --models out/parts --object part_tblock --seed 1

The outlines are drawn in millimetres, triangulated by ear clipping and extruded with trimesh, so every flat face
reaches the library as several triangles, as from any tool; nothing here is fitted to the hand.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import trimesh

# outline (mm, counter-clockwise), extrusion depth (mm), and whether the outline stands up (drawn in the x-z plane)
PARTS: dict[str, tuple[list[tuple[float, float]], float, bool]] = {
    "part_box_60x40x30": ([(0, 0), (60, 0), (60, 40), (0, 40)], 30, False),
    "part_lbracket": ([(0, 0), (60, 0), (60, 10), (10, 10), (10, 40), (0, 40)], 30, True),
    "part_tblock": ([(0, 0), (15, 0), (15, 28), (32, 28), (32, 40), (-17, 40), (-17, 28), (0, 28)], 30, True),
    "part_uchannel": ([(0, 0), (60, 0), (60, 30), (42, 30), (42, 14), (18, 14), (18, 30), (0, 30)], 35, True),
    "part_chamfered": ([(0, 0), (50, 0), (50, 17), (42, 25), (0, 25)], 50, True),
    "part_hexprism": ([(20 * np.cos(a), 20 * np.sin(a)) for a in np.arange(6) * np.pi / 3], 15, False),
    "part_small_step": ([(0, 0), (30, 0), (30, 8), (18, 8), (18, 15), (0, 15)], 20, True),
    "part_roof_bar": ([(0, 0), (90, 0), (90, 12), (60, 45), (30, 45), (0, 12)], 40, True),
}


def ear_clip(p: np.ndarray) -> np.ndarray:
    """Triangles (T, 3) of the simple counter-clockwise polygon ``p`` (n, 2), by ear clipping."""

    def cross(o, a, b) -> float:
        return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))

    idx, tris = list(range(len(p))), []
    while len(idx) > 3:
        for k in range(len(idx)):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = p[i0], p[i1], p[i2]
            if cross(a, b, c) <= 1e-12:
                continue  # a reflex or straight corner
            inside = (cross(a, b, p[j]) >= 0 and cross(b, c, p[j]) >= 0 and cross(c, a, p[j]) >= 0
                      for j in idx if j not in (i0, i1, i2))  # fmt: skip
            if any(inside):
                continue
            tris.append((i0, i1, i2))
            idx.pop(k)
            break
        else:
            raise ValueError("the outline is not a simple counter-clockwise polygon")
    tris.append(tuple(idx))
    return np.array(tris)


def part(outline: list[tuple[float, float]], depth: float, standing: bool) -> trimesh.Trimesh:
    """The outline (mm) extruded ``depth`` mm, in metres; stood up in the x-z plane when ``standing``."""
    p = np.asarray(outline, dtype=float) / 1000.0
    mesh = trimesh.creation.extrude_triangulation(p, ear_clip(p), depth / 1000.0)
    if standing:
        mesh.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0]))
    return mesh


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path, help="new (or empty) directory to write the STL files into")
    args = ap.parse_args(argv)
    if args.out.exists() and any(args.out.iterdir()):
        print(f"error: {args.out} is not empty", file=sys.stderr)
        return 1
    args.out.mkdir(parents=True, exist_ok=True)
    for name, (outline, depth, standing) in PARTS.items():
        part(outline, depth, standing).export(args.out / f"{name}.stl")
    print(f"wrote {len(PARTS)} parts to {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
