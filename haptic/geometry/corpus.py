"""A corpus of third-party-like model files: formula solids written as other tools write them.

Every solid is written in four encodings, one library directory each, at one seeded random pose:

- ``obj6``: polygonal OBJ in metres at 6 decimals (a common exporter default: 1 µm);
- ``objmm3``: polygonal OBJ in millimetres at 3 decimals, declaring ``# units: mm``;
- ``stl``: binary STL (float32, triangulated) in metres;
- ``objtri``: triangulated OBJ in metres at 6 decimals.

Each solid's V/E/F and the order of its rotation group are known from its formula (not measured from the
model), and written to ``manifest.json`` beside the directories, so an import can be checked against them.
"""

from __future__ import annotations

import functools
import json
import os
import struct
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from haptic.errors import ModelError
from haptic.geometry.io import atomic_write
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import random_rotation
from haptic.geometry.shapes import (
    PLATONIC,
    antiprism,
    bipyramid,
    l_bracket,
    platonic,
    random_convex_hull,
    regular_prism,
    slotted_block,
    stepped_block,
    trapezohedron,
)

ENCODINGS = ("obj6", "objmm3", "stl", "objtri")
"""The corpus's file encodings, one library directory each."""

RADIUS = 0.04
"""Circumradius of the non-Platonic formula solids [m] (the Platonic ones: 50 mm); each is 5–12 cm across."""

_PLATONIC_COUNTS = {
    "tetrahedron": (4, 6, 4, 12),
    "cube": (8, 12, 6, 24),
    "octahedron": (6, 12, 8, 24),
    "dodecahedron": (20, 30, 12, 60),
    "icosahedron": (12, 30, 20, 60),
}


@dataclass(frozen=True)
class CorpusSolid:
    """One solid of the corpus with what its formula says about it."""

    name: str
    """Model name (the file stem in every encoding)."""
    family: str
    """Family: platonic, prism, antiprism, bipyramid, trapezohedron, hull, cad."""
    V: int
    """Number of vertices, from the formula."""
    E: int
    """Number of edges, from the formula."""
    F: int
    """Number of faces, from the formula."""
    symmetry: int
    """Order of the rotation group, from the formula."""


@functools.lru_cache(maxsize=4)
def corpus_solids(sides: range = range(3, 13), hulls: int = 8, seed: int = 0) -> list[tuple[CorpusSolid, Polyhedron]]:
    """The corpus's solids in their formula frames, with their known counts.

    ``sides``: the polygons of the prism, antiprism, bipyramid and trapezohedron families; ``hulls``: how many
    seeded random convex hulls (6 to 13 points, rotation group of order 1).
    """
    r = RADIUS
    out: list[tuple[CorpusSolid, Polyhedron]] = []
    for kind in PLATONIC:
        v, e, f, g = _PLATONIC_COUNTS[kind]
        out.append((CorpusSolid(f"platonic_{kind}", "platonic", v, e, f, g), platonic(kind, 0.05)))
    for n in sides:
        # heights away from the special values at which a solid gains symmetry (cube, octahedron)
        out.append((CorpusSolid(f"prism_{n:02d}", "prism", 2 * n, 3 * n, n + 2, 2 * n), regular_prism(n, r, 0.055)))
        out.append(
            (CorpusSolid(f"antiprism_{n:02d}", "antiprism", 2 * n, 4 * n, 2 * n + 2, 2 * n), antiprism(n, r, 0.045))
        )
        out.append(
            (CorpusSolid(f"bipyramid_{n:02d}", "bipyramid", n + 2, 3 * n, 2 * n, 2 * n), bipyramid(n, r, 0.05))
        )
        c = np.cos(np.pi / n)
        zigzag = 0.045 * (1 - c) / (1 + c)  # apexes 45 mm from the middle
        out.append(
            (
                CorpusSolid(f"trapezohedron_{n:02d}", "trapezohedron", 2 * n + 2, 4 * n, 2 * n, 2 * n),
                trapezohedron(n, r, zigzag),
            )
        )
    rng = np.random.default_rng(seed)
    for k in range(hulls):
        n = 6 + k % 8
        poly = random_convex_hull(rng, n, r)  # triangles only: F = 2n − 4, E = 3n − 6
        out.append((CorpusSolid(f"hull_{k:02d}", "hull", n, 3 * n - 6, 2 * n - 4, 1), poly))
    out += [
        (CorpusSolid("cad_stepped", "cad", 12, 18, 8, 1), stepped_block(0.10, 0.06, 0.06)),
        (CorpusSolid("cad_stepped3", "cad", 16, 24, 10, 1), stepped_block(0.10, 0.06, 0.06, steps=3)),
        (CorpusSolid("cad_lbracket", "cad", 12, 18, 8, 2), l_bracket(0.08, 0.08, 0.02, 0.05)),
        (CorpusSolid("cad_lbracket_long", "cad", 12, 18, 8, 1), l_bracket(0.10, 0.06, 0.02, 0.05)),
        (CorpusSolid("cad_slotted", "cad", 16, 24, 10, 2), slotted_block(0.10, 0.06, 0.05, 0.03, 0.02)),
    ]
    return [(s, Polyhedron.from_faces(p.vertices, p.faces, name=s.name)) for s, p in out]


