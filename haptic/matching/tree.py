"""The interpretation tree of seed §2.3 over a whole model library, updated one data component at a time.

The tree is kept as its current leaves: each leaf is an interpretation, a model and the model component paired
with every data component so far (``assign[leaf, data id]``, global ids of :class:`LibraryArrays`), and, for
each data edge, the *sense* that pairs its direction with the model edge's (``b_d ≈ sense · R b_m``).

Adding a component extends every leaf (§2.3): (1) candidates from adjacency — for each data component reported
adjacent to the new one, the model components adjacent to its partner in this leaf, intersected; the first
component pairs with every model component of its kind in the library (a first edge: every model edge long
enough, found by bisection in the library's length index,
:meth:`~haptic.matching.library.LibraryArrays.edges_longer_than`); (2) the intrinsic test (edge length); (3)
geometric relations with the earlier components. Each candidate that passes becomes a child; a leaf without
a valid child is pruned. All of it is vectorised over the candidate children.

Senses. Seed §2.4 forces the directions of a data edge and of its model edge clockwise about a known common
face (reverse ``b`` and move ``p`` when that face is the edge's left face). Doing so on both sides is the same as
keeping the data edge as reported and orienting the model edge to match: the sense of a pairing is
``σ_d σ_m``, with ``σ_d`` the side (left +1, right −1) of the adjacent data face relative to ``b_d`` (from the
determinant of normal, direction and relative position, :func:`~haptic.matching.constraints.face_side`) and
``σ_m`` the side of the paired model face. Every face adjacent to an edge must give the same sense (a face on
the wrong side is a mirror-image pairing). A data edge's sense is fixed by the first of its faces to be paired;
tests that need a sense (edge pairs, face–edge, vertex–edge) use edges whose sense is known, which through any
adjacent face covers the non-adjacent pairs of §2.6.

A data component may pair with the same model component as an earlier one: the robot can touch a face again
without knowing it; the geometric tests decide (two data faces on one model face must be coplanar).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from types import MappingProxyType

import numpy as np

from haptic.errors import MatchError
from haptic.geometry.polyhedron import LearnedBounds, Polyhedron
from haptic.geometry.se3 import SE3, cross
from haptic.matching import constraints as C
from haptic.matching import kernels
from haptic.matching.batch_poses import StackedPoses
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex
from haptic.matching.library import EDGE, FACE, KIND_INDEX, KINDS, VERTEX, LibraryArrays

PARALLEL_FACES = 1e-6
"""Model face normals closer than this to (anti-)parallel take the plane-distance test [rad]."""


@dataclass(frozen=True, eq=False)
class Interpretation:
    """One surviving interpretation: a model and a pairing of every data component with one of its components."""

    model: Polyhedron
    """The model."""
    model_index: int
    """Index of the model in the tree's library."""
    faces: Mapping[int, int]
    """Data face id → model face id."""
    edges: Mapping[int, int]
    """Data edge id → model edge id."""
    vertices: Mapping[int, int]
    """Data vertex id → model vertex id."""
    edge_senses: Mapping[int, int]
    """Data edge id → +1 when ``b_d ≈ R b_m``, −1 when ``b_d ≈ −R b_m``, 0 when not yet known."""
    world_from_model: SE3 | None
    """Pose ``w_d = R w_m + t`` by least squares over all pairings, or None while it is undetermined."""
    leaf: int
    """Index of this interpretation among the tree's current leaves."""

    @property
    def name(self) -> str:
        """Model name."""
        return self.model.name

    def component(self, data_id: int) -> tuple[str, int]:
        """``(kind, model component id)`` paired with a data component."""
        for kind, table in (("face", self.faces), ("edge", self.edges), ("vertex", self.vertices)):
            if data_id in table:
                return kind, table[data_id]
        raise MatchError(f"data component {data_id} is not in this interpretation (ids {self.data_ids})")

    @property
    def data_ids(self) -> tuple[int, ...]:
        return tuple(sorted([*self.faces, *self.edges, *self.vertices]))


