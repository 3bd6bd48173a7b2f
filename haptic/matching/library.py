"""Per-library arrays for the matcher: every model's components in one global numbering per kind.

The interpretation tree works on all models at once, so each face, edge and vertex of the library gets a
global id (``offset[model] + local id``), and all geometry and adjacency lives in flat numpy arrays built once.

No component is adjacent to a component of another model, so adjacency is kept as sorted, padded neighbour
lists per component (built from each model's own winged-edge lists) rather than dense whole-library matrices:
time and memory grow linearly with the number of components. :meth:`LibraryArrays.build` keeps the arrays of the
last few libraries per process, keyed by the models' content, so the episodes of a sweep that run in one worker
build them once.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from haptic.errors import MatchError
from haptic.geometry.polyhedron import Polyhedron

FACE, EDGE, VERTEX = 0, 1, 2
KINDS = ("face", "edge", "vertex")
KIND_INDEX = {k: i for i, k in enumerate(KINDS)}

CACHE_SIZE = 4
"""Libraries whose arrays one process keeps (least recently used dropped first)."""
_CACHE: OrderedDict[bytes, LibraryArrays] = OrderedDict()
_BY_IDS: dict[tuple[int, ...], LibraryArrays] = {}


def _padded(n_rows: int, n_cols: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Neighbour lists from pairs ``(i, j)``: row ``r`` holds the distinct ``j`` paired with ``r``, ascending,
    padded with −1, shape (n_rows, max count) (at least one column)."""
    key = np.unique(np.asarray(i, dtype=np.int64) * max(n_cols, 1) + np.asarray(j, dtype=np.int64))
    rows, cols = key // max(n_cols, 1), key % max(n_cols, 1)
    count = np.bincount(rows, minlength=n_rows)
    out = np.full((n_rows, max(int(count.max(initial=0)), 1)), -1, dtype=np.int64)
    first = np.cumsum(count) - count
    out[rows, np.arange(len(rows)) - first[rows]] = cols
    return out


def _padded_ranges(offsets: np.ndarray) -> np.ndarray:
    """Row ``i``: ``offsets[i] .. offsets[i + 1] − 1``, padded with −1."""
    count = np.diff(offsets)
    width = max(int(count.max(initial=0)), 1)
    cols = np.arange(width)
    return np.where(cols < count[:, None], offsets[:-1, None] + cols, -1).astype(np.int64)