def posed(poly: Polyhedron, rng: np.random.Generator) -> np.ndarray:
    """The solid's vertices at a random orientation about its centroid, centred near the origin [m]."""
    c = poly.centroid
    return (poly.vertices - c) @ random_rotation(rng).T + rng.uniform(-0.01, 0.01, size=3)


def obj_text(name: str, vertices: np.ndarray, faces, decimals: int, units: str = "m") -> str:
    """OBJ text with coordinates written at ``decimals`` in ``units`` (declared in a comment)."""
    scale = {"m": 1.0, "mm": 1e3}[units]
    lines = [f"# {name}", f"# units: {units}"]
    lines += [f"v {x:.{decimals}f} {y:.{decimals}f} {z:.{decimals}f}" for x, y, z in vertices * scale]
    lines += ["f " + " ".join(str(i + 1) for i in f) for f in faces]
    return "\n".join(lines) + "\n"


def binary_stl(name: str, vertices: np.ndarray, triangles: np.ndarray) -> bytes:
    """Binary STL bytes (float32 normals and corners), one record per triangle."""
    out = [f"{name} binary STL, metres".encode().ljust(80, b" ")[:80], struct.pack("<I", len(triangles))]
    for a, b, c in triangles:
        n = np.cross(vertices[b] - vertices[a], vertices[c] - vertices[a])
        n = n / np.linalg.norm(n)
        out.append(struct.pack("<12fH", *n, *vertices[a], *vertices[b], *vertices[c], 0))
    return b"".join(out)


def write_corpus(
    directory: str | os.PathLike,
    seed: int = 0,
    encodings: tuple[str, ...] = ENCODINGS,
    solids: list[tuple[CorpusSolid, Polyhedron]] | None = None,
) -> dict[str, Path]:
    """Write the corpus under ``directory`` (one library directory per encoding, and ``manifest.json``).

    Returns the library directory of each encoding. Deterministic in ``seed`` (the poses and the hulls).
    """
    root = Path(directory)
    rng = np.random.default_rng(seed)
    solids = corpus_solids(seed=seed) if solids is None else solids
    dirs = {enc: root / enc for enc in encodings}
    for spec, poly in solids:
        v = posed(poly, rng)
        tris = poly.triangles
        for enc, d in dirs.items():
            if enc == "obj6":
                atomic_write(d / f"{spec.name}.obj", obj_text(spec.name, v, poly.faces, 6))
            elif enc == "objmm3":
                atomic_write(d / f"{spec.name}.obj", obj_text(spec.name, v, poly.faces, 3, units="mm"))
            elif enc == "stl":
                atomic_write(d / f"{spec.name}.stl", binary_stl(spec.name, v, tris))
            elif enc == "objtri":
                atomic_write(d / f"{spec.name}.obj", obj_text(spec.name, v, tris, 6))
            else:
                raise ModelError(f"unknown corpus encoding {enc!r}; valid: {', '.join(ENCODINGS)}")
    manifest = {"seed": seed, "encodings": list(encodings), "solids": [asdict(s) for s, _ in solids]}
    atomic_write(root / "manifest.json", json.dumps(manifest, indent=1) + "\n")
    return dirs
