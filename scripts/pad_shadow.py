"""Whether the moves of the vertices the verification cannot measure lie in the pad's shadow: for each episode's
object at its true resting pose, each vertex that ``--verify full`` counts out of the hand's reach off the table or
cannot pin on it, and each move of that vertex, how deep a free pad -- a ball of the pad's radius, anywhere clear of
the object and of the table, no finger attached -- feels the moved object apart from the model.

    .venv/bin/python scripts/pad_shadow.py [--pairs BOX01N:1,FRAME01:3] [--objects ...] [--seeds 1,2,3]
                                           [--models DIR] [--step MM] [--json out.json]

The moves: along the vertex normal by 2, 4 and 8 mm (:func:`~haptic.geometry.perturb.move_vertex`, what
``scripts/bench_unknown.py`` perturbs); 4 mm along plus and minus each of its faces' normals (the model's triangles
with the vertex moved: a move in a face's plane keeps that face's plane and moves its rim); and 4 mm chamfers of its
convex edges (:func:`~haptic.geometry.perturb.chamfer_edge`; "refused" where the chamfer's plane would cut other
vertices of a concave model). A pad centre on a grid (``--step``, 2 mm) near where the two differ, at least the
executor's limit over the table (its lowest point 2 mm up), clear of one of them and within a step of touching the
other, feels the difference when its distances to the two differ by more than :data:`FELT` (how far apart a pad
pressing from there meets them); the model faces nearest such centres say where. A vertex every one of whose
moves no such pad feels lies in the pad's shadow: no measurement by any finger could tell those moves apart, and the
verification could take it on trust, as it takes the table's shadow (:func:`~haptic.planning.verify.table_shadow`).
A free pad reaches more than the hand's fingers do, so a move it feels is one some finger might measure, not one the
hand does. Geometry only; ground truth is read here (this is evaluation), never by the executor.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass

import numpy as np

from haptic.episode.spec import EpisodeSpec, episode_pairs
from haptic.episode.worlds import build_episode
from haptic.errors import HapticError, ModelError
from haptic.geometry import Polyhedron, load_library
from haptic.geometry.distance import point_triangle_distance, surface_distance, surface_grid
from haptic.geometry.io import atomic_write
from haptic.geometry.kernels import contains
from haptic.geometry.perturb import chamfer_edge, move_vertex
from haptic.geometry.se3 import SE3
from haptic.matching.acceptance import corner_triangle
from haptic.planning.verify import out_of_reach

SEVEN = "BOX01N:1,BOX01N:3,BOX01P:1,BOX01P:2,FRAME01:1,FRAME01:2,FRAME01:3"
"""The seed library's episodes whose default full verification ends with vertices out of the hand's reach."""
PAD_LIMIT = 0.002
"""The pad's lowest point at least this above the table (the executor's limit; the planner keeps 4 mm) [m]."""
FELT = 5e-4
"""A pad centre clear of one surface and this far inside the other feels the difference [m] (the hand's position
noise is about 0.15 mm)."""
SAMPLE = 1e-3
"""Spacing of the points sampled over the two surfaces to find where they differ [m]."""
DIFFER = 3e-4
"""A sampled point of one surface farther than this from the other is where they differ [m]."""
NORMAL_MM = (2.0, 4.0, 8.0)
ALONG_MM = 4.0
CHAMFER_MM = 4.0


@dataclass(frozen=True)
class Surface:
    """A closed triangulated surface (model frame): a model's triangles with one vertex moved, which need not make
    a valid :class:`Polyhedron` (no face split where it bends), for the distance and inside tests."""

    vertices: np.ndarray
    triangles: np.ndarray

    def contains(self, points: np.ndarray) -> np.ndarray:
        tri = np.ascontiguousarray(self.vertices[self.triangles], dtype=float)
        return contains(np.ascontiguousarray(np.atleast_2d(points), dtype=float), tri)


def _signed(surface, points: np.ndarray) -> np.ndarray:
    d = surface_distance(surface, points)
    return np.where(surface.contains(points), -d, d)


def felt(model: Polyhedron, moved, world_from_model: SE3, table_z: float, radius: float,
         step: float = 0.002) -> tuple[float, list[int]]:  # fmt: skip
    """How deep a free pad of ``radius``, its lowest point at least :data:`PAD_LIMIT` over the table (``table_z``),
    feels ``moved`` (a :class:`Polyhedron` or a :class:`Surface`, model frame) apart from ``model`` at
    ``world_from_model`` [m], and the model faces nearest the pad centres that feel it by more than :data:`FELT`:
    over a grid of ``step`` within reach of where the two differ, at the centres clear of one surface (by
    ``radius``) and within ``step`` of touching the other, the largest difference of their distances to the two --
    how far apart a pad pressing from there meets them. (0, []) where they do not differ or no pad clear of the
    table comes near."""
    from scipy.spatial import cKDTree

    pm, pv = surface_grid(model, SAMPLE), surface_grid(moved, SAMPLE)
    where = np.concatenate([pm[surface_distance(moved, pm) > DIFFER], pv[surface_distance(model, pv) > DIFFER]])
    if not len(where):
        return 0.0, []
    lo, hi = where.min(axis=0) - radius - step, where.max(axis=0) + radius + step
    grid = np.stack(np.meshgrid(*(np.arange(lo[k], hi[k] + 1e-12, step) for k in range(3)), indexing="ij"), axis=-1)
    g = grid.reshape(-1, 3)
    g = g[np.isfinite(cKDTree(where).query(g, distance_upper_bound=radius + 2 * step)[0])]
    g = g[world_from_model.apply(g)[:, 2] - radius - table_z >= PAD_LIMIT]
    if not len(g):
        return 0.0, []
    dm, dv = _signed(model, g), _signed(moved, g)
    # a centre clear of one surface and within a step of touching the other: a pad pressing toward the surfaces
    # from there meets them that much apart (a grid finds a centre exactly at touching only by chance, and a
    # difference narrower than a step would slip between the centres)
    near = (np.maximum(dm, dv) >= radius) & (np.minimum(dm, dv) <= radius + step)
    depth = np.where(near, np.abs(dm - dv), 0.0)
    hit = depth > FELT
    faces = []
    if hit.any():
        nearest = np.argmin(point_triangle_distance(g[hit], model.vertices[model.triangles]), axis=1)
        faces = sorted({int(model.triangle_faces[i]) for i in nearest})
    return float(depth.max()), faces


def moves_of(model: Polyhedron, v: int) -> list[tuple[str, object | None]]:
    """The moves of vertex ``v`` of ``model`` asked about (the module's docstring), each with its moved surface or
    None where the move is refused."""
    out: list[tuple[str, object | None]] = []
    for mm in NORMAL_MM:
        try:
            out.append((f"normal {mm:g}", move_vertex(model, v, mm * 1e-3)))
        except ModelError:
            out.append((f"normal {mm:g}", None))
    for f in (int(f) for f in model.vertex_faces[v]):
        for sign in (1.0, -1.0):
            moved = np.array(model.vertices)
            moved[v] += sign * ALONG_MM * 1e-3 * model.face_normals[f]
            out.append((f"{'+' if sign > 0 else '-'}n{f} {ALONG_MM:g}", Surface(moved, np.asarray(model.triangles))))
    for e in (int(e) for e in model.vertex_edges[v]):
        if model.edge_convexity[e] <= 0:
            continue
        try:
            out.append((f"chamfer e{e} {CHAMFER_MM:g}", chamfer_edge(model, e, CHAMFER_MM * 1e-3)))
        except ModelError:
            out.append((f"chamfer e{e} {CHAMFER_MM:g}", None))
    return out


def study(model: str, seed: int, library, step: float) -> dict:
    """The vertices out of the verification's reach of one episode's object at its pose (off the table, or on it
    with nothing in reach to pin them) and, per move of each, how deep a free pad feels it and where."""
    ep = build_episode(EpisodeSpec(model=model, seed=seed, executor="physics", verify="full"), library)
    poly, pose, cfg = ep.true_model, ep.world_from_model, ep.config
    reach, hidden, unpinned = out_of_reach(poly, pose, cfg)
    z = pose.apply(poly.vertices)[:, 2] - cfg.table_z
    out = {"model": model, "seed": seed, "faces_in_reach": sorted(int(f) for f in reach[0]), "vertices": []}
    for v in [*hidden, *(int(u) for u in unpinned)]:
        rows = []
        for name, moved in moves_of(poly, v):
            if moved is None:
                rows.append({"move": name, "felt_mm": None, "faces": []})
                continue
            depth, faces = felt(poly, moved, pose, cfg.table_z, cfg.pad_radius, step)
            rows.append({"move": name, "felt_mm": round(depth * 1000.0, 2), "faces": faces})
        out["vertices"].append({
            "vertex": v, "height_mm": round(float(z[v]) * 1000.0, 1), "on_table": v not in hidden,
            "reflex_at": [int(f) for f in poly.vertex_faces[v] if corner_triangle(poly, v, int(f)) is None],
            "moves": rows,
            "shadowed": all(r["felt_mm"] is None or r["felt_mm"] <= FELT * 1000.0 for r in rows),
        })  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--models", default=None, metavar="DIR", help="library directory (default: the shipped one)")
    ap.add_argument("--objects", default=None, help="comma-separated model names (default: every model)")
    ap.add_argument("--seeds", default="1", help="comma-separated episode seeds")
    ap.add_argument("--pairs", default=None, help=f"OBJECT:SEED,... in place of --objects/--seeds (the seed "
                                                   f"library's seven out-of-reach episodes: {SEVEN})")
    ap.add_argument("--step", type=float, default=2.0, help="spacing of the pad centres' grid [mm]")
    ap.add_argument("--json", default=None, help="write the findings here")
    args = ap.parse_args(argv)
    try:
        library = load_library(args.models) if args.models else None
        pairs = episode_pairs(args.pairs, args.objects, args.seeds, lambda: sorted(library or load_library()))
        rows, n_vertices, shadowed, worst = [], 0, 0, []
        for model, seed in pairs:
            r = study(model, seed, library, args.step * 1e-3)
            rows.append(r)
            if not r["vertices"]:
                continue
            print(f"{model} seed {seed} (faces in the verification's reach {r['faces_in_reach']}):", flush=True)
            for x in r["vertices"]:
                n_vertices += 1
                shadowed += x["shadowed"]
                if not x["shadowed"]:
                    worst.append(max(m["felt_mm"] for m in x["moves"] if m["felt_mm"] is not None))
                where = "on the table" if x["on_table"] else f"{x['height_mm']:.0f} mm up"
                reflex = f", reflex on faces {x['reflex_at']}" if x["reflex_at"] else ""
                moves = "; ".join(
                    f"{m['move']} " + ("refused" if m["felt_mm"] is None
                                       else f"{m['felt_mm']:.2f}" + (f" on f{m['faces']}" if m["faces"] else ""))
                    for m in x["moves"])  # fmt: skip
                print(f"  v{x['vertex']} {where}{reflex}: {'in the pad shadow' if x['shadowed'] else 'felt'} "
                      f"(mm felt per move: {moves})", flush=True)  # fmt: skip
        felt_by = f"; the others' deepest move felt {min(worst):.2f} to {max(worst):.2f} mm" if worst else ""
        print(f"\n{n_vertices} vertices out of the verification's reach in {sum(1 for r in rows if r['vertices'])} "
              f"of {len(rows)} episodes; {shadowed} in the pad's shadow (no move felt by a free pad clear of the "
              f"table){felt_by}")  # fmt: skip
        if args.json:
            atomic_write(args.json, json.dumps(rows, indent=1))
        return 0
    except HapticError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
