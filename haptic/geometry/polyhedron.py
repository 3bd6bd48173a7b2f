"""A closed polyhedral solid in the winged-edge representation of seed §2.2.

Faces are ``(n, d)`` with the outward unit normal ``n`` and the plane ``n·w − d = 0``, and a counter-clockwise
vertex loop as seen from outside. Edges are ``(b, p, l)``: ``p`` the source vertex, ``b`` the unit direction
toward the destination vertex, ``l`` the length; each edge knows its left and right face as seen from outside
relative to ``b``. Vertices know their edges and faces.

Left and right: walking a face's counter-clockwise loop keeps the face on the walker's left (seen from
outside), so the face whose loop holds ``source → dest`` is the edge's *left* face and the face whose loop holds
``dest → source`` is its *right* face.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from haptic.errors import ModelError
from haptic.geometry.se3 import plane_basis
from haptic.geometry.tolerances import Tolerances


def _readonly(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


def newell_normal(points: np.ndarray) -> np.ndarray:
    """Area-weighted normal of a closed polygon loop by Newell's method (length = twice the area)."""
    nxt = np.roll(points, -1, axis=0)
    return np.cross(points, nxt).sum(axis=0)


@dataclass(frozen=True)
class LearnedBounds:
    """The error bounds of the data a learned model was made from (a model file's ``provenance.bounds``)."""

    normal: float
    """Face normal direction [rad]."""
    position: float
    """Position of a face, an edge or a vertex [m]."""
    direction: float
    """Edge direction [rad]."""


