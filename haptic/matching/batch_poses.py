"""Poses of many interpretations at once: their residuals stacked into arrays (seed §2.1, §2.6).

All interpretations of a tree pair the same data components, each with a component of its own model, so their
least-squares problems have one structure: the same rows (a direction per paired face and per edge of known
sense, a plane row per touched point, two line rows per edge, a point per vertex), the same data side, and
model sides that differ only in which model component fills each row. :class:`StackedPoses` holds the model
side as arrays with a leading axis over interpretations, and every step of
:func:`~haptic.matching.pose.estimate_pose` — the proper-rotation fit of the directions, the linear least
squares for the translation, and the Gauss–Newton refinement — runs as one batched array operation over all of
them. An edge whose sense is not known yet keeps its direction row with weight 0 (it then constrains position
only, as in the single problem).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from haptic.geometry.se3 import cross
from haptic.matching import kernels
from haptic.matching.components import DataComponent

MIN_SPREAD = 0.05
"""Directions must span at least this sine of an angle to fix a rotation."""
MIN_CONDITION = 1e-4
"""Smallest accepted ratio of singular values of the translation system (else the pose is undetermined)."""
GN_ITERATIONS = 6
"""Most Gauss–Newton iterations of the refinement (each problem stops early once its step is below
:data:`GN_TOLERANCE`)."""
GN_TOLERANCE = 1e-9
"""A problem's refinement stops after a Gauss–Newton step shorter than this (rotation vector [rad] and translation
[m] together). The steps shrink about a thousandfold per iteration from the closed-form pose (2e-3, 3e-6, 6e-9,
2e-11 in the median) down to the finite-difference Jacobian's noise (about 1e-11), where further iterations move
the pose by no more than that: four iterations then, where a bound at the noise itself ran all six."""


def exp_so3(w: np.ndarray) -> np.ndarray:
    """Rotation matrices ``exp([w]×)`` of rotation vectors, shape (..., 3) → (..., 3, 3) (Rodrigues)."""
    w = np.asarray(w, dtype=float)
    th = np.linalg.norm(w, axis=-1)[..., None, None]
    k = np.zeros((*w.shape[:-1], 3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    k[..., 1, 0], k[..., 2, 0], k[..., 2, 1] = w[..., 2], -w[..., 1], w[..., 0]
    small = th < 1e-12
    safe = np.where(small, 1.0, th)
    a = np.where(small, 1.0, np.sin(safe) / safe)
    b = np.where(small, 0.0, (1 - np.cos(safe)) / safe**2)
    return np.eye(3) + a * k + b * (k @ k)


def proper_rotations(world: np.ndarray, model: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Per interpretation, the proper rotation R minimising ``Σ w ‖a − R c‖²`` (Wahba's problem by SVD).

    ``world`` (K, 3) or (N, K, 3), ``model`` (N, K, 3), ``weights`` (N, K) → (N, 3, 3)."""
    h = np.swapaxes(world * weights[..., None], -1, -2) @ model
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(u @ vt))
    d = np.where(d == 0, 1.0, d)
    u = u.copy()
    u[..., :, 2] *= d[..., None]
    return u @ vt


