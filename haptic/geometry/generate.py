"""Deterministic libraries of many models, for scale tests (``haptic models generate``).

:func:`generate_library` draws ``count`` models from a seeded generator in fixed proportions of families:

- random convex polyhedra (hulls of random points on a sphere, stretched along the axes, kept only when every
  edge, face and dihedral angle is large enough for a fingertip to trace and tell apart), and the mirror image
  of some of them;
- right prisms on regular polygons and antiprisms;
- boxes, wedges and rectangular pyramids whose dimensions lie on a grid of ``DIMENSION_STEP`` (so two of them
  can be as close as one step in one dimension);
- a few non-convex parts: L brackets and blocks with a slot across the top.

The solids come from :mod:`haptic.geometry.shapes`; this module draws their dimensions and keeps them distinct.

Every model is a validated :class:`Polyhedron`; no two are congruent (a key of their sorted dimensions, or for
random solids their sorted edge lengths, is kept unique). :func:`write_library` writes them as native model files
so that they are loaded back through the same import and validation as any library.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import numpy as np

from haptic.errors import ModelError
from haptic.geometry.io import load_library, save_model
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.shapes import (
    antiprism,
    box,
    convex_hull,
    extrusion_xz,
    l_bracket,
    pyramid,
    random_convex_hull,
    regular_prism,
    slotted_block,
)

DIMENSION_STEP = 0.006
"""Grid of the dimensions of boxes, wedges, pyramids, prisms and non-convex parts [m]: well above twice the
matcher's length bound, as in the look-alike library."""
MIN_EDGE = 0.015
"""Shortest edge of a random convex polyhedron [m]."""
MIN_TURN = np.deg2rad(15.0)
"""Smallest angle between the normals of two adjacent faces of a random convex polyhedron [rad]."""
MIN_FACE_WIDTH = 0.010
"""Smallest distance of a face's vertex from a non-adjacent side of its face, for random convex polyhedra [m]."""

FAMILIES = (
    ("hull", 0.30),
    ("mirror", 0.10),
    ("prism", 0.12),
    ("antiprism", 0.08),
    ("box", 0.14),
    ("wedge", 0.10),
    ("pyramid", 0.10),
    ("lblock", 0.03),
    ("slot", 0.03),
)
"""Families and their share of a generated library (they sum to 1)."""


def _grid(rng: np.random.Generator, lo: float, hi: float) -> float:
    """A dimension on the ``DIMENSION_STEP`` grid in [lo, hi] [m]."""
    k = int(rng.integers(int(round(lo / DIMENSION_STEP)), int(round(hi / DIMENSION_STEP)) + 1))
    return round(k * DIMENSION_STEP, 6)


def _traceable(poly: Polyhedron) -> bool:
    """Whether a random solid is one a fingertip can trace: long edges, wide faces, clear dihedral angles."""
    if float(poly.edge_lengths.min()) < MIN_EDGE:
        return False
    n = poly.face_normals
    cos_turn = np.einsum("ij,ij->i", n[poly.edge_left_face], n[poly.edge_right_face])
    if float(cos_turn.max()) > np.cos(MIN_TURN):
        return False
    for loop in poly.faces:
        pts = poly.vertices[list(loop)]
        k = len(pts)
        for i in range(k):
            a, b = pts[i], pts[(i + 1) % k]
            d = (b - a) / np.linalg.norm(b - a)
            for j in range(k):
                if j in (i, (i + 1) % k):
                    continue
                r = pts[j] - a
                if np.linalg.norm(r - (r @ d) * d) < MIN_FACE_WIDTH:
                    return False
    return True


def _random_hull(rng: np.random.Generator, name: str) -> tuple[Polyhedron, tuple]:
    """A traceable convex hull of 6–9 random points on a sphere, stretched along the axes (an affine map keeps
    faces planar and the solid convex)."""
    for _ in range(200):
        k = int(rng.integers(6, 10))
        try:
            base = random_convex_hull(rng, k, 1.0, min_turn_deg=12.0, min_edge=0.3, name=name)
        except ModelError:
            continue
        poly = convex_hull(base.vertices * rng.uniform(0.030, 0.055, size=3), name=name)
        if _traceable(poly):
            return poly, ("hull", *np.round(np.sort(poly.edge_lengths), 3))
    raise ModelError(f"{name}: no traceable random convex polyhedron in 200 draws")


