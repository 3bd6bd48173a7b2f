"""Compiled forms of geometric inner loops, and the switch the compiled kernels of the whole core share.

A kernel is a plain loop over small arrays, compiled by numba (``@njit(cache=True)``: compiled on the first call
of a checkout and kept in ``__pycache__``) and called in place of the Python or numpy form of the same
arithmetic, which stays the reference. :data:`COMPILED` is False, and the callers take the reference forms, when
numba is not installed or the environment variable ``HAPTIC_COMPILED`` is ``0``. The matcher's kernels are in
:mod:`haptic.matching.kernels`.
"""

from __future__ import annotations

import os

import numpy as np

try:
    if os.environ.get("HAPTIC_COMPILED", "1") == "0":
        raise ImportError("compiled kernels disabled by HAPTIC_COMPILED=0")
    from numba import njit
except ImportError:  # the reference forms alone
    njit = None

COMPILED = njit is not None
"""Whether the callers use the compiled kernels (numba installed and ``HAPTIC_COMPILED`` not ``0``)."""


def compile_kernel(fn):
    """``fn`` compiled (cached on disk), or ``fn`` itself without numba."""
    return njit(cache=True, nogil=True)(fn) if njit is not None else fn


def face_crossing(corners, sides, n, start, d, steady, margin):
    """The crossing loop of :func:`~haptic.geometry.tracing.trace_face` with the same arithmetic: of the face's
    sides (``corners`` (K, 3), ``sides`` (K, 3), on the plane of unit normal ``n``), the first that the trace from
    ``start`` along unit ``d`` meets. Sides it misses by far more than the arithmetic's error are left out first
    (the crossing solved for every side with ``(a × b) · n`` products: a side whose sine with the trace exceeds
    ``steady`` and whose crossing lies ``margin`` behind the start or beyond its ends); the others are solved by
    the 2 × 2 normal equations in the same scalar operations as the Python loop. Returns ``(k, t, u, |side|)``, ``k
    = -1`` when none is met."""
    n0, n1, n2 = n[0], n[1], n[2]
    dx, dy, dz = d[0], d[1], d[2]
    sx, sy, sz = start[0], start[1], start[2]
    best_k, best_t, best_u, best_len = -1, 0.0, 0.0, 0.0
    for k in range(corners.shape[0]):
        ax, ay, az = corners[k, 0], corners[k, 1], corners[k, 2]
        gx, gy, gz = sides[k, 0], sides[k, 1], sides[k, 2]
        rx, ry, rz = ax - sx, ay - sy, az - sz
        den = (dy * gz - dz * gy) * n0 + (dz * gx - dx * gz) * n1 + (dx * gy - dy * gx) * n2
        if abs(den) > steady * np.sqrt(gx * gx + gy * gy + gz * gz):
            t_all = ((ry * gz - rz * gy) * n0 + (rz * gx - rx * gz) * n1 + (rx * gy - ry * gx) * n2) / den
            u_all = ((ry * dz - rz * dy) * n0 + (rz * dx - rx * dz) * n1 + (rx * dy - ry * dx) * n2) / den
            if t_all < -margin or u_all < -margin or u_all > 1 + margin:
                continue
        dg, gg = dx * gx + dy * gy + dz * gz, gx * gx + gy * gy + gz * gz
        dr, gr = dx * rx + dy * ry + dz * rz, gx * rx + gy * ry + gz * rz
        det = gg - dg * dg
        if det <= 1e-24 * gg:
            continue  # parallel
        t = (gg * dr - dg * gr) / det
        u = (dg * dr - gr) / det
        if t <= 1e-12 or u < -1e-12 or u > 1 + 1e-12:
            continue
        ex, ey, ez = sx + t * dx - (ax + u * gx), sy + t * dy - (ay + u * gy), sz + t * dz - (az + u * gz)
        if np.sqrt(ex * ex + ey * ey + ez * ez) > 1e-7:
            continue  # off-plane
        if best_k < 0 or t < best_t:
            best_k, best_t, best_u, best_len = k, t, u, np.sqrt(gg)
    return best_k, best_t, best_u, best_len