def _lstsq(a: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Batched least squares ``a x ≈ y`` (minimum norm) and the singular values of ``a`` (descending)."""
    u, s, vt = np.linalg.svd(a, full_matrices=False)
    cutoff = np.finfo(float).eps * max(a.shape[-2:]) * s[..., :1]
    inv = np.where(s > cutoff, 1.0 / np.where(s > 0, s, 1.0), 0.0)
    x = np.swapaxes(vt, -1, -2) @ ((np.swapaxes(u, -1, -2) @ y[..., None])[..., 0] * inv)[..., None]
    return x[..., 0], s


def _gauss_newton_step(jac: np.ndarray, f0: np.ndarray) -> np.ndarray:
    """The steps minimising ``‖J x + f₀‖`` (N, 6): by the normal equations (6 × 6 per problem), or by the SVD
    least squares where those are singular."""
    jt = np.swapaxes(jac, -1, -2)
    try:
        return np.linalg.solve(jt @ jac, -(jt @ f0[..., None]))[..., 0]
    except np.linalg.LinAlgError:
        return _lstsq(jac, -f0)[0]


class StackedPoses:
    """The weighted residuals of N interpretations of the same data, stacked (leading axis N).

    The data side (shared): ``face_ids``, ``edge_ids``, ``vertex_ids`` are the data components paired, in
    order. The model side (per interpretation): the paired model faces' normals (N, F, 3) and offsets (N, F),
    edges' source points and directions (N, E, 3) with the senses (N, E) that pair them (+1: ``b_d ≈ R b_m``,
    −1: ``b_d ≈ −R b_m``, 0 unknown), and vertex positions (N, V, 3), all in the model frame [m].
    """

    def __init__(
        self,
        data: Sequence[DataComponent],
        face_ids: Sequence[int],
        edge_ids: Sequence[int],
        vertex_ids: Sequence[int],
        face_normal: np.ndarray,
        face_offset: np.ndarray,
        edge_point: np.ndarray,
        edge_direction: np.ndarray,
        senses: np.ndarray,
        vertex_position: np.ndarray,
    ) -> None:
        n = len(face_normal)
        self.n = n
        faces = [data[i] for i in face_ids]
        edges = [data[i] for i in edge_ids]
        verts = [data[i] for i in vertex_ids]
        senses = np.asarray(senses, dtype=float).reshape(n, len(edges))
        # directions: one row per face, one per edge (weight 0 while its sense is unknown)
        self.dirs_w = np.array([c.normal for c in faces] + [c.direction for c in edges], dtype=float).reshape(-1, 3)
        self.dirs_m = np.concatenate(
            [np.asarray(face_normal, float).reshape(n, -1, 3), senses[..., None] * np.asarray(edge_direction)],
            axis=1,
        )
        wt = np.array(
            [1.0 / max(c.normal_bound, 1e-6) ** 2 for c in faces]
            + [1.0 / max(c.direction_bound, 1e-6) ** 2 for c in edges]
        )
        known = np.concatenate([np.ones((n, len(faces)), bool), senses != 0], axis=1)
        self.dirs_wt = np.where(known, wt, 0.0)
        self.dirs_known = known
        self._dirs_sw = np.sqrt(self.dirs_wt)
        # planes: one row per touched point of a paired face
        k = [len(np.atleast_2d(c.points)) for c in faces]
        self.plane_n = np.repeat(np.asarray(face_normal, float).reshape(n, -1, 3), k, axis=1)
        self.plane_d = np.repeat(np.asarray(face_offset, float).reshape(n, -1), k, axis=1)
        self.plane_q = np.concatenate([np.asarray(c.points, float).reshape(-1, 3) for c in faces] or [np.zeros((0, 3))])
        self.plane_w = np.repeat([1.0 / max(c.position_bound, 1e-7) for c in faces], k).astype(float)
        # lines: two rows (the explored interval's ends) per paired edge
        self.line_p = np.repeat(np.asarray(edge_point, float).reshape(n, -1, 3), 2, axis=1)
        self.line_b = np.repeat(np.asarray(edge_direction, float).reshape(n, -1, 3), 2, axis=1)
        self.line_x = np.array([x for c in edges for x in (c.point, c.end_point)], dtype=float).reshape(-1, 3)
        rho = [max(c.position_bound, 1e-7) for c in edges]
        self.line_w = np.array(
            [w for c, r in zip(edges, rho, strict=True) for w in (1.0 / r, 1.0 / (r + c.length * c.direction_bound))]
        ).reshape(-1)
        # points: one per paired vertex
        self.pt_m = np.asarray(vertex_position, float).reshape(n, -1, 3)
        self.pt_d = np.array([c.position for c in verts], dtype=float).reshape(-1, 3)
        self.pt_w = np.array([1.0 / max(c.position_bound, 1e-7) for c in verts], dtype=float)
        self._rows: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._normal: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def subset(self, rows: np.ndarray) -> StackedPoses:
        """The problems of some interpretations only (``rows`` indexes the leading axis)."""
        out = object.__new__(StackedPoses)
        out.__dict__.update(self.__dict__)
        for name in ("dirs_m", "dirs_wt", "dirs_known", "_dirs_sw", "plane_n", "plane_d", "line_p", "line_b", "pt_m"):
            setattr(out, name, getattr(self, name)[rows])
        out.n = len(rows)
        out._rows = None if self._rows is None else tuple(a if a.ndim == 2 else a[rows] for a in self._rows)
        out._normal = None if self._normal is None else tuple(a[rows] for a in self._normal)
        return out

    def rotations(self) -> tuple[np.ndarray, np.ndarray]:
        """``(R (N, 3, 3), ok (N,))``: the rotation from all directions, where they span enough (seed §2.6)."""
        u = np.where(self.dirs_known[..., None], self.dirs_m, 0.0)
        ok = self.dirs_known.sum(axis=1) >= 2
        if u.shape[1]:
            # the largest |u_i × u_j| over pairs, from |u × v|² = |u|² |v|² − (u · v)²
            gram = u @ np.swapaxes(u, -1, -2)
            sq = np.einsum("nii->ni", gram)
            cross2 = sq[:, :, None] * sq[:, None, :] - gram**2
            ok &= np.sqrt(np.maximum(cross2.max(axis=(1, 2)), 0.0)) >= MIN_SPREAD
        if not u.shape[1] or not ok.any():
            return np.broadcast_to(np.eye(3), (self.n, 3, 3)).copy(), ok
        return proper_rotations(self.dirs_w, self.dirs_m, self.dirs_wt), ok

    def _compiled_initial(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`initial` by the compiled kernels (:mod:`haptic.matching.kernels`): the same poses to the rounding."""
        if not self.dirs_w.shape[0]:
            return np.broadcast_to(np.eye(3), (self.n, 3, 3)).copy(), np.zeros(self.n, bool), np.zeros((self.n, 3))
        r, ok = kernels.closed_form_rotations(
            self.dirs_w, np.ascontiguousarray(self.dirs_m), np.ascontiguousarray(self.dirs_wt),
            np.ascontiguousarray(self.dirs_known), MIN_SPREAD,
        )  # fmt: skip
        if not ok.any():
            return np.broadcast_to(np.eye(3), (self.n, 3, 3)).copy(), ok, np.zeros((self.n, 3))
        if len(self.plane_q) + 3 * len(self.line_x) + 3 * len(self.pt_d) < 3:
            return r, np.zeros(self.n, bool), np.zeros((self.n, 3))
        x, c, _ = self._position_rows()
        q, total, ok_t = self._normal_matrices()
        ok &= ok_t
        t = kernels.closed_form_translations(
            np.ascontiguousarray(q), np.ascontiguousarray(total), ok, np.ascontiguousarray(x),
            np.ascontiguousarray(c), r,
        )  # fmt: skip
        return r, ok, t

    def translations(self, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(t (N, 3), ok (N,))``: the translation by linear least squares on planes, lines and vertices given
        the rotations, where that system is well conditioned (its smallest singular value at least
        :data:`MIN_CONDITION` times its largest).

        With the rows of :meth:`_position_rows` (``M (Rᵀ (x − t) − c)``, ``Q = MᵀM`` per row), the normal
        equations are ``R (Σ Q) Rᵀ t = R Σ Q (Rᵀ x − c)``, so ``t = R (Σ Q)⁻¹ Σ Q (Rᵀ x − c)``: the system's matrix
        is the model-frame ``Σ Q`` turned, and its singular values (the square roots of ``Σ Q``'s eigenvalues) do
        not depend on the rotation."""
        n_rows = len(self.plane_q) + 3 * len(self.line_x) + 3 * len(self.pt_d)
        if n_rows < 3:
            return np.zeros((self.n, 3)), np.zeros(self.n, bool)
        x, c, m = self._position_rows()
        q, total, ok = self._normal_matrices()
        v = np.einsum("nkij,nkj->ni", q, x @ r - c)
        safe = np.where(ok[:, None, None], total, np.eye(3))
        t = (r @ np.linalg.solve(safe, v[..., None]))[..., 0]
        return t, ok

    def _normal_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``Q = MᵀM`` of each position row (N, K, 3, 3) (``w²`` times its projector), their sum per problem (N, 3,
        3), and whether that sum is well conditioned (its eigenvalues within :data:`MIN_CONDITION`² of each other);
        built once per problem."""
        if self._normal is None:
            x, c, m = self._position_rows()
            w = np.concatenate([self.plane_w, self.line_w, self.pt_w])
            q = w[:, None, None] * m  # M is w times a projector P: MᵀM = w² P
            total = q.sum(axis=1)
            lam = np.linalg.eigvalsh(total)
            self._normal = (q, total, lam[:, 0] >= MIN_CONDITION**2 * lam[:, 2])
        return self._normal

    def residuals(self, r: np.ndarray, t: np.ndarray) -> np.ndarray:
        """All weighted residuals at poses ``r`` (..., N, 3, 3), ``t`` (..., N, 3): shape (..., N, rows)."""
        lead = r.shape[:-2]
        parts = [((self.dirs_w - self.dirs_m @ np.swapaxes(r, -1, -2)) * self._dirs_sw[..., None]).reshape(*lead, -1)]
        if len(self.plane_q):  # (an empty block adds no row: left out, it costs no array operations)
            q = (self.plane_q - t[..., None, :]) @ r
            parts.append(self.plane_w * (np.einsum("...ij,...ij->...i", q, self.plane_n) - self.plane_d))
        if len(self.line_x):
            y = (self.line_x - t[..., None, :]) @ r - self.line_p
            along = np.einsum("...ij,...ij->...i", y, self.line_b)[..., None] * self.line_b
            parts.append((self.line_w[:, None] * (y - along)).reshape(*lead, -1))
        if len(self.pt_d):
            parts.append((self.pt_w[:, None] * ((self.pt_d - t[..., None, :]) @ r - self.pt_m)).reshape(*lead, -1))
        return np.concatenate(parts, axis=-1)

    def initial(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(R, t, ok)``: the closed-form poses (rotation from directions, then translation), unrefined."""
        if kernels.COMPILED:
            r, ok, t = self._compiled_initial()
            return r, t, ok
        r, ok = self.rotations()
        t = np.zeros((self.n, 3))
        if ok.any():
            idx = np.flatnonzero(ok)
            t_ok, ok_t = self.subset(idx).translations(r[idx])
            t[idx] = t_ok
            ok[idx] = ok_t
        return r, t, ok

    def _position_rows(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The plane, line and point rows in one form, built once per problem: the data points ``x`` (K, 3), a
        point ``c`` (N, K, 3) of each paired model feature and a weighted projector ``M`` (N, K, 3, 3), such that
        the block's residual vector at a pose is ``M (Rᵀ (x − t) − c)``. A plane row's projector is ``w n nᵀ``
        (a vector along the normal whose length is the weighted plane residual ``w (n · Rᵀ (x − t) − d)``, with
        ``c = d n``), a line row's ``w (I − b bᵀ)``, a point row's ``w I``: the same sum of squares as
        :meth:`residuals`, in a third of the array operations."""
        if self._rows is not None:
            return self._rows
        n = self.n
        eye = np.eye(3)
        x, c, m = [], [], []
        if len(self.plane_q):
            nrm = self.plane_n
            x.append(self.plane_q)
            c.append(nrm * self.plane_d[..., None])
            m.append(self.plane_w[:, None, None] * (nrm[..., :, None] * nrm[..., None, :]))
        if len(self.line_x):
            b = self.line_b
            x.append(self.line_x)
            c.append(self.line_p)
            m.append(self.line_w[:, None, None] * (eye - b[..., :, None] * b[..., None, :]))
        if len(self.pt_d):
            x.append(self.pt_d)
            c.append(self.pt_m)
            m.append(np.broadcast_to(self.pt_w[:, None, None] * eye, (n, len(self.pt_d), 3, 3)))
        if not x:
            self._rows = (np.zeros((0, 3)), np.zeros((n, 0, 3)), np.zeros((n, 0, 3, 3)))
        else:
            self._rows = (np.concatenate(x), np.concatenate(c, axis=1), np.concatenate(m, axis=1))
        return self._rows

    def _residuals_and_jacobian(self, r: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The residual vectors (N, rows) with the sum of squares of :meth:`residuals` at poses ``r`` (N, 3, 3),
        ``t`` (N, 3), and their Jacobian (N, rows, 6) for the pose perturbed on the left, ``(R, t) ↦ (E R, E t +
        v)`` with ``E = exp([ω]×)``, by rotation vector ω and translation v. Directions as ``√w (Rᵀ a − u)`` (the
        length of ``√w (a − R u)``): ``∂/∂ω = √w Rᵀ [a]×``; positions as :meth:`_position_rows`, ``M (Rᵀ (x − t)
        − c)``: ``∂/∂ω = M Rᵀ [x]×``, ``∂/∂v = −M Rᵀ`` (each row of ``B [x]×`` is that row of B crossed with x)."""
        n = self.n
        x, c, m = self._position_rows()
        sw = self._dirs_sw[..., None]
        f_dirs = (self.dirs_w @ r - self.dirs_m) * sw  # (N, D, 3)
        # √w Rᵀ [a]×: row i is √w (column i of R) × a
        cols = np.swapaxes(r, -1, -2)[:, None] * sw[..., None]  # (N, D, 3 rows, 3)
        j_dirs = np.concatenate([cross(cols, self.dirs_w[None, :, None]), np.zeros_like(cols)], axis=-1)
        if not len(x):
            return f_dirs.reshape(n, -1), j_dirs.reshape(n, -1, 6)
        a = m @ np.swapaxes(r, -1, -2)[:, None]  # M Rᵀ (N, K, 3, 3)
        f_pos = (a @ (x - t[:, None, :])[..., None])[..., 0] - (m @ c[..., None])[..., 0]
        j_pos = np.concatenate([cross(a, x[None, :, None]), -a], axis=-1)
        f = np.concatenate([f_dirs.reshape(n, -1), f_pos.reshape(n, -1)], axis=1)
        return f, np.concatenate([j_dirs.reshape(n, -1, 6), j_pos.reshape(n, -1, 6)], axis=1)

    def refine(self, r: np.ndarray, t: np.ndarray, iterations: int = GN_ITERATIONS) -> tuple[np.ndarray, np.ndarray]:
        """Gauss–Newton on the weighted residuals of every interpretation at once, perturbing each pose on the
        left (world frame), with the Jacobians in closed form (:meth:`_residuals_and_jacobian`); a problem whose
        step falls below :data:`GN_TOLERANCE` stops there (its later steps are not applied), and the iterations
        end when every problem has stopped."""
        r, t = np.array(r, dtype=float), np.array(t, dtype=float)
        if not len(r):
            return r, t
        if kernels.COMPILED:
            x, c, m = (np.ascontiguousarray(a) for a in self._position_rows())
            r_c, t_c = r.copy(), t.copy()
            sw = np.ascontiguousarray(self._dirs_sw)
            if kernels.refine_poses(
                self.dirs_w, np.ascontiguousarray(self.dirs_m), sw, x, c, m, r_c, t_c, iterations, GN_TOLERANCE
            ):
                return r_c, t_c
        active = np.ones(len(r), bool)
        for _ in range(iterations):
            f, jac = self._residuals_and_jacobian(r, t)
            step = _normal_step(jac, f)
            step[~active] = 0.0
            dr = _cayley(step[:, :3])
            r, t = dr @ r, (dr @ t[..., None])[..., 0] + step[:, 3:]
            active &= np.sqrt(np.einsum("ni,ni->n", step, step)) >= GN_TOLERANCE
            if not active.any():
                break
        return r, t


def _normal_step(jac: np.ndarray, f0: np.ndarray) -> np.ndarray:
    """The Gauss–Newton steps (N, 6) minimising ``‖J x + f₀‖`` for Jacobians ``jac`` (N, rows, 6), by the normal
    equations, or by the SVD least squares where those are singular."""
    jt = np.swapaxes(jac, -1, -2)
    try:
        return np.linalg.solve(jt @ jac, -(jt @ f0[..., None]))[..., 0]
    except np.linalg.LinAlgError:
        return _lstsq(jac, -f0)[0]


_HAT_HALF = np.zeros((3, 9))
_HAT_HALF[2, 1], _HAT_HALF[1, 2], _HAT_HALF[0, 5] = -0.5, 0.5, -0.5
_HAT_HALF[2, 3], _HAT_HALF[1, 6], _HAT_HALF[0, 7] = 0.5, -0.5, 0.5
"""``w @ _HAT_HALF`` is the skew matrix ``[w / 2]×`` of each rotation vector, flattened row-major."""


def _cayley(w: np.ndarray) -> np.ndarray:
    """The rotations (N, 3, 3) of the Cayley map of rotation vectors ``w`` (N, 3): ``I + 2 ([v]× + [v]×²) / (1 +
    |v|²)`` with ``v = w / 2``, a proper rotation that agrees with ``exp([w]×)`` to second order (to within
    ``|w|³ / 12``), in a third of the array operations of :func:`exp_so3`: the Gauss–Newton update, whose steps the
    next iteration corrects."""
    k = (w @ _HAT_HALF).reshape(-1, 3, 3)
    s = 2.0 / (1.0 + 0.25 * np.einsum("ni,ni->n", w, w))[:, None, None]
    return np.eye(3) + s * (k + k @ k)


_FD_STEP = 1e-7
"""Finite-difference step of the Gauss–Newton Jacobian."""
_FD_XI = np.eye(6) * _FD_STEP
_FD_ROT = exp_so3(_FD_XI[:, :3])
"""The six perturbations of the Jacobian and their rotations, computed once."""


__all__ = [
    "GN_ITERATIONS",
    "GN_TOLERANCE",
    "MIN_CONDITION",
    "MIN_SPREAD",
    "StackedPoses",
    "exp_so3",
    "proper_rotations",
]
