"""Symmetry grouping and the recognition status (seed §2.3, §2.5).

Interpretations of one model whose poses differ by a symmetry of the model (a proper rigid self-map,
:func:`~haptic.geometry.symmetry_group`, or one within touch's resolution, :func:`near_symmetries`) describe the
same solid in the world: they form one *pose class*, and no touch data can tell them apart (BOX01 has 4). The
object is *recognized* when every survivor belongs to one model and one pose class; *ambiguous* when the
survivors fall in several classes that all describe the same solid in the world (models congruent by a proper
rigid motion), so no further data can separate them;
*no-match* when none survive; otherwise still *exploring*.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3, rotation_angle
from haptic.geometry.symmetry import congruences, symmetry_group
from haptic.matching import kernels
from haptic.matching.tree import Interpretation, InterpretationTree

RECOGNIZED, AMBIGUOUS, NO_MATCH, EXPLORING = "recognized", "ambiguous", "no-match", "exploring"

_SYMMETRY: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_SYMMETRY_ARRAYS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_CONGRUENCE: dict[tuple[int, int], list[SE3]] = {}


NEAR_SYMMETRY = 0.5e-3
"""Farthest [m] a rotation may carry each vertex of a model from another vertex and still be, for touch, a
symmetry of it (:func:`near_symmetries`): a sixth of the smallest perturbation a verification promises to catch
(3 mm), and below what one data component's position bound resolves."""
NEAR_SYMMETRY_OF_SIZE = 0.01
"""... and at most this fraction of the model's size (its bounding box's diagonal), for small models."""


def near_symmetries(model: Polyhedron) -> list[SE3]:
    """The proper rotations that map the model onto itself within :data:`NEAR_SYMMETRY` (vertices onto vertices,
    edges onto edges, faces onto faces) but not within the precision of its file, so that
    :func:`~haptic.geometry.symmetry_group` does not hold them: a solid written from inexact coordinates (a
    snub disphenoid whose edges differ by 0.01 mm) or drawn nearly symmetric. No touch tells two poses that differ
    by one apart, so for recognition they are symmetries; empty for most models."""
    from haptic.geometry.symmetry import congruence_pairs

    eps = min(NEAR_SYMMETRY, NEAR_SYMMETRY_OF_SIZE * float(np.linalg.norm(model.extents)))
    exact = model.tolerances.match
    if eps <= exact:
        return []
    near = []
    for t, perm in congruence_pairs(model, model, eps):
        if float(np.linalg.norm(t.apply(model.vertices) - model.vertices[perm], axis=1).max()) > exact:
            near.append(t)
    return near


def model_symmetries(model: Polyhedron) -> list[SE3]:
    """The rotations that touch cannot tell from the identity (cached per model object): the model's symmetry
    group (identity first), then its :func:`near_symmetries`."""
    if model not in _SYMMETRY:
        _SYMMETRY[model] = symmetry_group(model) + near_symmetries(model)
    return _SYMMETRY[model]


POSE_BOUNDS = 6
"""Two poses fitted to the same data are equal within this many times the data's largest error bound."""


@dataclass(frozen=True)
class PoseTolerance:
    """When two poses are the same (up to noise): derived from the data's error bounds by :meth:`from_data`."""

    angle: float = np.deg2rad(3.0)
    """Largest rotation between equal poses [rad]."""
    distance: float = 3e-3
    """Largest displacement of the model centroid between equal poses [m]."""

    @classmethod
    def from_data(cls, data) -> PoseTolerance:
        """``max(3°, 6 × the largest angular bound)`` and ``max(3 mm, 6 × the largest position bound)`` (the
        defaults, and :data:`POSE_BOUNDS`): distinct pose classes of a rigid solid differ by far more than the pose
        noise."""
        ang, pos = 0.0, 0.0
        for c in data:
            ang = max(ang, getattr(c, "normal_bound", 0.0), getattr(c, "direction_bound", 0.0))
            pos = max(pos, getattr(c, "position_bound", 0.0), getattr(c, "length_bound", 0.0))
        return cls(max(cls.angle, POSE_BOUNDS * ang), max(cls.distance, POSE_BOUNDS * pos))


def same_pose(a: SE3, b: SE3, model: Polyhedron, tol: PoseTolerance) -> bool:
    """True when two ``world_from_model`` poses place the model alike (rotation and centroid within ``tol``)."""
    c = model.centroid
    return (
        rotation_angle(a.rotation.T @ b.rotation) <= tol.angle
        and float(np.linalg.norm(a.apply(c) - b.apply(c))) <= tol.distance
    )


def equivalent_by_symmetry(a: SE3, b: SE3, model: Polyhedron, tol: PoseTolerance) -> bool:
    """True when ``b ≈ a ∘ S`` for a symmetry S of the model: the two poses put the same solid in the world."""
    return any(same_pose(a @ s, b, model, tol) for s in model_symmetries(model))


