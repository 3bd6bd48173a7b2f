"""Verification before recognition: the pose check and what of a model the data have measured.

When one pose class is left the matcher has shown only that no *other* library interpretation fits; an object
outside the library that is close to one model (one dimension a few percent off, a corner moved) fits that
model's interpretation until the data measure where it differs. Two checks make a recognition a promise:

- **The pose check** (:func:`pose_check`): the recognised pose, a least-squares fit over every data component
  (:func:`~haptic.matching.pose.estimate_pose`), must explain each component within its error bounds: a face's
  normal and every touched point (on the model face's polygon, not only its plane), an edge's direction and
  both ends of its explored interval (on the model edge's line *and* within the edge's extent), a vertex's
  position. The pairwise tests of the tree (seed §2.4) each allow the full lever arm of an angular error, so
  that a 3 mm change of a 100 mm box passes every one of them; one pose fitted to all the data removes most of
  that slack: a change of ``d`` leaves a residual of about ``d / 2`` on the components at either side of it.
- **Coverage** (:func:`coverage`): which model faces, edges and vertices the interpretation pairs with data.
  Verification moves are chosen (:mod:`haptic.planning.verify`) until a coverage target (:data:`TARGETS`) is
  met; each new component is tested by the tree and by the pose check.

Like Grimson & Huttenlocher's acceptance test ("On the verification of hypothesized matches in model-based
recognition", MIT AI Memo 1110, 1989) the thresholds derive from the noise model, not from an ad-hoc fraction:
each residual is compared with its component's own bound ``k σ``, times :data:`POSE_SAFETY` for the error of
the fitted pose itself; and the coverage target says which features must have been measured, so that a
change of a feature that is measured is caught by the residual test whatever the number of other features.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from haptic.geometry.distance import paired_point_triangle_distance
from haptic.geometry.polyhedron import LearnedBounds, Polyhedron
from haptic.geometry.se3 import SE3
from haptic.matching import kernels
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex, SensorNoise
from haptic.matching.tree import Interpretation

VERIFY_MODES = ("none", "fast", "full")
"""``none``: recognise as soon as one pose class is left (no checks); ``fast``: the pose check, and every
reachable face and edge of the model measured; ``full``: the pose check, every reachable vertex measured, and the
acceptance test."""
DEFAULT_VERIFY = "full"
"""The default of ``haptic explore`` and ``haptic bench``: the cheapest mode that keeps 0 false recognitions on
``scripts/bench_unknown.py`` (perturbations ≥ 3 % or ≥ 3 mm)."""
TARGETS = {
    "none": (0.0, 0.0, 0.0),
    "fast": (1.0, 1.0, 0.0),
    "full": (0.0, 0.0, 1.0),
}
"""Coverage target per mode: fractions of the reachable model faces, edges and vertices to be measured.