@dataclass(frozen=True, eq=False)
class Polyhedron:
    """A validated closed, connected, consistently oriented polyhedral solid (any genus, any convexity).

    Build one with :meth:`from_faces` (which validates); the fields below are derived once and read-only.
    """

    name: str
    """Model name (the file stem when loaded from a library)."""
    vertices: np.ndarray
    """Vertex positions in the model frame, shape (V, 3) [m]."""
    faces: tuple[tuple[int, ...], ...]
    """Vertex loops, counter-clockwise seen from outside, one per face."""
    source: str | None = None
    """Where the model came from (a file path), for messages."""
    precision: float = 0.0
    """How far the source rounded each coordinate: half a unit of its last written digit, 0 for exact data [m]."""
    vertex_labels: tuple[str, ...] | None = field(default=None, repr=False)
    """The source file's own number of each vertex (1-based for OBJ), for messages; ``None``: the index here."""
    learned_bounds: LearnedBounds | None = field(default=None, repr=False)
    """For a model learned by touch: the error bounds of the data it was learned from, which its features are
    known to no better than (the verification widens its tests by them); ``None`` for a model made exactly."""

    tolerances: Tolerances = field(init=False, repr=False)
    """Numerical tolerances of this model, from its size and :attr:`precision`."""

    face_normals: np.ndarray = field(init=False, repr=False)
    """Outward unit normals ``n``, shape (F, 3)."""
    face_offsets: np.ndarray = field(init=False, repr=False)
    """Plane offsets ``d`` with ``n·w − d = 0``, shape (F,) [m]."""
    face_areas: np.ndarray = field(init=False, repr=False)
    """Face areas, shape (F,) [m^2]."""
    edges: np.ndarray = field(init=False, repr=False)
    """Source and destination vertex of each edge, shape (E, 2), source < destination."""
    edge_left_face: np.ndarray = field(init=False, repr=False)
    """Face on the left of each edge seen from outside, relative to ``b``, shape (E,)."""
    edge_right_face: np.ndarray = field(init=False, repr=False)
    """Face on the right of each edge, shape (E,)."""
    face_edges: tuple[tuple[int, ...], ...] = field(init=False, repr=False)
    """Edge ids of each face, in loop order (edge k joins loop vertex k to loop vertex k+1)."""

    # ----------------------------------------------------------------------------------------- construction

    @classmethod
    def from_faces(
        cls,
        vertices,
        faces,
        name: str = "model",
        source: str | None = None,
        precision: float = 0.0,
        vertex_labels=None,
        learned_bounds: LearnedBounds | None = None,
    ) -> Polyhedron:
        """Validate and build a polyhedron from vertex positions [m] and CCW-from-outside face loops.

        ``precision`` is how far the source rounded each coordinate [m] (the tolerances follow it);
        ``vertex_labels`` the source's own vertex numbers, for messages; ``learned_bounds`` those of a learned
        model's data. Raises :class:`ModelError` naming the
        model and the offending element when the input is not a closed, connected, consistently
        outward-oriented 2-manifold with planar, non-degenerate faces that do not cross each other.
        """
        where = source or name
        try:
            v = np.array(vertices, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ModelError(f"{where}: vertices are not a list of [x, y, z] numbers ({exc})") from None
        if v.ndim != 2 or v.shape[1] != 3 or len(v) < 4:
            raise ModelError(f"{where}: vertices must be a list of at least 4 [x, y, z] triples, got shape {v.shape}")
        bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
        if len(bad):
            raise ModelError(f"{where}: vertex {bad[0]} has a non-finite coordinate {v[bad[0]].tolist()}")
        labels = None if vertex_labels is None else tuple(str(x) for x in vertex_labels)
        loops: list[tuple[int, ...]] = []
        for fi, f in enumerate(faces):
            try:
                items = list(f)
            except TypeError:
                raise ModelError(f"{where}: face {fi} is not a list of vertex indices: {f!r}") from None
            for i in items:
                if isinstance(i, bool) or not isinstance(i, int | np.integer):
                    raise ModelError(
                        f"{where}: face {fi} has vertex index {i!r}, which is not an integer "
                        f"(valid: whole numbers 0..{len(v) - 1})"
                    )
            loop = tuple(int(i) for i in items)
            if len(loop) < 3:
                raise ModelError(f"{where}: face {fi} has {len(loop)} vertices; a face needs at least 3")
            if len(set(loop)) != len(loop):
                raise ModelError(f"{where}: face {fi} repeats a vertex in its loop {list(loop)}")
            if min(loop) < 0 or max(loop) >= len(v):
                raise ModelError(f"{where}: face {fi} names a vertex outside 0..{len(v) - 1}: {list(loop)}")
            loops.append(loop)
        if len(loops) < 4:
            raise ModelError(f"{where}: a closed polyhedron needs at least 4 faces, got {len(loops)}")
        return cls(
            name=name, vertices=_readonly(v), faces=tuple(loops), source=source, precision=float(precision),
            vertex_labels=labels, learned_bounds=learned_bounds,
        )  # fmt: skip

    def vertex_label(self, i: int) -> str:
        """How messages name vertex ``i``: by the source file's own number when known."""
        return self.vertex_labels[i] if self.vertex_labels is not None else str(i)

    def __post_init__(self) -> None:
        where = self.source or self.name
        v = self.vertices
        set_ = object.__setattr__
        t = Tolerances.for_model(float(np.linalg.norm(np.ptp(v, axis=0))), self.precision)
        set_(self, "tolerances", t)
        lab = self.vertex_label

        seen: dict[frozenset, int] = {}
        for fi, loop in enumerate(self.faces):
            key = frozenset(loop)
            if key in seen:
                raise ModelError(
                    f"{where}: faces {seen[key]} and {fi} are duplicates (same vertices "
                    f"{[lab(i) for i in sorted(key)]})"
                )
            seen[key] = fi

        # edges and their left/right faces from the directed half-edges
        half: dict[tuple[int, int], int] = {}
        for fi, loop in enumerate(self.faces):
            for k, a in enumerate(loop):
                b = loop[(k + 1) % len(loop)]
                if np.linalg.norm(v[a] - v[b]) < t.merge:
                    raise ModelError(
                        f"{where}: face {fi} has a zero-length edge: vertices {lab(a)} and {lab(b)} are the same "
                        f"point (closer than {t.merge * 1e3:.3g} mm)"
                    )
                if (a, b) in half:
                    other = half[(a, b)]
                    undirected = sum(
                        1
                        for lp in self.faces
                        for j, x in enumerate(lp)
                        if {x, lp[(j + 1) % len(lp)]} == {a, b}
                    )
                    if undirected > 2:
                        raise ModelError(
                            f"{where}: edge {lab(a)}-{lab(b)} is non-manifold: {undirected} faces meet on it (a closed "
                            "2-manifold has exactly 2)"
                        )
                    raise ModelError(
                        f"{where}: faces {other} and {fi} both run edge {lab(a)}->{lab(b)} in the same direction: "
                        "inconsistent face orientation (loops must all be counter-clockwise seen from outside)"
                    )
                half[(a, b)] = fi
        edges, left, right, index = [], [], [], {}
        for (a, b), fi in half.items():
            if (b, a) not in half:
                raise ModelError(
                    f"{where}: edge {lab(a)}-{lab(b)} of face {fi} has no second face: the surface is open "
                    "(not watertight)"
                )
            if a < b:
                index[(a, b)] = len(edges)
                edges.append((a, b))
                left.append(fi)
                right.append(half[(b, a)])
        face_edges = tuple(
            tuple(index[(min(a, b), max(a, b))] for a, b in zip(loop, loop[1:] + loop[:1], strict=True))
            for loop in self.faces
        )
        used = np.zeros(len(v), dtype=bool)
        for loop in self.faces:
            used[list(loop)] = True
        if not used.all():
            raise ModelError(f"{where}: vertex {lab(int(np.flatnonzero(~used)[0]))} is used by no face")

        # plane of each face, planarity and area
        # all faces at once: Newell sums and plane offsets accumulate in loop order
        sizes = np.array([len(loop) for loop in self.faces])
        flat = np.concatenate([np.asarray(loop) for loop in self.faces])
        nxt = np.concatenate([np.roll(np.asarray(loop), -1) for loop in self.faces])
        owner = np.repeat(np.arange(len(self.faces)), sizes)
        nn = np.zeros((len(self.faces), 3))
        np.add.at(nn, owner, np.cross(v[flat], v[nxt]))
        norm = np.linalg.norm(nn, axis=1)
        small = np.flatnonzero(0.5 * norm < t.area)
        if len(small):
            fi = int(small[0])
            raise ModelError(f"{where}: face {fi} has zero area (vertices {[lab(i) for i in self.faces[fi]]})")
        normals = nn / norm[:, None]
        along = np.einsum("ij,ij->i", v[flat], normals[owner])
        offsets = np.zeros(len(self.faces))
        np.add.at(offsets, owner, along)
        offsets /= sizes
        off = np.abs(along - offsets[owner])
        dev = np.zeros(len(self.faces))
        np.maximum.at(dev, owner, off)
        bad = np.flatnonzero(dev > t.planar)
        if len(bad):
            fi = int(bad[0])
            worst = int(flat[owner == fi][int(np.argmax(off[owner == fi]))])
            raise ModelError(
                f"{where}: face {fi} is not planar: vertex {lab(worst)} is off its plane by {dev[fi] * 1e3:.4g} mm "
                f"(tolerance {t.planar * 1e3:.3g} mm at this model's size and precision)"
            )
        areas = 0.5 * norm

        set_(self, "face_normals", _readonly(np.array(normals)))
        set_(self, "face_offsets", _readonly(np.array(offsets)))
        set_(self, "face_areas", _readonly(np.array(areas)))
        set_(self, "edges", _readonly(np.array(edges, dtype=int).reshape(-1, 2)))
        set_(self, "edge_left_face", _readonly(np.array(left, dtype=int)))
        set_(self, "edge_right_face", _readonly(np.array(right, dtype=int)))
        set_(self, "face_edges", face_edges)

        # each face's loop a simple polygon: a loop that crosses itself overlaps its own face. A loop turning left
        # at every corner and once round in all is convex, hence simple; the others are tested edge by edge
        prv = np.concatenate([np.roll(np.asarray(loop), 1) for loop in self.faces])
        into, out = v[flat] - v[prv], v[nxt] - v[flat]
        turn = np.arctan2(np.einsum("ij,ij->i", np.cross(into, out), normals[owner]), np.einsum("ij,ij->i", into, out))
        total = np.zeros(len(self.faces))
        np.add.at(total, owner, turn)
        turns_left = np.ones(len(self.faces), dtype=bool)
        np.logical_and.at(turns_left, owner, turn > -1e-9)
        convex = turns_left & (np.abs(total - 2 * np.pi) < 1e-6)
        for fi in map(int, np.flatnonzero(~convex)):
            loop = self.faces[fi]
            crossed = loop_crossing(v, loop, normals[fi], t.planar)
            if crossed is not None:
                (a, b), (c, d) = crossed
                raise ModelError(
                    f"{where}: face {fi} (vertices {[lab(i) for i in loop]}) crosses itself: its edges "
                    f"{lab(a)}-{lab(b)} and {lab(c)}-{lab(d)} intersect; a face's loop must be a simple polygon"
                )

        # coplanar neighbours would be an edge no finger can feel
        for e, (fl, fr) in enumerate(zip(left, right, strict=True)):
            if _coplanar(v, self.faces[fl], normals[fl], offsets[fl], self.faces[fr], normals[fr], offsets[fr], t):
                raise ModelError(
                    f"{where}: faces {fl} and {fr} are coplanar and share edge {lab(edges[e][0])}-{lab(edges[e][1])} "
                    f"(within {t.planar * 1e3:.3g} mm of one plane): merge them into one face"
                )

        # each vertex's faces must form a single fan (no pinched vertices)
        nxt: dict[int, dict[int, int]] = {}
        for loop in self.faces:
            for k, a in enumerate(loop):
                prev = loop[k - 1]
                b = loop[(k + 1) % len(loop)]
                # around vertex a: from half-edge (a,b) of face fi, the next face around a owns (prev... )
                nxt.setdefault(a, {})[b] = prev
        for a, ring in nxt.items():
            start = next(iter(ring))
            cur, count = start, 0
            while True:
                cur = ring[cur]
                count += 1
                if cur == start or count > len(ring):
                    break
            if count != len(ring):
                raise ModelError(
                    f"{where}: vertex {lab(a)} is non-manifold: its faces form more than one fan (a pinch point)"
                )

        # connectivity over faces
        parent = list(range(len(self.faces)))

        def find(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for fl, fr in zip(left, right, strict=True):
            parent[find(fl)] = find(fr)
        roots = {find(i) for i in range(len(self.faces))}
        if len(roots) > 1:
            raise ModelError(f"{where}: the surface is not connected: it has {len(roots)} separate parts")

        try:
            volume = self.volume
        except ModelError as exc:
            raise ModelError(f"{where}: {exc}") from None
        if volume <= 0:
            raise ModelError(
                f"{where}: the faces are oriented inward (signed volume {self.volume:.4g} m^3); loops must be "
                "counter-clockwise seen from outside"
            )
        crossing = self_intersection(self)
        if crossing is not None:
            fa, fb = crossing
            raise ModelError(
                f"{where}: the surface intersects itself: faces {fa} (vertices {[lab(i) for i in self.faces[fa]]}) "
                f"and {fb} (vertices {[lab(i) for i in self.faces[fb]]}) cross; a solid's faces meet only along "
                "shared edges"
            )

    # ------------------------------------------------------------------------------------------ counts

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_edges(self) -> int:
        return len(self.edges)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    @property
    def euler_characteristic(self) -> int:
        """V − E + F (= 2 − 2g for a closed orientable surface)."""
        return self.n_vertices - self.n_edges + self.n_faces

    @property
    def genus(self) -> int:
        """Number of handles (0 for a sphere-like solid, 1 for a frame with a hole)."""
        return (2 - self.euler_characteristic) // 2

    # ------------------------------------------------------------------------------------------ edges

    @cached_property
    def edge_points(self) -> np.ndarray:
        """``p``: the source vertex of each edge, shape (E, 3) [m]."""
        return _readonly(self.vertices[self.edges[:, 0]].copy())

    @cached_property
    def edge_lengths(self) -> np.ndarray:
        """``l``: edge lengths, shape (E,) [m]."""
        return _readonly(np.linalg.norm(self.vertices[self.edges[:, 1]] - self.vertices[self.edges[:, 0]], axis=1))

    @cached_property
    def edge_directions(self) -> np.ndarray:
        """``b``: unit edge directions from source to destination, shape (E, 3)."""
        d = self.vertices[self.edges[:, 1]] - self.vertices[self.edges[:, 0]]
        return _readonly(d / np.linalg.norm(d, axis=1)[:, None])

    @cached_property
    def edge_convexity(self) -> np.ndarray:
        """+1 for a convex edge (the surface falls away), −1 for a concave one, shape (E,)."""
        nl = self.face_normals[self.edge_left_face]
        nr = self.face_normals[self.edge_right_face]
        s = np.einsum("ij,ij->i", np.cross(nl, nr), self.edge_directions)
        return _readonly(np.where(s > 0, 1, -1))

    # ------------------------------------------------------------------------------------------ adjacency

    def face_vertices(self, f: int) -> tuple[int, ...]:
        """Vertices of face ``f`` in counter-clockwise order seen from outside."""
        return self.faces[f]

    def edge_faces(self, e: int) -> tuple[int, int]:
        """(left, right) faces of edge ``e``."""
        return int(self.edge_left_face[e]), int(self.edge_right_face[e])

    @cached_property
    def vertex_edges(self) -> tuple[tuple[int, ...], ...]:
        """Edge ids incident on each vertex."""
        out: list[list[int]] = [[] for _ in range(self.n_vertices)]
        for e, (a, b) in enumerate(self.edges):
            out[a].append(e)
            out[b].append(e)
        return tuple(tuple(x) for x in out)

    @cached_property
    def vertex_faces(self) -> tuple[tuple[int, ...], ...]:
        """Face ids incident on each vertex."""
        out: list[list[int]] = [[] for _ in range(self.n_vertices)]
        for f, loop in enumerate(self.faces):
            for a in loop:
                out[a].append(f)
        return tuple(tuple(x) for x in out)

    # ------------------------------------------------------------------------------------------ solid

    @cached_property
    def triangles(self) -> np.ndarray:
        """A triangulation of the faces (ear clipping, so non-convex faces are fine), shape (T, 3)."""
        tris: list[tuple[int, int, int]] = []
        for f, loop in enumerate(self.faces):
            tris.extend(triangulate_polygon(self.vertices, loop, self.face_normals[f]))
        return _readonly(np.array(tris, dtype=int))

    @cached_property
    def triangle_faces(self) -> np.ndarray:
        """Face id of each row of :attr:`triangles`."""
        ids = [f for f, loop in enumerate(self.faces) for _ in range(len(loop) - 2)]
        return _readonly(np.array(ids, dtype=int))

    @cached_property
    def volume(self) -> float:
        """Signed volume (positive when faces point outward) [m^3]."""
        t = self.vertices[self.triangles]
        return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)

    @cached_property
    def centroid(self) -> np.ndarray:
        """Centre of mass of the solid (uniform density) [m]."""
        t = self.vertices[self.triangles]
        vol = np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])) / 6.0
        c = t.sum(axis=1) / 4.0
        return _readonly((vol[:, None] * c).sum(axis=0) / vol.sum())

    @property
    def is_convex(self) -> bool:
        """True when every edge is convex and the solid has no handle."""
        return bool(self.genus == 0 and (self.edge_convexity > 0).all())

    @cached_property
    def extents(self) -> np.ndarray:
        """Axis-aligned bounding box size in the model frame [m]."""
        return _readonly(self.vertices.max(axis=0) - self.vertices.min(axis=0))

    @cached_property
    def _box(self) -> tuple[np.ndarray, np.ndarray]:
        """The axis-aligned bounding box ``(lo, hi)`` of the vertices, model frame [m]."""
        return _readonly(self.vertices.min(axis=0)), _readonly(self.vertices.max(axis=0))

    def contains(self, points: np.ndarray) -> np.ndarray:
        """Inside test by the generalised winding number (robust for any closed oriented surface); points outside
        the bounding box are outside without it (their winding number is 0)."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        lo, hi = self._box
        boxed = ((p >= lo) & (p <= hi)).all(axis=1)
        if boxed.all():
            return self._winding_inside(p)
        out = np.zeros(len(p), dtype=bool)
        if boxed.any():
            out[boxed] = self._winding_inside(p[boxed])
        return out

    def _winding_inside(self, p: np.ndarray) -> np.ndarray:
        """Whether each point (P, 3) has a generalised winding number over 1/2, (P,) bool."""
        t = self.vertices[self.triangles]  # (T,3,3)
        a = t[None, :, 0, :] - p[:, None, :]
        b = t[None, :, 1, :] - p[:, None, :]
        c = t[None, :, 2, :] - p[:, None, :]
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        num = np.einsum("ptk,ptk->pt", a, np.cross(b, c))
        den = (
            la * lb * lc
            + np.einsum("ptk,ptk->pt", a, b) * lc
            + np.einsum("ptk,ptk->pt", b, c) * la
            + np.einsum("ptk,ptk->pt", c, a) * lb
        )
        w = 2.0 * np.arctan2(num, den).sum(axis=1) / (4.0 * np.pi)
        return w > 0.5

    # ------------------------------------------------------------------------------------------ transforms

    def transformed(self, rotation: np.ndarray, translation: np.ndarray, name: str | None = None) -> Polyhedron:
        """The same solid with vertices mapped by ``w' = R w + t`` (R a proper rotation)."""
        v = self.vertices @ np.asarray(rotation).T + np.asarray(translation)
        return Polyhedron.from_faces(
            v, self.faces, name=name or self.name, source=self.source, precision=self.precision,
            vertex_labels=self.vertex_labels, learned_bounds=self.learned_bounds,
        )  # fmt: skip

    def mirrored(self, name: str | None = None) -> Polyhedron:
        """The mirror image through the x = 0 plane (face loops reversed to stay outward)."""
        v = self.vertices * np.array([-1.0, 1.0, 1.0])
        faces = [tuple(reversed(loop)) for loop in self.faces]
        return Polyhedron.from_faces(
            v, faces, name=name or f"{self.name}_mirror", source=self.source, precision=self.precision,
            vertex_labels=self.vertex_labels, learned_bounds=self.learned_bounds,
        )  # fmt: skip

    def to_trimesh(self):
        """A triangulated :class:`trimesh.Trimesh` with outward winding (for export and simulation)."""
        import trimesh

        return trimesh.Trimesh(vertices=np.array(self.vertices), faces=np.array(self.triangles), process=False)

    def __repr__(self) -> str:
        return f"Polyhedron({self.name!r}, V={self.n_vertices}, E={self.n_edges}, F={self.n_faces})"


