"""Compiled forms of the matcher's inner loops: the refinement and the closed-form poses of many interpretations
(:mod:`haptic.matching.batch_poses`), the grouping of poses into pose classes (:mod:`haptic.matching.recognition`),
the edge-pair tests of the interpretation tree (:mod:`haptic.matching.tree`), the distances of the pose check and
the free-space test (:mod:`haptic.matching.acceptance`, :mod:`haptic.matching.free_space`), and the planner's
table of which hypotheses a predicted outcome tells apart (:func:`~haptic.planning.efficiency.distinguishable`).

Each kernel is a plain loop over small arrays, compiled by numba (``@njit(cache=True)``: compiled on the first
call of a checkout and kept in ``__pycache__``) and called in place of the numpy form of the same arithmetic,
which stays the reference: the numpy forms spend most of their time in the overhead of many operations on arrays
of a few elements. The results agree with the numpy forms' to the rounding of sums taken in another order (about
1e-15 relative); ``tests/matching/test_kernels.py`` checks that, and that episodes decide the same either way.

:data:`COMPILED` is False, and the callers take the numpy forms, when numba is not installed or the environment
variable ``HAPTIC_COMPILED`` is ``0`` (:mod:`haptic.geometry.kernels`, which holds the geometric kernels).
"""

from __future__ import annotations

import numpy as np

from haptic.geometry import kernels as _geometry

COMPILED = _geometry.COMPILED
"""Whether the callers use the compiled kernels (numba installed and ``HAPTIC_COMPILED`` not ``0``: the switch of
:mod:`haptic.geometry.kernels`)."""
_compile = _geometry.compile_kernel


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


def _wahba(h, out, w, v):
    """The proper rotation R maximising ``trace(Rᵀ h)`` into ``out`` (3, 3): with ``h = U Σ Vᵀ`` (singular values
    descending), ``R = U diag(1, 1, det(U Vᵀ)) Vᵀ``, which is ``u₁v₁ᵀ + u₂v₂ᵀ + det(V) (u₁ × u₂) v₃ᵀ`` and needs
    neither ``σ₃`` nor ``u₃``. The SVD by one-sided Jacobi rotations (Hestenes): ``h V``'s columns turned in pairs
    until orthogonal to the last bits, which keeps each singular vector as accurate as LAPACK's however far apart
    the singular values are. ``w``, ``v``: (3, 3) scratch. False when ``h`` has rank below 2 (the caller then takes
    LAPACK's SVD)."""
    w[:] = h
    v[:] = 0.0
    v[0, 0] = v[1, 1] = v[2, 2] = 1.0
    for _ in range(30):
        turned = False
        for p, q in ((0, 1), (0, 2), (1, 2)):
            alpha = w[0, p] * w[0, p] + w[1, p] * w[1, p] + w[2, p] * w[2, p]
            beta = w[0, q] * w[0, q] + w[1, q] * w[1, q] + w[2, q] * w[2, q]
            gamma = w[0, p] * w[0, q] + w[1, p] * w[1, q] + w[2, p] * w[2, q]
            if abs(gamma) <= 1e-15 * np.sqrt(alpha * beta):
                continue
            turned = True
            zeta = (beta - alpha) / (2.0 * gamma)
            t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
            c = 1.0 / np.sqrt(1.0 + t * t)
            s = c * t
            for k in range(3):
                wp, wq = w[k, p], w[k, q]
                w[k, p], w[k, q] = c * wp - s * wq, s * wp + c * wq
                vp, vq = v[k, p], v[k, q]
                v[k, p], v[k, q] = c * vp - s * vq, s * vp + c * vq
        if not turned:
            break
    s0 = np.sqrt(w[0, 0] * w[0, 0] + w[1, 0] * w[1, 0] + w[2, 0] * w[2, 0])
    s1 = np.sqrt(w[0, 1] * w[0, 1] + w[1, 1] * w[1, 1] + w[2, 1] * w[2, 1])
    s2 = np.sqrt(w[0, 2] * w[0, 2] + w[1, 2] * w[1, 2] + w[2, 2] * w[2, 2])
    # the columns by singular value, descending
    i1, i2, i3 = 0, 1, 2
    if s1 > s0:
        i1, i2 = 1, 0
    big, mid = (s1, s0) if s1 > s0 else (s0, s1)
    if s2 > big:
        i1, i2, i3 = 2, i1, i2
        big, mid = s2, big
    elif s2 > mid:
        i2, i3 = 2, i2
        mid = s2
    if big == 0.0 or mid <= 1e-12 * big:
        return False
    a0, a1, a2 = w[0, i1] / big, w[1, i1] / big, w[2, i1] / big
    b0, b1, b2 = w[0, i2] / mid, w[1, i2] / mid, w[2, i2] / mid
    det_v = (v[1, i1] * v[2, i2] - v[2, i1] * v[1, i2]) * v[0, i3]
    det_v += (v[2, i1] * v[0, i2] - v[0, i1] * v[2, i2]) * v[1, i3]
    det_v += (v[0, i1] * v[1, i2] - v[1, i1] * v[0, i2]) * v[2, i3]
    sign = 1.0 if det_v > 0.0 else -1.0
    c0, c1, c2 = sign * (a1 * b2 - a2 * b1), sign * (a2 * b0 - a0 * b2), sign * (a0 * b1 - a1 * b0)
    for j in range(3):
        out[0, j] = a0 * v[j, i1] + b0 * v[j, i2] + c0 * v[j, i3]
        out[1, j] = a1 * v[j, i1] + b1 * v[j, i2] + c1 * v[j, i3]
        out[2, j] = a2 * v[j, i1] + b2 * v[j, i2] + c2 * v[j, i3]
    return True


