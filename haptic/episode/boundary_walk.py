"""Exploring a non-convex object to closure: a walk over its traced boundary to the nearest open part of it.

A non-convex object has no convex estimate to predict moves in, but its traced boundary
(:class:`~haptic.learning.boundary.BoundaryEstimate`) is a graph the sensor moves over with known outcomes: an
edge move along a closed edge ends at its other vertex, a vertex move across a face of the current edge ends on
the next edge round the vertex on that face. :class:`BoundaryWalk` finds, over that graph, the cheapest way
(seed §3.1 costs) to a place where one move measures something not measured yet:

- on an edge that reaches a vertex at one end or none: the edge move toward the end not reached (it measures
  the vertex, and the edge is closed);
- at a vertex whose fan of faces is open on a face of the current edge (fewer than two edges on that face's
  plane, or not as many in as out): the vertex move across that face (it measures the next edge round the
  vertex, and steps onto the face beyond it).

Off the graph (on a face, or on an edge with no vertex known) it first moves onto it: a face move toward the
nearest open vertex or edge, an edge move toward an end. Pure: no simulator, no ground truth.
"""

from __future__ import annotations

import heapq
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from haptic.geometry.se3 import plane_basis
from haptic.learning.boundary import BoundaryEstimate
from haptic.learning.folds import crosses
from haptic.matching.components import DataComponent, DataEdge, DataFace
from haptic.planning.config import PlannerConfig
from haptic.planning.move_scores import same_move
from haptic.planning.moves import EdgeMove, FaceMove, Move, ProbeMove, SensorState, VertexMove

FOLD_PROBE_AFTER = 2
"""Fold moves off the faces with diagonals left to cross that crossed none, after which the fold check probes
(:meth:`BoundaryWalk.fold_move`)."""
FOLD_PROBE_STANDOFF = 1.0
"""A fold check's probe starts this many times the data's size outside the face it is aimed at (outside every
measured point) [-]."""