def triangulate_polygon(
    vertices: np.ndarray, loop: tuple[int, ...], normal: np.ndarray, min_area: float = 5e-19
) -> list[tuple[int, int, int]]:
    """Ear-clip a simple planar polygon (CCW about ``normal``) into triangles of vertex ids.

    Corners whose triangle has less than ``min_area`` [m^2] count as straight (never clipped): with rounded
    coordinates, pass the model's area tolerance so that no sliver ear is cut.
    """
    if len(loop) == 3:
        return [(loop[0], loop[1], loop[2])]
    u, w = plane_basis(normal)
    pts = {i: np.array([vertices[i] @ u, vertices[i] @ w]) for i in loop}
    idx = list(loop)
    out: list[tuple[int, int, int]] = []

    def cross2(o, a, b) -> float:
        return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))

    guard = 0
    while len(idx) > 3 and guard < 10 * len(loop) ** 2:
        guard += 1
        m = len(idx)
        for k in range(m):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % m]
            a, b, c = pts[i0], pts[i1], pts[i2]
            if cross2(a, b, c) <= 2 * min_area:
                continue  # reflex or collinear corner
            inside = False
            for j in idx:
                if j in (i0, i1, i2):
                    continue
                p = pts[j]
                if cross2(a, b, p) >= 0 and cross2(b, c, p) >= 0 and cross2(c, a, p) >= 0:
                    inside = True
                    break
            if not inside:
                out.append((i0, i1, i2))
                idx.pop(k)
                break
        else:
            raise ModelError(f"face loop {list(loop)} is self-intersecting or not simple: cannot triangulate")
    out.append((idx[0], idx[1], idx[2]))
    return out