_wahba = _compile(_wahba)


def closed_form_rotations(dirs_w, dirs_m, dirs_wt, known, min_spread):
    """:meth:`~haptic.matching.batch_poses.StackedPoses.rotations` one problem at a time: whether the known
    directions span at least ``min_spread`` (the largest ``|u_i × u_j|``), and the proper rotation of Wahba's
    problem by the SVD of ``Σ w a uᵀ``, its last singular vector turned where ``det(U Vᵀ) < 0``. Returns ``(R (N,
    3, 3), ok (N,))``; a problem that is not ok has no pose, and the identity in place of its rotation."""
    n_prob, n_dirs = dirs_m.shape[0], dirs_w.shape[0]
    out = np.empty((n_prob, 3, 3))
    ok = np.zeros(n_prob, np.bool_)
    h = np.empty((3, 3))
    w_buf = np.empty((3, 3))
    v_buf = np.empty((3, 3))
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
        if not ok[p]:  # no pose: the rotation is not used
            out[p] = 0.0
            out[p, 0, 0] = out[p, 1, 1] = out[p, 2, 2] = 1.0
            continue
        h[:] = 0.0
        for d in range(n_dirs):
            w = dirs_wt[p, d]
            for i in range(3):
                wa = dirs_w[d, i] * w
                for j in range(3):
                    h[i, j] += wa * dirs_m[p, d, j]
        if _wahba(h, out[p], w_buf, v_buf):
            continue
        u, _, vt = np.linalg.svd(h)  # rank below 2: as numpy does it
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


# ------------------------------------------------------------------------------------------- edge pairs


def _position_ok(s_d, l_d, s_m, l_m, eps, at_start, at_end):
    """:func:`~haptic.matching.constraints.edge_position_test` of one pair."""
    if np.isnan(s_d) or not np.isfinite(eps):
        return True
    lo, hi = s_d - l_d, s_m - l_m
    ok = (hi - eps < lo) and (s_d < s_m + eps)
    if at_start:
        ok = ok and abs(s_d - s_m) < eps
    if at_end:
        ok = ok and abs(lo - hi) < eps
    return ok


_position_ok = _compile(_position_ok)


