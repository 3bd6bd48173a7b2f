"""Compiled forms of the matcher's inner loops: the refinement and the closed-form poses of many interpretations
(:mod:`haptic.matching.batch_poses`), and the grouping of poses into pose classes
(:mod:`haptic.matching.recognition`).

Each kernel is a plain loop over small arrays, compiled by numba (``@njit(cache=True)``: compiled on the first
call of a checkout and kept in ``__pycache__``) and called in place of the numpy form of the same arithmetic,
which stays the reference: the numpy forms spend most of their time in the overhead of many operations on arrays
of a few elements. The results agree with the numpy forms' to the rounding of sums taken in another order (about
1e-15 relative); ``tests/matching/test_kernels.py`` checks that, and that episodes decide the same either way.

:data:`COMPILED` is False, and the callers take the numpy forms, when numba is not installed or the environment
variable ``HAPTIC_COMPILED`` is ``0``.
"""

from __future__ import annotations

import os

import numpy as np

try:
    if os.environ.get("HAPTIC_COMPILED", "1") == "0":
        raise ImportError("compiled kernels disabled by HAPTIC_COMPILED=0")
    from numba import njit
except ImportError:  # the numpy forms alone
    njit = None

COMPILED = njit is not None
"""Whether the callers use the compiled kernels (numba installed and ``HAPTIC_COMPILED`` not ``0``)."""


def _compile(fn):
    return njit(cache=True, nogil=True)(fn) if njit is not None else fn


# ------------------------------------------------------------------------------------------- small algebra


def _solve_in_place(a, b, n):
    """Solve ``a x = b`` (n × n, n ≤ 6) by Gaussian elimination with partial pivoting, as LAPACK's ``gesv``;
    ``b`` becomes ``x``. False (and ``a``, ``b`` spoilt) when a pivot is exactly zero: a singular matrix, for
    which numpy's ``solve`` raises."""
    for col in range(n):
        piv = col
        big = abs(a[col, col])
        for row in range(col + 1, n):
            v = abs(a[row, col])
            if v > big:
                big, piv = v, row
        if big == 0.0:
            return False
        if piv != col:
            for k in range(n):
                a[col, k], a[piv, k] = a[piv, k], a[col, k]
            b[col], b[piv] = b[piv], b[col]
        inv = 1.0 / a[col, col]
        for row in range(col + 1, n):
            f = a[row, col] * inv
            if f != 0.0:
                for k in range(col + 1, n):
                    a[row, k] -= f * a[col, k]
                b[row] -= f * b[col]
    for row in range(n - 1, -1, -1):
        s = b[row]
        for k in range(row + 1, n):
            s -= a[row, k] * b[k]
        b[row] = s / a[row, row]
    return True


_solve_in_place = _compile(_solve_in_place)


# ------------------------------------------------------------------------------------------- poses