@dataclass(eq=False)
class BoundaryWalk:
    """The traced boundary as a graph of (vertex, edge) places, and the move toward its nearest open part."""

    est: BoundaryEstimate
    components: Mapping[int, DataComponent]
    config: PlannerConfig

    def __post_init__(self) -> None:
        est = self.est
        self.at: dict[int, list[int]] = {}
        """Vertex → the edges at it."""
        for k, be in enumerate(est.edges):
            for v in be.vertices:
                self.at.setdefault(v, []).append(k)
        self.open_fans: set[tuple[int, int]] = set(est.unbalanced)
        """``(vertex, plane)`` where the vertex's fan of faces is open on the plane."""
        for v, ks in self.at.items():
            deg: dict[int, int] = {}
            for k in ks:
                for p in est.edges[k].planes:
                    deg[p] = deg.get(p, 0) + 1
            self.open_fans.update((v, p) for p, n in deg.items() if n < 2)
            if len(deg) < 3:
                self.open_fans.update((v, p) for p in deg)
        for p, loop in est.holes:
            self.open_fans.update((v, p) for v in loop)

    # ------------------------------------------------------------------------------------------ geometry

    def _away(self, v: int, k: int) -> np.ndarray | None:
        """Unit direction of edge ``k`` leaving vertex ``v`` (None when its other end is not known)."""
        be = self.est.edges[k]
        others = [w for w in be.vertices if w != v]
        if others:
            d = self.est.positions[others[0]] - self.est.positions[v]
        else:
            e = self.components[be.data[0]]
            mid = 0.5 * (e.point + e.end_point)
            d = mid - self.est.positions[v]
        n = float(np.linalg.norm(d))
        return d / n if n > 0 else None

    def _sides(self, k: int, p: int, v: int) -> list[float]:
        """The senses (+1 CCW, −1 CW about plane ``p``'s normal, from edge ``k`` at ``v``) toward the face of
        plane ``p`` beside edge ``k``: one for an edge between two planes, both for a flat edge."""
        be = self.est.edges[k]
        if be.flat:
            return [1.0, -1.0]
        a = self._away(v, k)
        pts = be.sides.get(p, [])
        if a is None or not pts:
            return []
        n = self.est.planes[p].normal
        s = float(np.sum([np.sign(np.cross(a, q - self.est.positions[v]) @ n) for q in pts]))
        return [1.0 if s >= 0 else -1.0]

    def next_round(self, v: int, k: int, p: int, sense: float) -> tuple[int, float] | None:
        """The edge met circling vertex ``v`` from edge ``k`` across the face of plane ``p`` in ``sense``, and
        the angle swept [rad]; None when no other edge at ``v`` on ``p`` is known."""
        a = self._away(v, k)
        if a is None:
            return None
        x, y = plane_basis(self.est.planes[p].normal)
        a0 = np.arctan2(a @ y, a @ x)
        best = None
        for k2 in self.at.get(v, []):
            if k2 == k or p not in self.est.edges[k2].planes:
                continue
            b = self._away(v, k2)
            if b is None:
                continue
            ang = (sense * (np.arctan2(b @ y, b @ x) - a0)) % (2 * np.pi)
            if best is None or ang < best[1]:
                best = (k2, float(ang))
        return best

    # ------------------------------------------------------------------------------------------ search

    def exploring(self, v: int, k: int) -> tuple[int, float] | None:
        """``(plane, sense)`` of a vertex move from edge ``k`` at vertex ``v`` that measures an edge not known yet:
        across a face of the edge whose fan at the vertex is open, toward no known edge; None when none does."""
        be = self.est.edges[k]
        for p in dict.fromkeys(be.planes):
            if (v, p) not in self.open_fans:
                continue
            for sense in self._sides(k, p, v):
                if self.next_round(v, k, p, sense) is None:
                    return p, sense
        return None

    def _goal(self, v: int, k: int) -> bool:
        return not self.est.edges[k].closed or self.exploring(v, k) is not None

    def steps(self, v: int, k: int) -> list[tuple[float, int, int, tuple]]:
        """The graph steps from the sensor at vertex ``v`` on edge ``k``: ``(cost, vertex, edge, step)`` of the
        edge move to the edge's other end and of each vertex move round ``v`` to a known edge."""
        c = self.config.costs
        be = self.est.edges[k]
        out = []
        for w in be.vertices:
            if w != v:
                length = float(np.linalg.norm(self.est.positions[w] - self.est.positions[v]))
                out.append((c.edge_move(length), w, k, ("edge", v, k, w)))
        for p in dict.fromkeys(be.planes):
            for sense in self._sides(k, p, v):
                nxt = self.next_round(v, k, p, sense)
                if nxt is not None:
                    out.append(
                        (c.vertex_move(self.config.vertex_radius * nxt[1]), v, nxt[0], ("vertex", v, k, p, sense))
                    )
        return out

    def route(self, starts: list[tuple[float, int, int, tuple]]) -> list[tuple] | None:
        """The cheapest sequence of graph steps from any of ``starts`` ``(cost, vertex, edge, first step)`` to a
        place where a move measures something new (Dijkstra); the steps' first, or None."""
        heap = [(cost, i, v, k, first) for i, (cost, v, k, first) in enumerate(starts)]
        heapq.heapify(heap)
        done: set[tuple[int, int]] = set()
        tie = len(heap)
        while heap:
            cost, _, v, k, first = heapq.heappop(heap)
            if (v, k) in done:
                continue
            done.add((v, k))
            if self._goal(v, k):
                return [first]
            for dc, w, k2, step in self.steps(v, k):
                if (w, k2) not in done:
                    tie += 1
                    heapq.heappush(heap, (cost + dc, tie, w, k2, first if first is not None else step))
        return None

    # ------------------------------------------------------------------------------------------ moves

    def _edge_sense(self, data_edge: DataEdge, toward: np.ndarray) -> int:
        return 1 if float((toward - data_edge.point) @ data_edge.direction) > 0.5 * data_edge.length else -1

    def _vertex_move(self, state: SensorState, v: int, k: int, p: int, sense: float) -> Move | None:
        """The vertex move across the face of the current data edge on plane ``p`` in ``sense``."""
        e = self.components.get(state.edge)
        faces = [f for f in state.edge_faces if self.est.plane_of.get(f) == p]
        if not faces or not isinstance(e, DataEdge):
            return None
        if len(faces) == 1:
            return VertexMove(faces[0])
        a = self._away(v, k)
        n = self.est.planes[p].normal
        pts = dict(e.side_points)
        for f in faces:
            q = pts.get(f)
            if q is not None and a is not None and np.sign(np.cross(a, q - self.est.positions[v]) @ n) == sense:
                return VertexMove(f)
        return VertexMove(faces[0])

    def _step_move(self, state: SensorState, step: tuple) -> Move | None:
        if step[0] == "edge":
            _, _, _, w = step
            return EdgeMove(self._edge_sense(self.components[state.edge], self.est.positions[w]))
        _, v, k, p, sense = step
        return self._vertex_move(state, v, k, p, sense)

    def _open_points(self) -> list[np.ndarray]:
        """Where the open parts are: vertices with an open fan, the data of open edges, bare planes' points."""
        est = self.est
        pts = [est.positions[v] for v, _ in self.open_fans]
        for k in est.open_edges():
            e = self.components[est.edges[k].data[0]]
            pts.append(0.5 * (e.point + e.end_point))
        return pts

    def best_move(self, state: SensorState, avoid: tuple[Move, ...], turn: int = 0) -> Move | None:
        """The next move toward the nearest open part of the boundary (module docstring); None when the walk
        knows none."""
        move = self._best(state)
        if move is not None and not any(same_move(move, bad) for bad in avoid):
            return move
        return self._face_move(state, avoid, turn)

    def _best(self, state: SensorState) -> Move | None:
        est = self.est
        k = est.edge_of.get(state.edge) if state.edge is not None else None
        v = est.vertex_of.get(state.vertex) if state.vertex is not None else None
        if k is None:
            return None
        be = est.edges[k]
        data_edge = self.components[state.edge]
        if not be.closed:  # toward the end not reached
            known = [est.positions[w] for w in be.vertices]
            if not known:
                return EdgeMove(1)
            mid = 0.5 * (data_edge.point + data_edge.end_point)
            t = float((known[0] - mid) @ data_edge.direction)
            return EdgeMove(-1 if t > 0 else 1)
        if v is not None and v in be.vertices:
            starts = [(0.0, v, k, None)]
        else:  # on a closed edge, not at a vertex: to either end
            c = self.config.costs
            starts = []
            for w in be.vertices:
                d = float(np.linalg.norm(est.positions[w] - state.position))
                starts.append((c.edge_move(d), w, k, ("edge", None, k, w)))
        found = self.route(starts)
        if found is None:
            return None
        step = found[0]
        if step is None:  # a goal here: the exploring move
            p, sense = self.exploring(v, k)
            return self._vertex_move(state, v, k, p, sense)
        return self._step_move(state, step)

    def _face_move(self, state: SensorState, avoid: tuple[Move, ...], turn: int) -> Move | None:
        """A face move across the current face: toward the nearest open part, else round the compass."""
        face = self.components.get(state.face)
        if not isinstance(face, DataFace):
            return None
        n = face.normal
        dirs = []
        pts = self._open_points()
        if pts:
            d = np.array(pts) - state.position
            d = d - np.outer(d @ n, n)
            norms = np.linalg.norm(d, axis=1)
            for i in np.argsort(norms):
                if norms[i] > 1e-6:
                    dirs.append(d[i] / norms[i])
                    break
        x, y = plane_basis(n)
        for j in range(8):
            ang = (turn + j) * 3 * np.pi / 8
            dirs.append(np.cos(ang) * x + np.sin(ang) * y)
        for u in dirs:
            move = FaceMove(u)
            if not any(same_move(move, bad) for bad in avoid):
                return move
        return None

    # ------------------------------------------------------------------------------------------ fold check

    def fold_move(self, state: SensorState, avoid: tuple[Move, ...], targets: list[tuple[int, np.ndarray, np.ndarray]],
                  turn: int = 0, stalled: int = 0) -> Move | None:
        """A face move for the fold check (:mod:`haptic.learning.folds`), ``targets`` the diagonals left to cross
        ``(plane, one end, the other)``: on a face with some, the move across it that crosses the most of them
        before it meets the face's boundary (aimed at each one's middle); elsewhere, toward the nearest one's
        middle (onto the next face that way); None when no such move is left. Elsewhere after
        :data:`FOLD_PROBE_AFTER` moves that crossed no diagonal (``stalled``), where the move set admits probes, a
        probe onto the nearest one's middle (:meth:`fold_probe`): the way toward a middle can lead onto a face whose
        own way toward it leads back (BOX01N with a vertex moved 2 mm went back and forth between two faces of its
        notch until the check gave up, and the learned model had a face and an edge too few)."""
        face = self.components.get(state.face)
        if not isinstance(face, DataFace) or not targets:
            return None
        p = self.est.plane_of.get(state.face)
        n = face.normal
        here = [(a, b) for k, a, b in targets if k == p]
        dirs: list[np.ndarray] = []
        if here:
            scored = []
            for a, b in here:
                d = 0.5 * (a + b) - state.position
                d = d - (d @ n) * n
                norm = float(np.linalg.norm(d))
                if norm < 1e-6:
                    continue
                u = d / norm
                end = self._exit(state.position, u, p)
                got = sum(crosses(state.position, end, x, y, n) for x, y in here)
                scored.append((-got, float(np.linalg.norm(end - state.position)), len(scored), u))
            dirs = [u for *_, u in sorted(scored, key=lambda x: x[:3])]
        else:
            probe = self.fold_probe(state, avoid, targets) if stalled >= FOLD_PROBE_AFTER else None
            if probe is not None:
                return probe
            mids = np.array([0.5 * (a + b) for _, a, b in targets]) - state.position
            mids = mids - np.outer(mids @ n, n)
            norms = np.linalg.norm(mids, axis=1)
            dirs = [mids[i] / norms[i] for i in np.argsort(norms) if norms[i] > 1e-6][:1]
        for u in dirs:
            move = FaceMove(u)
            if not any(same_move(move, bad) for bad in avoid):
                return move
        return self._face_move(state, avoid, turn)

    def fold_probe(self, state: SensorState, avoid: tuple[Move, ...],
                   targets: list[tuple[int, np.ndarray, np.ndarray]]) -> Move | None:
        """A probe onto the middle of the nearest of ``targets``' diagonals along its plane's normal, from
        :data:`FOLD_PROBE_STANDOFF` times the data's size outside it, when the move set admits probes and the
        sensor is a point (no table); None otherwise or when one was tried from here (``avoid``)."""
        if self.config.moves == "tracing" or self.config.table_z is not None:
            return None
        mids = [(float(np.linalg.norm(0.5 * (a + b) - state.position)), k, 0.5 * (a + b)) for k, a, b in targets]
        _, k, mid = min(mids, key=lambda x: x[0])
        n = self.est.planes[k].normal
        far = FOLD_PROBE_STANDOFF * max(self.est.bounds.size, 1e-3)
        move = ProbeMove(mid + far * n, -n, far + far)
        return None if any(same_move(move, bad) for bad in avoid) else move

    def _exit(self, start: np.ndarray, u: np.ndarray, p: int | None) -> np.ndarray:
        """Where the path from ``start`` along ``u`` first meets an edge of plane ``p``'s faces (the traced loops)
        [m]; far along ``u`` when it meets none."""
        x, y = plane_basis(self.est.planes[p].normal) if p is not None else plane_basis(u)
        s2 = np.array([start @ x, start @ y])
        r = np.array([u @ x, u @ y])
        best = np.inf
        for loop in self.est.loops.get(p, []) if p is not None else []:
            pts = self.est.positions[loop]
            q = np.stack([pts @ x, pts @ y], axis=1)
            for i in range(len(q)):
                a, b = q[i], q[(i + 1) % len(q)]
                e = b - a
                denom = float(r[0] * e[1] - r[1] * e[0])
                if abs(denom) < 1e-15:
                    continue
                w = a - s2
                t = float(w[0] * e[1] - w[1] * e[0]) / denom
                v = float(w[0] * r[1] - w[1] * r[0]) / denom
                if t > 1e-4 and -1e-9 <= v <= 1 + 1e-9:
                    best = min(best, t)
        return start + (best if np.isfinite(best) else 1.0) * u