def _family_makers() -> dict[str, Callable[[np.random.Generator, str], tuple[Polyhedron, tuple]]]:
    def hull(rng, name):
        return _random_hull(rng, name)

    def prism_(rng, name):
        s, r, h = int(rng.integers(3, 9)), _grid(rng, 0.030, 0.060), _grid(rng, 0.030, 0.090)
        return regular_prism(s, r, h, name=name), ("prism", s, r, h)

    def antiprism_(rng, name):
        s, r, h = int(rng.integers(3, 8)), _grid(rng, 0.030, 0.060), _grid(rng, 0.030, 0.078)
        return antiprism(s, r, h, name=name), ("antiprism", s, r, h)

    def box_(rng, name):
        d = sorted(_grid(rng, 0.036, 0.120) for _ in range(3))
        return box(*d, name=name), ("box", *d)

    def wedge(rng, name):
        lx, lz, w = _grid(rng, 0.060, 0.120), _grid(rng, 0.036, 0.090), _grid(rng, 0.036, 0.096)
        return extrusion_xz([(0, 0), (lx, 0), (0, lz)], w, name=name), ("wedge", lx, lz, w)

    def pyramid_(rng, name):
        bx, by, h = _grid(rng, 0.048, 0.120), _grid(rng, 0.048, 0.120), _grid(rng, 0.036, 0.096)
        bx, by = max(bx, by), min(bx, by)
        return pyramid(bx, by, h, name=name), ("pyramid", bx, by, h)

    def lblock(rng, name):
        lx, lz, t, w = _grid(rng, 0.060, 0.110), _grid(rng, 0.060, 0.110), _grid(rng, 0.024, 0.042), _grid(
            rng, 0.030, 0.072
        )
        return l_bracket(lx, lz, t, w, name=name), ("lblock", lx, lz, t, w)

    def slot(rng, name):
        lx, w, h = _grid(rng, 0.072, 0.120), _grid(rng, 0.048, 0.096), _grid(rng, 0.048, 0.084)
        sw, sd = _grid(rng, 0.018, 0.036), _grid(rng, 0.012, 0.024)
        return slotted_block(lx, w, h, sw, sd, name=name), ("slot", lx, w, h, sw, sd)

    return {
        "hull": hull, "prism": prism_, "antiprism": antiprism_, "box": box_, "wedge": wedge, "pyramid": pyramid_,
        "lblock": lblock, "slot": slot,
    }  # fmt: skip


def family_counts(count: int) -> dict[str, int]:
    """How many models of each family a library of ``count`` models holds (largest remainders)."""
    share = np.array([s for _, s in FAMILIES]) * count
    n = np.floor(share).astype(int)
    for i in np.argsort(-(share - n), kind="stable")[: count - int(n.sum())]:
        n[i] += 1
    return {f: int(k) for (f, _), k in zip(FAMILIES, n, strict=True)}


def iter_library(count: int, seed: int = 0) -> Iterator[Polyhedron]:
    """The models of a generated library, one at a time (names ``GEN_<family>_<index>``)."""
    if count < 1:
        raise ModelError(f"--count must be at least 1, got {count}")
    rng = np.random.default_rng(seed)
    makers = _family_makers()
    counts = family_counts(count)
    seen: set[tuple] = set()
    hulls: list[Polyhedron] = []
    width = len(str(count - 1))
    index = 0
    for family, n in counts.items():
        for _ in range(n):
            name = f"GEN_{family.upper()}_{index:0{width}d}"
            if family == "mirror":
                if hulls:
                    src = hulls.pop(0)
                    poly = src.mirrored(name=name)
                    yield poly
                    index += 1
                    continue
                family_ = "hull"
            else:
                family_ = family
            for _attempt in range(500):
                poly, key = makers[family_](rng, name)
                if key not in seen:
                    break
            else:
                raise ModelError(f"{name}: no new {family_} in 500 draws; ask for fewer models")
            seen.add(key)
            if family_ == "hull":
                hulls.append(poly)
            yield poly
            index += 1


def generate_library(count: int, seed: int = 0) -> list[Polyhedron]:
    """``count`` models drawn deterministically from ``seed`` (see the module docstring)."""
    return list(iter_library(count, seed))


def write_library(models: Iterable[Polyhedron], out: str | os.PathLike) -> dict[str, Polyhedron]:
    """Write models as native files into a new (or empty) directory and load them back through the library
    import (which validates every file); returns the loaded library. Nothing is left at ``out`` unless all of
    it is written and valid: the files go to a temporary directory beside ``out``, renamed to ``out`` at the
    end."""
    import shutil
    import tempfile

    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise ModelError(f"{out}: the output directory exists and is not empty; give a new directory")
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    try:
        for m in models:
            save_model(m, tmp / f"{m.name}.json")
        load_library(tmp)
        try:
            if out.exists():
                out.rmdir()
            tmp.rename(out)
        except OSError:
            raise ModelError(f"{out}: another library was written there meanwhile; give a new directory") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return load_library(out)
