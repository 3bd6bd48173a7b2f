"""Per-library arrays for the matcher: every model's components in one global numbering per kind.

The interpretation tree works on all models at once, so each face, edge and vertex of the library gets a
global id (``offset[model] + local id``), and all geometry and adjacency lives in flat numpy arrays built once.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from haptic.errors import MatchError
from haptic.geometry.polyhedron import Polyhedron

FACE, EDGE, VERTEX = 0, 1, 2
KINDS = ("face", "edge", "vertex")
KIND_INDEX = {k: i for i, k in enumerate(KINDS)}


def _pad(rows: list[list[int]]) -> np.ndarray:
    width = max((len(r) for r in rows), default=0)
    out = np.full((len(rows), max(width, 1)), -1, dtype=np.int64)
    for i, r in enumerate(rows):
        out[i, : len(r)] = r
    return out


def _ro(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


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
    side: np.ndarray = field(init=False)
    """``side[f, e]``: +1 when face f is edge e's left face, −1 its right face, 0 not adjacent, shape (F, E)."""
    adjacency: dict = field(init=False)
    """``adjacency[(a, b)]``: dense boolean matrix, component of kind a adjacent to component of kind b."""
    neighbors: dict = field(init=False)
    """``neighbors[(a, b)]``: padded (−1) lists of kind-b neighbours of each kind-a component."""
    members: tuple[np.ndarray, np.ndarray, np.ndarray] = field(init=False)
    """``members[kind]``: padded (−1) global ids of each model's components of that kind, shape (M, max)."""

    @classmethod
    def build(cls, library: Mapping[str, Polyhedron] | Sequence[Polyhedron]) -> LibraryArrays:
        models = tuple(library.values()) if isinstance(library, Mapping) else tuple(library)
        if not models:
            raise MatchError("the model library is empty: give at least one Polyhedron")
        for m in models:
            if not isinstance(m, Polyhedron):
                raise MatchError(f"library entries must be Polyhedron objects, got {type(m).__name__}")
        return cls(models)

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

        side = np.zeros((nf, ne), dtype=np.int8)
        fe = np.zeros((nf, ne), dtype=bool)
        ev = np.zeros((ne, nv), dtype=bool)
        fv = np.zeros((nf, nv), dtype=bool)
        for i, m in enumerate(ms):
            e_ids = np.arange(m.n_edges) + eo[i]
            side[m.edge_left_face + fo[i], e_ids] = 1
            side[m.edge_right_face + fo[i], e_ids] = -1
            ev[e_ids, m.edges[:, 0] + vo[i]] = True
            ev[e_ids, m.edges[:, 1] + vo[i]] = True
            for f, loop in enumerate(m.faces):
                fv[f + fo[i], np.asarray(loop) + vo[i]] = True
        fe = side != 0
        # incidence products in float32 (BLAS; counts this small are exact): integer matmul is far slower
        ff = (fe.astype(np.float32) @ fe.T.astype(np.float32)) > 0
        np.fill_diagonal(ff, False)
        ee = (ev.astype(np.float32) @ ev.T.astype(np.float32)) > 0
        np.fill_diagonal(ee, False)
        vv = (ev.T.astype(np.float32) @ ev.astype(np.float32)) > 0
        np.fill_diagonal(vv, False)
        adjacency = {
            (0, 0): ff, (0, 1): fe, (0, 2): fv,
            (1, 0): fe.T.copy(), (1, 1): ee, (1, 2): ev,
            (2, 0): fv.T.copy(), (2, 1): ev.T.copy(), (2, 2): vv,
        }  # fmt: skip
        for a in adjacency.values():
            a.setflags(write=False)
        neighbors = {key: _ro(_pad([list(np.flatnonzero(row)) for row in a])) for key, a in adjacency.items()}
        s(self, "side", _ro(side))
        s(self, "adjacency", adjacency)
        s(self, "neighbors", neighbors)
        s(
            self,
            "members",
            tuple(_ro(_pad([list(range(offsets[k, i], offsets[k, i + 1])) for i in range(len(ms))])) for k in range(3)),
        )

    @property
    def n_models(self) -> int:
        return len(self.models)

    def count(self, kind: int) -> int:
        """Number of global components of a kind."""
        return int(self.offsets[kind, -1])

    def local(self, kind: int, global_id: int) -> int:
        """Local (per-model) id of a global component id."""
        return int(global_id - self.offsets[kind, self.model_of[kind][global_id]])