def refine_poses(dirs_w, dirs_m, dirs_sw, x, c, m, r, t, iterations, tol):
    """:meth:`~haptic.matching.batch_poses.StackedPoses.refine`, one problem at a time: Gauss–Newton on the
    direction rows ``√w (Rᵀ a − u)`` and the position rows ``M (Rᵀ (x − t) − c)`` with the closed-form Jacobian
    of a pose perturbed on the left, the normal equations (6 × 6) accumulated row by row, the step applied by the
    Cayley map; a problem stops after a step shorter than ``tol``. ``r`` (N, 3, 3) and ``t`` (N, 3) are updated
    in place. Returns False as soon as some normal equations are singular (the caller then takes the numpy
    form, which solves those by least squares)."""
    n_prob, n_dirs, n_pos = dirs_m.shape[0], dirs_w.shape[0], x.shape[0]
    jtj = np.empty((6, 6))
    jtf = np.empty(6)
    row = np.empty(6)
    a = np.empty((3, 3))
    dr = np.empty((3, 3))
    nr = np.empty((3, 3))
    for p in range(n_prob):
        for _ in range(iterations):
            jtj[:] = 0.0
            jtf[:] = 0.0
            for d in range(n_dirs):
                sw = dirs_sw[p, d]
                a0, a1, a2 = dirs_w[d, 0], dirs_w[d, 1], dirs_w[d, 2]
                for i in range(3):
                    c0, c1, c2 = sw * r[p, 0, i], sw * r[p, 1, i], sw * r[p, 2, i]
                    f = (a0 * r[p, 0, i] + a1 * r[p, 1, i] + a2 * r[p, 2, i] - dirs_m[p, d, i]) * sw
                    row[0], row[1], row[2] = c1 * a2 - c2 * a1, c2 * a0 - c0 * a2, c0 * a1 - c1 * a0
                    for u in range(3):
                        jtf[u] += row[u] * f
                        for v in range(3):
                            jtj[u, v] += row[u] * row[v]
            t0, t1, t2 = t[p, 0], t[p, 1], t[p, 2]
            for k in range(n_pos):
                x0, x1, x2 = x[k, 0], x[k, 1], x[k, 2]
                for i in range(3):
                    for j in range(3):
                        a[i, j] = m[p, k, i, 0] * r[p, j, 0] + m[p, k, i, 1] * r[p, j, 1] + m[p, k, i, 2] * r[p, j, 2]
                for i in range(3):
                    f = a[i, 0] * (x0 - t0) + a[i, 1] * (x1 - t1) + a[i, 2] * (x2 - t2)
                    f -= m[p, k, i, 0] * c[p, k, 0] + m[p, k, i, 1] * c[p, k, 1] + m[p, k, i, 2] * c[p, k, 2]
                    row[0] = a[i, 1] * x2 - a[i, 2] * x1
                    row[1] = a[i, 2] * x0 - a[i, 0] * x2
                    row[2] = a[i, 0] * x1 - a[i, 1] * x0
                    row[3], row[4], row[5] = -a[i, 0], -a[i, 1], -a[i, 2]
                    for u in range(6):
                        jtf[u] += row[u] * f
                        for v in range(6):
                            jtj[u, v] += row[u] * row[v]
            for u in range(6):
                jtf[u] = -jtf[u]
            if not _solve_in_place(jtj, jtf, 6):
                return False
            # the Cayley map of the rotation step: I + s ([v]× + [v]×²), v = ω / 2, s = 2 / (1 + |v|²)
            v0, v1, v2 = 0.5 * jtf[0], 0.5 * jtf[1], 0.5 * jtf[2]
            s = 2.0 / (1.0 + 0.25 * (jtf[0] * jtf[0] + jtf[1] * jtf[1] + jtf[2] * jtf[2]))
            dr[0, 0] = 1.0 + s * (-v2 * v2 - v1 * v1)
            dr[0, 1] = s * (-v2 + v0 * v1)
            dr[0, 2] = s * (v1 + v0 * v2)
            dr[1, 0] = s * (v2 + v0 * v1)
            dr[1, 1] = 1.0 + s * (-v2 * v2 - v0 * v0)
            dr[1, 2] = s * (-v0 + v1 * v2)
            dr[2, 0] = s * (-v1 + v0 * v2)
            dr[2, 1] = s * (v0 + v1 * v2)
            dr[2, 2] = 1.0 + s * (-v1 * v1 - v0 * v0)
            for i in range(3):
                for j in range(3):
                    nr[i, j] = dr[i, 0] * r[p, 0, j] + dr[i, 1] * r[p, 1, j] + dr[i, 2] * r[p, 2, j]
            r[p] = nr
            for i in range(3):
                row[i] = dr[i, 0] * t0 + dr[i, 1] * t1 + dr[i, 2] * t2 + jtf[3 + i]
            t[p, 0], t[p, 1], t[p, 2] = row[0], row[1], row[2]
            norm2 = 0.0
            for u in range(6):
                norm2 += jtf[u] * jtf[u]
            if np.sqrt(norm2) < tol:
                break
    return True


refine_poses = _compile(refine_poses)


def closed_form_rotations(dirs_w, dirs_m, dirs_wt, known, min_spread):
    """:meth:`~haptic.matching.batch_poses.StackedPoses.rotations` one problem at a time: whether the known
    directions span at least ``min_spread`` (the largest ``|u_i × u_j|``), and the proper rotation of Wahba's
    problem by the SVD of ``Σ w a uᵀ``, its last singular vector turned where ``det(U Vᵀ) < 0``. Returns ``(R (N,
    3, 3), ok (N,))``; a problem that is not ok gets its SVD rotation all the same."""
    n_prob, n_dirs = dirs_m.shape[0], dirs_w.shape[0]
    out = np.empty((n_prob, 3, 3))
    ok = np.zeros(n_prob, np.bool_)
    h = np.empty((3, 3))
    for p in range(n_prob):
        n_known = 0
        best = 0.0
        for i in range(n_dirs):
            if not known[p, i]:
                continue
            n_known += 1
            ui0, ui1, ui2 = dirs_m[p, i, 0], dirs_m[p, i, 1], dirs_m[p, i, 2]
            sq_i = ui0 * ui0 + ui1 * ui1 + ui2 * ui2
            for j in range(n_dirs):
                if not known[p, j]:
                    continue
                uj0, uj1, uj2 = dirs_m[p, j, 0], dirs_m[p, j, 1], dirs_m[p, j, 2]
                g = ui0 * uj0 + ui1 * uj1 + ui2 * uj2
                v = sq_i * (uj0 * uj0 + uj1 * uj1 + uj2 * uj2) - g * g
                if v > best:
                    best = v
        ok[p] = n_known >= 2 and np.sqrt(best) >= min_spread
        h[:] = 0.0
        for d in range(n_dirs):
            w = dirs_wt[p, d]
            for i in range(3):
                wa = dirs_w[d, i] * w
                for j in range(3):
                    h[i, j] += wa * dirs_m[p, d, j]
        u, _, vt = np.linalg.svd(h)
        rot = u @ vt
        det = (rot[0, 0] * (rot[1, 1] * rot[2, 2] - rot[1, 2] * rot[2, 1])
               - rot[0, 1] * (rot[1, 0] * rot[2, 2] - rot[1, 2] * rot[2, 0])
               + rot[0, 2] * (rot[1, 0] * rot[2, 1] - rot[1, 1] * rot[2, 0]))  # fmt: skip
        if det < 0.0:
            for i in range(3):
                u[i, 2] = -u[i, 2]
            rot = u @ vt
        out[p] = rot
    return out, ok