def loop_crossing(
    vertices: np.ndarray, loop: tuple[int, ...], normal: np.ndarray, eps: float
) -> tuple[tuple[int, int], tuple[int, int]] | None:
    """Two edges of face loop ``loop`` (not neighbours in it) that meet, seen along ``normal``, or ``None`` for
    a simple polygon. Edges that come within ``eps`` [m] of each other's line count as meeting only where
    each passes more than ``eps`` beyond the other's ends' sides, so rounding in a source does not."""
    m = len(loop)
    if m < 4:
        return None
    u, w = plane_basis(normal)
    q = np.asarray(vertices)[list(loop)]
    pts = np.stack([q @ u, q @ w], axis=1)
    a, b = pts, np.roll(pts, -1, axis=0)
    i, j = np.triu_indices(m, k=2)
    keep = ~((i == 0) & (j == m - 1))  # the loop's last edge neighbours its first
    i, j = i[keep], j[keep]
    if len(i) == 0:
        return None

    def side(p0, p1, x):
        d = p1 - p0
        length = np.maximum(np.linalg.norm(d, axis=1), 1e-300)
        return (d[:, 0] * (x[:, 1] - p0[:, 1]) - d[:, 1] * (x[:, 0] - p0[:, 0])) / length

    s1, s2 = side(a[i], b[i], a[j]), side(a[i], b[i], b[j])
    s3, s4 = side(a[j], b[j], a[i]), side(a[j], b[j], b[i])
    hit = (((s1 > eps) & (s2 < -eps)) | ((s1 < -eps) & (s2 > eps))) & (
        ((s3 > eps) & (s4 < -eps)) | ((s3 < -eps) & (s4 > eps))
    )
    # a vertex of one edge lying on the other (within eps, between its ends) meets it too
    for (p0, p1), (x0, x1) in (((a[i], b[i]), (a[j], b[j])), ((a[j], b[j]), (a[i], b[i]))):
        d = p1 - p0
        length2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
        for x in (x0, x1):
            t_ = np.einsum("ij,ij->i", x - p0, d) / length2
            off = np.abs(side(p0, p1, x))
            reach = eps / np.sqrt(length2)
            hit |= (off <= eps) & (t_ > reach) & (t_ < 1 - reach)
    if not hit.any():
        return None
    k = int(np.flatnonzero(hit)[0])
    e1, e2 = int(i[k]), int(j[k])
    return (loop[e1], loop[(e1 + 1) % m]), (loop[e2], loop[(e2 + 1) % m])