@dataclass(frozen=True, eq=False)
class PoseClass:
    """Interpretations of one model whose poses differ by a model symmetry."""

    model: Polyhedron
    """The model."""
    leaves: tuple[int, ...]
    """Leaf indices (in the tree) of the interpretations in the class."""
    world_from_model: SE3
    """Pose of the class's first interpretation (least-squares refined)."""

    @property
    def name(self) -> str:
        return self.model.name


@dataclass(frozen=True, eq=False)
class Recognition:
    """The matcher's verdict after the data so far."""

    status: str
    """"recognized", "ambiguous", "no-match" or "exploring"."""
    model: str | None
    """The recognised model's name (status "recognized"), else None."""
    world_from_model: SE3 | None
    """The recognised pose (status "recognized"), else None."""
    classes: tuple[PoseClass, ...]
    """Pose classes of the survivors (empty while some pose is undetermined or there are too many)."""
    count: int
    """Number of surviving interpretations."""
    models: tuple[str, ...]
    """Names of the models with surviving interpretations."""


def _symmetry_arrays(model: Polyhedron) -> tuple[np.ndarray, np.ndarray]:
    """The model's symmetries stacked: rotations (S, 3, 3) and translations (S, 3) (cached per model object)."""
    if model not in _SYMMETRY_ARRAYS:
        sym = model_symmetries(model)
        _SYMMETRY_ARRAYS[model] = (np.stack([s.rotation for s in sym]), np.stack([s.translation for s in sym]))
    return _SYMMETRY_ARRAYS[model]


def _same_pose_as(
    a: SE3,
    rotations: np.ndarray,
    translations: np.ndarray,
    model: Polyhedron,
    tol: PoseTolerance,
    placed: np.ndarray | None = None,
):
    """:func:`equivalent_by_symmetry` of the pose ``a`` and each of N poses ``(rotations, translations)``,
    vectorised over the poses and the model's symmetries (``placed``: the model's centroid placed by each pose,
    ``translations + rotations @ centroid``, when already computed)."""
    c = model.centroid
    tb = translations + rotations @ c if placed is None else placed  # the centroid placed by each pose
    s_rot, s_trans = _symmetry_arrays(model)
    r_as = a.rotation @ s_rot  # a ∘ S for every symmetry S
    c_as = r_as @ c + s_trans @ a.rotation.T + a.translation
    cos = (np.einsum("sij,nij->sn", r_as, rotations) - 1.0) / 2.0
    near = np.arccos(np.clip(cos, -1.0, 1.0)) <= tol.angle
    near &= np.linalg.norm(c_as[:, None] - tb[None], axis=2) <= tol.distance
    return near.any(axis=0)


MAX_PAIRS = 2_000_000
"""Most (pose, symmetry, pose) triples of one model that :func:`_group` compares in one array; a model with more
poses than that allows is grouped one class at a time."""


def _same_pose_pairs(
    rot: np.ndarray, trans: np.ndarray, placed: np.ndarray, model: Polyhedron, tol: PoseTolerance
) -> np.ndarray:
    """``same[i, j]``: pose ``j`` equals pose ``i`` up to a symmetry of the model (:func:`_same_pose_as` of pose
    ``i`` and every pose, for every ``i`` at once); ``rot`` (N, 3, 3), ``trans`` (N, 3) and ``placed`` (N, 3), the
    centroid placed by each pose."""
    c = model.centroid
    s_rot, s_trans = _symmetry_arrays(model)
    if kernels.COMPILED:
        f = np.ascontiguousarray
        return kernels.same_pose_pairs(
            f(rot, float), f(trans, float), f(placed, float), f(c, float), f(s_rot, float), f(s_trans, float),
            float(tol.angle), float(tol.distance),
        )  # fmt: skip
    r_as = rot[:, None] @ s_rot[None]  # (N, S, 3, 3): pose i ∘ symmetry s
    c_as = r_as @ c + s_trans @ np.swapaxes(rot, -1, -2) + trans[:, None]
    cos = (np.einsum("isab,jab->isj", r_as, rot) - 1.0) / 2.0
    near = np.arccos(np.clip(cos, -1.0, 1.0)) <= tol.angle
    near &= np.linalg.norm(c_as[:, :, None] - placed[None, None], axis=3) <= tol.distance
    return near.any(axis=1)


def _group(models: Sequence[Polyhedron], model_index: np.ndarray, poses: Sequence[SE3], tol: PoseTolerance):
    """Positions of the poses grouped into pose classes (:func:`_group_arrays` of the poses stacked; ``models``: the
    model of each pose)."""
    model_of = {int(m): models[i] for i, m in enumerate(np.asarray(model_index).tolist())}
    rot = np.stack([p.rotation for p in poses])
    trans = np.stack([p.translation for p in poses])
    return _group_arrays(model_of, np.asarray(model_index), rot, trans, tol)


