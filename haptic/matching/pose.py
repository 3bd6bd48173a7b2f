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
    """The residuals of all pairings of one interpretation, weighted by the error bounds."""

    def __init__(self, model: Polyhedron, data: Sequence[DataComponent], faces, edges, senses, vertices):
        self.dirs_w, self.dirs_m, self.dirs_wt = [], [], []
        self.planes = []  # (n_m, d_m, points (k,3), weight)
        self.lines = []  # (p_m, b_m, point, weight)
        self.points = []  # (v_m, v_d, weight)
        for i, f in faces.items():
            c = data[i]
            self.dirs_w.append(c.normal)
            self.dirs_m.append(model.face_normals[f])
            self.dirs_wt.append(1.0 / max(c.normal_bound, 1e-6) ** 2)
            self.planes.append(
                (model.face_normals[f], model.face_offsets[f], c.points, 1.0 / max(c.position_bound, 1e-7))
            )
        for i, e in edges.items():
            c = data[i]
            s = senses.get(i, 0)
            pm, bm = model.edge_points[e], model.edge_directions[e]
            if s != 0:
                self.dirs_w.append(c.direction)
                self.dirs_m.append(s * bm)
                self.dirs_wt.append(1.0 / max(c.direction_bound, 1e-6) ** 2)
            rho = max(c.position_bound, 1e-7)
            self.lines.append((pm, bm, c.point, 1.0 / rho))
            self.lines.append((pm, bm, c.end_point, 1.0 / (rho + c.length * c.direction_bound)))
        for i, v in vertices.items():
            c = data[i]
            self.points.append((model.vertices[v], c.position, 1.0 / max(c.position_bound, 1e-7)))
        self.dirs_w = np.array(self.dirs_w).reshape(-1, 3)
        self.dirs_m = np.array(self.dirs_m).reshape(-1, 3)
        self.dirs_wt = np.array(self.dirs_wt)

    def rotation(self) -> np.ndarray | None:
        if len(self.dirs_m) < 2:
            return None
        u = self.dirs_m
        spread = np.linalg.norm(np.cross(u[:, None, :], u[None, :, :]), axis=2).max()
        if spread < MIN_SPREAD:
            return None
        return proper_rotation_fit(self.dirs_w, self.dirs_m, self.dirs_wt)

    def translation(self, r: np.ndarray) -> np.ndarray | None:
        rows, rhs = [], []
        for n_m, d_m, pts, w in self.planes:
            n = r @ n_m
            for q in pts:
                rows.append(w * n)
                rhs.append(w * (n @ q - d_m))
        for p_m, b_m, x, w in self.lines:
            b = r @ b_m
            perp = np.eye(3) - np.outer(b, b)
            rows.extend(w * perp)
            rhs.extend(w * perp @ (x - r @ p_m))
        for v_m, v_d, w in self.points:
            rows.extend(w * np.eye(3))
            rhs.extend(w * (v_d - r @ v_m))
        if not rows:
            return None
        a, y = np.array(rows), np.array(rhs)
        sv = np.linalg.svd(a, compute_uv=False)
        if len(sv) < 3 or sv[-1] < MIN_CONDITION * sv[0]:
            return None
        return np.linalg.lstsq(a, y, rcond=None)[0]

    def residuals(self, r: np.ndarray, t: np.ndarray) -> np.ndarray:
        out = [((self.dirs_w - self.dirs_m @ r.T) * np.sqrt(self.dirs_wt)[:, None]).ravel()]
        for n_m, d_m, pts, w in self.planes:
            out.append(w * ((pts - t) @ r @ n_m - d_m))
        for p_m, b_m, x, w in self.lines:
            y = r.T @ (x - t) - p_m
            out.append(w * (y - (y @ b_m) * b_m))
        for v_m, v_d, w in self.points:
            out.append(w * (r.T @ (v_d - t) - v_m))
        return np.concatenate(out)


def _exp_so3(w: np.ndarray) -> np.ndarray:
    th = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    if th < 1e-12:
        return np.eye(3) + k
    return np.eye(3) + np.sin(th) / th * k + (1 - np.cos(th)) / th**2 * k @ k


def refine_pose(problem: _Problem, pose: SE3, iterations: int = 6) -> SE3:
    """Gauss–Newton on the weighted residuals, perturbing the pose on the left (world frame)."""
    r, t = pose.rotation, pose.translation
    h = 1e-7
    for _ in range(iterations):
        f0 = problem.residuals(r, t)
        jac = np.empty((len(f0), 6))
        for j in range(6):
            xi = np.zeros(6)
            xi[j] = h
            dr = _exp_so3(xi[:3])
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