def edge_pair_tests(
    p_d1, b_d1, l_d1, p_d2, b_d2, l_d2, p_m1, b_m1, l_m1, p_m2, b_m2, l_m2,
    beta_1, beta_2, rho_1, rho_2, lam_1, lam_2, start_1, end_1, start_2, end_2,
    safety, angle_floor, length_floor, min_sin, cos_parallel,
):  # fmt: skip
    """:func:`~haptic.matching.constraints.edge_pair_tests` of one data edge (``p_d1``, ``b_d1`` (3,), ``l_d1``,
    its bounds and vertex ends scalars) against E earlier ones (``p_d2``, ``b_d2`` (E, 3), the rest (E,)), for C
    candidate pairings (model edge 1: ``p_m1``, ``b_m1`` (C, 3), ``l_m1`` (C,); model edges 2: (C, E, 3) and (C,
    E)): the same tests pair by pair, shape (C, E). The constants are those of
    :mod:`~haptic.matching.constraints`."""
    n_c, n_e = p_m2.shape[0], p_m2.shape[1]
    out = np.zeros((n_c, n_e), np.bool_)
    for e in range(n_e):
        # the data side of the pair
        dd0, dd1, dd2 = p_d2[e, 0] - p_d1[0], p_d2[e, 1] - p_d1[1], p_d2[e, 2] - p_d1[2]
        d_norm = np.sqrt(dd0 * dd0 + dd1 * dd1 + dd2 * dd2)
        c_d = b_d1[0] * b_d2[e, 0] + b_d1[1] * b_d2[e, 1] + b_d1[2] * b_d2[e, 2]
        theta_d = np.arccos(min(max(c_d, -1.0), 1.0))
        eps_angle = beta_1 + beta_2[e] + angle_floor
        big_beta = max(beta_1, beta_2[e])
        eps_par = rho_1 + rho_2[e] + safety * d_norm * big_beta + length_floor
        eps_ord = lam_1 + lam_2[e] + safety * d_norm * big_beta + length_floor
        th = min(theta_d, np.pi - theta_d) - beta_1 - beta_2[e]
        sin_min = np.sin(min(max(th, 0.0), np.pi / 2))
        usable = sin_min >= min_sin
        den = 1.0 - c_d * c_d
        den = den if den > 1e-15 else np.nan
        db1 = dd0 * b_d1[0] + dd1 * b_d1[1] + dd2 * b_d1[2]
        db2 = dd0 * b_d2[e, 0] + dd1 * b_d2[e, 1] + dd2 * b_d2[e, 2]
        s_d1 = (db1 - c_d * db2) / den
        s_d2 = (c_d * db1 - db2) / den
        cx = b_d1[1] * b_d2[e, 2] - b_d1[2] * b_d2[e, 1]
        cy = b_d1[2] * b_d2[e, 0] - b_d1[0] * b_d2[e, 2]
        cz = b_d1[0] * b_d2[e, 1] - b_d1[1] * b_d2[e, 0]
        cn = np.sqrt(cx * cx + cy * cy + cz * cz)
        h_d = (cx * dd0 + cy * dd1 + cz * dd2) / cn if cn > 1e-12 else np.nan
        if usable:
            b12 = beta_1 + beta_2[e]
            prop = (rho_1 + rho_2[e] + abs(s_d1) * beta_1 + abs(s_d2) * beta_2[e]) / sin_min
            prop = prop + abs(h_d) * b12 / (sin_min * sin_min)
            eps_1 = lam_1 + safety * prop + length_floor
            b21 = beta_2[e] + beta_1
            prop = (rho_2[e] + rho_1 + abs(s_d2) * beta_2[e] + abs(s_d1) * beta_1) / sin_min
            prop = prop + abs(h_d) * b21 / (sin_min * sin_min)
            eps_2 = lam_2[e] + safety * prop + length_floor
            eps_skew = rho_1 + rho_2[e] + safety * d_norm * b12 / sin_min + length_floor
        for c in range(n_c):
            m1x, m1y, m1z = b_m1[c, 0], b_m1[c, 1], b_m1[c, 2]
            m2x, m2y, m2z = b_m2[c, e, 0], b_m2[c, e, 1], b_m2[c, e, 2]
            c_m = m1x * m2x + m1y * m2y + m1z * m2z
            if not abs(theta_d - np.arccos(min(max(c_m, -1.0), 1.0))) < eps_angle:
                continue
            dm0, dm1, dm2 = p_m2[c, e, 0] - p_m1[c, 0], p_m2[c, e, 1] - p_m1[c, 1], p_m2[c, e, 2] - p_m1[c, 2]
            anti = c_m < -cos_parallel
            if c_m > cos_parallel or anti:
                sgn = -1.0 if anti else 1.0
                ux, uy, uz = b_d1[0] + sgn * b_d2[e, 0], b_d1[1] + sgn * b_d2[e, 1], b_d1[2] + sgn * b_d2[e, 2]
                un = max(np.sqrt(ux * ux + uy * uy + uz * uz), 1e-12)
                ux, uy, uz = ux / un, uy / un, uz / un
                vx, vy, vz = m1x + sgn * m2x, m1y + sgn * m2y, m1z + sgn * m2z
                vn = max(np.sqrt(vx * vx + vy * vy + vz * vz), 1e-12)
                vx, vy, vz = vx / vn, vy / vn, vz / vn
                x_d = dd0 * ux + dd1 * uy + dd2 * uz
                x_m = dm0 * vx + dm1 * vy + dm2 * vz
                ex, ey, ez = dd0 - x_d * ux, dd1 - x_d * uy, dd2 - x_d * uz
                fx, fy, fz = dm0 - x_m * vx, dm1 - x_m * vy, dm2 - x_m * vz
                sep = np.sqrt(ex * ex + ey * ey + ez * ez) - np.sqrt(fx * fx + fy * fy + fz * fz)
                if not abs(sep) < eps_par:
                    continue
                if anti:
                    ok = (x_m - (l_m1[c] + l_m2[c, e]) - eps_ord < x_d - (l_d1 + l_d2[e])) and (x_d < x_m + eps_ord)
                else:
                    ok = (x_m - (l_m1[c] - l_d1) - eps_ord < x_d) and (x_d < x_m + (l_m2[c, e] - l_d2[e]) + eps_ord)
                out[c, e] = ok
                continue
            if not usable:
                out[c, e] = True
                continue
            # general position: closest approach along each model edge, and the skew distance
            den_m = 1.0 - c_m * c_m
            den_m = den_m if den_m > 1e-15 else np.nan
            mb1 = dm0 * m1x + dm1 * m1y + dm2 * m1z
            mb2 = dm0 * m2x + dm1 * m2y + dm2 * m2z
            s_m1 = (mb1 - c_m * mb2) / den_m
            s_m2 = (c_m * mb1 - mb2) / den_m
            if not _position_ok(s_d1, l_d1, s_m1, l_m1[c], eps_1, start_1, end_1):
                continue
            if not _position_ok(s_d2, l_d2[e], s_m2, l_m2[c, e], eps_2, start_2[e], end_2[e]):
                continue
            gx, gy, gz = m1y * m2z - m1z * m2y, m1z * m2x - m1x * m2z, m1x * m2y - m1y * m2x
            gn = np.sqrt(gx * gx + gy * gy + gz * gz)
            h_m = (gx * dm0 + gy * dm1 + gz * dm2) / gn if gn > 1e-12 else np.nan
            out[c, e] = abs(h_d - h_m) < eps_skew or np.isnan(h_d) or np.isnan(h_m) or not np.isfinite(eps_skew)
    return out