def _group_arrays(model_of, model_index: np.ndarray, rot: np.ndarray, trans: np.ndarray, tol: PoseTolerance):
    """Positions of the poses ``(rot (N, 3, 3), trans (N, 3))`` grouped into pose classes, in the order of each
    class's first member: each pose joins the first earlier class of its model whose first pose it equals up to a
    symmetry (every pair of a model's poses compared in one array operation, :func:`_same_pose_pairs`, the classes
    then taken in one pass over the pairs as bit sets; or, past :data:`MAX_PAIRS`, each class's first pose against
    the poses left). ``model_of[m]`` is the model of model index ``m``."""
    groups: list[list[int]] = []
    for m in dict.fromkeys(model_index.tolist()):
        left = np.flatnonzero(model_index == m)
        model = model_of[m]
        placed = trans[left] + rot[left] @ model.centroid  # each pose's centroid, computed once per model
        if len(left) ** 2 * len(_symmetry_arrays(model)[0]) <= MAX_PAIRS:
            same = _same_pose_pairs(rot[left], trans[left], placed, model, tol)
            groups.extend(_first_classes(same, left.tolist()))
            continue
        full = np.empty_like(trans)
        full[left] = placed
        while len(left):
            rep, rest = int(left[0]), left[1:]
            same = _same_pose_as(SE3(rot[rep], trans[rep]), rot[rest], trans[rest], model, tol, full[rest])
            groups.append([rep, *rest[same].tolist()])
            left = rest[~same]
    return sorted(groups)


def _first_classes(same: np.ndarray, names: list[int]) -> list[list[int]]:
    """The classes of a pairwise relation ``same`` (L, L): the first member left opens a class, which takes every
    member left that ``same`` relates to it; members named by ``names``. Each row is a bit set (an int), so a class
    costs a few integer operations."""
    n = len(names)
    if n == 1:
        return [[names[0]]]
    packed = np.packbits(same, axis=1, bitorder="little")
    rows = [int.from_bytes(b, "little") for b in map(bytes, packed)]
    out = []
    alive = (1 << n) - 1
    while alive:
        low = alive & -alive
        k = low.bit_length() - 1
        members = alive & rows[k] & ~low
        alive &= ~(members | low)
        group = [names[k]]
        while members:
            bit = members & -members
            group.append(names[bit.bit_length() - 1])
            members ^= bit
        out.append(group)
    return out


def group_pose_classes(interpretations: list[Interpretation], tol: PoseTolerance) -> list[PoseClass] | None:
    """Group interpretations into pose classes; None when some interpretation has no pose yet."""
    if any(it.world_from_model is None for it in interpretations):
        return None
    if not interpretations:
        return []
    models = [it.model for it in interpretations]
    poses = [it.world_from_model for it in interpretations]
    groups = _group(models, np.array([it.model_index for it in interpretations]), poses, tol)
    return [PoseClass(models[g[0]], tuple(interpretations[i].leaf for i in g), poses[g[0]]) for g in groups]


def same_solid(a: PoseClass, b: PoseClass, tol: PoseTolerance) -> bool:
    """True when two pose classes put congruent solids at the same place (no touch can separate them)."""
    if a.model is b.model:
        return equivalent_by_symmetry(a.world_from_model, b.world_from_model, a.model, tol)
    key = (id(a.model), id(b.model))
    if key not in _CONGRUENCE:
        _CONGRUENCE[key] = congruences(a.model, b.model)
    # T_a(A) = T_b(B) with B = C(A)  ⇔  T_a ≈ T_b ∘ C
    return any(same_pose(b.world_from_model @ c, a.world_from_model, a.model, tol) for c in _CONGRUENCE[key])


def recognize(tree: InterpretationTree, max_interpretations: int = 64, tol: PoseTolerance | None = None) -> Recognition:
    """The recognition status of a tree (poses are computed only for up to ``max_interpretations``)."""
    models = tree.models_alive()
    n = tree.count
    if n == 0:
        return Recognition(NO_MATCH, None, None, (), 0, ())
    if n > max_interpretations:
        return Recognition(EXPLORING, None, None, (), n, models)
    tol = tol if tol is not None else PoseTolerance.from_data(tree.data)
    rot, trans, ok = tree.initial_poses()
    if not ok.all():
        return Recognition(EXPLORING, None, None, (), n, models)
    lib = tree.library
    model_index = tree.model_indices
    groups = _group_arrays(lib.models, model_index, rot, trans, tol)
    refined = tree.poses([g[0] for g in groups], refine=True)
    classes = [
        PoseClass(lib.models[model_index[g[0]]], tuple(g), r if r is not None else SE3(rot[g[0]], trans[g[0]]))
        for g, r in zip(groups, refined, strict=True)
    ]
    if len(classes) == 1:
        c = classes[0]
        return Recognition(RECOGNIZED, c.name, c.world_from_model, tuple(classes), n, models)
    if all(same_solid(classes[0], c, tol) for c in classes[1:]):
        return Recognition(AMBIGUOUS, None, None, tuple(classes), n, models)
    return Recognition(EXPLORING, None, None, tuple(classes), n, models)


__all__ = [
    "AMBIGUOUS",
    "EXPLORING",
    "NO_MATCH",
    "RECOGNIZED",
    "PoseClass",
    "PoseTolerance",
    "Recognition",
    "equivalent_by_symmetry",
    "group_pose_classes",
    "model_symmetries",
    "near_symmetries",
    "recognize",
    "same_pose",
    "same_solid",
]
