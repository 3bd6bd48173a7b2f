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


def contains(points, tri):
    """:meth:`~haptic.geometry.polyhedron.Polyhedron.contains`, the same generalised winding number: whether each
    point (P, 3) is inside the closed surface of the triangles (T, 3, 3), (P,) bool."""
    n_p, n_t = points.shape[0], tri.shape[0]
    out = np.zeros(n_p, np.bool_)
    for i in range(n_p):
        total = 0.0
        for k in range(n_t):
            a0, a1, a2 = tri[k, 0, 0] - points[i, 0], tri[k, 0, 1] - points[i, 1], tri[k, 0, 2] - points[i, 2]
            b0, b1, b2 = tri[k, 1, 0] - points[i, 0], tri[k, 1, 1] - points[i, 1], tri[k, 1, 2] - points[i, 2]
            c0, c1, c2 = tri[k, 2, 0] - points[i, 0], tri[k, 2, 1] - points[i, 1], tri[k, 2, 2] - points[i, 2]
            la = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
            lb = np.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
            lc = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
            num = a0 * (b1 * c2 - b2 * c1) + a1 * (b2 * c0 - b0 * c2) + a2 * (b0 * c1 - b1 * c0)
            den = la * lb * lc + (a0 * b0 + a1 * b1 + a2 * b2) * lc
            den = den + (b0 * c0 + b1 * c1 + b2 * c2) * la + (c0 * a0 + c1 * a1 + c2 * a2) * lb
            total += np.arctan2(num, den)
        out[i] = 2.0 * total / (4.0 * np.pi) > 0.5
    return out


contains = compile_kernel(contains)


__all__ = ["COMPILED", "compile_kernel", "contains", "face_crossing", "line_params"]
