"""Compiled forms of the planner's inner loops (numba; the switch and the compilation of
:mod:`haptic.geometry.kernels`): each in place of the numpy form of the same arithmetic, which stays the reference.
"""

from __future__ import annotations

import numpy as np

from haptic.geometry import kernels as _geometry

COMPILED = _geometry.COMPILED
"""Whether the callers use the compiled kernels (the switch of :mod:`haptic.geometry.kernels`)."""


def face_outcomes(dirs, rots, start, normal, a_all, seg_all, real, b_all, p_all, len_all, dih_all, seg_len, costs):
    """The arrays of :func:`~haptic.planning.predict.face_outcomes`, the same formulas move by move and hypothesis by
    hypothesis: for each face move (``dirs`` (M, 3), world frame) in each posed hypothesis (its rotation ``rots``
    (m, 3, 3), the sensor on its face ``start`` (m, 3), the face's normal (m, 3) and its K sides padded, ``real``
    (m, K)), the first side met ahead clear of its ends; ``costs``: ``c_f, c_j, c_b, c_n``. Returns ``(hit (M, m),
    distance, edge angle, dihedral, cost, clearance)``, the last five (M, m) and meaningful where ``hit``."""
    n_m, n_h, n_k = dirs.shape[0], start.shape[0], a_all.shape[1]
    hit = np.zeros((n_m, n_h), np.bool_)
    dist = np.zeros((n_m, n_h))
    angle = np.zeros((n_m, n_h))
    dih = np.zeros((n_m, n_h))
    cost = np.zeros((n_m, n_h))
    clear = np.zeros((n_m, n_h))
    c_f, c_j, c_b, c_n = costs[0], costs[1], costs[2], costs[3]
    for mv in range(n_m):
        for h in range(n_h):
            # the move's direction in the model frame (SE3.rotate's arithmetic), in the face's plane
            w0 = dirs[mv, 0] * rots[h, 0, 0] + dirs[mv, 1] * rots[h, 1, 0] + dirs[mv, 2] * rots[h, 2, 0]
            w1 = dirs[mv, 0] * rots[h, 0, 1] + dirs[mv, 1] * rots[h, 1, 1] + dirs[mv, 2] * rots[h, 2, 1]
            w2 = dirs[mv, 0] * rots[h, 0, 2] + dirs[mv, 1] * rots[h, 1, 2] + dirs[mv, 2] * rots[h, 2, 2]
            n0, n1, n2 = normal[h, 0], normal[h, 1], normal[h, 2]
            wn = w0 * n0 + w1 * n1 + w2 * n2
            d0, d1, d2 = w0 - wn * n0, w1 - wn * n1, w2 - wn * n2
            norm = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if not norm >= 1e-9:
                continue
            d0, d1, d2 = d0 / norm, d1 / norm, d2 / norm
            s0, s1, s2 = start[h, 0], start[h, 1], start[h, 2]
            best, tb, ub = -1, np.inf, 0.0
            for k in range(n_k):
                g0, g1, g2 = seg_all[h, k, 0], seg_all[h, k, 1], seg_all[h, k, 2]
                r0, r1, r2 = a_all[h, k, 0] - s0, a_all[h, k, 1] - s1, a_all[h, k, 2] - s2
                den = (d1 * g2 - d2 * g1) * n0 + (d2 * g0 - d0 * g2) * n1 + (d0 * g1 - d1 * g0) * n2
                steady = abs(den) > 1e-15
                safe = den if steady else 1.0
                t = ((r1 * g2 - r2 * g1) * n0 + (r2 * g0 - r0 * g2) * n1 + (r0 * g1 - r1 * g0) * n2) / safe
                u = ((r1 * d2 - r2 * d1) * n0 + (r2 * d0 - r0 * d2) * n1 + (r0 * d1 - r1 * d0) * n2) / safe
                if not (real[h, k] and steady and t > 1e-12 and u >= -1e-12 and u <= 1 + 1e-12):
                    continue
                m0 = s0 + t * d0 - (a_all[h, k, 0] + u * g0)
                m1 = s1 + t * d1 - (a_all[h, k, 1] + u * g1)
                m2 = s2 + t * d2 - (a_all[h, k, 2] + u * g2)
                if not np.sqrt(m0 * m0 + m1 * m1 + m2 * m2) <= 1e-7:
                    continue
                if t < tb:
                    best, tb, ub = k, t, u
            if best < 0 or not min(ub, 1 - ub) * seg_len[h, best] >= 1e-6:
                continue
            hit[mv, h] = True
            b0, b1, b2 = b_all[h, best, 0], b_all[h, best, 1], b_all[h, best, 2]
            dot = abs(b0 * w0 + b1 * w1 + b2 * w2)
            cos = dot / (np.sqrt(b0 * b0 + b1 * b1 + b2 * b2) * np.sqrt(w0 * w0 + w1 * w1 + w2 * w2))
            p0, p1, p2 = s0 + tb * d0, s1 + tb * d1, s2 + tb * d2
            s_hit = (p0 - p_all[h, best, 0]) * b0 + (p1 - p_all[h, best, 1]) * b1 + (p2 - p_all[h, best, 2]) * b2
            dist[mv, h] = tb
            angle[mv, h] = np.arccos(min(max(cos, 0.0), 1.0))
            dih[mv, h] = dih_all[h, best]
            cost[mv, h] = c_f * tb + c_j + c_b + c_n
            clear[mv, h] = min(s_hit, len_all[h, best] - s_hit)
    return hit, dist, angle, dih, cost, clear


face_outcomes = _geometry.compile_kernel(face_outcomes)


def least_path(start, step):
    """The Held-Karp table of :func:`~haptic.planning.tour.least_path` by the same sums: ``start`` (n,), the cost of
    each node taken first, and ``step`` (n, n), from node ``j`` to node ``k``; the least over the last node of the
    full subset's row. Every entry is the least of the same float sums ``best[subset, j] + step[j, k]`` over every
    ``j`` as the numpy form's (+inf for ``j`` outside the subset, the costs being finite), subsets in increasing
    order (each entry's subsets are smaller numbers): the same value to the bit."""
    n = start.shape[0]
    full = 1 << n
    best = np.full((full, n), np.inf)
    for j in range(n):
        best[1 << j, j] = start[j]
    for mask in range(1, full):
        for k in range(n):
            if (mask >> k) & 1:
                continue
            low = np.inf
            for j in range(n):
                v = best[mask, j] + step[j, k]
                if v < low:
                    low = v
            best[mask | (1 << k), k] = low
    out = np.inf
    for j in range(n):
        if best[full - 1, j] < out:
            out = best[full - 1, j]
    return out


least_path = _geometry.compile_kernel(least_path)


__all__ = ["COMPILED", "face_outcomes", "least_path"]