class _Data:
    """The data components so far, with stacked arrays per kind for vectorised tests."""

    def __init__(self) -> None:
        self.items: list[DataComponent] = []
        self.kinds: list[int] = []
        self.adj: list[set[int]] = []
        self._cache: dict[int, dict] = {}

    def __len__(self) -> int:
        return len(self.items)

    def ids(self, kind: int, exclude: int = -1) -> np.ndarray:
        return np.array([i for i, k in enumerate(self.kinds) if k == kind and i != exclude], dtype=np.int64)

    def arrays(self, kind: int) -> dict:
        """Per-kind arrays indexed by data id (rows of other kinds are unused)."""
        if kind in self._cache:
            return self._cache[kind]
        n = len(self.items)
        if kind == FACE:
            out = {"n": np.zeros((n, 3)), "q": np.zeros((n, 3)), "delta": np.zeros(n), "rho": np.zeros(n)}
            for i, c in enumerate(self.items):
                if self.kinds[i] == FACE:
                    out["n"][i], out["q"][i] = c.normal, c.points.mean(axis=0)
                    out["delta"][i], out["rho"][i] = c.normal_bound, c.position_bound
        elif kind == EDGE:
            out = {
                "p": np.zeros((n, 3)), "b": np.zeros((n, 3)), "l": np.zeros(n), "beta": np.zeros(n),
                "rho": np.zeros(n), "lam": np.zeros(n), "start": np.zeros(n, bool), "end": np.zeros(n, bool),
                "start_id": np.full(n, -1), "end_id": np.full(n, -1),
            }  # fmt: skip
            for i, c in enumerate(self.items):
                if self.kinds[i] == EDGE:
                    out["p"][i], out["b"][i], out["l"][i] = c.point, c.direction, c.length
                    out["beta"][i], out["rho"][i], out["lam"][i] = c.direction_bound, c.position_bound, c.length_bound
                    out["start"][i], out["end"][i] = c.start_vertex is not None, c.end_vertex is not None
                    out["start_id"][i] = -1 if c.start_vertex is None else c.start_vertex
                    out["end_id"][i] = -1 if c.end_vertex is None else c.end_vertex
        else:
            out = {"x": np.zeros((n, 3)), "rho": np.zeros(n)}
            for i, c in enumerate(self.items):
                if self.kinds[i] == VERTEX:
                    out["x"][i], out["rho"][i] = c.position, c.position_bound
        self._cache[kind] = out
        return out

    def put(self, comp: DataComponent, kind: int) -> None:
        if comp.id == len(self.items):
            self.items.append(comp)
            self.kinds.append(kind)
            self.adj.append(set())
        else:
            self.items[comp.id] = comp
        for a in comp.adjacent:
            self.adj[comp.id].add(a)
            self.adj[a].add(comp.id)
        self._cache.clear()

    def side(self, face_id: int, edge_id: int, face: DataFace | None = None, edge: DataEdge | None = None) -> int:
        """``σ_d``: +1 when the data face lies left of the data edge's direction, −1 right (seed §2.4), 0 when
        the face point is too close to the edge line for the error bounds to tell."""
        f = face if face is not None else self.items[face_id]
        e = edge if edge is not None else self.items[edge_id]
        q = None
        for fid, pt in e.side_points:
            if fid == face_id:
                q = pt
                break
        if q is None:
            # the touched point nearest the explored interval
            rel = f.points - e.point
            s = np.clip(rel @ e.direction, 0.0, e.length)
            dist = np.linalg.norm(rel - s[:, None] * e.direction, axis=1)
            q = f.points[int(np.argmin(dist))]
        # too close to the line for its errors: no side (the sense then comes from another face)
        r = np.asarray(q) - e.point
        margin = e.position_bound + f.position_bound + np.linalg.norm(r) * (e.direction_bound + f.normal_bound)
        if abs(float(cross(f.normal, e.direction) @ r)) <= C.SAFETY * margin + 1e-9:
            return 0
        return int(C.face_side(f.normal, e.direction, e.point, q))


def _kind_of(comp) -> int:
    if isinstance(comp, DataFace):
        return FACE
    if isinstance(comp, DataEdge):
        return EDGE
    if isinstance(comp, DataVertex):
        return VERTEX
    raise MatchError(f"not a data component: {type(comp).__name__} (expected DataFace, DataEdge or DataVertex)")


def learned_widening(models) -> LearnedBounds | None:
    """The bounds a library's learned models were learned with (the largest of each kind), or None when every
    model is exact. A learned model's features are no more exact than the data it was learned from, so the tests
    of seed §2.4, which take the model as exact, see every data component's bounds widened by them."""
    learned = [m.learned_bounds for m in models if m.learned_bounds is not None]
    if not learned:
        return None
    return LearnedBounds(max(b.normal for b in learned), max(b.position for b in learned),
                         max(b.direction for b in learned))  # fmt: skip


