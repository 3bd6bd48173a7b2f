"""Matching with free-space probe data (seed §1.1, §2.6): a contact is a face, a miss is free space.

A probe moves the sensor along a line through free space until it touches the object (Grimson and
Lozano-Pérez's paradigm). What it yields:

- **A hit** is a face data component (:func:`probe_face`): one point and an outward normal with their error
  bounds, adjacent to nothing known. The interpretation tree takes it as it is: with no adjacency it pairs
  with every model face of each leaf (§2.3 step 1), and the geometric relations with every earlier component
  prune the pairings. Against every other data face that is the face-pair angle, which §2.6 notes needs no
  adjacency (outward normals have consistent senses); against vertices and edges the tree's height and
  face–edge angle tests. Once a leaf's pose is known, :func:`consistent_leaves` adds the pose check of
  :mod:`haptic.matching.acceptance`: with the pose refitted over every pairing, the hit point must lie on the
  model face's polygon (plane *and* extent) within its bounds, as every other component must.
- **A miss**, and the path of a hit up to its contact, is a :class:`FreeSegment`: negative evidence. A leaf
  whose posed model that segment enters is eliminated, but only when it enters deeper than the segment's
  error bound plus the error of the leaf's pose at that point (:func:`free_margin`), so the true
  interpretation is never eliminated by data within their bounds.

The pose error margin is the matcher's own tolerance for "the same pose"
(:meth:`~haptic.matching.recognition.PoseTolerance.from_data`, from the data's error bounds): a displacement
``δ`` of the model centroid and a rotation ``a`` move a model point ``x`` by at most ``δ + a ‖x − c‖``.
"""

from __future__ import annotations

import weakref
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from haptic.geometry import kernels as geometry_kernels
from haptic.geometry.distance import surface_distance
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.raycast import (
    BARYCENTRIC_SLACK,
    CROSSING_SLACK,
    DEPTH_SAMPLES,
    depth_samples,
    sample_inside_many,
)
from haptic.geometry.se3 import SE3
from haptic.matching import kernels
from haptic.matching.acceptance import leaf_pose_check, leaf_pose_checks
from haptic.matching.components import DataFace, readonly_vector
from haptic.matching.recognition import PoseTolerance
from haptic.matching.tree import InterpretationTree

MIN_SPAN = 0.3
"""Smallest ratio of singular values of the directions that fix the data's position (face normals, per touched
point; the two across each edge; all three at a vertex) for the probe data to be tested against posed leaves
(:func:`consistent_leaves`): below it, as with a few probe contacts on faces of nearly coplanar normals, a pose
fitted to the data is off along the weak direction by more than the pose check's factor and the pose tolerance
allow, and the truth could be eliminated."""
MAX_POSED = 400
"""Most leaves whose poses :func:`consistent_leaves` computes; above it every leaf is kept (sound, as the
matcher's recognition does: ``haptic.episode.state.MAX_GROUPED_INTERPRETATIONS``)."""


@dataclass(frozen=True, eq=False)
class FreeSegment:
    """A straight path the sensor travelled without touching the object: ``{start + t u : 0 ≤ t ≤ length}``."""

    start: np.ndarray
    """Start of the segment in the world frame, shape (3,) [m]."""
    direction: np.ndarray
    """Unit direction ``u`` in the world frame, shape (3,)."""
    length: float
    """Length of the segment (≥ 0) [m]."""
    position_bound: float
    """Error bound on the position of every point of the segment: the true path lies within this of it [m]."""

    kind = "free"

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", readonly_vector(self.start))
        object.__setattr__(self, "direction", readonly_vector(self.direction))
        object.__setattr__(self, "length", float(self.length))

    @property
    def end(self) -> np.ndarray:
        """``start + length · u`` [m]."""
        return self.start + self.length * self.direction

    def to_dict(self) -> dict:
        """A JSON-friendly dict (floats at full precision)."""
        return {"kind": "free", "start": self.start.tolist(), "direction": self.direction.tolist(),
                "length": self.length, "position_bound": self.position_bound}  # fmt: skip

    @classmethod
    def from_dict(cls, d: Mapping) -> FreeSegment:
        """The inverse of :meth:`to_dict`."""
        d = {k: v for k, v in d.items() if k != "kind"}
        return cls(**d)


