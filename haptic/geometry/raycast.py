"""Lines against a polyhedron: where a straight path first meets the surface, and how deep it runs inside.

The free-space probe (Grimson and Lozano-Pérez's sensing paradigm, seed §1.1) moves the sensor along a line
until it touches the object. These functions give, in the model frame, the exact first contact of such a line
(Möller–Trumbore against the model's triangulation, vectorised over many lines at once) and, for a line that
would pass through the solid, how far inside it runs (the largest distance from the surface of a point of the
segment that is inside): a probe reported free of the object can only contradict a hypothesis whose object
that segment enters deeper than the probe's error bounds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from haptic.geometry import kernels
from haptic.geometry.distance import surface_distance
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import cross

BARYCENTRIC_SLACK = 1e-9
"""Relative slack on the barycentric coordinates: a line through a triangle's edge (a diagonal of a face's
triangulation, or an edge of the model) meets both triangles rather than neither."""
DEPTH_SAMPLES = 9
"""Points sampled across each inside interval of a segment for its depth (the ends and the middle included)."""


@dataclass(frozen=True, eq=False)
class LineHits:
    """Where each of R lines meets a polyhedron's surface (model frame)."""

    first: np.ndarray
    """Parameter ``t ≥ 0`` of the first surface point along each line (``start + t u``), +inf for none, (R,) [m]."""
    face: np.ndarray
    """Model face of that first point, −1 for none, shape (R,)."""
    params: np.ndarray
    """Every crossing parameter per line and triangle, NaN where a line misses a triangle, shape (R, T) [m]."""


def line_hits(poly: Polyhedron, starts: np.ndarray, directions: np.ndarray) -> LineHits:
    """Every crossing of the lines ``start + t u`` (unit ``u``, model frame; shapes (R, 3)) with the triangles
    of ``poly``, and the first with ``t ≥ 0``."""
    o = np.atleast_2d(np.asarray(starts, dtype=float))
    u = np.atleast_2d(np.asarray(directions, dtype=float))
    tri = poly.vertices[poly.triangles]  # (T, 3, 3)
    a = tri[:, 0]
    e1, e2 = tri[:, 1] - a, tri[:, 2] - a
    pvec = cross(u[:, None, :], e2[None])  # (R, T, 3)
    det = np.einsum("tk,rtk->rt", e1, pvec)
    ok = np.abs(det) > 1e-18
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = o[:, None, :] - a[None]
    bu = np.einsum("rtk,rtk->rt", s, pvec) * inv
    qvec = cross(s, e1[None])
    bv = np.einsum("rk,rtk->rt", u, qvec) * inv
    t = np.einsum("tk,rtk->rt", e2, qvec) * inv
    slack = BARYCENTRIC_SLACK
    hit = ok & (bu >= -slack) & (bv >= -slack) & (bu + bv <= 1.0 + slack)
    params = np.where(hit, t, np.nan)
    ahead = np.where(hit & (t >= 0.0), t, np.inf)
    k = np.argmin(ahead, axis=1) if ahead.shape[1] else np.zeros(len(o), dtype=int)
    first = ahead[np.arange(len(o)), k] if ahead.shape[1] else np.full(len(o), np.inf)
    face = np.where(np.isfinite(first), poly.triangle_faces[k] if len(k) else -1, -1)
    return LineHits(first=first, face=face.astype(np.int64), params=params)


def inside_intervals(poly: Polyhedron, start: np.ndarray, direction: np.ndarray, length: float) -> list[tuple]:
    """The parts ``[t0, t1]`` of the segment ``start + t u``, ``0 ≤ t ≤ length``, inside the solid (model frame).

    The segment is cut at every surface crossing; each piece is inside or outside as its midpoint is
    (:meth:`Polyhedron.contains`), which stays right where the line grazes an edge or a vertex.
    """
    hits = line_hits(poly, start[None], direction[None])
    ts = hits.params[0]
    ts = np.unique(np.clip(ts[np.isfinite(ts)], 0.0, length))
    cuts = np.unique(np.concatenate([[0.0], ts, [float(length)]]))
    if len(cuts) < 2:
        return []
    mids = 0.5 * (cuts[:-1] + cuts[1:])
    return _inside_spans(cuts, poly.contains(start + mids[:, None] * direction))


def _inside_spans(cuts: np.ndarray, inside: np.ndarray) -> list[tuple[float, float]]:
    """The pieces between successive ``cuts`` whose midpoints are ``inside``, touching pieces joined."""
    out: list[tuple[float, float]] = []
    for lo, hi, ins in zip(cuts[:-1], cuts[1:], inside, strict=True):
        if not ins or hi <= lo:
            continue
        if out and abs(out[-1][1] - lo) < 1e-12:
            out[-1] = (out[-1][0], float(hi))
        else:
            out.append((float(lo), float(hi)))
    return out