def widened(c: DataComponent, w: LearnedBounds) -> DataComponent:
    """``c`` with its error bounds and ``w``'s added in quadrature (independent errors): normal and direction
    angles, positions, and an edge interval's ends (a model edge's end is a vertex, off by a position bound)."""

    def q(a: float, b: float) -> float:
        return float(np.hypot(a, b))

    if isinstance(c, DataFace):
        return replace(c, normal_bound=q(c.normal_bound, w.normal), position_bound=q(c.position_bound, w.position))
    if isinstance(c, DataEdge):
        return replace(c, direction_bound=q(c.direction_bound, w.direction),
                       position_bound=q(c.position_bound, w.position),
                       length_bound=q(c.length_bound, w.position))  # fmt: skip
    return replace(c, position_bound=q(c.position_bound, w.position))


class InterpretationTree:
    """Incremental interpretation tree over a model library (seed §2.3).

    >>> tree = InterpretationTree(load_library())
    >>> tree.add(face)          # the number of interpretations after it
    """

    def __init__(self, library: Mapping[str, Polyhedron] | Sequence[Polyhedron] | LibraryArrays) -> None:
        self.library = library if isinstance(library, LibraryArrays) else LibraryArrays.build(library)
        self.widen = learned_widening(self.library.models)
        """The largest learned model's own bounds, added to every data component's (None: every model exact)."""
        self._data = _Data()
        self._raw: dict[int, DataComponent] = {}
        self._model = np.zeros(0, dtype=np.int64)
        self._assign = np.zeros((0, 0), dtype=np.int64)
        self._sense = np.zeros((0, 0), dtype=np.int8)
        self.counts: list[int] = []
        """Number of interpretations after each ``add`` (re-reported edges included)."""
        self._pose_cache: dict[tuple[bool, int], SE3 | None] = {}
        """Poses by (refined, leaf) of the current leaves, emptied by every ``add`` and renumbered by ``retain``."""
        self.leaf_memo: dict[tuple[str, int], object] = {}
        """Results computed from one leaf and the data so far, by ``(what, leaf)`` (the pose check of
        :func:`~haptic.matching.acceptance.leaf_pose_check`), emptied by every ``add`` and renumbered by ``retain``."""
        self.data_memo: dict[str, object] = {}
        """Results computed from the data alone, by name (the position span of
        :func:`~haptic.matching.free_space.consistent_leaves`), emptied by every ``add``; a ``retain`` keeps them."""
        self._initial: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        """The closed-form poses of every leaf as arrays (:meth:`initial_poses`), emptied by every ``add`` and
        renumbered by ``retain``."""
        self._stack: StackedPoses | None = None
        """The least-squares problems of every current leaf, once built (:meth:`_stacked`); emptied by every ``add``
        and ``retain``."""

    # ------------------------------------------------------------------------------------------ state

    @property
    def count(self) -> int:
        """Number of surviving interpretations (leaves)."""
        return int(len(self._model))

    def __len__(self) -> int:
        return self.count

    @property
    def data(self) -> tuple[DataComponent, ...]:
        """The data components so far (re-reported edges in their latest form), indexed by id, with the bounds
        they were reported with (the tests' widening for learned models left out)."""
        if self.widen is None:
            return tuple(self._data.items)
        return tuple(self._raw.get(i, c) for i, c in enumerate(self._data.items))

    @property
    def model_indices(self) -> np.ndarray:
        """Model index of each leaf, shape (N,)."""
        return self._model.copy()

    @property
    def assignments(self) -> np.ndarray:
        """Global model component id paired with each data component, per leaf, shape (N, D)."""
        return self._assign.copy()

    @property
    def senses(self) -> np.ndarray:
        """Sense of each data edge's pairing per leaf (0 for non-edges or unknown), shape (N, D)."""
        return self._sense.copy()

    def models_alive(self) -> tuple[str, ...]:
        """Names of the models that still have an interpretation."""
        return tuple(self.library.names[i] for i in np.unique(self._model))

    def copy(self) -> InterpretationTree:
        """An independent copy (the library arrays are shared: they are read-only)."""
        t = InterpretationTree(self.library)
        t._data.items = list(self._data.items)
        t._data.kinds = list(self._data.kinds)
        t._data.adj = [set(a) for a in self._data.adj]
        t._raw = dict(self._raw)
        t._model, t._assign, t._sense = self._model.copy(), self._assign.copy(), self._sense.copy()
        t.counts = list(self.counts)
        return t

    # ------------------------------------------------------------------------------------------ updates

    def add(self, component: DataComponent) -> int:
        """Add a data component (or a re-reported, extended edge); returns the number of interpretations."""
        if self.widen is not None:
            self._raw[component.id] = component
            component = widened(component, self.widen)
        kind, new = self._check_input(component)
        if new:
            parents, cands = self._candidates(component, kind)
            ok, assign, sense = self._evaluate(component, kind, parents, cands, new=True)
            models = self._leaf_models(parents, cands, kind)
            self._data.put(component, kind)
            self._model = models[ok]
            self._assign, self._sense = assign[ok], sense[ok]
        else:
            previous = self._data.items[component.id]
            self._data.put(component, kind)
            parents = np.arange(self.count)
            ok, assign, sense = self._evaluate(
                component, kind, parents, self._assign[:, component.id], new=False, previous=previous
            )
            self._model, self._assign, self._sense = self._model[ok], assign[ok], sense[ok]
        self.counts.append(self.count)
        self._pose_cache.clear()  # poses are of the data before this add
        self.leaf_memo.clear()
        self.data_memo.clear()
        self._initial = None
        self._stack = None
        return self.count

    def add_move(self, components: Sequence[DataComponent]) -> int:
        """Add the components one move yielded together -- a placement's faces, one per finger -- and return the
        number of interpretations. The move's new components must come in order of their ids, as an executor
        numbers them. Each is paired with every admissible model component (§2.3) and tested against every
        earlier component, the move's own before it included, so every pairwise constraint of §2.6 between the
        move's components holds in each interpretation left: the relative positions and normals measured in one
        hand frame apply at once, the paper's constraints unchanged (seed §5: "the matching part is essentially
        unchanged")."""
        fresh = list(dict.fromkeys(c.id for c in components if c.id >= len(self._data)))  # (an edge re-reported)
        if fresh != list(range(len(self._data), len(self._data) + len(fresh))):
            raise MatchError(f"a move's new components must have the next ids in order ({len(self._data)} on), "
                             f"got {fresh}")  # fmt: skip
        for c in components:
            self.add(c)
        return self.count

    def add_all(self, components: Iterable[DataComponent]) -> list[int]:
        """Add components in order; the interpretation count after each."""
        return [self.add(c) for c in components]

    def retain(self, keep: np.ndarray) -> int:
        """Eliminate the leaves where ``keep`` (shape (N,) bool) is False: evidence that is no pairing, such as
        the free space a probe passed through (:mod:`haptic.matching.free_space`). Returns the number left; the
        count after the last ``add`` is updated to it."""
        keep = np.asarray(keep, dtype=bool)
        if keep.shape != (self.count,):
            raise MatchError(f"retain: expected one flag per leaf, shape ({self.count},), got {keep.shape}")
        self._model, self._assign, self._sense = self._model[keep], self._assign[keep], self._sense[keep]
        renumber = np.cumsum(keep) - 1  # a kept leaf's new index; its pose (same data) stays valid
        self._pose_cache = {(r, int(renumber[i])): p for (r, i), p in self._pose_cache.items() if keep[i]}
        self.leaf_memo = {(w, int(renumber[i])): v for (w, i), v in self.leaf_memo.items() if keep[i]}
        if self._initial is not None:
            self._initial = tuple(a[keep] for a in self._initial)
        self._stack = None
        if self.counts:
            self.counts[-1] = self.count
        return self.count

    def test(self, component: DataComponent) -> np.ndarray:
        """Which current interpretations would survive ``component`` (a prediction), without changing the tree.

        Returns a boolean array over the leaves: True when the leaf would keep at least one valid child (for a
        new component) or would pass the re-test (for a re-reported edge).
        """
        kind, new = self._check_input(component)
        if self.count == 0:
            return np.zeros(0, dtype=bool)
        if new:
            parents, cands = self._candidates(component, kind)
            ok, _, _ = self._evaluate(component, kind, parents, cands, new=True)
            return np.bincount(parents[ok], minlength=self.count) > 0
        saved = self._data.items[component.id]
        self._data.put(component, kind)
        try:
            ok, _, _ = self._evaluate(
                component, kind, np.arange(self.count), self._assign[:, component.id], new=False, previous=saved
            )
        finally:
            self._data.put(saved, kind)
        return ok

    # ------------------------------------------------------------------------------------------ internals

    def _check_input(self, comp) -> tuple[int, bool]:
        kind = _kind_of(comp)
        n = len(self._data)
        if comp.id == n:
            for a in comp.adjacent:
                if not 0 <= a < n:
                    raise MatchError(
                        f"data {KINDS[kind]} {comp.id} names adjacent component {a}, which is not an earlier "
                        f"component (valid ids 0..{n - 1})"
                    )
            return kind, True
        if 0 <= comp.id < n:
            if kind != EDGE or self._data.kinds[comp.id] != EDGE:
                raise MatchError(
                    f"data {KINDS[kind]} {comp.id} re-uses the id of an earlier {KINDS[self._data.kinds[comp.id]]}; "
                    "only an edge may be re-reported (with the id it first had)"
                )
            for a in comp.adjacent:
                if not 0 <= a < n:
                    raise MatchError(f"re-reported edge {comp.id} names unknown adjacent component {a}")
            return kind, False
        raise MatchError(f"data component id {comp.id} is out of order: the next id is {n}")

    def _leaf_models(self, parents: np.ndarray, cands: np.ndarray, kind: int) -> np.ndarray:
        if len(self._data) == 0:
            return self.library.model_of[kind][cands]
        return self._model[parents]

    def _candidates(self, comp, kind: int) -> tuple[np.ndarray, np.ndarray]:
        """Seed §2.3 step 1: ``(parent leaf, candidate model component)`` pairs."""
        lib = self.library
        if len(self._data) == 0:
            if kind == EDGE:  # the length index; the intrinsic test then decides at the boundary
                eps = C.edge_length_epsilon(comp.length_bound, comp.position_bound, comp.direction_bound)
                cands = lib.edges_longer_than(float(comp.length - eps) - 1e-9)
            else:  # a face or a vertex has no invariant of its own yet: every one of its kind
                cands = np.arange(lib.count(kind))
            return np.zeros(len(cands), dtype=np.int64), cands
        n = self.count
        if n == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        adj = list(comp.adjacent)
        if not adj:
            table = lib.members[kind][self._model]
        else:
            a0 = adj[0]
            table = lib.neighbors[(self._data.kinds[a0], kind)][self._assign[:, a0]]
        parents = np.repeat(np.arange(n), table.shape[1])
        cands = table.reshape(-1)
        keep = cands >= 0
        parents, cands = parents[keep], cands[keep]
        for a in adj[1:]:
            m = lib.adjacency[(self._data.kinds[a], kind)]
            keep = m[self._assign[parents, a], cands]
            parents, cands = parents[keep], cands[keep]
        return parents, cands

    def _evaluate(self, comp, kind: int, parents, cands, new: bool, previous: DataEdge | None = None):
        """Seed §2.3 steps 2–3 for ``comp`` paired with ``cands`` under ``parents``; ``previous``: the earlier
        report of a re-reported edge.

        Returns ``(ok, assign, sense)`` with the children's full assignment and sense matrices.
        """
        k = comp.id
        if new:
            base = self._assign[parents] if len(self._data) else np.zeros((len(cands), 0), dtype=np.int64)
            sbase = self._sense[parents] if len(self._data) else np.zeros((len(cands), 0), dtype=np.int8)
            assign = np.concatenate([base, cands[:, None]], axis=1)
            sense = np.concatenate([sbase, np.zeros((len(cands), 1), dtype=np.int8)], axis=1)
            adjacent = set(comp.adjacent)
        else:
            assign, sense = self._assign[parents].copy(), self._sense[parents].copy()
            # A pairing's sense is a fact about the leaf, found from a face side when it was decided; it carries
            # over to the new report (flipped if the direction was reversed), and the faces re-check it. (The
            # side of a face from the new report may be undecidable: a longer interval puts p farther from the
            # side point, and the margin grows with that lever arm.)
            c = float(comp.direction @ previous.direction) if isinstance(previous, DataEdge) else 0.0
            sense[:, k] = sense[:, k] * (1 if c > 0.5 else -1 if c < -0.5 else 0)
            adjacent = set(self._data.adj[k]) | set(comp.adjacent)
        ok = np.ones(len(cands), dtype=bool)
        if len(cands) == 0:
            return ok, assign, sense
        if kind == FACE:
            ok &= self._face_tests(comp, k, cands, assign, sense, adjacent)
        elif kind == EDGE:
            ok &= self._edge_tests(comp, k, cands, assign, sense, adjacent)
        else:
            ok &= self._vertex_tests(comp, k, cands, assign, sense, adjacent)
        return ok, assign, sense

    def _others(self, kind: int, k: int, width: int) -> np.ndarray:
        ids = self._data.ids(kind, exclude=k)
        return ids[ids < width]

    # ---- faces

    def _face_tests(self, comp: DataFace, k, cands, assign, sense, adjacent) -> np.ndarray:
        lib, data = self.library, self._data
        ok = np.ones(len(cands), dtype=bool)
        n_d, q_d = comp.normal, comp.points.mean(axis=0)
        delta, rho = comp.normal_bound, comp.position_bound
        # sides of the adjacent edges: fix or check their senses
        for a in sorted(adjacent):
            if a == k or a >= len(data.kinds) or data.kinds[a] != EDGE:
                continue
            s_m = lib.side[cands, assign[:, a]]
            ok &= s_m != 0
            s = data.side(k, a, face=comp) * s_m
            cur = sense[:, a]
            ok &= (cur == 0) | (s == 0) | (cur == s)
            sense[:, a] = np.where(cur == 0, s, cur).astype(np.int8)
        n_m = lib.face_normal[cands]
        d_m = lib.face_offset[cands]
        width = assign.shape[1]
        fd = data.arrays(FACE)
        fids = self._others(FACE, k, width)
        if len(fids):
            mj = assign[:, fids]
            n_mj = lib.face_normal[mj]
            eps = C.face_pair_epsilon(delta, fd["delta"][fids])
            ok &= C.face_pair_test(n_d, fd["n"][fids], n_m[:, None], n_mj, eps).all(axis=1)
            c = np.einsum("ci,cji->cj", n_m, n_mj)
            par = np.abs(c) > np.cos(PARALLEL_FACES)
            if par.any():
                d_mj = lib.face_offset[mj]
                h_m = np.where(c > 0, d_mj - d_m[:, None], -d_mj - d_m[:, None])
                pf = C.parallel_faces_test(n_d, q_d, fd["q"][fids], rho, fd["rho"][fids], delta, h_m)
                ok &= (pf | ~par).all(axis=1)
        vd = data.arrays(VERTEX)
        vids = self._others(VERTEX, k, width)
        if len(vids):
            v_m = lib.vertex_position[assign[:, vids]]
            ok &= C.vertex_face_test(
                vd["x"][vids], vd["rho"][vids], n_d, q_d, rho, delta, n_m[:, None], d_m[:, None], v_m
            ).all(axis=1)
        ed = data.arrays(EDGE)
        eids = self._others(EDGE, k, width)
        if len(eids):
            sj = sense[:, eids]
            b_m = sj[..., None] * lib.edge_direction[assign[:, eids]]
            t = C.face_edge_angle_test(n_d, ed["b"][eids], n_m[:, None], b_m, delta, ed["beta"][eids])
            ok &= (t | (sj == 0)).all(axis=1)
        return ok

    # ---- edges

    def _aligned_edge(self, cands, s):
        lib = self.library
        p = np.where((s > 0)[..., None], lib.edge_point[cands], lib.edge_end[cands])
        b = s[..., None] * lib.edge_direction[cands]
        start_v = np.where(s > 0, lib.edge_source[cands], lib.edge_dest[cands])
        return p, b, start_v

    def _edge_tests(self, comp: DataEdge, k, cands, assign, sense, adjacent) -> np.ndarray:
        lib, data = self.library, self._data
        ok = C.edge_length_test(
            comp.length,
            lib.edge_length[cands],
            C.edge_length_epsilon(comp.length_bound, comp.position_bound, comp.direction_bound),
        )
        width = assign.shape[1]
        # sense from the adjacent faces (each must agree), starting from a re-reported edge's known sense
        s_k = sense[:, k].astype(np.int8)
        for f in sorted(adjacent):
            if f == k or f >= len(data.kinds) or data.kinds[f] != FACE:
                continue
            s_m = lib.side[assign[:, f], cands]
            s = (data.side(f, k, edge=comp) * s_m).astype(np.int8)
            ok &= (s_m != 0) & ((s_k == 0) | (s == 0) | (s_k == s))
            s_k = np.where(s_k == 0, s, s_k).astype(np.int8)
        sense[:, k] = s_k
        known = s_k != 0
        if not known.any():
            return ok
        p_d, b_d, l_d = comp.point, comp.direction, comp.length
        beta, rho, lam = comp.direction_bound, comp.position_bound, comp.length_bound
        start, end = comp.start_vertex is not None, comp.end_vertex is not None
        p_m, b_m, _ = self._aligned_edge(cands, s_k)
        l_m = lib.edge_length[cands]
        ed = data.arrays(EDGE)
        eids = self._others(EDGE, k, width)
        if len(eids):
            sj = sense[:, eids]
            mj = assign[:, eids]
            p_mj, b_mj, _ = self._aligned_edge(mj, sj)
            if kernels.COMPILED:
                f = np.ascontiguousarray
                res = kernels.edge_pair_tests(
                    f(p_d, float), f(b_d, float), float(l_d), f(ed["p"][eids]), f(ed["b"][eids]), f(ed["l"][eids]),
                    f(p_m, float), f(b_m, float), f(l_m, float), f(p_mj, float), f(b_mj, float),
                    f(lib.edge_length[mj], float), float(beta), f(ed["beta"][eids]), float(rho), f(ed["rho"][eids]),
                    float(lam), f(ed["lam"][eids]), start, end, f(ed["start"][eids]), f(ed["end"][eids]),
                    C.SAFETY, C.ANGLE_FLOOR, C.LENGTH_FLOOR, C.MIN_SIN, float(np.cos(C.PARALLEL_MODEL)),
                )  # fmt: skip
            else:
                res = C.edge_pair_tests(
                    p_d, b_d, l_d, ed["p"][eids], ed["b"][eids], ed["l"][eids],
                    p_m[:, None], b_m[:, None], l_m[:, None], p_mj, b_mj, lib.edge_length[mj],
                    beta, ed["beta"][eids], rho, ed["rho"][eids], lam, ed["lam"][eids],
                    start, end, ed["start"][eids], ed["end"][eids],
                )  # fmt: skip
            ok &= (res | ~(known[:, None] & (sj != 0))).all(axis=1)
        fd = data.arrays(FACE)
        fids = self._others(FACE, k, width)
        if len(fids):
            n_mj = lib.face_normal[assign[:, fids]]
            t = C.face_edge_angle_test(fd["n"][fids], b_d, n_mj, b_m[:, None], fd["delta"][fids], beta)
            ok &= t.all(axis=1) | ~known
        vd = data.arrays(VERTEX)
        vids = self._others(VERTEX, k, width)
        if len(vids):
            v_m = lib.vertex_position[assign[:, vids]]
            t_m, h_m = C.vertex_on_line(v_m, p_m[:, None], b_m[:, None])
            t = C.vertex_edge_test(
                vd["x"][vids], vd["rho"][vids], p_d, b_d, l_d, rho, lam, beta, t_m, h_m, l_m[:, None],
                vids == comp.start_vertex, vids == comp.end_vertex,
            )  # fmt: skip
            ok &= t.all(axis=1) | ~known
        return ok

    # ---- vertices

    def _vertex_tests(self, comp: DataVertex, k, cands, assign, sense, adjacent) -> np.ndarray:
        lib, data = self.library, self._data
        ok = np.ones(len(cands), dtype=bool)
        x, rho = comp.position, comp.position_bound
        v_m = lib.vertex_position[cands]
        width = assign.shape[1]
        ed = data.arrays(EDGE)
        eids = self._others(EDGE, k, width)
        if len(eids):
            sj = sense[:, eids]
            mj = assign[:, eids]
            p_mj, b_mj, _ = self._aligned_edge(mj, sj)
            t_m, h_m = C.vertex_on_line(v_m[:, None], p_mj, b_mj)
            t = C.vertex_edge_test(
                x, rho, ed["p"][eids], ed["b"][eids], ed["l"][eids], ed["rho"][eids], ed["lam"][eids],
                ed["beta"][eids], t_m, h_m, lib.edge_length[mj], ed["start_id"][eids] == k, ed["end_id"][eids] == k,
            )  # fmt: skip
            ok &= (t | (sj == 0)).all(axis=1)
        vd = data.arrays(VERTEX)
        vids = self._others(VERTEX, k, width)
        if len(vids):
            v_mj = lib.vertex_position[assign[:, vids]]
            ok &= C.vertex_pair_test(x, vd["x"][vids], rho, vd["rho"][vids], v_m[:, None], v_mj).all(axis=1)
        fd = data.arrays(FACE)
        fids = self._others(FACE, k, width)
        if len(fids):
            mj = assign[:, fids]
            ok &= C.vertex_face_test(
                x, rho, fd["n"][fids], fd["q"][fids], fd["rho"][fids], fd["delta"][fids],
                lib.face_normal[mj], lib.face_offset[mj], v_m[:, None],
            ).all(axis=1)  # fmt: skip
        return ok

    # ------------------------------------------------------------------------------------------ results

    def interpretation(self, leaf: int, with_pose: bool = True, refine: bool = True) -> Interpretation:
        """The interpretation at one leaf (with its pose, least-squares refined unless ``refine`` is False)."""
        lib = self.library
        mi = int(self._model[leaf])
        row, srow = self._assign[leaf], self._sense[leaf]
        maps: dict[int, dict[int, int]] = {FACE: {}, EDGE: {}, VERTEX: {}}
        senses: dict[int, int] = {}
        for i, kind in enumerate(self._data.kinds):
            maps[kind][i] = int(row[i] - lib.offsets[kind, mi])
            if kind == EDGE:
                senses[i] = int(srow[i])
        pose = self.poses([leaf], refine)[0] if with_pose else None
        return Interpretation(
            model=lib.models[mi],
            model_index=mi,
            faces=MappingProxyType(maps[FACE]),
            edges=MappingProxyType(maps[EDGE]),
            vertices=MappingProxyType(maps[VERTEX]),
            edge_senses=MappingProxyType(senses),
            world_from_model=pose,
            leaf=leaf,
        )

    def initial_poses(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The closed-form (unrefined) poses of every leaf as arrays: ``(R (N, 3, 3), t (N, 3), ok (N,))``, ``ok``
        False where the data do not determine a pose yet (:meth:`~haptic.matching.batch_poses.StackedPoses.initial`,
        all leaves in one batch). Computed once per data update; :meth:`poses` with ``refine=False`` gives the same
        poses as :class:`~haptic.geometry.se3.SE3`."""
        if self._initial is None:
            n = self.count
            if n == 0:
                self._initial = (np.zeros((0, 3, 3)), np.zeros((0, 3)), np.zeros(0, bool))
            else:
                self._initial = self._stacked(np.arange(n)).initial()
        return self._initial

    def poses(self, leaves: Sequence[int], refine: bool = True) -> list[SE3 | None]:
        """Poses ``world_from_model`` of some leaves (None where the data do not determine one yet), least-squares
        refined unless ``refine`` is False: all of them in one batch
        (:class:`~haptic.matching.batch_poses.StackedPoses`), from the unrefined ones for a refinement. Poses are kept
        until the next ``add``, so a leaf is posed once per data update (the unrefined ones of every leaf at once,
        :meth:`initial_poses`, once asked for all)."""
        leaves = [int(i) for i in leaves]
        todo = sorted({i for i in leaves if (refine, i) not in self._pose_cache})
        if todo:
            rows = np.array(todo, dtype=np.int64)
            if not refine and (self._initial is not None or len(todo) == self.count):
                r, t, ok = (a[rows] for a in self.initial_poses())
            elif refine:
                prob = self._stacked(rows)
                if self._initial is not None:
                    r, t, ok = (a[rows] for a in self._initial)
                else:
                    start = self.poses(todo, refine=False)
                    ok = np.array([p is not None for p in start])
                    r = np.stack([p.rotation if p is not None else np.eye(3) for p in start])
                    t = np.stack([p.translation if p is not None else np.zeros(3) for p in start])
                idx = np.flatnonzero(ok)
                if len(idx):
                    r, t = r.copy(), t.copy()
                    r[idx], t[idx] = prob.subset(idx).refine(r[idx], t[idx])
            else:
                r, t, ok = self._stacked(rows).initial()
            for j, leaf in enumerate(todo):
                self._pose_cache[(refine, leaf)] = SE3(r[j], t[j]) if ok[j] else None
        return [self._pose_cache[(refine, i)] for i in leaves]

    def _stacked(self, rows: np.ndarray) -> StackedPoses:
        """The stacked least-squares problems of the leaves ``rows`` (global ids gathered from the library). Those of
        every leaf, once built for a request of all of them (the matcher's verdict poses every leaf, then refines
        one per pose class), are kept until the data or the leaves change, and a later request takes its rows from
        them (:meth:`~haptic.matching.batch_poses.StackedPoses.subset`: the same arrays row by row)."""
        if self._stack is not None:
            return self._stack.subset(rows)
        prob = self._build_stacked(rows)
        if len(rows) == self.count and bool((rows == np.arange(self.count)).all()):
            self._stack = prob
        return prob

    def _build_stacked(self, rows: np.ndarray) -> StackedPoses:
        lib, kinds = self.library, np.array(self._data.kinds, dtype=np.int64)
        fids, eids, vids = (np.flatnonzero(kinds == k) for k in (FACE, EDGE, VERTEX))
        a = self._assign[rows]
        f, e, v = a[:, fids], a[:, eids], a[:, vids]
        return StackedPoses(
            self._data.items, fids.tolist(), eids.tolist(), vids.tolist(),
            lib.face_normal[f], lib.face_offset[f], lib.edge_point[e], lib.edge_direction[e],
            self._sense[rows][:, eids], lib.vertex_position[v],
        )  # fmt: skip

    def interpretations(
        self, with_pose: bool = True, limit: int | None = None, refine: bool = True
    ) -> list[Interpretation]:
        """The surviving interpretations (the first ``limit`` of them), with poses when determined."""
        n = self.count if limit is None else min(limit, self.count)
        return [self.interpretation(i, with_pose, refine) for i in range(n)]

    def summary(self) -> dict[str, int]:
        """Interpretation count per model (models with none left out)."""
        names, counts = np.unique(self._model, return_counts=True)
        return {self.library.names[int(i)]: int(c) for i, c in zip(names, counts, strict=True)}


__all__ = ["KIND_INDEX", "Interpretation", "InterpretationTree"]