def _coplanar(v: np.ndarray, loop_a, n_a, d_a, loop_b, n_b, d_b, t: Tolerances) -> bool:
    """True when two faces lie in one plane as far as the model's precision can tell.

    Either their planes agree (normals within ``t.angle``, offsets within ``t.planar``), or each face's
    vertices lie within ``t.planar`` of the other's plane: a bend no larger than the rounding of the
    coordinates can explain.
    """
    cos = float(np.dot(n_a, n_b))
    if cos > np.cos(t.angle) and abs(d_a - d_b) < t.planar:
        return True
    if cos <= 0:
        return False
    return bool(
        np.abs(v[list(loop_b)] @ n_a - d_a).max() <= t.planar and np.abs(v[list(loop_a)] @ n_b - d_b).max() <= t.planar
    )


def self_intersection(poly: Polyhedron) -> tuple[int, int] | None:
    """Two faces that cross each other (an edge of one passes through the inside of the other), or ``None``.

    Triangles of different faces whose bounding boxes overlap and that share no edge are tested: an edge of
    either must not pass through the other's interior by more than the planar tolerance.
    """
    tris = poly.triangles
    if len(tris) == 0:
        return None
    faces = poly.triangle_faces
    eps = poly.tolerances.planar
    p = poly.vertices[tris]  # (T, 3, 3)
    lo, hi = p.min(axis=1) - eps, p.max(axis=1) + eps
    # sweep along x: each triangle against those starting (in x) before it ends
    order = np.argsort(lo[:, 0], kind="stable")
    lo, hi, p, tris, faces = lo[order], hi[order], p[order], tris[order], faces[order]
    stop = np.searchsorted(lo[:, 0], hi[:, 0], side="right")
    count = np.maximum(stop - np.arange(len(tris)) - 1, 0)
    i = np.repeat(np.arange(len(tris)), count)
    j = i + 1 + (np.arange(len(i)) - np.repeat(np.cumsum(count) - count, count))
    ok = (lo[i, 1:] <= hi[j, 1:]).all(axis=1) & (hi[i, 1:] >= lo[j, 1:]).all(axis=1) & (faces[i] != faces[j])
    i, j = i[ok], j[ok]
    if len(i) == 0:
        return None
    shared = (tris[i][:, :, None] == tris[j][:, None, :]).sum(axis=(1, 2))
    keep = shared < 2
    i, j = i[keep], j[keep]
    hit = np.zeros(len(i), dtype=bool)
    for a, b in ((i, j), (j, i)):
        for k in range(3):
            hit |= _segment_crosses(p[a, k], p[a, (k + 1) % 3], p[b], eps)
    if not hit.any():
        return None
    first = int(np.flatnonzero(hit)[0])
    fa, fb = sorted((int(faces[i[first]]), int(faces[j[first]])))
    return fa, fb


def _segment_crosses(s0: np.ndarray, s1: np.ndarray, tri: np.ndarray, eps: float) -> np.ndarray:
    """Per row: does segment ``s0→s1`` pass through the interior of triangle ``tri`` (rows of 3 points)?"""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    nn = np.cross(b - a, c - a)
    nn /= np.maximum(np.linalg.norm(nn, axis=1), 1e-300)[:, None]
    h0 = np.einsum("ij,ij->i", s0 - a, nn)
    h1 = np.einsum("ij,ij->i", s1 - a, nn)
    crosses = ((h0 > eps) & (h1 < -eps)) | ((h0 < -eps) & (h1 > eps))
    x = s0 + (h0 / np.where(crosses, h0 - h1, 1.0))[:, None] * (s1 - s0)
    inside = crosses
    for u, w in ((a, b), (b, c), (c, a)):
        edge = w - u
        side = np.einsum("ij,ij->i", np.cross(edge, x - u), nn) / np.maximum(np.linalg.norm(edge, axis=1), 1e-300)
        inside &= side > eps
    return inside
