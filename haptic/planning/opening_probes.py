"""Probe lines of the opening, before any hypothesis has a pose (``--moves probing``): the library's extent
(:class:`LibraryExtent`: how large its objects are, and what the opening's tracing moves travel on them on
average, for choosing between those and a probe), the estimated centre of the object's region from the data
faces, and the lines toward it, ranked by how much a face they would hit adds to the faces measured."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.matching.components import DataFace
from haptic.planning.moves import ProbeMove
from haptic.planning.probe_lines import ProbeConfig, clip_to_balls, fibonacci_directions, line_through

BEHIND = 0.05
"""Opening probes head along every known face's normal, or across it within this (``u · n ≥ −0.05``)."""


@dataclass(frozen=True)
class LibraryExtent:
    """How large the library's objects are, for aiming probes before any hypothesis has a pose, and what the
    opening's tracing moves travel on them on average (for choosing between those and a probe)."""

    reach: float
    """The largest distance between two vertices of one model: every point of the object lies within this of
    every contact [m]."""
    depth: float
    """The median over the library of a model's centroid's distance to its nearest face plane: how far behind
    a contact, against its normal, the object's inside is aimed at [m]."""
    face_run: float = 0.0
    """Expected length of a face move from a point of a face to its boundary: half the mean chord of a
    uniform random line across a face, ``π A / (2 P)`` (area ``A``, perimeter ``P``), averaged over the
    library's faces weighted by area (the sensor lands on a face with chance in proportion to it) [m]."""
    edge_run: float = 0.0
    """Expected length of an edge move from where a face move met an edge to the edge's end: half an edge,
    edges weighted by length (a face move meets an edge with chance in proportion to it), ``E[l²] / (2 E[l])``
    over the library's edges [m]."""
    corner_angle: float = 0.0
    """Mean interior angle of the library's face corners: the turn of a vertex move from the edge it starts on
    to the next edge of the face [rad]."""

    @classmethod
    def of(cls, models: Iterable[Polyhedron]) -> LibraryExtent:
        """The extent of a library's models."""
        reach, depths = 0.0, []
        runs, areas, lengths, corners = [], [], [], []
        for poly in models:
            v = poly.vertices
            reach = max(reach, float(np.sqrt(((v[:, None] - v[None]) ** 2).sum(-1)).max()))
            depths.append(float(np.abs(poly.face_offsets - poly.face_normals @ poly.centroid).min()))
            edge_l = poly.edge_lengths
            lengths.extend(edge_l.tolist())
            for f, fe in enumerate(poly.face_edges):
                area = float(poly.face_areas[f])
                runs.append(np.pi * area / (2.0 * float(edge_l[list(fe)].sum())))
                areas.append(area)
                ring = v[list(poly.face_vertices(f))]
                a, b = np.roll(ring, 1, axis=0) - ring, np.roll(ring, -1, axis=0) - ring
                cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
                corners.extend(np.arccos(np.clip(cos, -1.0, 1.0)).tolist())
        if not depths:
            return cls(0.0, 0.0)
        lengths = np.array(lengths)
        return cls(
            reach,
            float(np.median(depths)),
            face_run=float(np.average(runs, weights=areas)),
            edge_run=float((lengths**2).sum() / (2.0 * lengths.sum())),
            corner_angle=float(np.mean(corners)),
        )


def region_centre(faces: Sequence[DataFace], extent: LibraryExtent) -> np.ndarray:
    """The estimated centre of the object's region before any pose, ``c = mean(q_i − depth · n_i)`` over the
    data faces (contact points ``q_i``, outward normals ``n_i``) [m]; the opening probes' lines run through it."""
    q = np.array([np.mean(np.atleast_2d(f.points), axis=0) for f in faces])
    n = np.array([f.normal for f in faces])
    return (q - extent.depth * n).mean(axis=0)


def opening_probes(
    faces: Sequence[DataFace], extent: LibraryExtent, config: ProbeConfig | None = None, unmeasured: bool = False
) -> list[ProbeMove]:
    """Probe lines toward the object's region before hypotheses have poses (the opening of ``--moves probing``),
    best first: a fixed spread of approach directions (:attr:`ProbeConfig.n_directions`, a Fibonacci lattice),
    each line through the region's estimated centre ``c = mean(q_i − depth · n_i)`` over the data faces (their
    contact points ``q_i`` and outward normals ``n_i``), running across the region that must hold the object:
    the intersection of the balls of radius ``reach`` about the contacts (plus the standoff). Ranked by how
    nearly the face each would hit is perpendicular to every normal measured so far (smallest
    ``max_i |u · n_i|``): a face whose normal is independent of the known ones is what fixes the rotation (two
    normals) and the translation (three planes), hence the poses. Directions heading against a known face's
    normal (``u · n_i < −``:data:`BEHIND`) come after all the others: such a line may enter through that face
    again, and a convex object's face is never met from behind. With ``unmeasured`` (once the rotation is
    known, under ``--moves probing`` while the tree is too large for the probe matcher to test hits by their
    position) they are ranked instead by how far the approach is from every measured normal (smallest
    ``max_i (−u · n_i)``): the faces not met yet, those opposite the known ones first (whose distance from
    them the tree tests, §2.6)."""
    config = config or ProbeConfig()
    if not faces:
        return []
    q = np.array([np.mean(np.atleast_2d(f.points), axis=0) for f in faces])
    n = np.array([f.normal for f in faces])
    centre = region_centre(faces, extent)
    radius = extent.reach + extent.depth + config.standoff
    dirs = fibonacci_directions(config.n_directions)
    if config.table_z is not None:
        dirs = dirs[dirs[:, 2] <= config.max_climb]
    # from behind every known face first (no such line enters through one again), then the rest
    if unmeasured:
        order = np.argsort((-(dirs @ n.T)).max(axis=1), kind="stable")
    else:
        ahead = ~(dirs @ n.T >= -BEHIND).all(axis=1)
        order = np.lexsort((np.abs(dirs @ n.T).max(axis=1), ahead))
    within = (q, np.full(len(q), extent.reach))  # every point of the object is within reach of every contact
    out = []
    for u in dirs[order]:
        move = line_through(centre, u, centre, radius, config)
        if move is not None:
            move = clip_to_balls(move, within, config.standoff, union=False)
        if move is not None:
            out.append(move)
    return out


__all__ = ["BEHIND", "LibraryExtent", "opening_probes", "region_centre"]
