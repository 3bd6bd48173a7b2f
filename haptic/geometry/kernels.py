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


__all__ = ["COMPILED", "compile_kernel", "face_crossing"]