``full`` asks for every vertex and nothing else, from the perturbations it must catch: a polyhedron is fixed by
its vertices (each face's plane and each edge's line pass through measured vertices), so an object that differs
from the model by ≥ 3 mm anywhere — a vertex moved, a chamfer (which moves the vertices at the ends of the edge
by its legs), a dimension changed by ≥ 3 % (which moves every vertex off the mid-plane by ≥ 1.5 % of the extent)
— differs at a vertex, where the vertex's residual (bound 0.6 mm at noise 1) or the acceptance test over all of
them sees it. A face or an edge measured between vertices adds nothing the vertices do not fix, and asking for
every edge too cost about 2 moves more per edge. A vertex the hand cannot reach (on the table) is not asked for;
what could hide there is said in README, "Verification". An object with every vertex of the model where the model
has it and more between them (a slot across a face leaves the box's eight vertices in place) fits the vertices: where
probes are admitted the full verification then probes the middle of every reachable face
(:func:`haptic.planning.verify.unmeasured_middles`); under tracing alone it is not caught."""
POSE_SAFETY = 2.0
"""A residual of the fitted pose may reach this many times its component's error bound: the fitted pose is
itself off by the noise of the data it is fitted to. Measured on the seed library (random walks of 4-19 moves,
noise 0.5-8x): with every noise draw exactly at its bound (the worst case) the true interpretation's largest
ratio reached 1.88 (193 walks), with noise drawn inside the bounds 1.15 (200 walks)."""
ROUND_OFF = 1e-7
"""Added to every bound: arithmetic round-off [m or rad]."""


def check_verify_mode(mode: str) -> str:
    """``mode`` when it is one of :data:`VERIFY_MODES`, else a :class:`~haptic.errors.HapticError` naming them."""
    from haptic.errors import HapticError

    if mode not in VERIFY_MODES:
        raise HapticError(f"--verify {mode!r} is not a verification mode; valid: {', '.join(VERIFY_MODES)}")
    return mode


@dataclass(frozen=True)
class PoseCheck:
    """The result of :func:`pose_check`."""

    ok: bool
    """Whether every residual is within ``POSE_SAFETY`` times its bound."""
    worst: float
    """The largest ratio of a residual to its bound (0 without data)."""
    component: int | None
    """Id of the data component of the largest ratio."""
    what: str
    """What that residual measures ("face normal", "face point", "edge direction", "edge line", "edge extent",
    "vertex")."""
    world_from_model: SE3 | None
    """The fitted pose (None: undetermined)."""


def _angle(u: np.ndarray, v: np.ndarray) -> float:
    """Angle between two 3-vectors [rad]: the arithmetic of ``arccos(clip(u·v / (‖u‖ ‖v‖), −1, 1))`` with numpy
    (the same bits) on Python floats, which the residuals' per-component loop calls many times. The arc cosine is
    numpy's: the C library's ``acos`` differs from it in the last bit on some machines."""
    num, den = float(u @ v), math.sqrt(float(u.dot(u))) * math.sqrt(float(v.dot(v)))
    if den == 0.0:  # a zero vector: as numpy divides
        with np.errstate(divide="ignore", invalid="ignore"):
            return float(np.arccos(np.clip(np.float64(num) / den, -1.0, 1.0)))
    c = num / den
    return float(np.arccos(-1.0 if c < -1.0 else 1.0 if c > 1.0 else c))


def _coplanar(model: Polyhedron, f: int) -> np.ndarray:
    """Face ``f`` and the model faces in its plane with its outward normal."""
    n, d = model.face_normals[f], model.face_offsets[f]
    return np.flatnonzero((model.face_normals @ n > 1.0 - 1e-9) & (np.abs(model.face_offsets - d) < 1e-7))


EXACT = LearnedBounds(0.0, 0.0, 0.0)
"""A model made exactly: its features add nothing to the data's bounds."""


def _model_bounds(model: Polyhedron) -> LearnedBounds:
    """How far the model's own features may be off: a learned model's data bounds
    (:attr:`~haptic.geometry.polyhedron.Polyhedron.learned_bounds`), which each test adds to the data's in
    quadrature (independent errors), else none."""
    return model.learned_bounds if model.learned_bounds is not None else EXACT


_PLANE_TRIANGLES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_TRIANGLES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _plane_triangles(model: Polyhedron) -> np.ndarray:
    """For each model face, which of the model's triangles lie on it or on a face coplanar with it
    (:func:`_coplanar`), shape (F, T) bool; computed once per model."""
    if model not in _PLANE_TRIANGLES:
        _PLANE_TRIANGLES[model] = np.stack(
            [np.isin(model.triangle_faces, _coplanar(model, f)) for f in range(model.n_faces)]
        ).reshape(model.n_faces, len(model.triangles))
    return _PLANE_TRIANGLES[model]


def _triangles(model: Polyhedron) -> np.ndarray:
    """The model's triangles' corners, shape (T, 3, 3) (computed once per model)."""
    if model not in _TRIANGLES:
        _TRIANGLES[model] = np.ascontiguousarray(model.vertices[model.triangles], float)
    return _TRIANGLES[model]


def _face_point_distances(
    model: Polyhedron, data: Sequence[DataComponent], it: Interpretation, model_from_world: SE3
) -> np.ndarray:
    """For each face pairing of ``it`` (in its order), the largest distance of the data face's touched points
    from the model face's polygon or a coplanar face's (the robot cannot tell which of two faces in one plane
    it touched, and the interpretation may pair either): off its plane, or beyond them, shape (len(it.faces),)
    [m]. One distance computation for every point of every face."""
    pairs = list(it.faces.items())
    if not pairs:
        return np.zeros(0)
    pts = [model_from_world.apply(np.atleast_2d(data[i].points)) for i, _ in pairs]
    owner = np.repeat(np.arange(len(pairs)), [len(p) for p in pts])
    allowed = _plane_triangles(model)[np.array([f for _, f in pairs])][owner]
    # only the (point, triangle) pairs that count: every point has its own face's triangles
    point, tri = np.nonzero(allowed)
    if kernels.COMPILED:
        d = kernels.paired_point_triangle_distance(
            np.ascontiguousarray(np.concatenate(pts)[point], float), np.ascontiguousarray(_triangles(model)[tri])
        )
    else:
        d = paired_point_triangle_distance(np.concatenate(pts)[point], model.vertices[model.triangles][tri])
    nearest = np.minimum.reduceat(d, np.flatnonzero(np.diff(point, prepend=-1)))
    out = np.full(len(pairs), -np.inf)
    np.maximum.at(out, owner, nearest)
    return out


def residual_ratios(
    model: Polyhedron, data: Sequence[DataComponent], it: Interpretation, world_from_model: SE3
) -> list[tuple[float, int, str]]:
    """``(residual / bound, data id, what)`` of every measured quantity of interpretation ``it`` at a pose (each kind
    of component's in one array operation; per face its normal then its points, per edge its direction when its
    sense is known, its line at either end and its extent, per vertex its position)."""
    inv = world_from_model.inverse()
    rot_t, shift = inv.rotation.T, inv.translation
    mb = _model_bounds(model)
    out: list[tuple[float, int, str]] = []
    faces = list(it.faces.items())
    if faces:
        fc = [data[i] for i, _ in faces]
        assert all(isinstance(c, DataFace) for c in fc)
        turn = _angles(np.array([c.normal for c in fc]) @ rot_t, model.face_normals[[f for _, f in faces]])
        normal = turn / (np.hypot([c.normal_bound for c in fc], mb.normal) + ROUND_OFF)
        point = _face_point_distances(model, data, it, inv) / (
            np.hypot([c.position_bound for c in fc], mb.position) + ROUND_OFF)  # fmt: skip
        for k, (i, _) in enumerate(faces):
            out += [(float(normal[k]), i, "face normal"), (float(point[k]), i, "face point")]
    edges = list(it.edges.items())
    if edges:
        ec = [data[i] for i, _ in edges]
        assert all(isinstance(c, DataEdge) for c in ec)
        em = [e for _, e in edges]
        b_m, l_m = model.edge_directions[em], model.edge_lengths[em]
        senses = np.array([it.edge_senses.get(i, 0) for i, _ in edges])
        beta = np.hypot([c.direction_bound for c in ec], mb.direction)
        direction = _angles(np.array([c.direction for c in ec]) @ rot_t, senses[:, None] * b_m) / (beta + ROUND_OFF)
        ends = np.array([(c.point, c.end_point) for c in ec]) @ rot_t + shift - model.edge_points[em][:, None]
        along = np.einsum("eak,ek->ea", ends, b_m)
        perp = np.linalg.norm(ends - along[..., None] * b_m[:, None], axis=2)
        rho = np.hypot([c.position_bound for c in ec], mb.position) + ROUND_OFF
        start = perp[:, 0] / rho
        end = perp[:, 1] / (rho + np.array([c.length for c in ec]) * beta)
        beyond = np.maximum(np.maximum(-along, along - l_m[:, None]).max(axis=1), 0.0)
        extent = beyond / (np.hypot([c.length_bound for c in ec], mb.position) + ROUND_OFF)
        for k, (i, _) in enumerate(edges):
            if senses[k] != 0:
                out.append((float(direction[k]), i, "edge direction"))
            out += [(float(start[k]), i, "edge line"), (float(end[k]), i, "edge line"),
                    (float(extent[k]), i, "edge extent")]  # fmt: skip
    vertices = list(it.vertices.items())
    if vertices:
        vc = [data[i] for i, _ in vertices]
        assert all(isinstance(c, DataVertex) for c in vc)
        off = np.array([c.position for c in vc]) @ rot_t + shift - model.vertices[[v for _, v in vertices]]
        ratio = np.linalg.norm(off, axis=1) / (np.hypot([c.position_bound for c in vc], mb.position) + ROUND_OFF)
        out += [(float(ratio[k]), i, "vertex") for k, (i, _) in enumerate(vertices)]
    return out


def _angles(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angles between rows of two (K, 3) arrays [rad]: ``arccos(clip(u·v / (‖u‖ ‖v‖), −1, 1))``."""
    num = np.einsum("ki,ki->k", u, v)
    den = np.sqrt(np.einsum("ki,ki->k", u, u)) * np.sqrt(np.einsum("ki,ki->k", v, v))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.arccos(np.clip(num / den, -1.0, 1.0))


def pose_check(model: Polyhedron, data: Sequence[DataComponent], it: Interpretation) -> PoseCheck:
    """Whether interpretation ``it``'s least-squares pose (``it.world_from_model``, refined over all its
    pairings) explains every data component within ``POSE_SAFETY`` times its bounds — or, where the data leave
    the pose's translation free along some direction (:func:`free_directions`), the pose shifted along it that
    explains them best (:func:`_slide`)."""
    pose = it.world_from_model
    if pose is None:
        return PoseCheck(False, float("inf"), None, "pose undetermined", None)
    ratios = residual_ratios(model, data, it, pose)
    if not ratios:
        return PoseCheck(True, 0.0, None, "", pose)
    return _checked(model, data, it, max(ratios, key=lambda r: r[0]))


def _checked(model: Polyhedron, data: Sequence[DataComponent], it: Interpretation,
             largest: tuple[float, int, str], free_memo: dict | None = None) -> PoseCheck:  # fmt: skip
    """:func:`pose_check` of ``it`` (posed) from its largest residual ratio at its pose: the slide where the data
    leave a direction free and a residual a shift may change is beyond the bound. ``free_memo``: the free
    directions already found on ``data``, by the data ids paired (:func:`free_directions` reads only those)."""
    pose = it.world_from_model
    worst, cid, what = largest
    if worst > POSE_SAFETY and what not in ("face normal", "edge direction"):  # what a shift may change
        if free_memo is None:
            free = free_directions(data, it)
        else:
            key = (tuple(it.faces), tuple(it.edges), tuple(it.vertices))
            if key not in free_memo:
                free_memo[key] = free_directions(data, it)
            free = free_memo[key]
        if len(free):
            slid = _slide(model, data, it, pose, free)
            if slid is not None:
                return slid
    return PoseCheck(bool(worst <= POSE_SAFETY), float(worst), cid, what, pose)


def pose_checks(data: Sequence[DataComponent], its: Sequence[Interpretation]) -> list[PoseCheck]:
    """:func:`pose_check` of each of ``its`` (interpretations of one tree, the same data paired in each) on
    ``data``, their residuals at their poses computed together (:func:`_largest_ratios`): the same checks to the
    bit, without the cost of one small array operation per component kind and interpretation, which the free-space
    test pays for every leaf after every move."""
    out: list[PoseCheck | None] = [None] * len(its)
    posed = [k for k, it in enumerate(its) if it.world_from_model is not None]
    largest = _largest_ratios(data, [its[k] for k in posed]) if posed else []
    free_memo: dict = {}  # the leaves pair the same data: the same free directions
    for k, top in zip(posed, largest, strict=True):
        if top is not None:
            out[k] = _checked(its[k].model, data, its[k], top, free_memo)
    return [c if c is not None else pose_check(it.model, data, it) for c, it in zip(out, its, strict=True)]


def _largest_ratios(data: Sequence[DataComponent], its: Sequence[Interpretation]) -> list[tuple | None]:
    """For each of ``its`` (posed), ``max(residual_ratios(...), key=ratio)`` at its pose, the same float operations
    on arrays stacked over the interpretations (each matrix product the same (k, 3) by (3, 3) one, each
    elementwise operation the same, the reductions over the same rows in the same order); None for one to be
    measured alone: the data pairing differs from the first's, a ratio is NaN or the largest is -inf, no ratio,
    without the compiled kernels, or a rotation not stored row by row."""
    its = list(its)
    if not its or not kernels.COMPILED:
        return [None] * len(its)
    first = its[0]
    shape = (tuple(first.faces), tuple(first.edges), tuple(first.vertices))
    fids, eids, vids = (list(x) for x in shape)
    if not (fids or eids or vids):
        return [None] * len(its)
    same = [(tuple(it.faces), tuple(it.edges), tuple(it.vertices)) == shape for it in its]
    invs = [it.world_from_model.inverse() for it in its]
    rots = [inv.rotation.T for inv in invs]
    ok = [k for k, r in enumerate(rots) if same[k] and r.flags.c_contiguous]
    if len(ok) < len(its):  # the others alone
        out: list[tuple | None] = [None] * len(its)
        for k, top in zip(ok, _largest_ratios(data, [its[k] for k in ok]), strict=True):
            out[k] = top
        return out
    n = len(its)
    rot = np.stack(rots)  # (L, 3, 3): each leaf's ``rot_t`` of :func:`residual_ratios`
    shift = np.stack([inv.translation for inv in invs])  # (L, 3)
    mbs = [_model_bounds(it.model) for it in its]
    columns: list[np.ndarray] = []
    labels: list[tuple[int, str]] = []
    if fids:
        fc = [data[i] for i in fids]
        assert all(isinstance(c, DataFace) for c in fc)
        k = len(fids)
        mf = np.array([[it.faces[i] for i in fids] for it in its])  # (L, K) model faces
        mn = np.stack([it.model.face_normals[row] for it, row in zip(its, mf, strict=True)])
        turned = np.matmul(np.array([c.normal for c in fc]), rot)  # (L, K, 3)
        turn = _angles(turned.reshape(n * k, 3), mn.reshape(n * k, 3)).reshape(n, k)
        nb = np.array([c.normal_bound for c in fc])
        pb = np.array([c.position_bound for c in fc])
        normal = turn / (np.hypot(nb[None, :], np.array([mb.normal for mb in mbs])[:, None]) + ROUND_OFF)
        point = _face_point_distances_many(fc, its, mf, rot, shift) / (
            np.hypot(pb[None, :], np.array([mb.position for mb in mbs])[:, None]) + ROUND_OFF)  # fmt: skip
        for j, i in enumerate(fids):
            columns += [normal[:, j], point[:, j]]
            labels += [(i, "face normal"), (i, "face point")]
    if eids:
        ec = [data[i] for i in eids]
        assert all(isinstance(c, DataEdge) for c in ec)
        e = len(eids)
        em = np.array([[it.edges[i] for i in eids] for it in its])  # (L, E) model edges
        b_m = np.stack([it.model.edge_directions[row] for it, row in zip(its, em, strict=True)])
        l_m = np.stack([it.model.edge_lengths[row] for it, row in zip(its, em, strict=True)])
        p_m = np.stack([it.model.edge_points[row] for it, row in zip(its, em, strict=True)])
        senses = np.array([[it.edge_senses.get(i, 0) for i in eids] for it in its])
        beta = np.hypot(np.array([c.direction_bound for c in ec])[None, :],
                        np.array([mb.direction for mb in mbs])[:, None])  # fmt: skip
        turned = np.matmul(np.array([c.direction for c in ec]), rot)
        direction = _angles(turned.reshape(n * e, 3), (senses[:, :, None] * b_m).reshape(n * e, 3)).reshape(n, e) / (
            beta + ROUND_OFF)  # fmt: skip
        ends = np.matmul(np.array([(c.point, c.end_point) for c in ec]), rot[:, None]) + shift[:, None, None] - (
            p_m[:, :, None])  # fmt: skip
        flat_ends, flat_b = ends.reshape(n * e, 2, 3), b_m.reshape(n * e, 3)
        along = np.einsum("eak,ek->ea", flat_ends, flat_b)
        perp = np.linalg.norm(flat_ends - along[..., None] * flat_b[:, None], axis=2).reshape(n, e, 2)
        along = along.reshape(n, e, 2)
        rho = np.hypot(np.array([c.position_bound for c in ec])[None, :],
                       np.array([mb.position for mb in mbs])[:, None]) + ROUND_OFF  # fmt: skip
        start = perp[:, :, 0] / rho
        end = perp[:, :, 1] / (rho + np.array([c.length for c in ec])[None, :] * beta)
        beyond = np.maximum(np.maximum(-along, along - l_m[:, :, None]).max(axis=2), 0.0)
        extent = beyond / (np.hypot(np.array([c.length_bound for c in ec])[None, :],
                                    np.array([mb.position for mb in mbs])[:, None]) + ROUND_OFF)  # fmt: skip
        for j, i in enumerate(eids):
            columns += [np.where(senses[:, j] != 0, direction[:, j], -np.inf), start[:, j], end[:, j], extent[:, j]]
            labels += [(i, "edge direction"), (i, "edge line"), (i, "edge line"), (i, "edge extent")]
    if vids:
        vc = [data[i] for i in vids]
        assert all(isinstance(c, DataVertex) for c in vc)
        v = len(vids)
        mv = np.array([[it.vertices[i] for i in vids] for it in its])
        at = np.stack([it.model.vertices[row] for it, row in zip(its, mv, strict=True)])
        off = np.matmul(np.array([c.position for c in vc]), rot) + shift[:, None] - at
        ratio = np.linalg.norm(off.reshape(n * v, 3), axis=1).reshape(n, v) / (
            np.hypot(np.array([c.position_bound for c in vc])[None, :],
                     np.array([mb.position for mb in mbs])[:, None]) + ROUND_OFF)  # fmt: skip
        for j, i in enumerate(vids):
            columns.append(ratio[:, j])
            labels.append((i, "vertex"))
    out = []
    table = np.stack(columns, axis=1)  # (L, ratios) in residual_ratios' order; -inf: no direction measured
    col = np.argmax(table, axis=1)  # the first largest, as max() keeps
    for row, c in zip(table, col, strict=True):
        worst = row[c]
        if np.isnan(row).any() or worst == -np.inf:
            out.append(None)
        else:
            out.append((float(worst), *labels[c]))
    return out


def _face_point_distances_many(fc: Sequence[DataFace], its: Sequence[Interpretation], mf: np.ndarray, rot: np.ndarray,
                               shift: np.ndarray) -> np.ndarray:  # fmt: skip
    """:func:`_face_point_distances` of each of ``its`` (model faces ``mf`` (L, K) paired with the data faces ``fc``,
    ``rot`` and ``shift`` the inverse poses' as :func:`residual_ratios` applies them), shape (L, K): each face's
    points mapped by the same matrix product per leaf, the (point, triangle) pairs of the leaves of one model
    measured in one kernel call, each point's nearest and each face's largest taken over the same values."""
    n, k = mf.shape
    pts = [np.matmul(np.atleast_2d(c.points), rot) + shift[:, None] for c in fc]  # each (L, P_k, 3)
    owner = np.repeat(np.arange(k), [p.shape[1] for p in pts])
    allp = np.concatenate(pts, axis=1)  # (L, P, 3)
    out = np.full((n, k), -np.inf)
    models: dict[int, list[int]] = {}
    for row, it in enumerate(its):
        models.setdefault(id(it.model), []).append(row)
    for rows in models.values():
        model = its[rows[0]].model
        allowed = _plane_triangles(model)[mf[rows]][:, owner]  # (Lm, P, T)
        leaf, point, tri = np.nonzero(allowed)
        at = np.ascontiguousarray(allp[np.asarray(rows)[leaf], point], float)
        d = kernels.paired_point_triangle_distance(at, np.ascontiguousarray(_triangles(model)[tri]))
        starts = np.flatnonzero(np.diff(leaf * len(owner) + point, prepend=-1))  # each (leaf, point)'s first pair
        nearest = np.minimum.reduceat(d, starts)
        block = np.full((len(rows), k), -np.inf)
        np.maximum.at(block, (leaf[starts], owner[point[starts]]), nearest)
        out[rows] = block
    return out


def leaf_pose_checks(tree, leaves: Sequence[int], its: Sequence[Interpretation] | None = None) -> None:
    """:func:`leaf_pose_check` of every one of ``leaves`` not yet checked, computed together (:func:`pose_checks`)
    and kept in ``tree.leaf_memo`` as it keeps them; ``its``: the tree's interpretations of every leaf (refined
    poses) when the caller has them."""
    todo = [int(leaf) for leaf in leaves if ("pose check", int(leaf)) not in tree.leaf_memo]
    if not todo:
        return
    if its is None:
        its = [tree.interpretation(leaf, with_pose=True, refine=True) for leaf in todo]
    else:
        its = [its[leaf] for leaf in todo]
    for leaf, check in zip(todo, pose_checks(tree.data, its), strict=True):
        tree.leaf_memo[("pose check", leaf)] = check


def leaf_pose_check(tree, leaf: int) -> PoseCheck:
    """:func:`pose_check` of the tree's interpretation at ``leaf`` (its refined pose) on the tree's data, computed
    once per data update (kept in ``tree.leaf_memo``: the free-space check and the verification ask the same
    leaf)."""
    key = ("pose check", int(leaf))
    if key not in tree.leaf_memo:
        it = tree.interpretation(leaf, with_pose=True, refine=True)
        tree.leaf_memo[key] = pose_check(it.model, tree.data, it)
    return tree.leaf_memo[key]


FREE_SINGULAR = 0.25
"""A translation direction ``u`` is left free by the data when ``√Σ (a·u)²`` over the unit directions ``a`` their
positions constrain (a face's normal, the two normals of an edge's line, any direction at a vertex) is below
this: a shift along it moves no face plane or edge line by more than a quarter of the shift, so the least-squares
pose is not determined along it by more than its bounds over this [-]."""
SLIDE_STEPS = (41, 15)
"""Shifts tried along one free direction, and along each of two, over the model's diameter either way, before the
best is refined."""


def free_directions(data: Sequence[DataComponent], it: Interpretation) -> np.ndarray:
    """Unit translation directions (world frame) that the positions of ``it``'s paired data leave free
    (:data:`FREE_SINGULAR`): the axis of a prism whose side faces alone were touched, the plane of one face
    touched alone. Shape (k, 3), k ≤ 3."""
    rows: list[np.ndarray] = []
    for i in it.faces:
        rows.append(np.asarray(data[i].normal, float))
    for i in it.edges:
        b = np.asarray(data[i].direction, float)
        u = np.cross(b, np.eye(3)[int(np.argmin(np.abs(b)))])
        u /= np.linalg.norm(u)
        rows += [u, np.cross(b, u)]
    if it.vertices:
        return np.zeros((0, 3))
    if not rows:
        return np.eye(3)
    _, sv, vt = np.linalg.svd(np.array(rows))
    sv = np.concatenate([sv, np.zeros(3 - len(sv))])
    return vt[sv < FREE_SINGULAR]


def _slide(
    model: Polyhedron, data: Sequence[DataComponent], it: Interpretation, pose: SE3, free: np.ndarray
) -> PoseCheck | None:
    """The pose shifted along the ``free`` directions (one or two) that makes the largest residual ratio least (a
    grid of :data:`SLIDE_STEPS` over the model's diameter either way of the shift that brings the model's
    centroid level with the measured points' along them -- the least-squares pose may lie anywhere along a free
    direction, metres off -- then bounded refinement along each), checked as :func:`pose_check` does; None when
    the data leave more than two directions free."""
    from scipy.optimize import minimize_scalar

    if len(free) > 2:
        return None
    span = float(np.linalg.norm(np.ptp(model.vertices, axis=0)))
    pts = [p for c in data for p in (np.atleast_2d(c.points) if isinstance(c, DataFace) else
                                     (c.point, c.end_point) if isinstance(c, DataEdge) else (c.position,))]
    centre = (np.mean(pts, axis=0) - pose.apply(model.centroid)) @ free.T if pts else np.zeros(len(free))

    def at(shift: np.ndarray) -> SE3:
        return SE3(pose.rotation, pose.translation + shift @ free)

    def worst(shift: np.ndarray) -> float:
        return max(r[0] for r in residual_ratios(model, data, it, at(shift)))

    grid = np.linspace(-span, span, SLIDE_STEPS[len(free) - 1])
    points = np.array(np.meshgrid(*([grid] * len(free)), indexing="ij")).reshape(len(free), -1).T + centre
    best = min(points, key=worst)
    step = grid[1] - grid[0]
    for k in range(len(free)):

        def along(x: float, k: int = k, base: np.ndarray = best) -> float:
            s = base.copy()
            s[k] = x
            return worst(s)

        res = minimize_scalar(along, bounds=(best[k] - step, best[k] + step), method="bounded",
                              options={"xatol": 1e-5})  # fmt: skip
        if res.fun <= along(best[k]):
            best = best.copy()
            best[k] = res.x
    shifted = at(best)
    w, cid, what = max(residual_ratios(model, data, it, shifted), key=lambda r: r[0])
    return PoseCheck(bool(w <= POSE_SAFETY), float(w), cid, what, shifted)


OWN_BOUNDS_LEAVES = 64
"""Most interpretations :func:`own_bounds_keep` pose-checks (more: none eliminated)."""


def own_bounds_keep(tree, k_sigma: float | None = None, floors: BoundFloors | None = None) -> np.ndarray | None:
    """Which interpretations of ``tree`` (:class:`~haptic.matching.tree.InterpretationTree`) pass the pose check
    (:func:`pose_check`) and the acceptance test (:func:`acceptance`, σ = bound / ``k_sigma``) with their own
    model's bounds, and whose model the data do not find far less likely than another's, shape (N,) bool; None when
    there is nothing to tell: the library holds no learned model, one interpretation is left, or more than
    :data:`OWN_BOUNDS_LEAVES` interpretations.

    With a learned model in the library the tree widens every data component by the learned models' bounds
    (:func:`~haptic.matching.tree.learned_widening`), for every model at once: an object a few millimetres from a
    library model, learned, then keeps both the learned model's interpretation and its source's, which the tree's
    tests no longer tell apart and no move would; so are two poses of one learned model a few millimetres from
    symmetric (PYR01 with a corner of its base moved 2 mm, learned, kept at a half turn of the pose that fits it,
    whose statistic was 434 against a threshold of 287). The pose check and the acceptance test hold each model to its
    own bounds (none added for an exact model); an interpretation that fails them is no interpretation of the
    data, as when it is the last one left (the verification's mismatch or rejection). A leaf whose pose the data
    do not fix yet is kept.

    Two models that both pass may still differ within their bounds (a learned model and the library model it is
    2 mm from at one vertex, each learned model's features known to the data's bounds only): the data then tell
    them apart by how well each fits, not by any one residual. Each kept interpretation's acceptance statistic is
    taken again with the same bounds for every model (the tree's widening, :attr:`~InterpretationTree.widen`), at
    which the statistics' difference is twice the log of the models' likelihood ratio under the noise model; a model
    whose best statistic exceeds the best model's by more than :data:`LIKELIHOOD_GAP` (the data
    ``1 / ACCEPT_ALPHA`` times less likely under it), over the same quantities, is dropped. ``floors``: how the
    components' bounds are made (:func:`acceptance`)."""
    k_sigma = K_SIGMA if k_sigma is None else k_sigma
    if tree.widen is None or tree.count > OWN_BOUNDS_LEAVES or tree.count < 2:
        return None
    keep = np.ones(tree.count, dtype=bool)
    common = np.full(tree.count, np.inf)
    dof = np.full(tree.count, -1)
    poses = tree.poses(range(tree.count), refine=True)
    data = tree.data
    for i, pose in enumerate(poses):
        if pose is not None:
            it = tree.interpretation(i, with_pose=True, refine=True)
            chk = pose_check(it.model, data, it)
            # the test at the least-squares pose, or at the pose slid along what the data leave free
            at = tuple(dict.fromkeys((pose, chk.world_from_model)))
            keep[i] = chk.ok and any(acceptance(it.model, data, it, p, k_sigma=k_sigma, floors=floors).ok for p in at)
            if keep[i]:
                same = [acceptance(it.model, data, it, p, k_sigma=k_sigma, model_bounds=tree.widen, floors=floors)
                        for p in at]  # fmt: skip
                common[i], dof[i] = min(a.statistic for a in same), same[0].dof
    posed = np.isfinite(common)
    if posed.any():
        best = int(np.argmin(common))
        models = tree.model_indices
        for m in np.unique(models[posed]):
            mine = posed & (models == m)
            if m == models[best] or (dof[mine] != dof[best]).any():
                continue
            if common[mine].min() > common[best] + LIKELIHOOD_GAP:
                keep[mine] = False
    return keep


ACCEPT_ALPHA = 1e-3
"""False-alarm probability of the acceptance test (:func:`acceptance`) on an object that is the model, under the
noise model: the chance that a true recognition is turned away as no-match."""
LIKELIHOOD_GAP = 2.0 * float(np.log(1.0 / ACCEPT_ALPHA))
"""How much larger one model's acceptance statistic may be than another's, both at the same bounds, before
:func:`own_bounds_keep` drops it: twice the log of a likelihood ratio of ``1 / ACCEPT_ALPHA`` (13.8)."""
K_SIGMA = SensorNoise.k
"""A component's error bound is this many standard deviations (:class:`~haptic.matching.components.SensorNoise`
``k``): the acceptance test's σ of a residual is its bound over ``K_SIGMA``."""
K_SIGMA_PHYSICS = 6.0
"""The same for the physics executor's components. Their bounds are ``k √(σ² + floor²)`` with systematic floors
(pad compliance, detection delay) taken at their worst; what the components actually scatter by is less: on the
physics executor's library objects (the four episodes of ``scripts/bench_unknown.py --executor physics`` that
reached the test, PYR01 twice, BOX01, TETRA01L, and the recorded BOX01 fixture) the statistic at ``K_SIGMA`` summed
to 0.14 of its degrees of freedom (44.2 of 312), i.e. the bounds are about 8 σ. 6 keeps a margin of 1.8 in
variance over that estimate (every one of them then passes, the statistic at most 0.54 of its threshold). It holds
where the floors dominate the bounds (noise level 1); where the noise does, a bound is ``k`` of its σ, which the test
takes from the executor's :class:`BoundFloors`."""


@dataclass(frozen=True)
class BoundFloors:
    """How an executor's error bounds are made where they are not ``k σ`` alone: ``k √(σ² + floor²)``, σ the
    statistical part (the sensor's noise over the samples a component is fitted from, the fit's residuals) and the
    floor a systematic part taken at its worst (pad compliance, contact-point bias, detection delay: the simulated
    hand's segmenter, :meth:`haptic.executor.segment.SegmentBounds.floors`), per measured quantity.

    The acceptance test takes a residual's σ as its bound over ``k_sigma`` (:data:`K_SIGMA_PHYSICS`: at noise
    level 1, where the floors dominate the bounds, the components scatter by about an eighth of them) or, where it
    is more, the bound's statistical part ``√((bound / k)² − floor²)``: the noise a component's bound follows as
    the noise level grows. At level 4 the face normals of the seed library at 60 and 150 mm scattered by a quarter
    of their bounds per axis (σn 4° over each face's rows, the bound ``3 σ`` and the floor a fifth of it), twice the
    sixth the test took: their terms summed to 3.2 per dimension, and BOX01P and HEXPRISM01 at 150 mm (seed 1), every
    component within its bounds, were turned away (338 over a threshold of 269, 220 over 212)."""

    k: float
    """The bounds are ``k √(σ² + floor²)``."""
    face_normal: float = 0.0
    """Floor of a face normal's bound [rad]."""
    face_point: float = 0.0
    """... of a face's touched points' distance from its plane [m]."""
    edge_direction: float = 0.0
    """... of an edge direction [rad]."""
    edge_line: float = 0.0
    """... of an edge line's position [m]."""
    vertex: float = 0.0
    """... of a vertex position [m]."""

    def statistical(self, bound: float, floor: float) -> float:
        """The statistical σ inside ``bound`` whose floor is ``floor``: ``√((bound / k)² − floor²)`` (0 when the
        floor is all of it)."""
        s2 = (bound / self.k) ** 2 - floor * floor
        return math.sqrt(s2) if s2 > 0.0 else 0.0


@dataclass(frozen=True)
class Acceptance:
    """The result of :func:`acceptance`."""

    ok: bool
    """Whether the sum of squared normalised residuals is within the threshold."""
    statistic: float
    """Σ (residual / σ)² over every measured quantity (dimensionless)."""
    dof: int
    """Degrees of freedom: the quantities' dimensions less the 6 of the fitted pose."""
    threshold: float
    """The χ² quantile at ``1 − ACCEPT_ALPHA`` for ``dof`` (inf when ``dof`` ≤ 0)."""
    table_residual: float | None = None
    """With a table: the fitted model's lowest point above the table top [m] (negative: through it)."""


def acceptance(
    model: Polyhedron, data: Sequence[DataComponent], it: Interpretation, world_from_model: SE3,
    alpha: float = ACCEPT_ALPHA,
    k_sigma: float = K_SIGMA,
    table_z: float | None = None,
    model_bounds: LearnedBounds | None = None,
    floors: BoundFloors | None = None,
) -> Acceptance:
    """The statistical acceptance test of a fitted pose (after Grimson & Huttenlocher 1989: a threshold from the
    noise model and the number of measured features, not an ad-hoc fraction).

    Under the noise model every measured quantity is off by a Gaussian error of σ = bound / ``k_sigma``
    (:data:`K_SIGMA`, :data:`K_SIGMA_PHYSICS`) per dimension; at the least-squares pose the sum of the squared
    normalised residuals then follows a χ² law with
    (dimensions − 6) degrees of freedom. The quantities: each face's normal (2 dimensions) and the mean offset
    of its touched points from the model face's plane (1, with the σ of one point: robust to points whose
    errors are correlated), each edge's direction (2, when its sense is known) and the offset of its first
    point from the model edge's line (2), each vertex's position (3). A systematic discrepancy that each
    component's hard bound (:func:`pose_check`, 2 × ``k σ``) allows — a height 1.8 mm off seen at four
    vertices, each within its own bound — adds up here: the statistic grows with the number of components that
    see it, the threshold only with their square root.

    With a table (``table_z``, the top's height in the world) the object rests on it, and the table is a datum
    (:func:`resting_vertices`): the model rests on the facet of its convex hull that faces down at the pose, and
    each vertex of that facet lies on the table plane -- one more quantity each (1 dimension: its height), σ that
    of the data's median position bound. A face on the table fixes the model's tilt and height as a touched face
    would: a tetrahedron 3 % taller than the model, of which the hand measures the apex and the side faces, fits
    them at a pose that tilts the model's base off the table or lifts it. The pose the data were fitted at knows
    nothing of the table; the statistic is taken at the pose refitted to the data and the table together
    (:func:`_refit`), the least-squares pose its χ² law is for (or at the given pose where that is less).

    ``model_bounds``: how far the model's features are taken to be off (default: the model's own,
    :func:`_model_bounds`); two models' statistics at the same bounds compare as their likelihoods do
    (:func:`own_bounds_keep`). ``floors``: how the components' bounds are made (:class:`BoundFloors`); a residual's
    σ is then at least its bound's statistical part."""
    from scipy.stats import chi2

    mb = _model_bounds(model) if model_bounds is None else model_bounds
    resting = None
    if table_z is not None and len(data):
        resting = resting_vertices(model, world_from_model)
    terms = _StatisticTerms(model, data, it, k_sigma, mb, table_z, resting, floors)
    pose, total = world_from_model, terms.total(world_from_model)
    if resting is not None:
        refit = _refit(terms, world_from_model)
        if refit is not None and terms.total(refit) < total:
            pose, total = refit, terms.total(refit)
    rest = None
    if resting is not None:
        rest = float(pose.apply(model.vertices)[:, 2].min()) - table_z
    dof = terms.dims - 6
    threshold = float(chi2.ppf(1.0 - alpha, dof)) if dof > 0 else float("inf")
    return Acceptance(bool(total <= threshold), float(total), int(dof), threshold, rest)


@dataclass
class _StatisticTerms:
    """The quantities of :func:`acceptance` for one interpretation, summed at any pose (:meth:`total`)."""

    model: Polyhedron
    data: Sequence[DataComponent]
    it: Interpretation
    k_sigma: float
    mb: LearnedBounds
    table_z: float | None
    resting: np.ndarray | None
    """Model vertices on the table (:func:`resting_vertices`), None without a table."""
    floors: BoundFloors | None = None
    """How the components' bounds are made (None: ``k σ`` alone)."""

    def sigma(self, bound: float, model_bound: float, floor: float) -> float:
        """A residual's σ: its bound (with the model's, in quadrature) over ``k_sigma``, or the bound's statistical
        part (:meth:`BoundFloors.statistical`) where that is more."""
        s = (math.hypot(bound, model_bound) + ROUND_OFF) / self.k_sigma
        return s if self.floors is None else max(s, self.floors.statistical(bound, floor))

    @property
    def dims(self) -> int:
        """The quantities' dimensions."""
        n = 3 * len(self.it.faces) + sum(2 + 2 * (self.it.edge_senses.get(i, 0) != 0) for i in self.it.edges)
        n += 3 * len(self.it.vertices)
        return n + (len(self.resting) if self.resting is not None else 0)

    def total(self, world_from_model: SE3) -> float:
        """Σ (residual / σ)² over every quantity at ``world_from_model``."""
        model, data, it, k_sigma, mb = self.model, self.data, self.it, self.k_sigma, self.mb
        fl = self.floors or BoundFloors(1.0)
        inv = world_from_model.inverse()
        total = 0.0
        for i, f in it.faces.items():
            c = data[i]
            assert isinstance(c, DataFace)
            n_m = model.face_normals[f]
            turn = _angle(inv.rotate(c.normal), n_m)
            total += (turn / self.sigma(c.normal_bound, mb.normal, fl.face_normal)) ** 2
            off = float(np.mean(inv.apply(c.points) @ n_m - model.face_offsets[f]))
            total += (off / self.sigma(c.position_bound, mb.position, fl.face_point)) ** 2
        for i, e in it.edges.items():
            c = data[i]
            assert isinstance(c, DataEdge)
            p_m, b_m = model.edge_points[e], model.edge_directions[e]
            s = it.edge_senses.get(i, 0)
            if s != 0:
                turn = _angle(inv.rotate(c.direction), s * b_m)
                total += (turn / self.sigma(c.direction_bound, mb.direction, fl.edge_direction)) ** 2
            q = inv.apply(c.point) - p_m
            perp = float(np.linalg.norm(q - (q @ b_m) * b_m))
            total += (perp / self.sigma(c.position_bound, mb.position, fl.edge_line)) ** 2
        for i, v in it.vertices.items():
            c = data[i]
            assert isinstance(c, DataVertex)
            d = float(np.linalg.norm(inv.apply(c.position) - model.vertices[v]))
            total += (d / self.sigma(c.position_bound, mb.position, fl.vertex)) ** 2
        if self.resting is not None and len(self.resting):
            height = world_from_model.apply(model.vertices[self.resting])[:, 2] - self.table_z
            bound = float(np.median([c.position_bound for c in data]))
            total += float(np.sum((height * k_sigma / (np.hypot(bound, mb.position) + ROUND_OFF)) ** 2))
        return total


def _refit(terms: _StatisticTerms, world_from_model: SE3) -> SE3 | None:
    """The pose near ``world_from_model`` that makes ``terms``' statistic least: turned about the data's centroid
    and shifted (parameters in mrad and mm, so that both are of the order of the bounds); None when the search
    fails."""
    from scipy.optimize import minimize
    from scipy.spatial.transform import Rotation

    pts = [p for c in terms.data for p in (np.atleast_2d(c.points) if isinstance(c, DataFace) else
                                           (c.point,) if isinstance(c, DataEdge) else (c.position,))]  # fmt: skip
    centre = np.mean(pts, axis=0)

    def at(x: np.ndarray) -> SE3:
        turn = Rotation.from_rotvec(1e-3 * x[:3]).as_matrix()
        return SE3(turn @ world_from_model.rotation,
                   turn @ (world_from_model.translation - centre) + centre + 1e-3 * x[3:])  # fmt: skip

    res = minimize(lambda x: terms.total(at(x)), np.zeros(6), method="BFGS", options={"gtol": 1e-6})
    return at(res.x) if np.all(np.isfinite(res.x)) else None


_HULL_FACETS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _hull_facets(model: Polyhedron) -> tuple[np.ndarray, list[np.ndarray]]:
    """The facets of the model's convex hull: their outward unit normals (P, 3) (model frame) and each one's model
    vertices (those in its plane, to a millionth of the model's size); computed once per model."""
    if model not in _HULL_FACETS:
        from scipy.spatial import ConvexHull

        v = np.asarray(model.vertices, float)
        tol = 1e-6 * float(np.linalg.norm(np.ptp(v, axis=0)))
        normals, members = [], []
        for eq in ConvexHull(v).equations:
            n, d = eq[:3], eq[3]
            if any(float(n @ m) > 1.0 - 1e-9 for m in normals):
                continue
            normals.append(n)
            members.append(np.flatnonzero(np.abs(v @ n + d) <= tol))
        _HULL_FACETS[model] = (np.array(normals), members)
    return _HULL_FACETS[model]


def resting_vertices(model: Polyhedron, world_from_model: SE3) -> np.ndarray:
    """The model vertices that rest on the table at ``world_from_model``: those of the facet of the model's convex
    hull whose outward normal points most nearly down (an object on a table rests on a facet of its hull: a face,
    or for a non-convex model the facet spanning the vertices it stands on)."""
    normals, members = _hull_facets(model)
    down = world_from_model.inverse().rotate(np.array([0.0, 0.0, -1.0]))
    return members[int(np.argmax(normals @ down))]


PIN_SPAN = 5e-3
"""Three measured vertices give their face's plane, for placing a vertex on the table, when they spread at least this
far across (the second singular value of their offsets) [m]: a thinner triangle tilts the plane by more than a
vertex's bound over its height."""


@dataclass(frozen=True)
class TablePin:
    """A model vertex resting on the table out of the pad's reach. The table gives its height and nothing else; its
    place on the table is given by one of its rising edges measured (the edge's line meets the table there), or by
    the planes of two of its faces (their planes and the table's meet there). A face's plane is known when the face
    is measured, or when three of its measured vertices span it (a planar face through them)."""

    vertex: int
    """The model vertex."""
    edges: frozenset[int]
    """Its edges that rise from the table and the hand can measure."""
    faces: tuple[tuple[int, tuple[int, ...], np.ndarray], ...] = field(compare=False)
    """Its faces off the table: each as (face, its vertices the hand can measure, their model points (k, 3))."""
    span: float = PIN_SPAN
    """Measured vertices span their face's plane when they spread at least this far across (:data:`PIN_SPAN`) [m]."""

    def plane_known(self, i: int, faces: frozenset[int], vertices: frozenset[int]) -> bool:
        """Whether the plane of the ``i``-th of :attr:`faces` is given by a measured face or measured vertices."""
        f, ids, points = self.faces[i]
        if f in faces:
            return True
        got = [k for k, v in enumerate(ids) if v in vertices]
        if len(got) < 3:
            return False
        p = points[got] - points[got[0]]
        s = np.linalg.svd(p, compute_uv=False)
        return bool(s[1] > self.span)

    def given(self, faces: frozenset[int], edges: frozenset[int], vertices: frozenset[int]) -> bool:
        """Whether measured ``faces``, ``edges`` and ``vertices`` give this vertex's place on the table."""
        if self.edges & edges:
            return True
        return sum(self.plane_known(i, faces, vertices) for i in range(len(self.faces))) >= 2


CORNER_SPAN = 0.3
"""The unit normals of a vertex's faces span space when the least singular value of their matrix is at least this
(a box's corner: 1; a regular tetrahedron's: 0.58; two faces turned 25° apart and a third across both: 0.31): a
corner moved 3 mm then moves at least 3 × 0.3 / √k mm along the normal of one of its k faces, which tilts that
face's corner."""


def corner_triangle(model: Polyhedron, v: int, f: int) -> np.ndarray | None:
    """The corner of face ``f`` at vertex ``v`` of ``model``: the triangle of ``v`` and its two neighbours in the
    face's loop (model frame, shape (3, 3), ``v`` first), or None where the face's corner at ``v`` is reflex (the
    triangle lies off the face). A corner of the object moved off the model's place tilts this triangle of each of
    its faces and keeps the rest of the face's plane (:func:`haptic.geometry.perturb.move_vertex`'s variants: the
    corner triangle becomes a face of its own): a face measured there sees the move, one measured elsewhere on the
    face need not."""
    loop = list(model.faces[f])
    k = loop.index(v)
    tri = model.vertices[[v, loop[(k + 1) % len(loop)], loop[k - 1]]]
    if float(np.cross(tri[1] - tri[0], tri[2] - tri[0]) @ model.face_normals[f]) <= 0.0:
        return None
    return tri


def in_corner(points: np.ndarray, tri: np.ndarray, normal: np.ndarray, slack: float = 0.0) -> np.ndarray:
    """Whether each of ``points`` (model frame, (P, 3)) lies, seen along the face's ``normal``, within the corner
    triangle ``tri`` (:func:`corner_triangle`) or within ``slack`` of it, shape (P,)."""
    inside = np.ones(len(points), dtype=bool)
    for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
        inward = np.cross(normal, b - a)
        inward /= max(float(np.linalg.norm(inward)), 1e-12)
        inside &= (points - a) @ inward >= -slack
    return inside


def faces_measured_near(model: Polyhedron, data: Sequence[DataComponent], it: Interpretation,
                        world_from_model: SE3, v: int) -> frozenset[int]:  # fmt: skip
    """The faces of ``model`` at vertex ``v`` that ``it`` pairs with a data face touched within the face's corner at
    ``v`` alone (:func:`corner_triangle`; every touched point, within its position bound): the faces whose plane is
    measured near ``v``. A face touched across the rest of the face too is not: its fit would mix the corner's tilt
    with the plane beyond."""
    inv = world_from_model.inverse()
    at_v = {int(f) for f in model.vertex_faces[v]}
    out = set()
    for i, f in it.faces.items():
        f = int(f)
        if f not in at_v or f in out:
            continue
        tri = corner_triangle(model, v, f)
        c = data[i]
        if tri is None or not isinstance(c, DataFace):
            continue
        pts = inv.apply(np.atleast_2d(c.points))
        if bool(np.all(in_corner(pts, tri, model.face_normals[f], c.position_bound))):
            out.add(f)
    return frozenset(out)


def corner_spans(model: Polyhedron, v: int) -> bool:
    """Whether the faces at vertex ``v`` are at least three with normals spanning space (:data:`CORNER_SPAN`)."""
    n = model.face_normals[[int(f) for f in model.vertex_faces[v]]]
    return len(n) >= 3 and float(np.linalg.svd(n, compute_uv=False)[-1]) >= CORNER_SPAN


def placed_near(model: Polyhedron, data: Sequence[DataComponent], it: Interpretation, world_from_model: SE3,
                v: int, edges: frozenset[int], vertices: frozenset[int]) -> bool:  # fmt: skip
    """Whether vertex ``v`` of ``model``, which no move touches (off the table, out of the hand's reach), is placed by
    the planes of its faces measured near it: it has at least three faces whose normals span space
    (:func:`corner_spans`), *every* one of them is measured within its corner at ``v``
    (:func:`faces_measured_near`: a corner moved 3 mm tilts at least one of them, and a vertex of more faces could
    move along the line where three of them meet while tilting only the rest), and every edge at ``v`` is measured
    (in ``edges``) or has its other end measured (in ``vertices``): a chamfer of an edge at ``v`` leaves the planes
    near ``v`` in place away from the edge and moves both of its ends by its legs, which a measured end sees. The
    pose check and the acceptance test then test the corner as they test every measured face."""
    if not corner_spans(model, v):
        return False
    if faces_measured_near(model, data, it, world_from_model, v) != {int(f) for f in model.vertex_faces[v]}:
        return False
    return all(int(e) in edges or int(sum(model.edges[int(e)])) - v in vertices for e in model.vertex_edges[v])


@dataclass(frozen=True)
class Coverage:
    """Which of a model's faces, edges and vertices the data have measured (under one interpretation)."""

    faces: frozenset[int]
    """Model faces paired with a data face."""
    edges: frozenset[int]
    """Model edges paired with a data edge."""
    vertices: frozenset[int]
    """Model vertices paired with a data vertex."""
    reachable_faces: frozenset[int]
    """Model faces that count towards the target (all of them without a table)."""
    reachable_edges: frozenset[int]
    """Model edges that count."""
    reachable_vertices: frozenset[int]
    """Model vertices that count."""
    pins: tuple[TablePin, ...] = ()
    """Under ``full``, the model vertices that rest on the table out of the pad's reach (:class:`TablePin`)."""

    def unpinned(self) -> tuple[TablePin, ...]:
        """The :attr:`pins` whose place on the table the data do not give yet."""
        return tuple(p for p in self.pins if not p.given(self.faces, self.edges, self.vertices))

    def fractions(self) -> tuple[float, float, float]:
        """Measured fraction of the reachable faces, edges and vertices (1 when none is reachable)."""

        def frac(got: frozenset[int], of: frozenset[int]) -> float:
            return len(got & of) / len(of) if of else 1.0

        return (
            frac(self.faces, self.reachable_faces),
            frac(self.edges, self.reachable_edges),
            frac(self.vertices, self.reachable_vertices),
        )

    def missing(self, mode: str) -> tuple[frozenset[int], frozenset[int], frozenset[int]]:
        """The reachable faces, edges and vertices still to be measured for ``mode``'s target. Under ``full``, once
        every reachable vertex is measured (measured vertices fix faces' planes, and so may pin a vertex resting on
        the table), the rising edges and the faces of the vertices on the table still unpinned."""
        tf, te, tv = TARGETS[mode]
        vertices = self.reachable_vertices - self.vertices if tv > 0 else frozenset()
        pin_edges: frozenset[int] = frozenset()
        pin_faces: frozenset[int] = frozenset()
        if tv > 0 and not vertices:
            for p in self.unpinned():
                pin_edges |= p.edges
                pin_faces |= frozenset(f for f, _, _ in p.faces) & self.reachable_faces
        return (
            (self.reachable_faces - self.faces if tf > 0 else frozenset()) | (pin_faces - self.faces),
            (self.reachable_edges - self.edges if te > 0 else frozenset()) | (pin_edges - self.edges),
            vertices,
        )

    def target_size(self, mode: str) -> int:
        """Number of reachable features ``mode``'s target asks for (the vertices under ``full``; the faces and
        edges under ``fast``)."""
        tf, te, tv = TARGETS[mode]
        return ((len(self.reachable_faces) if tf > 0 else 0) + (len(self.reachable_edges) if te > 0 else 0)
                + (len(self.reachable_vertices) + len(self.pins) if tv > 0 else 0))  # fmt: skip

    def measured(self) -> int:
        """Number of reachable features measured (faces, edges and vertices together)."""
        return (len(self.faces & self.reachable_faces) + len(self.edges & self.reachable_edges)
                + len(self.vertices & self.reachable_vertices) + len(self.pins) - len(self.unpinned()))  # fmt: skip

    def target_measured(self, mode: str) -> int:
        """Number of features of ``mode``'s target measured, growing only as the data do: the reachable faces and
        edges under ``fast``; under ``full`` the reachable vertices, the rising edges and faces of the vertices
        resting on the table (:meth:`missing` asks for them once every reachable vertex is measured) and those
        vertices pinned. A move measuring only features outside the target (a face or edge under ``full``) adds
        nothing."""
        tf, te, tv = TARGETS[mode]
        n = (len(self.faces & self.reachable_faces) if tf > 0 else 0) + (
            len(self.edges & self.reachable_edges) if te > 0 else 0
        )
        if tv > 0:
            pin_edges = frozenset(e for p in self.pins for e in p.edges)
            pin_faces = frozenset(f for p in self.pins for f, _, _ in p.faces) & self.reachable_faces
            n += (len(self.vertices & self.reachable_vertices) + len(self.edges & pin_edges)
                  + len(self.faces & pin_faces) + len(self.pins) - len(self.unpinned()))  # fmt: skip
        return n

    def met(self, mode: str) -> bool:
        """Whether ``mode``'s coverage target is met."""
        got = self.fractions()
        if TARGETS[mode][2] > 0 and self.unpinned():
            return False
        return all(g >= t - 1e-12 for g, t in zip(got, TARGETS[mode], strict=True))

    def record(self, model: Polyhedron) -> dict:
        """The JSON summary: counts measured, counts reachable, totals and fractions."""
        ff, fe, fv = self.fractions()
        return {
            "faces": len(self.faces), "edges": len(self.edges), "vertices": len(self.vertices),
            "faces_reachable": len(self.reachable_faces), "edges_reachable": len(self.reachable_edges),
            "vertices_reachable": len(self.reachable_vertices),
            "faces_total": model.n_faces, "edges_total": model.n_edges, "vertices_total": model.n_vertices,
            "faces_fraction": round(ff, 4), "edges_fraction": round(fe, 4), "vertices_fraction": round(fv, 4),
        }  # fmt: skip


def coverage(
    model: Polyhedron,
    it: Interpretation,
    reachable: tuple[frozenset[int], frozenset[int], frozenset[int]] | None = None,
    pins: tuple[TablePin, ...] = (),
) -> Coverage:
    """What interpretation ``it`` has measured of ``model``; ``reachable``: the faces, edges and vertices that
    count (default: all); ``pins``: :attr:`Coverage.pins`."""
    if reachable is None:
        reachable = (frozenset(range(model.n_faces)), frozenset(range(model.n_edges)),
                     frozenset(range(model.n_vertices)))  # fmt: skip
    return Coverage(
        frozenset(int(f) for f in it.faces.values()),
        frozenset(int(e) for e in it.edges.values()),
        frozenset(int(v) for v in it.vertices.values()),
        *reachable,
        pins,
    )


__all__ = [
    "ACCEPT_ALPHA",
    "CORNER_SPAN",
    "DEFAULT_VERIFY",
    "K_SIGMA",
    "K_SIGMA_PHYSICS",
    "Acceptance",
    "BoundFloors",
    "TablePin",
    "acceptance",
    "PIN_SPAN",
    "POSE_SAFETY",
    "TARGETS",
    "VERIFY_MODES",
    "Coverage",
    "PoseCheck",
    "check_verify_mode",
    "corner_spans",
    "corner_triangle",
    "faces_measured_near",
    "in_corner",
    "placed_near",
    "coverage",
    "own_bounds_keep",
    "pose_check",
    "leaf_pose_check",
    "residual_ratios",
]