def probe_face(
    id: int, point: np.ndarray, normal: np.ndarray, normal_bound: float, position_bound: float
) -> DataFace:
    """The face data component of a probe's contact: one touched point and the sensed outward normal, adjacent to
    nothing known (a probe arrives from free space)."""
    return DataFace(id=id, normal=normal, points=np.atleast_2d(point), normal_bound=normal_bound,
                    position_bound=position_bound, adjacent=())  # fmt: skip


def free_margin(seg: FreeSegment, tol: PoseTolerance, world_from_model: SE3, model: Polyhedron,
                points_in_world: np.ndarray) -> np.ndarray:  # fmt: skip
    """How deep a hypothesis's posed model may seem to enter ``seg`` at each point while the true object stays
    clear of the true path: the segment's bound plus the pose error there,
    ``ε(x) = ρ + δ + a ‖x − T(c)‖`` (``δ``, ``a``: ``tol.distance``, ``tol.angle``; ``c`` the model centroid),
    shape (P,) [m]."""
    c_w = world_from_model.apply(model.centroid)
    r = np.linalg.norm(np.atleast_2d(points_in_world) - c_w, axis=1)
    return seg.position_bound + tol.distance + tol.angle * r


def free_segment_consistent(
    model: Polyhedron, world_from_model: SE3, seg: FreeSegment, tol: PoseTolerance
) -> bool:
    """Whether the model at ``world_from_model`` leaves ``seg`` free within the bounds: no point of the segment
    lies inside it deeper than :func:`free_margin` (a ball of that radius about such a point would be inside
    the true object, and the true path passes through it)."""
    inv = world_from_model.inverse()
    pts_m, depth = depth_samples(model, inv.apply(seg.start), inv.rotate(seg.direction), seg.length)
    if not len(depth):
        return True
    margin = free_margin(seg, tol, world_from_model, model, world_from_model.apply(pts_m))
    return bool((depth <= margin).all())


def free_segments_consistent(
    model: Polyhedron, world_from_model: SE3, free: Sequence[FreeSegment], tol: PoseTolerance
) -> bool:
    """:func:`free_segment_consistent` for every segment of ``free`` (all of them), the segments tested together
    (:func:`~haptic.geometry.raycast.sample_inside_many`). A sample whose depth bound (its distance along the
    segment from where the line crosses the surface) is within its margin cannot fail, so only the others are
    measured (one distance computation for all of them): the same verdict as measuring every sample."""
    if not free:
        return True
    inv = world_from_model.inverse()
    starts = inv.apply(np.array([seg.start for seg in free]))
    dirs = inv.rotate(np.array([seg.direction for seg in free]))
    lengths = np.array([seg.length for seg in free])
    if kernels.COMPILED:  # every segment's samples from one kernel, their margins in one array operation
        tri = _triangles(model)
        pts_m, upper, owner = geometry_kernels.inside_samples(
            starts, dirs, lengths, tri, BARYCENTRIC_SLACK, DEPTH_SAMPLES, CROSSING_SLACK
        )
        if not len(pts_m):
            return True
        c_w = world_from_model.apply(model.centroid)
        r = np.linalg.norm(world_from_model.apply(pts_m) - c_w, axis=1)
        margin = np.array([seg.position_bound for seg in free])[owner] + tol.distance + tol.angle * r
        need = upper > margin
        if not need.any():
            return True
        depth = kernels.surface_distance(np.ascontiguousarray(pts_m[need]), tri)
        return bool((depth <= margin[need]).all())
    samples = sample_inside_many(model, starts, dirs, lengths)
    points, margins = [], []
    for seg, (pts_m, upper) in zip(free, samples, strict=True):
        if not len(pts_m):
            continue
        margin = free_margin(seg, tol, world_from_model, model, world_from_model.apply(pts_m))
        need = upper > margin
        if need.any():
            points.append(pts_m[need])
            margins.append(margin[need])
    if not points:
        return True
    return bool((surface_distance(model, np.concatenate(points)) <= np.concatenate(margins)).all())


_TRIANGLES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _triangles(model: Polyhedron) -> np.ndarray:
    """The model's triangles' corners, shape (T, 3, 3), contiguous (computed once per model)."""
    tri = _TRIANGLES.get(model)
    if tri is None:
        tri = _TRIANGLES[model] = np.ascontiguousarray(model.vertices[model.triangles], float)
    return tri


