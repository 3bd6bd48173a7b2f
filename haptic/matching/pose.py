"""Pose of an interpretation: ``w_d = R w_m + t`` (seed §2.1), from an edge pair and by least squares.

Seed §2.6: a pair of non-parallel edges with consistent senses fixes the rotation uniquely (which is why mirror
images are told apart) and, through their lines, the translation. :func:`pose_from_edge_pair` is that closed
form. :func:`estimate_pose` uses every pairing of an interpretation: a rotation from all directions (face
normals, edge directions with their senses) by the proper-rotation solution of Wahba's problem, a translation
by linear least squares on planes, lines and vertices, then Gauss–Newton on all residuals weighted by the
error bounds. The arrays and steps are those of :class:`~haptic.matching.batch_poses.StackedPoses`, for one
interpretation.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3, rotation_angle
from haptic.matching.batch_poses import StackedPoses, proper_rotations
from haptic.matching.components import DataComponent


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def proper_rotation_fit(world: np.ndarray, model: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """The proper rotation R minimising ``Σ w ‖a − R c‖²`` for direction pairs ``a`` (world) and ``c`` (model)."""
    w = np.ones(len(world)) if weights is None else np.asarray(weights, dtype=float)
    return proper_rotations(np.asarray(world, dtype=float), np.asarray(model, dtype=float)[None], w[None])[0]


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
    face_ids, edge_ids, vertex_ids = list(faces), list(edges), list(vertices)
    f, e, v = list(faces.values()), list(edges.values()), list(vertices.values())
    prob = StackedPoses(
        data, face_ids, edge_ids, vertex_ids,
        model.face_normals[f][None], model.face_offsets[f][None],
        model.edge_points[e][None], model.edge_directions[e][None],
        np.array([[senses.get(i, 0) for i in edge_ids]]), model.vertices[v][None],
    )  # fmt: skip
    r, t, ok = prob.initial()
    if not ok[0]:
        return None
    if refine:
        r, t = prob.refine(r, t)
    return SE3(r[0], t[0])


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


__all__ = ["estimate_pose", "pose_error", "pose_from_edge_pair", "proper_rotation_fit"]