edge_pair_tests = _compile(edge_pair_tests)


# ------------------------------------------------------------------------------------------- distances


def _triangle_distance(q0, q1, q2, tri, k):
    """:func:`~haptic.geometry.distance._distance` of the point ``q`` from triangle ``tri[k]``, the same formulas:
    the distance from its plane where the projection's barycentric coordinates fall inside, else from the nearest
    side."""
    a0, a1, a2 = tri[k, 0, 0], tri[k, 0, 1], tri[k, 0, 2]
    ab0, ab1, ab2 = tri[k, 1, 0] - a0, tri[k, 1, 1] - a1, tri[k, 1, 2] - a2
    ac0, ac1, ac2 = tri[k, 2, 0] - a0, tri[k, 2, 1] - a1, tri[k, 2, 2] - a2
    n0, n1, n2 = ab1 * ac2 - ab2 * ac1, ab2 * ac0 - ab0 * ac2, ab0 * ac1 - ab1 * ac0
    nn = n0 * n0 + n1 * n1 + n2 * n2 + 1e-30
    w0, w1, w2 = q0 - a0, q1 - a1, q2 - a2
    wn = w0 * n0 + w1 * n1 + w2 * n2
    f = wn / nn
    v0, v1, v2 = q0 - f * n0 - a0, q1 - f * n1 - a1, q2 - f * n2 - a2
    d00 = ab0 * ab0 + ab1 * ab1 + ab2 * ab2
    d01 = ab0 * ac0 + ab1 * ac1 + ab2 * ac2
    d11 = ac0 * ac0 + ac1 * ac1 + ac2 * ac2
    d20 = v0 * ab0 + v1 * ab1 + v2 * ab2
    d21 = v0 * ac0 + v1 * ac1 + v2 * ac2
    den = d00 * d11 - d01 * d01 + 1e-30
    s = (d11 * d20 - d01 * d21) / den
    t = (d00 * d21 - d01 * d20) / den
    if s >= 0 and t >= 0 and s + t <= 1:
        return abs(wn / np.sqrt(nn))
    best = np.inf
    for i, j in ((0, 1), (1, 2), (2, 0)):
        x0, x1, x2 = tri[k, i, 0], tri[k, i, 1], tri[k, i, 2]
        e0, e1, e2 = tri[k, j, 0] - x0, tri[k, j, 1] - x1, tri[k, j, 2] - x2
        h = ((q0 - x0) * e0 + (q1 - x1) * e1 + (q2 - x2) * e2) / (e0 * e0 + e1 * e1 + e2 * e2 + 1e-30)
        h = min(max(h, 0.0), 1.0)
        r0, r1, r2 = q0 - (x0 + h * e0), q1 - (x1 + h * e1), q2 - (x2 + h * e2)
        d = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        if d < best:
            best = d
    return best