def consistent_leaves(
    tree: InterpretationTree,
    free: Sequence[FreeSegment],
    probe_faces: Iterable[int] = (),
    tol: PoseTolerance | None = None,
    max_posed: int = MAX_POSED,
) -> np.ndarray:
    """Which leaves of ``tree`` the probe data leave standing, shape (N,) bool.

    A leaf whose pose is not yet determined, and every leaf while there are more than ``max_posed`` or while the
    data fix a position only weakly (:func:`position_span` below :data:`MIN_SPAN`), is kept.
    A leaf with a pose is eliminated when one of the ``free`` segments enters its posed model deeper than the
    bounds allow (:func:`free_segment_consistent`), or when it pairs one of the ``probe_faces`` (data ids of
    probe hits) and fails the pose check of :func:`~haptic.matching.acceptance.pose_check` (every component,
    the hit point included, on its model component within ``POSE_SAFETY`` times its bounds).
    """
    n = tree.count
    keep = np.ones(n, dtype=bool)
    hits = set(int(i) for i in probe_faces)
    if n > max_posed or (not free and not hits):
        return keep
    if "position span" not in tree.data_memo:  # of the data: the same until the next add
        tree.data_memo["position span"] = position_span(tree.data)
    if tree.data_memo["position span"] < MIN_SPAN:
        return keep
    tol = tol if tol is not None else PoseTolerance.from_data(tree.data)
    tree.poses(range(n), refine=True)  # every leaf's pose in one batch; interpretation() reads them back
    its = [tree.interpretation(leaf, with_pose=True, refine=True) for leaf in range(n)]
    # the pose checks of the leaves that pair a hit, all in one batch; the loop reads them back
    leaf_pose_checks(tree, [leaf for leaf, it in enumerate(its) if it.world_from_model is not None
                            and hits & set(it.faces)], its)  # fmt: skip
    for leaf, it in enumerate(its):
        pose = it.world_from_model
        if pose is None:
            continue
        if hits & set(it.faces) and not leaf_pose_check(tree, leaf).ok:
            keep[leaf] = False
            continue
        # the segments this leaf was found clear of at this pose (the memo is cleared when the data change): a miss
        # adds a segment and no component, and only the new segments need testing
        key = ("free segments", leaf)
        done, done_tol = tree.leaf_memo.get(key, ((), None))
        if done_tol != tol or len(done) > len(free) or any(
            a is not b for a, b in zip(done, free[: len(done)], strict=True)
        ):
            done = ()
        keep[leaf] = free_segments_consistent(it.model, pose, free[len(done) :], tol)
        if keep[leaf]:
            tree.leaf_memo[key] = (tuple(free), tol)
    return keep


def position_span(data: Sequence) -> float:
    """How well the data fix a position: the smallest over the largest singular value of the unit directions
    along which they constrain it (a face's normal once per touched point, the two directions across an edge,
    the three axes at a vertex); 0 when they constrain fewer than three."""
    rows = []
    for c in data:
        if isinstance(c, DataFace):
            rows.extend([c.normal] * len(np.atleast_2d(c.points)))
        elif getattr(c, "kind", None) == "edge":
            rows.extend(_across(c))
        elif getattr(c, "kind", None) == "vertex":
            rows.extend(np.eye(3))
    if len(rows) < 3:
        return 0.0
    sv = np.linalg.svd(np.asarray(rows, dtype=float), compute_uv=False)
    return float(sv[-1] / sv[0]) if sv[0] > 0 else 0.0


_ACROSS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _across(edge) -> np.ndarray:
    """The two unit directions across a data edge's line that :func:`position_span` counts, shape (2, 3): of the
    edge component itself (its direction does not change; a re-reported edge is a new component), computed once."""
    rows = _ACROSS.get(edge)
    if rows is None:
        b = np.asarray(edge.direction, dtype=float)
        rows = _ACROSS[edge] = np.linalg.svd(np.eye(3) - np.outer(b, b))[0][:, :2].T
    return rows


def apply_probes(
    tree: InterpretationTree,
    free: Sequence[FreeSegment],
    probe_faces: Iterable[int] = (),
    tol: PoseTolerance | None = None,
    max_posed: int = MAX_POSED,
) -> int:
    """Eliminate the leaves the probe data contradict (:func:`consistent_leaves`); the number left."""
    return tree.retain(consistent_leaves(tree, free, probe_faces, tol, max_posed))


__all__ = [
    "MAX_POSED",
    "MIN_SPAN",
    "FreeSegment",
    "apply_probes",
    "consistent_leaves",
    "free_margin",
    "free_segment_consistent",
    "free_segments_consistent",
    "position_span",
    "probe_face",
]
