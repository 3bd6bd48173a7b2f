"""Pose of an interpretation: ``w_d = R w_m + t`` (seed §2.1), from an edge pair and by least squares.

Seed §2.6: a pair of non-parallel edges with consistent senses fixes the rotation uniquely (which is why mirror
images are told apart) and, through their lines, the translation. :func:`pose_from_edge_pair` is that closed
form. :func:`estimate_pose` uses every pairing of an interpretation: a rotation from all directions (face
normals, edge directions with their senses) by the proper-rotation solution of Wahba's problem, a translation
by linear least squares on planes, lines and vertices, then Gauss–Newton on all residuals weighted by the
error bounds.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3, rotation_angle
from haptic.matching.components import DataComponent

MIN_SPREAD = 0.05
"""Directions must span at least this sine of an angle to fix a rotation."""
MIN_CONDITION = 1e-4
"""Smallest accepted ratio of singular values of the translation system (else the pose is undetermined)."""


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def proper_rotation_fit(world: np.ndarray, model: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """The proper rotation R minimising ``Σ w ‖a − R c‖²`` for direction pairs ``a`` (world) and ``c`` (model)."""
    w = np.ones(len(world)) if weights is None else np.asarray(weights)
    h = (np.asarray(world) * w[:, None]).T @ np.asarray(model)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    return u @ np.diag([1.0, 1.0, d]) @ vt


def _closest_points(p1, b1, p2, b2) -> tuple[np.ndarray, np.ndarray]:
    c = b1 @ b2
    d = p2 - p1
    den = 1 - c * c
    s1 = (d @ b1 - c * (d @ b2)) / den
    s2 = (c * (d @ b1) - d @ b2) / den
    return p1 + s1 * b1, p2 + s2 * b2


def pose_from_edge_pair(p_d1, b_d1, p_d2, b_d2, p_m1, b_m1, p_m2, b_m2) -> SE3:
    """Seed §2.6: the transform taking a non-parallel model edge pair onto the data pair (senses consistent).

    R maps the model frame ``(b_1, b_1 × b_2, …)`` onto the data one (fitted over ``b_1``, ``b_2`` and their
    normalised cross product, so it is proper); t maps the midpoint of the model lines' common perpendicular
    onto the data one.
    """
    b_d1, b_d2, b_m1, b_m2 = (_unit(np.asarray(x, float)) for x in (b_d1, b_d2, b_m1, b_m2))
    world = np.array([b_d1, b_d2, _unit(np.cross(b_d1, b_d2))])
    model = np.array([b_m1, b_m2, _unit(np.cross(b_m1, b_m2))])
    r = proper_rotation_fit(world, model)
    xd = np.mean(_closest_points(np.asarray(p_d1, float), b_d1, np.asarray(p_d2, float), b_d2), axis=0)
    xm = np.mean(_closest_points(np.asarray(p_m1, float), b_m1, np.asarray(p_m2, float), b_m2), axis=0)
    return SE3(r, xd - r @ xm)


class _Problem:
    """The residuals of all pairings of one interpretation, weighted by the error bounds.

    Every kind of pairing is stacked into arrays once, so that a residual evaluation (Gauss–Newton takes some
    forty) is a handful of array operations whatever the number of pairings."""

    def __init__(self, model: Polyhedron, data: Sequence[DataComponent], faces, edges, senses, vertices):
        dirs_w, dirs_m, dirs_wt = [], [], []
        plane_n, plane_d, plane_q, plane_w = [], [], [], []  # one row per touched point of a paired face
        line_p, line_b, line_x, line_w = [], [], [], []  # two rows (interval ends) per paired edge
        pt_m, pt_d, pt_w = [], [], []
        for i, f in faces.items():
            c = data[i]
            dirs_w.append(c.normal)
            dirs_m.append(model.face_normals[f])
            dirs_wt.append(1.0 / max(c.normal_bound, 1e-6) ** 2)
            k = len(c.points)
            plane_n.append(np.repeat(model.face_normals[f][None], k, axis=0))
            plane_d.append(np.full(k, model.face_offsets[f]))
            plane_q.append(np.asarray(c.points, dtype=float).reshape(-1, 3))
            plane_w.append(np.full(k, 1.0 / max(c.position_bound, 1e-7)))
        for i, e in edges.items():
            c = data[i]
            s = senses.get(i, 0)
            pm, bm = model.edge_points[e], model.edge_directions[e]
            if s != 0:
                dirs_w.append(c.direction)
                dirs_m.append(s * bm)
                dirs_wt.append(1.0 / max(c.direction_bound, 1e-6) ** 2)
            rho = max(c.position_bound, 1e-7)
            line_p += [pm, pm]
            line_b += [bm, bm]
            line_x += [c.point, c.end_point]
            line_w += [1.0 / rho, 1.0 / (rho + c.length * c.direction_bound)]
        for i, v in vertices.items():
            c = data[i]
            pt_m.append(model.vertices[v])
            pt_d.append(c.position)
            pt_w.append(1.0 / max(c.position_bound, 1e-7))
        self.dirs_w = np.array(dirs_w, dtype=float).reshape(-1, 3)
        self.dirs_m = np.array(dirs_m, dtype=float).reshape(-1, 3)
        self.dirs_wt = np.array(dirs_wt, dtype=float)
        self._dirs_sw = np.sqrt(self.dirs_wt)[:, None]
        cat = (lambda xs, shape: np.concatenate(xs) if xs else np.zeros(shape))  # noqa: E731
        self.plane_n, self.plane_d = cat(plane_n, (0, 3)), cat(plane_d, (0,))
        self.plane_q, self.plane_w = cat(plane_q, (0, 3)), cat(plane_w, (0,))
        arr = (lambda xs, shape: np.array(xs, dtype=float).reshape(shape))  # noqa: E731
        self.line_p, self.line_b = arr(line_p, (-1, 3)), arr(line_b, (-1, 3))
        self.line_x, self.line_w = arr(line_x, (-1, 3)), arr(line_w, (-1,))
        self.pt_m, self.pt_d, self.pt_w = arr(pt_m, (-1, 3)), arr(pt_d, (-1, 3)), arr(pt_w, (-1,))

    def rotation(self) -> np.ndarray | None:
        if len(self.dirs_m) < 2:
            return None
        u = self.dirs_m
        spread = np.linalg.norm(np.cross(u[:, None, :], u[None, :, :]), axis=2).max()
        if spread < MIN_SPREAD:
            return None
        return proper_rotation_fit(self.dirs_w, self.dirs_m, self.dirs_wt)

    def translation(self, r: np.ndarray) -> np.ndarray | None:
        n = self.plane_n @ r.T  # rotated normals, one per touched point
        plane_rows = self.plane_w[:, None] * n
        plane_rhs = self.plane_w * (np.einsum("ij,ij->i", n, self.plane_q) - self.plane_d)
        b = self.line_b @ r.T
        perp = np.eye(3)[None] - b[:, :, None] * b[:, None, :]  # (L, 3, 3)
        line_rows = (self.line_w[:, None, None] * perp).reshape(-1, 3)
        line_rhs = (self.line_w[:, None] * np.einsum("lij,lj->li", perp, self.line_x - self.line_p @ r.T)).reshape(-1)
        pt_rows = (self.pt_w[:, None, None] * np.eye(3)[None]).reshape(-1, 3)
        pt_rhs = (self.pt_w[:, None] * (self.pt_d - self.pt_m @ r.T)).reshape(-1)
        a = np.concatenate([plane_rows, line_rows, pt_rows])
        if not len(a):
            return None
        y = np.concatenate([plane_rhs, line_rhs, pt_rhs])
        sv = np.linalg.svd(a, compute_uv=False)
        if len(sv) < 3 or sv[-1] < MIN_CONDITION * sv[0]:
            return None
        return np.linalg.lstsq(a, y, rcond=None)[0]

    def residuals(self, r: np.ndarray, t: np.ndarray) -> np.ndarray:
        dirs = ((self.dirs_w - self.dirs_m @ r.T) * self._dirs_sw).ravel()
        planes = self.plane_w * (np.einsum("ij,ij->i", (self.plane_q - t) @ r, self.plane_n) - self.plane_d)
        y = (self.line_x - t) @ r - self.line_p
        lines = (self.line_w[:, None] * (y - np.einsum("ij,ij->i", y, self.line_b)[:, None] * self.line_b)).ravel()
        pts = (self.pt_w[:, None] * ((self.pt_d - t) @ r - self.pt_m)).ravel()
        return np.concatenate([dirs, planes, lines, pts])


def _exp_so3(w: np.ndarray) -> np.ndarray:
    th = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    if th < 1e-12:
        return np.eye(3) + k
    return np.eye(3) + np.sin(th) / th * k + (1 - np.cos(th)) / th**2 * k @ k


_FD_STEP = 1e-7
"""Finite-difference step of the Gauss–Newton Jacobian."""
_FD_XI = tuple(np.eye(6)[j] * _FD_STEP for j in range(6))
_FD_ROT = tuple(_exp_so3(xi[:3]) for xi in _FD_XI)
"""The six perturbations of the Jacobian and their rotations, computed once."""


def refine_pose(problem: _Problem, pose: SE3, iterations: int = 6) -> SE3:
    """Gauss–Newton on the weighted residuals, perturbing the pose on the left (world frame)."""
    r, t = pose.rotation, pose.translation
    h = _FD_STEP
    for _ in range(iterations):
        f0 = problem.residuals(r, t)
        jac = np.empty((len(f0), 6))
        for j in range(6):
            xi, dr = _FD_XI[j], _FD_ROT[j]
            jac[:, j] = (problem.residuals(dr @ r, dr @ t + xi[3:]) - f0) / h
        step, *_ = np.linalg.lstsq(jac, -f0, rcond=None)
        dr = _exp_so3(step[:3])
        r, t = dr @ r, dr @ t + step[3:]
        u, _, vt = np.linalg.svd(r)
        r = u @ vt
        if np.linalg.norm(step) < 1e-12:
            break
    return SE3(r, t)


def estimate_pose(
    model: Polyhedron,
    data: Sequence[DataComponent],
    faces: Mapping[int, int],
    edges: Mapping[int, int],
    senses: Mapping[int, int],
    vertices: Mapping[int, int],
    refine: bool = True,
) -> SE3 | None:
    """The pose ``world_from_model`` of one interpretation, or None while the data do not determine it.

    ``faces``, ``edges``, ``vertices`` map data ids to model component ids; ``senses`` gives, per data edge,
    +1 when ``b_d ≈ R b_m`` and −1 when ``b_d ≈ −R b_m`` (0 unknown: the edge then constrains position only).
    """
    prob = _Problem(model, data, faces, edges, senses, vertices)
    r = prob.rotation()
    if r is None:
        return None
    t = prob.translation(r)
    if t is None:
        return None
    pose = SE3(r, t)
    return refine_pose(prob, pose) if refine else pose


def pose_error(estimate: SE3, truth: SE3, model: Polyhedron, symmetries: Sequence[SE3] = ()) -> tuple[float, float]:
    """``(position error [m], rotation error [rad])`` of a pose estimate, up to a model symmetry.

    The position error is measured at the model's centroid; with ``symmetries`` (model self-maps, e.g. from
    :func:`~haptic.geometry.symmetry_group`) the smallest error over ``truth ∘ S`` is returned.
    """
    best = (np.inf, np.inf)
    c = model.centroid
    for s in [SE3.identity(), *symmetries]:
        tt = truth @ s
        dp = float(np.linalg.norm(estimate.apply(c) - tt.apply(c)))
        da = rotation_angle(estimate.rotation.T @ tt.rotation)
        if dp + 0.1 * da < best[0] + 0.1 * best[1]:
            best = (dp, da)
    return best


__all__ = ["estimate_pose", "pose_error", "pose_from_edge_pair", "proper_rotation_fit", "refine_pose"]