face_crossing = compile_kernel(face_crossing)


def line_params(starts, directions, tri, slack):
    """The ``params`` of :func:`~haptic.geometry.raycast.line_hits`, the same Möller–Trumbore formulas: the
    parameter ``t`` where each line ``start + t u`` (R of them) crosses each triangle (T, 3, 3), NaN where it
    misses it (barycentric coordinates beyond ``-slack`` or ``1 + slack``, or the line parallel to it), (R, T)."""
    n_r, n_t = starts.shape[0], tri.shape[0]
    out = np.full((n_r, n_t), np.nan)
    for r in range(n_r):
        o0, o1, o2 = starts[r, 0], starts[r, 1], starts[r, 2]
        u0, u1, u2 = directions[r, 0], directions[r, 1], directions[r, 2]
        for k in range(n_t):
            a0, a1, a2 = tri[k, 0, 0], tri[k, 0, 1], tri[k, 0, 2]
            e10, e11, e12 = tri[k, 1, 0] - a0, tri[k, 1, 1] - a1, tri[k, 1, 2] - a2
            e20, e21, e22 = tri[k, 2, 0] - a0, tri[k, 2, 1] - a1, tri[k, 2, 2] - a2
            p0, p1, p2 = u1 * e22 - u2 * e21, u2 * e20 - u0 * e22, u0 * e21 - u1 * e20
            det = e10 * p0 + e11 * p1 + e12 * p2
            if not abs(det) > 1e-18:
                continue
            inv = 1.0 / det
            s0, s1, s2 = o0 - a0, o1 - a1, o2 - a2
            bu = (s0 * p0 + s1 * p1 + s2 * p2) * inv
            q0, q1, q2 = s1 * e12 - s2 * e11, s2 * e10 - s0 * e12, s0 * e11 - s1 * e10
            bv = (u0 * q0 + u1 * q1 + u2 * q2) * inv
            if bu >= -slack and bv >= -slack and bu + bv <= 1.0 + slack:
                out[r, k] = (e20 * q0 + e21 * q1 + e22 * q2) * inv
    return out


line_params = compile_kernel(line_params)


def _winding_inside(x0, x1, x2, tri):
    """Whether the point ``x`` is inside the closed surface of the triangles (T, 3, 3): the generalised winding
    number of :meth:`~haptic.geometry.polyhedron.Polyhedron.contains`, the same arithmetic."""
    total = 0.0
    for k in range(tri.shape[0]):
        a0, a1, a2 = tri[k, 0, 0] - x0, tri[k, 0, 1] - x1, tri[k, 0, 2] - x2
        b0, b1, b2 = tri[k, 1, 0] - x0, tri[k, 1, 1] - x1, tri[k, 1, 2] - x2
        c0, c1, c2 = tri[k, 2, 0] - x0, tri[k, 2, 1] - x1, tri[k, 2, 2] - x2
        la = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
        lb = np.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
        lc = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
        num = a0 * (b1 * c2 - b2 * c1) + a1 * (b2 * c0 - b0 * c2) + a2 * (b0 * c1 - b1 * c0)
        den = la * lb * lc + (a0 * b0 + a1 * b1 + a2 * b2) * lc
        den = den + (b0 * c0 + b1 * c1 + b2 * c2) * la + (c0 * a0 + c1 * a1 + c2 * a2) * lb
        total += np.arctan2(num, den)
    return 2.0 * total / (4.0 * np.pi) > 0.5


_winding_inside = compile_kernel(_winding_inside)


def contains(points, tri):
    """:meth:`~haptic.geometry.polyhedron.Polyhedron.contains`, the same generalised winding number: whether each
    point (P, 3) is inside the closed surface of the triangles (T, 3, 3), (P,) bool."""
    out = np.zeros(points.shape[0], np.bool_)
    for i in range(points.shape[0]):
        out[i] = _winding_inside(points[i, 0], points[i, 1], points[i, 2], tri)
    return out