def _ro(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


class Adjacency:
    """Whether component ``i`` of one kind is adjacent to component ``j`` of another: ``adj[i, j]`` with
    arrays ``i`` and ``j`` (broadcast together) gives a boolean array, from the padded neighbour lists."""

    def __init__(self, neighbors: np.ndarray) -> None:
        self.neighbors = neighbors

    def __getitem__(self, ij: tuple) -> np.ndarray:
        i, j = (np.asarray(x) for x in ij)
        i, j = np.broadcast_arrays(i, j)
        return (self.neighbors[i] == j[..., None]).any(axis=-1)


class FaceEdgeSide:
    """``side[f, e]``: +1 when face ``f`` is edge ``e``'s left face, −1 its right face, 0 not adjacent (arrays
    broadcast together)."""

    def __init__(self, left: np.ndarray, right: np.ndarray) -> None:
        self.left, self.right = left, right

    def __getitem__(self, fe: tuple) -> np.ndarray:
        f, e = (np.asarray(x) for x in fe)
        return np.where(self.left[e] == f, 1, np.where(self.right[e] == f, -1, 0)).astype(np.int8)


def library_key(models: Sequence[Polyhedron]) -> bytes:
    """A digest of the models' names, vertices and face loops: equal for libraries of equal content."""
    h = hashlib.blake2b(digest_size=20)
    for m in models:
        h.update(m.name.encode())
        h.update(np.ascontiguousarray(m.vertices, dtype=np.float64).tobytes())
        for loop in m.faces:
            h.update(np.asarray(loop, dtype=np.int64).tobytes())
            h.update(b"|")
        h.update(b"#")
    return h.digest()


@dataclass(frozen=True, eq=False)
class LibraryArrays:
    """All models of a library as flat arrays with global component ids."""

    models: tuple[Polyhedron, ...]
    """The models, in library order."""
    names: tuple[str, ...] = field(init=False)
    """Model names, in library order."""
    offsets: np.ndarray = field(init=False)
    """``offsets[kind, model]``: global id of the model's first component of that kind, shape (3, M + 1)."""
    model_of: tuple[np.ndarray, np.ndarray, np.ndarray] = field(init=False)
    """Model index of each global face, edge and vertex."""
    face_normal: np.ndarray = field(init=False)
    """Outward unit normals ``n_m``, shape (F, 3)."""
    face_offset: np.ndarray = field(init=False)
    """Plane offsets ``d_m``, shape (F,) [m]."""
    edge_point: np.ndarray = field(init=False)
    """``p_m``: source vertex of each edge, shape (E, 3) [m]."""
    edge_end: np.ndarray = field(init=False)
    """Destination vertex position ``p_m + l_m b_m``, shape (E, 3) [m]."""
    edge_direction: np.ndarray = field(init=False)
    """``b_m``, shape (E, 3)."""
    edge_length: np.ndarray = field(init=False)
    """``l_m``, shape (E,) [m]."""
    edge_source: np.ndarray = field(init=False)
    """Global id of each edge's source vertex, shape (E,)."""
    edge_dest: np.ndarray = field(init=False)
    """Global id of each edge's destination vertex, shape (E,)."""
    vertex_position: np.ndarray = field(init=False)
    """Vertex positions, shape (V, 3) [m]."""
    edge_left_face: np.ndarray = field(init=False)
    """Global id of each edge's left face, shape (E,)."""
    edge_right_face: np.ndarray = field(init=False)
    """Global id of each edge's right face, shape (E,)."""
    side: FaceEdgeSide = field(init=False)
    """``side[f, e]``: +1 when face f is edge e's left face, −1 its right face, 0 not adjacent."""
    adjacency: dict = field(init=False)
    """``adjacency[(a, b)][i, j]``: component i of kind a adjacent to component j of kind b (:class:`Adjacency`)."""
    neighbors: dict = field(init=False)
    """``neighbors[(a, b)]``: padded (−1) ascending lists of kind-b neighbours of each kind-a component."""
    members: tuple[np.ndarray, np.ndarray, np.ndarray] = field(init=False)
    """``members[kind]``: padded (−1) global ids of each model's components of that kind, shape (M, max)."""
    edges_by_length: np.ndarray = field(init=False)
    """Global edge ids in ascending order of length: the index of a first data edge (:meth:`edges_longer_than`)."""

    @classmethod
    def build(cls, library: Mapping[str, Polyhedron] | Sequence[Polyhedron]) -> LibraryArrays:
        models = tuple(library.values()) if isinstance(library, Mapping) else tuple(library)
        if not models:
            raise MatchError("the model library is empty: give at least one Polyhedron")
        for m in models:
            if not isinstance(m, Polyhedron):
                raise MatchError(f"library entries must be Polyhedron objects, got {type(m).__name__}")
        ids = tuple(id(m) for m in models)
        hit = _BY_IDS.get(ids)
        if hit is not None and all(a is b for a, b in zip(hit.models, models, strict=True)):
            return hit  # the very model objects of a cached library: no need to digest them again
        key = library_key(models)
        hit = _CACHE.get(key)
        if hit is not None:
            _CACHE.move_to_end(key)
            return hit
        arrays = cls(models)
        _CACHE[key] = arrays
        _BY_IDS.clear()
        _BY_IDS[ids] = arrays
        while len(_CACHE) > CACHE_SIZE:
            _CACHE.popitem(last=False)
        return arrays

    def __post_init__(self) -> None:
        s = object.__setattr__
        ms = self.models
        s(self, "names", tuple(m.name for m in ms))
        counts = np.array([[m.n_faces for m in ms], [m.n_edges for m in ms], [m.n_vertices for m in ms]])
        offsets = np.zeros((3, len(ms) + 1), dtype=np.int64)
        offsets[:, 1:] = np.cumsum(counts, axis=1)
        s(self, "offsets", _ro(offsets))
        s(
            self,
            "model_of",
            tuple(_ro(np.repeat(np.arange(len(ms)), counts[k])) for k in range(3)),
        )
        fo, eo, vo = offsets[0], offsets[1], offsets[2]
        s(self, "face_normal", _ro(np.concatenate([m.face_normals for m in ms])))
        s(self, "face_offset", _ro(np.concatenate([m.face_offsets for m in ms])))
        s(self, "edge_point", _ro(np.concatenate([m.edge_points for m in ms])))
        s(self, "edge_end", _ro(np.concatenate([m.vertices[m.edges[:, 1]] for m in ms])))
        s(self, "edge_direction", _ro(np.concatenate([m.edge_directions for m in ms])))
        s(self, "edge_length", _ro(np.concatenate([m.edge_lengths for m in ms])))
        s(self, "edge_source", _ro(np.concatenate([m.edges[:, 0] + vo[i] for i, m in enumerate(ms)])))
        s(self, "edge_dest", _ro(np.concatenate([m.edges[:, 1] + vo[i] for i, m in enumerate(ms)])))
        s(self, "vertex_position", _ro(np.concatenate([m.vertices for m in ms])))
        nf, ne, nv = int(fo[-1]), int(eo[-1]), int(vo[-1])
        left = np.concatenate([m.edge_left_face + fo[i] for i, m in enumerate(ms)])
        right = np.concatenate([m.edge_right_face + fo[i] for i, m in enumerate(ms)])
        src, dst = self.edge_source, self.edge_dest
        e_all = np.arange(ne)
        loops = [np.asarray(loop) + vo[i] for i, m in enumerate(ms) for loop in m.faces]
        fv_f = np.repeat(np.arange(nf), [len(loop) for loop in loops])
        fv_v = np.concatenate(loops)
        # every adjacency is within one model: pairs from each component's own lists, O(components)
        pairs = {
            (0, 1): (np.concatenate([left, right]), np.concatenate([e_all, e_all])),
            (1, 2): (np.concatenate([e_all, e_all]), np.concatenate([src, dst])),
            (0, 2): (fv_f, fv_v),
            (0, 0): (np.concatenate([left, right]), np.concatenate([right, left])),
            (2, 2): (np.concatenate([src, dst]), np.concatenate([dst, src])),
        }
        # edges sharing a vertex: for each vertex, all ordered pairs of its edges
        v_of = np.concatenate([src, dst])
        e_of = np.concatenate([e_all, e_all])
        order = np.argsort(v_of, kind="stable")
        v_sorted, e_sorted = v_of[order], e_of[order]
        starts = np.searchsorted(v_sorted, np.arange(nv))
        deg = np.diff(np.append(starts, len(v_sorted)))
        # row r of the sorted list pairs with every row of the same vertex
        rep = np.repeat(np.arange(len(v_sorted)), deg[v_sorted])
        within = np.arange(len(rep)) - np.repeat(np.cumsum(deg[v_sorted]) - deg[v_sorted], deg[v_sorted])
        partner = starts[v_sorted[rep]] + within
        ee_i, ee_j = e_sorted[rep], e_sorted[partner]
        keep = ee_i != ee_j
        pairs[(1, 1)] = (ee_i[keep], ee_j[keep])
        sizes = {0: nf, 1: ne, 2: nv}
        for a, b in list(pairs):
            if a != b:
                i, j = pairs[(a, b)]
                pairs[(b, a)] = (j, i)
        neighbors = {key: _ro(_padded(sizes[key[0]], sizes[key[1]], *ij)) for key, ij in pairs.items()}
        s(self, "edge_left_face", _ro(left))
        s(self, "edge_right_face", _ro(right))
        s(self, "side", FaceEdgeSide(self.edge_left_face, self.edge_right_face))
        s(self, "neighbors", neighbors)
        s(self, "adjacency", {key: Adjacency(table) for key, table in neighbors.items()})
        s(
            self,
            "members",
            tuple(_ro(_padded_ranges(offsets[k])) for k in range(3)),
        )
        s(self, "edges_by_length", _ro(np.argsort(self.edge_length, kind="stable")))

    def edges_longer_than(self, length: float) -> np.ndarray:
        """Global ids (ascending) of the edges longer than ``length`` [m], by bisection in the length index: the
        candidates of a data edge that starts the tree, whose explored interval ``l_d`` a model edge must exceed
        less its ε (seed §2.3 step 2)."""
        lengths = self.edge_length[self.edges_by_length]
        start = int(np.searchsorted(lengths, length, side="right"))
        return np.sort(self.edges_by_length[start:])

    @property
    def n_models(self) -> int:
        return len(self.models)

    def count(self, kind: int) -> int:
        """Number of global components of a kind."""
        return int(self.offsets[kind, -1])

    def local(self, kind: int, global_id: int) -> int:
        """Local (per-model) id of a global component id."""
        return int(global_id - self.offsets[kind, self.model_of[kind][global_id]])
