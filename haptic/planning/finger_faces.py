"""Probes by another finger, or a tilted one, at the faces a verification needs and the index pointing down cannot
press: the faces of a vertex resting on the table whose place on it nothing in the pad's reach gives
(:func:`~haptic.planning.verify.table_pins`).

The verification's reach (:func:`~haptic.planning.verify.reachable_features`) is the index finger's, pointing down:
a face leaning under at a table vertex (an octahedron on a face, a bipyramid on its side) is out of it, and so is
the vertex's place on the table, which two of its faces' planes would give. Another finger, the thumb turned level,
or the index tilted toward the face can press such a face (measured within 0.2° on trapezohedron_05 of the formula
corpus). Here, for each such face, lines that a probe may follow to it (:func:`table_face_lines`): level, toward the
face, ending past a pad position near the vertex where the pad touches that face alone, clear of the table. Which
finger, if any, carries a line out, and the hand's way there, is the reach solver's answer
(``PlannerConfig.finger_reach``: the hand's, with the hypothesised model at its pose); the verification asks it
line by line (:meth:`~haptic.planning.verify.Verifier.choose`) and ends naming the faces no finger reaches.

The same probes measure the faces of a vertex off the table that no move touches (:class:`CornerProbes`), each within
its corner at the vertex (:func:`corner_lines`): every one of its faces measured there places it
(:func:`~haptic.matching.acceptance.placed_near`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from haptic.geometry.distance import surface_distance
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3, plane_basis
from haptic.geometry.tracing import inside_polygon
from haptic.matching.acceptance import corner_spans, corner_triangle, in_corner
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import ProbeMove

GRID = 0.002
"""Pad positions are weighed on a grid of this spacing over the face [m]."""
ON_FACE = 1e-4
"""A grid point within this of the surface is on it [m]."""
PAD_ALONE = 3e-4
"""Slack of the pad's clearance of the rest of the object at a pad position [m]."""
RUN_UP = 0.03
"""A line starts this far before the pad touches its face ..."""
RUN_ON = 0.02
"""... and goes on this far past it (a miss measures the face absent there) [m]."""
POSITIONS = 3
"""Pad positions tried per face, the nearest the vertex first, each a line (the reach solver's answer differs from
one to the next where the object is in the hand's way)."""
MIN_ROOM = 0.0035
"""Pad positions with less room than this to the face's rim are not weighed [m]: the stroke that measures the face
must span 3 mm along its principal axis and 1.5 mm across (``SegmentBounds.min_face_extent``, ``min_face_width``);
the pad travels about half the L it is commanded (:data:`haptic.executor.placement.STROKE_REACH`), an L kept within
twice the room (:func:`haptic.executor.placement.stroke_within`), and a travel of 3.5 mm along its diagonal stays on
the face with this much room about its start."""
ROOM = 0.008
"""A pad position whose contact is at least this far from the face's rim is preferred [m]: the probe's stroke runs
8 mm level along the face (:data:`haptic.executor.placement.PROBE_SETTINGS`), and one that leaves the face over an
edge measures none (the first pad positions taken, nearest the vertex, were 2-4 mm from an edge, and the stroke found
no face in 8 of 18 probes of the formula corpus's table vertices)."""
SPREAD = 0.004
"""Pad positions of one face at least this far apart [m]."""


def faces_to_probe(poly: Polyhedron, world_from_model: SE3, vertices: Iterable[int], measured: frozenset[int],
                   config: PlannerConfig) -> list[tuple[int, int]]:  # fmt: skip
    """The faces at ``vertices`` (resting on the table) that are off the table and not ``measured``, each with its
    vertex: (vertex, face), in the order of ``vertices``, each face once."""
    if config.table_z is None:
        return []
    z = world_from_model.apply(poly.vertices)[:, 2] - config.table_z
    out: list[tuple[int, int]] = []
    seen: set[int] = set()
    for v in vertices:
        for f in (int(f) for f in poly.vertex_faces[int(v)]):
            loop = list(poly.faces[f])
            if f in measured or f in seen or np.all(z[loop] <= config.table_clearance):
                continue
            seen.add(f)
            out.append((int(v), f))
    return out