closed_form_rotations = _compile(closed_form_rotations)


def closed_form_translations(q, total, ok, x, c, r):
    """:meth:`~haptic.matching.batch_poses.StackedPoses.translations` one problem at a time: ``t = R (Σ Q)⁻¹ Σ Q
    (Rᵀ x − c)`` where ``ok`` (the system well conditioned), else 0."""
    n_prob, n_pos = q.shape[0], x.shape[0]
    out = np.zeros((n_prob, 3))
    a = np.empty((3, 3))
    v = np.empty(3)
    y = np.empty(3)
    for p in range(n_prob):
        if not ok[p]:
            continue
        v[:] = 0.0
        for k in range(n_pos):
            for j in range(3):
                y[j] = x[k, 0] * r[p, 0, j] + x[k, 1] * r[p, 1, j] + x[k, 2] * r[p, 2, j] - c[p, k, j]
            for i in range(3):
                v[i] += q[p, k, i, 0] * y[0] + q[p, k, i, 1] * y[1] + q[p, k, i, 2] * y[2]
        a[:] = total[p]
        _solve_in_place(a, v, 3)  # well conditioned where ok
        for i in range(3):
            out[p, i] = r[p, i, 0] * v[0] + r[p, i, 1] * v[1] + r[p, i, 2] * v[2]
    return out


closed_form_translations = _compile(closed_form_translations)


# ------------------------------------------------------------------------------------------- pose classes


def same_pose_pairs(rot, trans, placed, centroid, s_rot, s_trans, angle, distance):
    """:func:`~haptic.matching.recognition._same_pose_pairs`: ``same[i, j]`` when pose ``j`` is within ``angle``
    [rad] and ``distance`` [m] (the model's centroid placed) of pose ``i`` composed with some symmetry of the
    model (``s_rot`` (S, 3, 3), ``s_trans`` (S, 3)), for the poses ``rot`` (N, 3, 3), ``trans`` (N, 3) and the
    centroid placed by each, ``placed`` (N, 3)."""
    n, n_sym = rot.shape[0], s_rot.shape[0]
    same = np.zeros((n, n), np.bool_)
    ra = np.empty((n_sym, 3, 3))
    ca = np.empty((n_sym, 3))
    for i in range(n):
        for s in range(n_sym):
            for a in range(3):
                for b in range(3):
                    ra[s, a, b] = (
                        rot[i, a, 0] * s_rot[s, 0, b] + rot[i, a, 1] * s_rot[s, 1, b] + rot[i, a, 2] * s_rot[s, 2, b]
                    )
            for a in range(3):
                ca[s, a] = (ra[s, a, 0] * centroid[0] + ra[s, a, 1] * centroid[1] + ra[s, a, 2] * centroid[2]
                            + s_trans[s, 0] * rot[i, a, 0] + s_trans[s, 1] * rot[i, a, 1] + s_trans[s, 2] * rot[i, a, 2]
                            + trans[i, a])  # fmt: skip
        for j in range(n):
            for s in range(n_sym):
                tr = 0.0
                for a in range(3):
                    for b in range(3):
                        tr += ra[s, a, b] * rot[j, a, b]
                cos = min(max((tr - 1.0) / 2.0, -1.0), 1.0)
                if np.arccos(cos) > angle:
                    continue
                d0, d1, d2 = ca[s, 0] - placed[j, 0], ca[s, 1] - placed[j, 1], ca[s, 2] - placed[j, 2]
                if np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) <= distance:
                    same[i, j] = True
                    break
    return same


same_pose_pairs = _compile(same_pose_pairs)


__all__ = ["COMPILED", "closed_form_rotations", "closed_form_translations", "refine_poses", "same_pose_pairs"]