def depth_samples(
    poly: Polyhedron, start: np.ndarray, direction: np.ndarray, length: float
) -> tuple[np.ndarray, np.ndarray]:
    """Points of the segment ``start + t u``, ``0 ≤ t ≤ length``, inside the solid (:data:`DEPTH_SAMPLES` per
    inside interval, its ends and middle included) and their distances from the surface (model frame); shapes
    (P, 3), (P,), with P = 0 when the segment stays outside [m]."""
    start, direction = np.asarray(start, dtype=float), np.asarray(direction, dtype=float)
    spans = inside_intervals(poly, start, direction, length)
    if not spans:
        return np.zeros((0, 3)), np.zeros(0)
    ts = np.concatenate([np.linspace(lo, hi, DEPTH_SAMPLES) for lo, hi in spans])
    pts = start + ts[:, None] * direction
    return pts, surface_distance(poly, pts)


def depth_samples_many(
    poly: Polyhedron, starts: np.ndarray, directions: np.ndarray, lengths: np.ndarray
) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`depth_samples` of several segments at once (shapes (S, 3), (S, 3), (S,)): the same points and
    depths per segment, from one crossing test, one inside test and one distance computation for all of them."""
    samples = sample_inside_many(poly, starts, directions, lengths)
    counts = [len(x) for x, _ in samples]
    depth = surface_distance(poly, np.concatenate([x for x, _ in samples])) if sum(counts) else np.zeros(0)
    bounds = np.cumsum([0, *counts])
    return [(samples[k][0], depth[bounds[k] : bounds[k + 1]]) for k in range(len(samples))]


def sample_inside_many(
    poly: Polyhedron, starts: np.ndarray, directions: np.ndarray, lengths: np.ndarray
) -> list[tuple[np.ndarray, np.ndarray]]:
    """The points :func:`depth_samples_many` takes on each segment (unit ``directions``), each with a bound its depth
    cannot exceed: the distance along the segment to an end of its inside interval where the line crosses the
    surface (plus :data:`CROSSING_SLACK`; inf when neither end is a crossing, an interval clipped at both ends of
    the segment). The surface passes through such an end, so no point is farther from the surface than from it."""
    starts = np.atleast_2d(np.asarray(starts, dtype=float))
    directions = np.atleast_2d(np.asarray(directions, dtype=float))
    if kernels.COMPILED:
        tri = np.ascontiguousarray(poly.vertices[poly.triangles], dtype=float)
        params = kernels.line_params(starts, directions, tri, BARYCENTRIC_SLACK)
    else:
        params = line_hits(poly, starts, directions).params
    cuts, mids, crossings = [], [], []
    for k, length in enumerate(np.asarray(lengths, dtype=float)):
        ts = params[k]
        ts = ts[np.isfinite(ts)]
        crossings.append(ts[(ts >= 0.0) & (ts <= length)])
        ts = np.unique(np.clip(ts, 0.0, length))
        c = np.unique(np.concatenate([[0.0], ts, [float(length)]]))
        cuts.append(c)
        mids.append(starts[k] + (0.5 * (c[:-1] + c[1:]))[:, None] * directions[k])
    if not sum(len(m) for m in mids):
        inside = np.zeros(0, dtype=bool)
    elif kernels.COMPILED:
        inside = kernels.contains(np.concatenate(mids), tri)
    else:
        inside = poly.contains(np.concatenate(mids))
    out, at = [], 0
    for k, c in enumerate(cuts):
        spans, at = _inside_spans(c, inside[at : at + len(c) - 1]), at + len(c) - 1
        ts = np.concatenate([np.linspace(lo, hi, DEPTH_SAMPLES) for lo, hi in spans]) if spans else np.zeros(0)
        upper = np.full(len(ts), np.inf)
        for j, (lo, hi) in enumerate(spans):
            piece = slice(j * DEPTH_SAMPLES, (j + 1) * DEPTH_SAMPLES)
            if np.isin(lo, crossings[k]):
                upper[piece] = np.minimum(upper[piece], ts[piece] - lo)
            if np.isin(hi, crossings[k]):
                upper[piece] = np.minimum(upper[piece], hi - ts[piece])
        out.append((starts[k] + ts[:, None] * directions[k], upper + CROSSING_SLACK))
    return out


CROSSING_SLACK = 1e-9
"""Added to the distance from a crossing in :func:`sample_inside_many`'s depth bound: the crossing lies on the
surface only to within the arithmetic's error, far below this [m]."""


def segment_depth(poly: Polyhedron, start: np.ndarray, direction: np.ndarray, length: float) -> float:
    """How deep the segment ``start + t u``, ``0 ≤ t ≤ length``, runs inside the solid: the largest distance
    from the surface of its inside points, sampled (:func:`depth_samples`), 0 when it stays outside (model
    frame) [m].

    Sampling can only under-estimate the depth, so a test "deeper than ε" built on it never fires wrongly.
    """
    _, depth = depth_samples(poly, start, direction, length)
    return float(depth.max()) if len(depth) else 0.0


__all__ = [
    "DEPTH_SAMPLES",
    "LineHits",
    "depth_samples",
    "depth_samples_many",
    "sample_inside_many",
    "inside_intervals",
    "line_hits",
    "segment_depth",
]