def pad_positions(poly: Polyhedron, world_from_model: SE3, v: int, f: int, config: PlannerConfig) -> np.ndarray:
    """Points of face ``f`` (world frame) where the pad touching it touches that face alone (its centre a pad's radius
    from the rest of the object, outside it), with :data:`MIN_ROOM` to the face's rim, and its lowest point stays
    ``config.table_clearance`` above the table;
    those with :data:`ROOM` to the face's rim first, then the nearest vertex ``v`` first. Anywhere on the face: its
    plane is what places the vertex, and a face leaning under is pressed clear of the table only well above it (the
    pad's lowest point lies ``r (1 + sin lean)`` under its contact)."""
    r = config.pad_radius
    inv = world_from_model.inverse()
    n = world_from_model.rotate(poly.face_normals[f])
    vw = world_from_model.apply(poly.vertices[v])
    a = np.cross(n, [1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.cross(n, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    corners = world_from_model.apply(poly.vertices[list(poly.faces[f])]) - vw
    ga = np.arange(float((corners @ a).min()), float((corners @ a).max()) + 1e-9, GRID)
    gb = np.arange(float((corners @ b).min()), float((corners @ b).max()) + 1e-9, GRID)
    x, y = np.meshgrid(ga, gb, indexing="ij")
    pts = vw + x.reshape(-1, 1) * a + y.reshape(-1, 1) * b
    if config.table_z is not None:
        pts = pts[pts[:, 2] + r * n[2] - r - config.table_z >= config.table_clearance]
    if not len(pts):
        return pts
    pts = pts[surface_distance(poly, inv.apply(pts)) < ON_FACE]
    if not len(pts):
        return pts
    centres = inv.apply(pts + r * n)
    keep = (surface_distance(poly, centres) >= r - PAD_ALONE) & ~poly.contains(centres)
    pts = pts[keep]
    room = _rim_distance(pts, world_from_model.apply(poly.vertices[list(poly.faces[f])]))
    pts, room = pts[room >= MIN_ROOM], np.minimum(room[room >= MIN_ROOM], ROOM)
    return pts[np.lexsort((np.linalg.norm(pts - vw, axis=1), -np.round(room, 4)))]


def _rim_distance(pts: np.ndarray, loop: np.ndarray) -> np.ndarray:
    """Distance of each of ``pts`` from the closed polygon ``loop``'s sides [m], shape (P,)."""
    best = np.full(len(pts), np.inf)
    for a, b in zip(loop, np.roll(loop, -1, axis=0), strict=True):
        d = b - a
        t = np.clip((pts - a) @ d / max(float(d @ d), 1e-18), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(pts - a - t[:, None] * d, axis=1))
    return best


def face_line(world_from_model: SE3, poly: Polyhedron, f: int, pad_point: np.ndarray, r: float,
              rim: np.ndarray | None = None, config: PlannerConfig | None = None) -> ProbeMove:  # fmt: skip
    """A probe line to the pad touching face ``f`` at ``pad_point`` (world): level toward the face (along its inward
    normal when the face is level), starting :data:`RUN_UP` before the touch and ending :data:`RUN_ON` past it; its
    ``room`` the point's distance to the face's rim (to the polygon ``rim``, world frame, where given: the stroke
    kept within it); with ``config``, on a face steep enough for the probe's level stroke, how far the pad can slide
    level either way and (``room_up``) up from there touching the face alone (:func:`slide_room`)."""
    n = world_from_model.rotate(poly.face_normals[f])
    u = -n * np.array([1.0, 1.0, 0.0])
    u = u / np.linalg.norm(u) if float(np.linalg.norm(u)) > 0.1 else -n
    p = np.asarray(pad_point, dtype=float)
    centre = p + r * n
    if rim is None:
        rim = world_from_model.apply(poly.vertices[list(poly.faces[f])])
    room = float(_rim_distance(p[None], rim)[0])
    room_up = None
    level = np.cross(np.array([0.0, 0.0, 1.0]), n)
    if config is not None and float(level @ level) > LEVEL_STROKE:  # the probe's stroke runs level, then up
        level = level / np.linalg.norm(level)
        up = np.cross(n, level)
        up = up if up[2] >= 0.0 else -up
        room = min(slide_room(poly, world_from_model, f, p, d, rim, config) for d in (level, -level))
        room_up = slide_room(poly, world_from_model, f, p, up, rim, config)
    return ProbeMove(centre + (r - RUN_UP) * u, u, RUN_UP + RUN_ON, room=room, room_up=room_up)


LEVEL_STROKE = 0.25
"""A probe's L runs level along a face, then up it, where ``|z × n|²`` exceeds this (the face leans under 60° from
horizontal, at least: ``PlacementSettings.level_stroke``, :func:`haptic.executor.placement._stroke`) [-]."""
SLIDE_MOST = 0.012
"""How far :func:`slide_room` looks [m]: past the probe's longest leg (8 mm)."""


def slide_room(poly: Polyhedron, world_from_model: SE3, f: int, pad_point: np.ndarray, d: np.ndarray,
               rim: np.ndarray, config: PlannerConfig) -> float:  # fmt: skip
    """How far the pad touching face ``f`` at ``pad_point`` (world) can slide along ``d`` (unit, in the face's plane)
    and still touch that face alone, within the polygon ``rim`` and its lowest point clear of the table (the tests of
    :func:`pad_positions`), in steps of :data:`GRID` up to :data:`SLIDE_MOST` [m]. The rim's distance alone does not
    say it: beside a concave edge the pad meets the face across a pad's radius before its contact reaches the edge
    (the back wall of BOX01N's slot at seed 1, 30 mm tall: a stroke 7.5 mm up from a contact 8 mm from the corner's
    side climbed the slot's floor)."""
    r = config.pad_radius
    n = world_from_model.rotate(poly.face_normals[f])
    a, b = plane_basis(n)
    loop2 = np.column_stack([(rim - pad_point) @ a, (rim - pad_point) @ b])
    inv = world_from_model.inverse()
    steps = np.arange(GRID, SLIDE_MOST + 1e-9, GRID)
    pts = np.asarray(pad_point, dtype=float) + steps[:, None] * np.asarray(d, dtype=float)
    centres = pts + r * n
    ok = (surface_distance(poly, inv.apply(centres)) >= r - PAD_ALONE) & ~poly.contains(inv.apply(centres))
    if config.table_z is not None:
        ok &= centres[:, 2] - r - config.table_z >= config.table_clearance
    ok &= np.array([inside_polygon(np.array([float((q - pad_point) @ a), float((q - pad_point) @ b)]), loop2)
                    for q in pts])  # fmt: skip
    bad = np.flatnonzero(~ok)
    return float(steps[bad[0]] - GRID) if len(bad) else SLIDE_MOST


def table_face_lines(poly: Polyhedron, world_from_model: SE3, v: int, f: int, config: PlannerConfig,
                     most: int = POSITIONS) -> list[ProbeMove]:  # fmt: skip
    """Up to ``most`` probe lines (:func:`face_line`) to face ``f`` near vertex ``v``, at pad positions
    (:func:`pad_positions`) at least :data:`SPREAD` apart, the nearest the vertex first; none where the pad cannot
    touch the face alone clear of the table."""
    return _spread_lines(poly, world_from_model, f, pad_positions(poly, world_from_model, v, f, config), config, most)


MIN_LEVEL_ROOM = 0.0035
"""A line whose pad can slide level less than this either way touching its face alone is not weighed [m]: the level
leg must span 3 mm (``SegmentBounds.min_face_extent``) ..."""
MIN_UP_ROOM = 0.002
"""... and one whose pad can slide up less than this (:data:`haptic.executor.placement.STROKE_ACROSS_MIN`: 1.5 mm
across the face, and the servo's lag) [m]."""


def _spread_lines(poly: Polyhedron, world_from_model: SE3, f: int, positions: np.ndarray, config: PlannerConfig,
                  most: int, rim: np.ndarray | None = None) -> list[ProbeMove]:  # fmt: skip
    """Lines (:func:`face_line`) to face ``f`` at the first of ``positions`` at least :data:`SPREAD` apart whose
    stroke has room on the face (where it runs level, then up: :data:`MIN_LEVEL_ROOM`, :data:`MIN_UP_ROOM`), up to
    ``most``."""
    picked: list[np.ndarray] = []
    lines: list[ProbeMove] = []
    for p in positions:
        if len(lines) >= most or not all(float(np.linalg.norm(p - q)) >= SPREAD for q in picked):
            continue
        line = face_line(world_from_model, poly, f, p, config.pad_radius, rim, config)
        if line.room_up is not None and (line.room < MIN_LEVEL_ROOM or line.room_up < MIN_UP_ROOM):
            continue
        picked.append(p)
        lines.append(line)
    return lines


def _first_reached(probes, lines: list[ProbeMove], key, h, avoid: Sequence[str] = ()) -> ProbeMove | None:
    """The first of ``lines`` (taken off the list as asked) that ``probes``' reach test reaches in hypothesis ``h``'s
    world, booked as ``probes``' pending probe of ``key`` with its finger; None when none is reached. With
    ``avoid``, the reach test is asked for a finger other than those first, then for any."""
    while lines:
        line = lines.pop(0)
        probes.asked += 1
        got = probes.reach(line, [h], avoid=tuple(avoid)) if avoid else None
        if got is None:
            got = probes.reach(line, [h])
        if got is not None:
            probes.pending = got
            probes.probed[key] = probes.probed.get(key, 0) + 1
            probes.fingers[str(got.finger)] = probes.fingers.get(str(got.finger), 0) + 1
            return got
    return None


@dataclass
class TableFaceProbes:
    """The verification's probes of the faces at table vertices that nothing in the pad's reach places, by whichever
    finger the hand's reach test (``reach``, ``PlannerConfig.finger_reach``) finds for each line: each face's lines
    (:func:`table_face_lines`) asked in turn until one is reached, that probe made; a face measured leaves the list,
    one not measured has its next line asked; a face none of whose lines any finger reaches is named as such."""

    reach: Callable
    """The reach test: (probe line, hypotheses) -> the probe with its finger and path, or None."""
    lines: dict[int, list[ProbeMove]] = field(default_factory=dict)
    """Each face's lines not asked yet (filled the first time the face is weighed)."""
    no_finger: list[int] = field(default_factory=list)
    """Faces none of whose lines any finger reaches, in the order found."""
    no_position: list[int] = field(default_factory=list)
    """Faces the pad cannot touch alone clear of the table anywhere (no line), in the order found."""
    probed: dict[int, int] = field(default_factory=dict)
    """Probes made per face."""
    fingers: dict[str, int] = field(default_factory=dict)
    """Probes made per finger."""
    asked: int = 0
    """Lines the reach test was asked about."""
    pending: ProbeMove | None = None
    """The probe chosen for the next verification move (None: none)."""

    def next(self, h, vertices: Sequence[int], measured: frozenset[int], config: PlannerConfig) -> ProbeMove | None:
        """The next probe for hypothesis ``h`` (a pose) at the faces of table ``vertices`` not ``measured``, kept as
        :attr:`pending`; None when every such face's lines are used up."""
        self.pending = None
        for v, f in faces_to_probe(h.poly, h.world_from_model, vertices, measured, config):
            if f not in self.lines:
                self.lines[f] = table_face_lines(h.poly, h.world_from_model, v, f, config)
                if not self.lines[f]:
                    self.no_position.append(f)
                    continue
            got = _first_reached(self, self.lines[f], f, h)
            if got is not None:
                return got
            if f not in self.probed and f not in self.no_finger and f not in self.no_position:
                self.no_finger.append(f)
        return None

    def take(self) -> ProbeMove | None:
        """The pending probe, once."""
        move, self.pending = self.pending, None
        return move

    def unmeasured(self, vertices: Sequence[int], h, measured: frozenset[int], config: PlannerConfig) -> str:
        """Why the faces at ``vertices`` are still not measured, in words ("" when no probe was weighed)."""
        left = {f for _, f in faces_to_probe(h.poly, h.world_from_model, vertices, measured, config)}
        none = sorted(f for f in self.no_finger if f in left)
        room = sorted(f for f in self.no_position if f in left)
        missed = sorted(f for f in self.probed if f in left)
        parts = []
        if room:
            parts.append(f"the pad touches face{'s' if len(room) > 1 else ''} {', '.join(map(str, room))} nowhere "
                         "clear of the table with room for a stroke")  # fmt: skip
        if none:
            parts.append(f"no finger reaches face{'s' if len(none) > 1 else ''} {', '.join(map(str, none))}")
        if missed:
            parts.append(f"face{'s' if len(missed) > 1 else ''} {', '.join(map(str, missed))} probed and not "
                         "measured")  # fmt: skip
        return "; ".join(parts)

    def record(self) -> dict:
        """What the probes did: lines asked, probes per finger, faces probed and faces no finger reaches."""
        return {"asked": self.asked, "fingers": dict(self.fingers), "faces_probed": len(self.probed),
                "no_finger": list(self.no_finger), "no_position": list(self.no_position)}  # fmt: skip


def corner_positions(poly: Polyhedron, world_from_model: SE3, v: int, f: int, config: PlannerConfig) -> np.ndarray:
    """Pad positions of face ``f`` (:func:`pad_positions`, world frame) within its corner at vertex ``v``
    (:func:`~haptic.matching.acceptance.corner_triangle`) with :data:`MIN_ROOM` to the corner's sides, so that the
    stroke measures the corner alone; those with :data:`ROOM` first, then the nearest ``v``. None where the face's
    corner at ``v`` is reflex."""
    tri = corner_triangle(poly, v, f)
    pts = pad_positions(poly, world_from_model, v, f, config)
    if tri is None or not len(pts):
        return np.zeros((0, 3))
    room = _rim_distance(pts, world_from_model.apply(tri))
    inside = in_corner(world_from_model.inverse().apply(pts), tri, poly.face_normals[f])
    keep = inside & (room >= MIN_ROOM)
    pts, room = pts[keep], np.minimum(room[keep], ROOM)
    vw = world_from_model.apply(poly.vertices[v])
    return pts[np.lexsort((np.linalg.norm(pts - vw, axis=1), -np.round(room, 4)))]


def corner_lines(poly: Polyhedron, world_from_model: SE3, v: int, f: int, config: PlannerConfig,
                 most: int = POSITIONS) -> list[ProbeMove]:  # fmt: skip
    """Up to ``most`` probe lines (:func:`face_line`) to face ``f`` within its corner at vertex ``v``
    (:func:`corner_positions`), at least :data:`SPREAD` apart, each line's room that to the corner's sides; none
    where the pad cannot touch the face alone there clear of the table with room for a stroke."""
    tri = corner_triangle(poly, v, f)
    rim = world_from_model.apply(tri) if tri is not None else None
    return _spread_lines(poly, world_from_model, f, corner_positions(poly, world_from_model, v, f, config), config,
                         most, rim)  # fmt: skip


@dataclass
class CornerProbes:
    """The verification's probes at the corners of the vertices out of the hand's reach off the table
    (:func:`~haptic.planning.verify.hidden_vertices`): such a vertex is placed when every one of its faces is measured
    within its corner at the vertex (:func:`~haptic.matching.acceptance.placed_near`). Each face left is probed along
    lines within its corner (:func:`corner_lines`) by whichever finger the hand's reach test (``reach``,
    ``PlannerConfig.finger_reach``) finds for each line, asked in turn until one is reached. Nothing is probed unless
    every such vertex could be placed (its faces span space, each of its edges or the edge's other end is measured,
    and each face left has a line): a vertex that cannot be leaves the verification incomplete whatever the others
    measure. The probes stop at the first (vertex, face) whose lines are used up unmeasured."""

    reach: Callable
    """The reach test: (probe line, hypotheses) -> the probe with its finger and path, or None."""
    lines: dict[tuple[int, int], list[ProbeMove]] = field(default_factory=dict)
    """Each (vertex, face)'s lines not asked yet (filled the first time it is weighed)."""
    no_position: list[tuple[int, int]] = field(default_factory=list)
    """(vertex, face) where the pad cannot touch the face within its corner, in the order found."""
    used_up: list[tuple[int, int]] = field(default_factory=list)
    """(vertex, face) whose lines were all asked and the face is still not measured there, in the order found."""
    too_few: list[int] = field(default_factory=list)
    """Vertices whose faces are fewer than three or do not span space (:func:`corner_spans`)."""
    open_edges: list[int] = field(default_factory=list)
    """Vertices with an edge of which neither the edge nor its other end is measured (a chamfer of it would not be
    seen: :func:`~haptic.matching.acceptance.placed_near`)."""
    probed: dict[tuple[int, int], int] = field(default_factory=dict)
    """Probes made per (vertex, face)."""
    tried: dict[tuple[int, int], list[str]] = field(default_factory=dict)
    """The fingers of the probes made per (vertex, face): while it is still to measure, each measured nothing there,
    and the next line is asked of another finger first (trapezohedron_08 of the formula corpus, seed 1: the index,
    level toward a kite rising 12°, stroked 0.6-1.2 mm across it at three pad positions, under the 1.5 mm a face's
    stroke must span, where the thumb stroked 2.2 mm and measured it)."""
    fingers: dict[str, int] = field(default_factory=dict)
    """Probes made per finger."""
    asked: int = 0
    """Lines the reach test was asked about."""
    pending: ProbeMove | None = None
    """The probe chosen for the next verification move (None: none)."""

    def next(self, h, todo: Mapping[int, frozenset[int]], edges: frozenset[int], vertices: frozenset[int],
             config: PlannerConfig, placing: bool = True) -> ProbeMove | None:  # fmt: skip
        """The next probe for hypothesis ``h`` (a pose): ``todo`` maps each vertex out of reach to its faces not yet
        measured within their corner at it; ``edges`` and ``vertices``: the model edges and vertices measured. Kept
        as :attr:`pending`; None when some vertex cannot be placed (too few faces, an edge at it with neither
        itself nor its other end measured, a face with no line within its corner: each named) or the lines of a
        face left are used up. With ``placing`` False the probes serve the table's shadow
        (:meth:`~haptic.planning.verify.Verifier._shadow_probe_next`: ``todo`` holds the corners rising out of
        it), which asks neither that the faces span space nor anything of the edges: only a line within each
        corner."""
        self.pending = None
        blocked = False
        for v, faces in todo.items():
            if placing and not corner_spans(h.poly, v):
                blocked = True
                if v not in self.too_few:
                    self.too_few.append(v)
                continue
            if placing and not all(int(e) in edges or int(sum(h.poly.edges[int(e)])) - v in vertices
                                   for e in h.poly.vertex_edges[v]):  # fmt: skip
                blocked = True
                if v not in self.open_edges:
                    self.open_edges.append(v)
            for f in sorted(faces):
                if (v, f) not in self.lines:
                    self.lines[(v, f)] = corner_lines(h.poly, h.world_from_model, v, f, config)
                    if not self.lines[(v, f)]:
                        self.no_position.append((v, f))
                blocked |= (v, f) in self.no_position
        if blocked:
            return None
        for v, faces in todo.items():
            for f in sorted(faces):
                key = (v, f)
                got = _first_reached(self, self.lines[key], key, h, self.tried.get(key, ()))
                if got is not None:
                    self.tried.setdefault(key, []).append(str(got.finger))
                    return got
                if key not in self.used_up:
                    self.used_up.append(key)
                return None
        return None

    def take(self) -> ProbeMove | None:
        """The pending probe, once."""
        move, self.pending = self.pending, None
        return move

    def unmeasured(self, vertices: Sequence[int]) -> str:
        """Why ``vertices`` (out of reach, not placed) are not placed by their faces' corners, in words ("" when no
        probe was weighed for them)."""
        left = set(int(v) for v in vertices)
        parts = []
        few = [v for v in self.too_few if v in left]
        if few:
            parts.append(f"fewer than three faces spanning space at {'vertices' if len(few) > 1 else 'vertex'} "
                         f"{', '.join(map(str, few))}")  # fmt: skip
        open_ = [v for v in self.open_edges if v in left]
        if open_:
            at = "each of vertices" if len(open_) > 1 else "vertex"
            parts.append(f"an edge at {at} {', '.join(map(str, open_))} with neither itself nor its other end "
                         "measured")  # fmt: skip
        room = [f"{f} at {v}" for v, f in self.no_position if v in left]
        if room:
            parts.append(f"the pad touches face{'s' if len(room) > 1 else ''} {', '.join(room)} nowhere within the "
                         "corner clear of the table with room for a stroke")  # fmt: skip
        none = [f"{f} at {v}" for v, f in self.used_up if v in left and (v, f) not in self.probed]
        if none:
            parts.append(f"no finger reaches face{'s' if len(none) > 1 else ''} {', '.join(none)} within the corner")
        missed = [f"{f} at {v}" for v, f in self.used_up if v in left and (v, f) in self.probed]
        if missed:
            parts.append(f"face{'s' if len(missed) > 1 else ''} {', '.join(missed)} probed and not measured within "
                         "the corner")  # fmt: skip
        return "; ".join(parts)

    def record(self) -> dict:
        """What the probes did: lines asked, probes per finger, corners probed, and the (vertex, face) pairs with no
        pad position or whose lines were used up."""
        return {"asked": self.asked, "fingers": dict(self.fingers), "corners_probed": len(self.probed),
                "no_position": [list(k) for k in self.no_position], "used_up": [list(k) for k in self.used_up],
                "too_few": list(self.too_few), "open_edges": list(self.open_edges)}  # fmt: skip


__all__ = ["GRID", "POSITIONS", "CornerProbes", "TableFaceProbes", "corner_lines", "corner_positions",
           "faces_to_probe", "face_line", "pad_positions", "table_face_lines"]