contains = compile_kernel(contains)


def inside_samples(starts, directions, lengths, tri, slack, n_samples, crossing_slack):
    """:func:`~haptic.geometry.raycast.sample_inside_many` of every segment ``start + t u``, ``0 ≤ t ≤ length``
    (R of them) at once, the same arithmetic: the crossings with the triangles (T, 3, 3) (:func:`line_params`), the
    segment cut at them, the pieces whose midpoints are inside (touching pieces joined), ``n_samples`` points across
    each (``np.linspace``'s formula) with the bound on their depth. Returns the points (P, 3), their bounds (P,) and
    the segment of each (P,)."""
    params = line_params(starts, directions, tri, slack)
    n_r, n_t = params.shape
    size = n_r * (n_t + 1) * n_samples
    pts = np.empty((size, 3))
    upper = np.empty(size)
    owner = np.empty(size, np.int64)
    at = 0
    ts = np.empty(n_t)
    cuts = np.empty(n_t + 2)
    span_lo = np.empty(n_t + 1)
    span_hi = np.empty(n_t + 1)
    div = n_samples - 1
    for r in range(n_r):
        length = lengths[r]
        n = 0
        for k in range(n_t):
            t = params[r, k]
            if np.isfinite(t):
                ts[n] = t
                n += 1
        # the cuts: 0, every crossing clipped to the segment, its length; sorted, repeats dropped (np.unique)
        cuts[0] = 0.0
        for j in range(n):
            cuts[j + 1] = min(max(ts[j], 0.0), length)
        cuts[n + 1] = length
        m = n + 2
        for i in range(1, m):
            x = cuts[i]
            j = i - 1
            while j >= 0 and cuts[j] > x:
                cuts[j + 1] = cuts[j]
                j -= 1
            cuts[j + 1] = x
        u = 1
        for i in range(1, m):
            if cuts[i] != cuts[u - 1]:
                cuts[u] = cuts[i]
                u += 1
        n_spans = 0
        for j in range(u - 1):
            lo, hi = cuts[j], cuts[j + 1]
            mid = 0.5 * (lo + hi)
            inside = _winding_inside(starts[r, 0] + mid * directions[r, 0], starts[r, 1] + mid * directions[r, 1],
                                     starts[r, 2] + mid * directions[r, 2], tri)
            if not inside or hi <= lo:
                continue
            if n_spans > 0 and abs(span_hi[n_spans - 1] - lo) < 1e-12:
                span_hi[n_spans - 1] = hi
            else:
                span_lo[n_spans] = lo
                span_hi[n_spans] = hi
                n_spans += 1
        for j in range(n_spans):
            lo, hi = span_lo[j], span_hi[j]
            lo_crosses, hi_crosses = False, False
            for i in range(n):
                if ts[i] >= 0.0 and ts[i] <= length:
                    lo_crosses = lo_crosses or ts[i] == lo
                    hi_crosses = hi_crosses or ts[i] == hi
            delta = hi - lo
            step = delta / div
            for i in range(n_samples):
                if i == div:
                    t = hi
                elif step == 0:
                    t = (i / div) * delta + lo
                else:
                    t = i * step + lo
                bound = np.inf
                if lo_crosses:
                    bound = min(bound, t - lo)
                if hi_crosses:
                    bound = min(bound, hi - t)
                pts[at, 0] = starts[r, 0] + t * directions[r, 0]
                pts[at, 1] = starts[r, 1] + t * directions[r, 1]
                pts[at, 2] = starts[r, 2] + t * directions[r, 2]
                upper[at] = bound + crossing_slack
                owner[at] = r
                at += 1
    return pts[:at], upper[:at], owner[:at]


inside_samples = compile_kernel(inside_samples)


__all__ = ["COMPILED", "compile_kernel", "contains", "face_crossing", "inside_samples", "line_params"]