_triangle_distance = _compile(_triangle_distance)


def paired_point_triangle_distance(points, tri):
    """:func:`~haptic.geometry.distance.paired_point_triangle_distance`: the distance (M,) of each point (M, 3)
    from its own triangle (M, 3, 3)."""
    out = np.empty(points.shape[0])
    for i in range(points.shape[0]):
        out[i] = _triangle_distance(points[i, 0], points[i, 1], points[i, 2], tri, i)
    return out


paired_point_triangle_distance = _compile(paired_point_triangle_distance)


def surface_distance(points, tri):
    """:func:`~haptic.geometry.distance.surface_distance`: the distance (P,) of each point (P, 3) from the nearest of
    the triangles (T, 3, 3)."""
    out = np.empty(points.shape[0])
    for i in range(points.shape[0]):
        best = np.inf
        for k in range(tri.shape[0]):
            d = _triangle_distance(points[i, 0], points[i, 1], points[i, 2], tri, k)
            if d < best:
                best = d
        out[i] = best
    return out


surface_distance = _compile(surface_distance)


# ------------------------------------------------------------------------------------------- eliminations


def distinguishable(outcomes, bounds):
    """:func:`~haptic.planning.efficiency.distinguishable`: ``D[i, j]`` when some attribute of hypothesis ``j``'s
    predicted outcome (``outcomes`` (N, A), NaN: none) differs from ``i``'s by more than its bound (``bounds``
    (A,)), the same comparisons."""
    n, n_attr = outcomes.shape
    thr = bounds * (1 + 1e-9) + 1e-12
    out = np.zeros((n, n), np.bool_)
    for i in range(n):
        for j in range(n):
            for a in range(n_attr):
                if abs(outcomes[i, a] - outcomes[j, a]) > thr[a]:  # False where either is NaN
                    out[i, j] = True
                    break
    return out


distinguishable = _compile(distinguishable)


__all__ = [
    "COMPILED",
    "closed_form_rotations",
    "closed_form_translations",
    "distinguishable",
    "edge_pair_tests",
    "paired_point_triangle_distance",
    "refine_poses",
    "same_pose_pairs",
    "surface_distance",
]
