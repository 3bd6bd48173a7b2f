"""The ideal-sensor executor: the seed's "simulated sensor move execution module" (§2.5).

Given the true model and its pose, a move's outcome is computed exactly with :mod:`haptic.geometry.tracing` in
the model frame, mapped to the world, then perturbed by the sensor-noise model (:class:`SensorNoise`): a
normal or an edge direction is turned by a random angle, positions are offset perpendicular to their
component, interval ends along their edge. Each draw is Gaussian with its σ and, by default, truncated to the
error bound ``k σ`` that the component reports (so the data always lie inside their bounds).

What the executor reports is what a robot would know: new data ids for every face, edge and vertex it meets
(it cannot tell that it is touching a face again), adjacency as acquired (§2.3), and short explored intervals
on edges that an edge move extends to a vertex (the edge is re-reported with its id). The ground truth of
every data id (``truth``) is kept for evaluation only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from haptic.geometry import tracing
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.raycast import line_hits
from haptic.geometry.se3 import SE3, plane_basis
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex, SensorNoise
from haptic.matching.free_space import FreeSegment
from haptic.planning.moves import (
    VERTEX_RADIUS,
    ZERO_LENGTH,
    CostModel,
    EdgeMove,
    FaceMove,
    Move,
    MoveResult,
    PlacementMove,
    ProbeMove,
    SensorState,
    VertexMove,
    in_plane,
)

INSIDE = 1e-7
"""A trace onto a new face starts this far in from the edge, off it (round-off) [m]."""
AT_VERTEX = 1e-9
"""An edge trace shorter than this started at its vertex (round-off) [m]."""


@dataclass(frozen=True)
class GeometricSettings:
    """Lengths of the short strokes that make up a move (seed §3.1 primitives)."""

    edge_probe: float = 0.003
    """Half-length of the interval explored on an edge to acquire its direction [m]."""
    step_onto_face: float = 0.008
    """How far the sensor moves onto a new face to acquire its normal [m]."""
    vertex_radius: float = VERTEX_RADIUS
    """Radius of the circular path around a vertex [m] (the hand's)."""
    start_margin: float = 0.004
    """Smallest distance of the landing point from the boundary of its face [m]."""
    vertex_standoff: float = 0.002
    """After an edge move the sensor rests this far back from the vertex along the edge ... [m]"""
    standoff_inward: float = 0.25
    """... and this fraction of that in on the current face [-] ..."""
    standoff_edge_fraction: float = 0.25
    """... at most this fraction of the edge's length back [-]."""
    step_room_fraction: float = 0.45
    """Stepping onto a new face, the sensor goes at most this fraction of the way to the face's far boundary [-]."""
    circle_clear: float = 0.3
    """A vertex move's new edge is explored from this fraction of the circle's radius from the vertex [-]."""
    truncate: bool = True
    """Truncate every noise draw to the error bound k σ (data always inside their bounds)."""
    at_bounds: bool = False
    """Scale every noise draw to exactly its error bound k σ (worst case, for soundness tests)."""


@dataclass
class _EdgeRecord:
    true_edge: int
    sense: int  # data b_d ≈ sense · R b_m
    direction: np.ndarray  # the noisy data direction (world), kept across re-reports
    interval: tuple[float, float]  # explored true parameters along b_m, lo < hi
    faces: list[int] = field(default_factory=list)
    side_points: list[tuple[int, np.ndarray]] = field(default_factory=list)
    vertices: dict[int, int] = field(default_factory=dict)  # true vertex -> data vertex id
    adjacent: list[int] = field(default_factory=list)


class GeometricExecutor:
    """Executes the seed's face, edge and vertex moves on a known model at a known pose (ideal sensor + noise)."""

    def __init__(
        self,
        model: Polyhedron,
        world_from_model: SE3,
        noise: SensorNoise | None = None,
        rng: np.random.Generator | None = None,
        costs: CostModel | None = None,
        settings: GeometricSettings | None = None,
    ) -> None:
        self.model = model
        self.world_from_model = world_from_model
        self.noise = noise if noise is not None else SensorNoise()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.costs = costs if costs is not None else CostModel()
        self.settings = settings if settings is not None else GeometricSettings()
        self.state: SensorState | None = None
        """Sensor state after the last move (None before :meth:`start`)."""
        self.components: list[DataComponent] = []
        """Every component reported so far, in order (re-reported edges appear again)."""
        self.truth: dict[int, tuple[str, int]] = {}
        """Ground truth: data id → (kind, true model component id). For evaluation only."""
        self.edge_senses: dict[int, int] = {}
        """Ground truth: data edge id → +1 when its direction is the model edge's, −1 when reversed."""
        self._next_id = 0
        self._pos = np.zeros(3)  # sensor position, model frame
        self._edges: dict[int, _EdgeRecord] = {}
        self._true_face: dict[int, int] = {}

    # ------------------------------------------------------------------------------------------ noise

    def _clip(self, x: np.ndarray, bound: float) -> np.ndarray:
        if self.settings.at_bounds:
            n = float(np.linalg.norm(x))
            return x * (bound / n) if n > 0 else x
        if not self.settings.truncate:
            return x
        n = float(np.linalg.norm(x))
        return x if n <= bound or n == 0 else x * (bound / n)

    def _turn(self, u: np.ndarray, sigma: float) -> np.ndarray:
        """``u`` turned by a random angle (2-D Gaussian σ per axis, truncated to k σ)."""
        if sigma <= 0:
            return u.copy()
        a, b = plane_basis(u, assume_unit=True)
        w = self._clip(self.rng.normal(0.0, sigma, 2), self.noise.k * sigma)
        ang = float(np.linalg.norm(w))
        if ang == 0:
            return u.copy()
        axis_perp = (w[0] * a + w[1] * b) / ang
        return np.cos(ang) * u + np.sin(ang) * axis_perp

    def _perp_offset(self, u: np.ndarray, sigma: float) -> np.ndarray:
        if sigma <= 0:
            return np.zeros(3)
        a, b = plane_basis(u, assume_unit=True)
        w = self._clip(self.rng.normal(0.0, sigma, 2), self.noise.k * sigma)
        return w[0] * a + w[1] * b

    def _scalar(self, sigma: float) -> float:
        if sigma <= 0:
            return 0.0
        return float(self._clip(np.array([self.rng.normal(0.0, sigma)]), self.noise.k * sigma)[0])

    def _vec3(self, sigma: float) -> np.ndarray:
        if sigma <= 0:
            return np.zeros(3)
        return self._clip(self.rng.normal(0.0, sigma, 3), self.noise.k * sigma)

    # ------------------------------------------------------------------------------------------ data

    def _new_id(self) -> int:
        i = self._next_id
        self._next_id += 1
        return i

    def _face(self, face: int, points_in_model: np.ndarray, adjacent: tuple[int, ...]) -> DataFace:
        nz = self.noise
        t = self.world_from_model
        n_w = t.rotate(self.model.face_normals[face])
        pts = t.apply(points_in_model)
        pts = pts + np.array([self._scalar(nz.position_sigma) for _ in range(len(pts))])[:, None] * n_w
        fid = self._new_id()
        self._true_face[fid] = face
        self.truth[fid] = ("face", face)
        return DataFace(
            id=fid,
            normal=self._turn(n_w, nz.normal_sigma),
            points=pts,
            normal_bound=nz.k * nz.normal_sigma,
            position_bound=nz.k * nz.position_sigma,
            adjacent=adjacent,
        )

    def _edge_record(self, rec: _EdgeRecord, eid: int) -> DataEdge:
        """The data edge for the explored interval of ``rec`` (noise drawn afresh at its ends)."""
        nz = self.noise
        m, t = self.model, self.world_from_model
        e = rec.true_edge
        p_m, b_m, length = m.edge_points[e], m.edge_directions[e], m.edge_lengths[e]
        lo, hi = rec.interval
        u_w = t.rotate(rec.sense * b_m)  # true direction in data sense
        s_start, s_end = (lo, hi) if rec.sense > 0 else (hi, lo)
        start_w = t.apply(p_m + s_start * b_m)
        end_w = t.apply(p_m + s_end * b_m)
        p_d = start_w + self._scalar(nz.length_sigma) * u_w + self._perp_offset(u_w, nz.position_sigma)
        end_target = end_w + self._scalar(nz.length_sigma) * u_w
        l_d = max(float((end_target - p_d) @ rec.direction), 0.0)
        src, dst = int(m.edges[e, 0]), int(m.edges[e, 1])

        def at(s: float) -> int | None:
            v = src if s <= ZERO_LENGTH else dst if s >= length - ZERO_LENGTH else None
            return rec.vertices.get(v) if v is not None else None

        return DataEdge(
            id=eid,
            direction=rec.direction,
            point=p_d,
            length=l_d,
            direction_bound=nz.k * nz.direction_sigma,
            position_bound=nz.k * nz.position_sigma,
            length_bound=nz.k * nz.length_sigma,
            start_vertex=at(s_start),
            end_vertex=at(s_end),
            adjacent=tuple(rec.adjacent),
            side_points=tuple(rec.side_points),
        )

    def _new_edge(self, edge: int, around: float, lo_limit: float, hi_limit: float) -> tuple[int, _EdgeRecord]:
        """A new data edge explored around true parameter ``around`` (clipped to [lo_limit, hi_limit])."""
        a = self.settings.edge_probe
        lo, hi = max(around - a, lo_limit), min(around + a, hi_limit)
        sense = 1 if self.rng.random() < 0.5 else -1
        direction = self._turn(
            self.world_from_model.rotate(sense * self.model.edge_directions[edge]), self.noise.direction_sigma
        )
        eid = self._new_id()
        rec = _EdgeRecord(true_edge=edge, sense=sense, direction=direction, interval=(lo, hi))
        self._edges[eid] = rec
        self.truth[eid] = ("edge", edge)
        self.edge_senses[eid] = sense
        return eid, rec

    def _inward(self, face: int, edge: int) -> np.ndarray:
        """Unit vector in ``face``'s plane, perpendicular to ``edge``, pointing from the edge into the face."""
        m = self.model
        w = np.cross(m.face_normals[face], m.edge_directions[edge])
        return w if m.edge_left_face[edge] == face else -w

    def _step_onto(self, face: int, edge: int, point: np.ndarray) -> np.ndarray:
        """Points on ``face`` reached by stepping in from ``point`` on ``edge`` (to acquire the normal)."""
        w = self._inward(face, edge)
        hit = tracing.trace_face(self.model, face, point + INSIDE * w, w)
        room = hit.distance if hit is not None else self.settings.step_onto_face
        s = min(self.settings.step_onto_face, self.settings.step_room_fraction * room)
        return np.array([point + 0.5 * s * w, point + s * w])

    def _arc_point(self, face: int, vertex: int, edge: int, angle: float, radius: float) -> np.ndarray:
        """The point of the circular path on ``face``, ``min(angle/2, π/2)`` back from where it met ``edge``."""
        m = self.model
        a = m.edge_directions[edge] * (1.0 if int(m.edges[edge, 0]) == vertex else -1.0)
        phi = min(angle / 2.0, np.pi / 2.0)
        return m.vertices[vertex] + radius * (np.cos(phi) * a + np.sin(phi) * self._inward(face, edge))

    def _state(self, **kw) -> SensorState:
        return SensorState(position=self.world_from_model.apply(self._pos), **kw)

    # ------------------------------------------------------------------------------------------ moves

    def start(self, face: int | None = None, point_in_model: np.ndarray | None = None) -> MoveResult:
        """Land on a face (random, area-weighted, unless given) at a general-position point; acquire its normal."""
        m = self.model
        if face is None:
            face = int(self.rng.choice(m.n_faces, p=m.face_areas / m.face_areas.sum()))
        if point_in_model is None:
            point_in_model = tracing.random_face_point(m, face, self.rng, margin=self.settings.start_margin)
        self._pos = np.asarray(point_in_model, dtype=float)
        comp = self._face(face, self._pos[None, :], ())
        self.components.append(comp)
        self.state = self._state(face=comp.id)
        return MoveResult(move=FaceMove(np.zeros(3)), status="ok", components=(comp,), state=self.state)

    def execute(self, move: Move) -> MoveResult:
        """Carry out a move from the current state; never raises for an inadmissible move (status "invalid")."""
        if self.state is None:
            return MoveResult(move=move, status="invalid", reason="call start() first")
        if isinstance(move, FaceMove):
            return self._face_move(move)
        if isinstance(move, EdgeMove):
            return self._edge_move(move)
        if isinstance(move, VertexMove):
            return self._vertex_move(move)
        if isinstance(move, ProbeMove):
            return self._probe_move(move)
        if isinstance(move, PlacementMove):
            return self._placement_move(move)
        return MoveResult(move=move, status="invalid", state=self.state, reason=f"unknown move {move!r}")

    def _probe_move(self, move: ProbeMove) -> MoveResult:
        """The free-space probe (seed §1.1): cast the line at the posed true model from where the sensor is. A hit
        is a face data component (the contact point and the face's normal, with the same noise as every face) and the
        sensor then rests on that face; a miss leaves the sensor where it was (it returns to its last contact, which
        the cost counts). Either way the path along the line is reported free (:class:`FreeSegment`), displaced as a
        whole by a position error within its bound. A bad line is "invalid", one that starts inside the object
        "unreachable"."""
        if (problem := move.problem()) is not None:
            return self._invalid(move, problem)
        start = np.asarray(move.start, dtype=float)
        u = np.asarray(move.direction, dtype=float)
        length = float(move.length)
        inv = self.world_from_model.inverse()
        s_m, u_m = inv.apply(start), inv.rotate(u)
        if bool(self.model.contains(s_m[None])[0]):
            return MoveResult(move=move, status="unreachable", state=self.state,
                              reason="the line starts inside the object")  # fmt: skip
        here = np.asarray(self.state.position, dtype=float)
        transfer = float(np.linalg.norm(start - here))
        hits = line_hits(self.model, s_m[None], u_m[None])
        t_hit, face = float(hits.first[0]), int(hits.face[0])
        rho = self.noise.k * self.noise.position_sigma
        if t_hit <= length:
            free = FreeSegment(start + self._vec3(self.noise.position_sigma), u, t_hit, rho)
            point_m = s_m + t_hit * u_m
            comp = self._face(face, point_m[None], ())
            self.components.append(comp)
            self._pos = point_m
            self.state = self._state(face=comp.id)
            s = transfer + t_hit
            return MoveResult(move=move, status="ok", components=(comp,), distance=s, cost=self.costs.probe_move(s),
                              state=self.state, free_space=(free,), info={"contact": t_hit})  # fmt: skip
        free = FreeSegment(start + self._vec3(self.noise.position_sigma), u, length, rho)
        s = transfer + length + float(np.linalg.norm(move.end - here))
        return MoveResult(move=move, status="ok", distance=s, cost=self.costs.probe_move(s), state=self.state,
                          free_space=(free,), info={"contact": None})  # fmt: skip

    def _placement_move(self, move: PlacementMove) -> MoveResult:
        """Several fingertips at once (seed §5): each finger closes along its line as a probe does (:meth:`_probe_move`)
        from one approach of the hand. Each finger that touches yields a face component (its contact point and the
        face's normal, each with its own noise), in the order of the fingers; one that meets nothing reports its line
        free; one whose line starts inside the object fails alone ("unreachable"), the others' components stand. The
        sensor rests on the first face touched (where it was when none is). The move fails only when every finger
        does. ``info["fingers"]``: per finger, its name, ``status`` ("touched", "missed" or why it failed) and the data
        id of its face (or None)."""
        if (problem := move.problem()) is not None:
            return self._invalid(move, problem)
        inv = self.world_from_model.inverse()
        here = np.asarray(self.state.position, dtype=float)
        rho = self.noise.k * self.noise.position_sigma
        comps: list[DataFace] = []
        free: list[FreeSegment] = []
        fingers: list[dict] = []
        transfer, closing, back = 0.0, 0.0, np.inf
        first_hit: tuple[np.ndarray, int] | None = None
        for f in move.fingers:
            start, u, length = np.asarray(f.start, dtype=float), np.asarray(f.direction, dtype=float), float(f.length)
            s_m, u_m = inv.apply(start), inv.rotate(u)
            if bool(self.model.contains(s_m[None])[0]):
                fingers.append({"finger": f.finger, "status": "unreachable", "component": None,
                                "reason": "the line starts inside the object"})  # fmt: skip
                continue
            transfer = max(transfer, float(np.linalg.norm(start - here)))
            hits = line_hits(self.model, s_m[None], u_m[None])
            t_hit, face = float(hits.first[0]), int(hits.face[0])
            if t_hit <= length:
                free.append(FreeSegment(start + self._vec3(self.noise.position_sigma), u, t_hit, rho))
                point_m = s_m + t_hit * u_m
                comp = self._face(face, point_m[None], ())
                comps.append(comp)
                if first_hit is None:
                    first_hit = (point_m, comp.id)
                closing = max(closing, t_hit)
                fingers.append({"finger": f.finger, "status": "touched", "component": comp.id, "contact": t_hit})
            else:
                free.append(FreeSegment(start + self._vec3(self.noise.position_sigma), u, length, rho))
                closing = max(closing, length)
                back = min(back, float(np.linalg.norm(start + length * u - here)))
                fingers.append({"finger": f.finger, "status": "missed", "component": None, "contact": None})
        if not free:
            return MoveResult(move=move, status="unreachable", state=self.state, info={"fingers": fingers},
                              reason="every finger's line starts inside the object")  # fmt: skip
        self.components.extend(comps)
        if first_hit is not None:
            self._pos = first_hit[0]
            self.state = self._state(face=first_hit[1])
        s = transfer + closing + (0.0 if comps else back)
        cost = self.costs.placement_move(s, len(move.fingers), 0)  # the ideal sensor has the normals at contact
        return MoveResult(move=move, status="ok", components=tuple(comps), distance=s, cost=cost, state=self.state,
                          free_space=tuple(free), info={"fingers": fingers})  # fmt: skip

    def _invalid(self, move: Move, reason: str) -> MoveResult:
        return MoveResult(move=move, status="invalid", state=self.state, reason=reason)

    def _face_move(self, move: FaceMove) -> MoveResult:
        m, st = self.model, self.state
        d = np.asarray(move.direction, dtype=float)
        if d.shape != (3,) or not np.all(np.isfinite(d)):
            return self._invalid(move, "direction must be a finite 3-vector")
        pos = self._pos
        if move.face is not None and move.face != st.face:  # across the other face of the edge the sensor is on
            if st.edge is None or move.face not in st.edge_faces or move.face not in self._true_face:
                return self._invalid(move, f"face {move.face} is not a face of the current edge (faces "
                                           f"{st.edge_faces})")  # fmt: skip
            if move.start is None:
                return self._invalid(move, "a face move across another face needs its start")
            g = self._true_face[move.face]  # the start, on the face's plane
            p = self.world_from_model.inverse().apply(np.asarray(move.start, dtype=float))
            pos = p - float(p @ m.face_normals[g] - m.face_offsets[g]) * m.face_normals[g]
        f = self._true_face[st.face if move.face is None else move.face]
        d_m = self.world_from_model.inverse().rotate(d)
        inplane = in_plane(d_m, m.face_normals[f])
        if inplane is None:
            return self._invalid(move, "direction is not in the plane of the current face")
        if pos is not self._pos:  # the sensor steps onto that face
            self._pos = pos
            self.state = st = self._state(face=move.face, edge=st.edge, vertex=st.vertex, edge_faces=st.edge_faces)
        hit = tracing.trace_face(m, f, self._pos, inplane)
        if hit is None:
            return MoveResult(move=move, status="unreachable", state=st, reason="trace met a vertex")
        e, g = hit.edge, hit.next_face
        s_hit = float((hit.point - m.edge_points[e]) @ m.edge_directions[e])
        eid, rec = self._new_edge(e, s_hit, 0.0, float(m.edge_lengths[e]))
        pts = self._step_onto(g, e, hit.point)
        new_face_id = self._next_id  # the face is reported right after the edge
        rec.adjacent = [st.face]
        rec.faces = [st.face, new_face_id]
        t = self.world_from_model
        # side points: where the trace started (the straight path meets the edge's line only at the hit) and
        # the farthest point stepped onto the next face
        rec.side_points = [(st.face, t.apply(self._pos)), (new_face_id, t.apply(pts[-1]))]
        edge = self._edge_record(rec, eid)
        face = self._face(g, pts, (eid,))
        self._pos = pts[-1]
        self.state = self._state(face=face.id, edge=eid, edge_faces=(st.face, face.id))
        comps = (edge, face)
        self.components.extend(comps)
        return MoveResult(
            move=move, status="ok", components=comps, distance=hit.distance,
            cost=self.costs.face_move(hit.distance), state=self.state,
        )  # fmt: skip

    def _edge_move(self, move: EdgeMove) -> MoveResult:
        m, st = self.model, self.state
        if st.edge is None:
            return self._invalid(move, "no current edge: an edge move starts on or near an edge")
        if move.sense not in (1, -1):
            return self._invalid(move, f"sense must be +1 or -1, got {move.sense!r}")
        rec = self._edges[st.edge]
        e = rec.true_edge
        p_m, b_m, length = m.edge_points[e], m.edge_directions[e], float(m.edge_lengths[e])
        s_pos = float(np.clip((self._pos - p_m) @ b_m, 0.0, length))
        ms = move.sense * rec.sense
        hit = tracing.trace_edge(m, e, p_m + s_pos * b_m, ms)
        if hit.distance < AT_VERTEX or (st.vertex is not None and rec.vertices.get(hit.vertex) == st.vertex):
            return self._invalid(move, "the sensor is already at the vertex in that sense")
        lo, hi = rec.interval
        rec.interval = (0.0, max(hi, s_pos)) if ms < 0 else (min(lo, s_pos), length)
        comps: list[DataComponent] = []
        new_vertex = None
        if hit.vertex not in rec.vertices:
            vid = self._new_id()
            rec.vertices[hit.vertex] = vid
            pos = self.world_from_model.apply(m.vertices[hit.vertex]) + self._vec3(self.noise.position_sigma)
            new_vertex = DataVertex(
                id=vid, position=pos, position_bound=self.noise.k * self.noise.position_sigma, adjacent=(st.edge,)
            )
            self.truth[vid] = ("vertex", hit.vertex)
        comps.append(self._edge_record(rec, st.edge))
        if new_vertex is not None:
            comps.append(new_vertex)
        # stop at the vertex, on the current face: a little back along the edge and in from it
        f = self._true_face[st.face]
        s = self.settings
        back = min(s.vertex_standoff, s.standoff_edge_fraction * length)
        self._pos = m.vertices[hit.vertex] - ms * back * b_m + s.standoff_inward * back * self._inward(f, e)
        self.state = self._state(face=st.face, edge=st.edge, vertex=rec.vertices[hit.vertex], edge_faces=st.edge_faces)
        self.components.extend(comps)
        return MoveResult(
            move=move, status="ok", components=tuple(comps), distance=hit.distance,
            cost=self.costs.edge_move(hit.distance), state=self.state,
        )  # fmt: skip

    def _vertex_move(self, move: VertexMove) -> MoveResult:
        m, st = self.model, self.state
        if st.vertex is None or st.edge is None:
            return self._invalid(move, "no current vertex: a vertex move starts near a vertex on a known edge")
        if move.across_face not in st.edge_faces:
            return self._invalid(
                move, f"face {move.across_face} is not a face of the current edge (faces {st.edge_faces})"
            )
        rec = self._edges[st.edge]
        e = rec.true_edge
        v = next(tv for tv, dv in rec.vertices.items() if dv == st.vertex)
        g = self._true_face[move.across_face]
        r = self.settings.vertex_radius
        try:
            hit = tracing.circle_vertex(m, v, e, g, r)
        except ValueError as exc:
            return self._invalid(move, str(exc))
        e2, g2 = hit.edge, hit.next_face
        length2 = float(m.edge_lengths[e2])
        from_src = int(m.edges[e2, 0]) == v
        rr = min(r, 0.5 * length2)
        s_hit = rr if from_src else length2 - rr
        clear = self.settings.circle_clear
        lo_lim, hi_lim = (clear * rr, length2) if from_src else (0.0, length2 - clear * rr)
        eid, rec2 = self._new_edge(e2, s_hit, lo_lim, hi_lim)
        h = m.edge_points[e2] + s_hit * m.edge_directions[e2]
        pts = self._step_onto(g2, e2, h)
        new_face_id = self._next_id
        t = self.world_from_model
        rec2.adjacent = [st.vertex, move.across_face]
        rec2.faces = [move.across_face, new_face_id]
        rec2.vertices[v] = st.vertex
        rec2.side_points = [
            (move.across_face, t.apply(self._arc_point(g, v, e2, hit.angle, r))),
            (new_face_id, t.apply(pts[-1])),
        ]
        edge = self._edge_record(rec2, eid)
        face = self._face(g2, pts, (eid,))
        self._pos = pts[-1]
        self.state = self._state(face=face.id, edge=eid, vertex=st.vertex, edge_faces=(move.across_face, face.id))
        comps = (edge, face)
        self.components.extend(comps)
        return MoveResult(
            move=move, status="ok", components=comps, distance=hit.arc_length,
            cost=self.costs.vertex_move(hit.arc_length), state=self.state,
        )  # fmt: skip

    # ------------------------------------------------------------------------------------------ helpers

    def admissible_moves(self, rng: np.random.Generator, n_directions: int = 8) -> list[Move]:
        """Candidate moves from the current state: face moves in ``n_directions`` random in-plane directions,
        edge moves both ways when on an edge, vertex moves across either face when at a vertex (§4.1)."""
        st = self.state
        if st is None:
            return []
        face = next(c for c in reversed(self.components) if c.id == st.face)
        a, b = plane_basis(face.normal)
        moves: list[Move] = []
        for ang in rng.uniform(0, 2 * np.pi, n_directions):
            moves.append(FaceMove(np.cos(ang) * a + np.sin(ang) * b))
        if st.edge is not None:
            moves.extend([EdgeMove(1), EdgeMove(-1)])
        if st.vertex is not None:
            moves.extend(VertexMove(f) for f in st.edge_faces)
        return moves


WALK_ATTEMPTS = 20
"""A random walk tries up to this many moves for each move it makes."""
WALK_FACE_SHARE = 0.4
"""A random walk makes a face move with this probability when an edge or vertex move is possible."""


def random_walk(executor: GeometricExecutor, n_moves: int, rng: np.random.Generator) -> list[MoveResult]:
    """Start on a random face and make ``n_moves`` random admissible moves (face moves with probability
    :data:`WALK_FACE_SHARE` when an edge or vertex move is possible). Returns the results of the start and every
    successful move."""
    results = [executor.start()]
    for _ in range(n_moves):
        for _attempt in range(WALK_ATTEMPTS):
            st = executor.state
            kinds = ["face"]
            if st.edge is not None:
                kinds.append("edge")
            if st.vertex is not None:
                kinds.append("vertex")
            face_move = len(kinds) == 1 or rng.random() < WALK_FACE_SHARE
            kind = kinds[0] if face_move else kinds[int(rng.integers(1, len(kinds)))]
            if kind == "face":
                move: Move = executor.admissible_moves(rng, n_directions=1)[0]
            elif kind == "edge":
                move = EdgeMove(int(rng.choice([-1, 1])))
            else:
                move = VertexMove(int(rng.choice(st.edge_faces)))
            res = executor.execute(move)
            if res.ok:
                results.append(res)
                break
    return results


__all__ = ["GeometricExecutor", "GeometricSettings", "random_walk"]
