"""Learning an object the library does not hold: after ``no-match``, explore until the surface is closed, then
write its model into a library (``--learn DIR``).

:class:`ClosureMoves` is a move source (:mod:`haptic.episode.sources`), asked before all others once the
matcher's verdict is ``no-match``. Each turn it rebuilds the object's convex estimate from the data alone
(:func:`~haptic.learning.reconstruct.convex_estimate`) and chooses the move that measures the most of its
unmeasured boundary -- open faces (where the data do not bound the object yet), edges and vertices not met --
per unit of path cost, looking up to :attr:`LearnSettings.depth` moves ahead in the estimate's own world
(:func:`~haptic.planning.simulate.simulate`). Once the data show the object is not convex (a measured point
outside a measured plane, planes that bound no solid, or an estimate that measured nothing new in
:attr:`LearnSettings.stall` moves) it traces the object's boundary instead
(:func:`~haptic.learning.boundary.boundary_estimate`), walking over it to the nearest open edge or vertex
(:class:`~haptic.episode.boundary_walk.BoundaryWalk`). Before either is called closed, every diagonal of each
measured face of four or more vertices is crossed by a face move (:mod:`haptic.learning.folds`: a face folded
along a diagonal is two faces). It has its own budget (:class:`LearnSettings`), reported in the record's
``learned``.

:func:`learning_endings` replaces the loop's ending conditions: a ``no-match`` verdict starts the learning
instead of ending the episode, which then ends, still ``no-match``, when the surface is closed or when the
learning budget is spent. :func:`run_learning` runs such an episode and writes the model (the half-space
intersection of a convex object, the traced boundary of any other: :func:`~haptic.learning.library.write_learned`).
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from haptic.episode.boundary_walk import BoundaryWalk
from haptic.episode.loop import (
    Ending,
    EpisodeRecord,
    failed_in_a_row,
    loop_steps,
    out_of_budget,
    too_many_interpretations,
    verdict,
)
from haptic.episode.sources import MoveSource, episode_sources
from haptic.episode.state import EpisodeState
from haptic.errors import ModelError
from haptic.geometry import SE3, Polyhedron
from haptic.learning.boundary import BoundaryEstimate, boundary_estimate
from haptic.learning.folds import Stroke, crosses, unchecked_diagonals
from haptic.learning.reconstruct import (
    ConvexEstimate,
    LearnBounds,
    LearnError,
    convex_estimate,
    convexity_violation,
    edge_faces,
)
from haptic.matching.components import DataComponent
from haptic.matching.recognition import NO_MATCH
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis, trace_in
from haptic.planning.move_scores import same_move
from haptic.planning.moves import EdgeMove, FaceMove, Move, MoveResult, SensorState, start_state
from haptic.planning.predict import candidate_moves
from haptic.planning.simulate import simulate

FACE_GAIN = 2.0
"""What measuring a new plane is worth against an edge or a vertex (a plane bounds several of each) [-]."""
FOLD_GAIN = 1.0
"""What crossing a diagonal not crossed yet is worth, against an edge or a vertex (:mod:`haptic.learning.folds`) [-]."""


@dataclass(frozen=True)
class LearnSettings:
    """How an episode learns an object the library does not hold (``--learn DIR``)."""

    directory: str | None = None
    """Library directory the learned model is written into (None: reconstructed, not written)."""
    name: str | None = None
    """The learned model's name (None: ``learned_`` and a digest of the episode's key)."""
    budget: float = 3000.0
    """Path-cost budget of the learning, on top of the episode's [units]."""
    max_moves: int = 150
    """Move budget of the learning, on top of the episode's."""
    depth: int = 3
    """Moves looked ahead when no single move measures anything new."""
    stall: int = 12
    """Moves after which a convex estimate that measured no new plane or vertex gives way to tracing the
    boundary (the object is taken for non-convex); a closed one whose diagonals no move crossed in as many is
    closed with them unchecked."""
    fold_check: bool | None = None
    """Whether every diagonal of each measured face of four or more vertices is crossed before the surface is
    closed (:mod:`haptic.learning.folds`); None: without a table only (the geometric executor's face moves run
    to the far edge; the hand's pad, resting on the table, is not asked to)."""

    def checks_folds(self, table_z: float | None) -> bool:
        """Whether the learning makes the fold check, on a world with a table at ``table_z`` (None: none)."""
        return table_z is None if self.fold_check is None else self.fold_check


class ClosureMoves(MoveSource):
    """After ``no-match``: the move that measures the most unmeasured boundary of the convex estimate per unit
    of path cost (module docstring); None when no move within :attr:`LearnSettings.depth` measures anything
    (the next source answers)."""

    name = "learning"

    def __init__(self, settings: LearnSettings) -> None:
        self.settings = settings
        self.active = False
        """Whether the learning is under way (the matcher said no-match)."""
        self.moves = 0
        self.failed = 0
        self.cost = 0.0
        self.started: float | None = None
        self.status = "not started"
        """"closed", "no solid", "budget", "failed" or "open" (still exploring)."""
        self.detail = ""
        self.estimate: ConvexEstimate | None = None
        self.convex = True
        """Whether the data so far are those of a convex object (else the boundary is traced to closure)."""
        self.nonconvex = ""
        """What showed the object is not convex."""
        self.boundary: BoundaryEstimate | None = None
        """The traced boundary (once the object is known not to be convex)."""
        self.components: dict[int, DataComponent] = {}
        self.strokes: list[Stroke] = []
        """The face moves' paths (all the episode's, the recognition's too), for the fold check."""
        self.folds: dict[int, list[tuple[int, int]]] = {}
        """Of a closed surface: face (:meth:`_fold_faces`) → the inner diagonals no move crossed."""
        self.fold_check = settings.fold_check
        self.fold_moves = 0
        """Learning moves made while only the fold check kept the surface open."""
        self._folds_only = False
        self._folds_given_up = False
        self._fold_best: tuple[int, int] | None = None
        self._sensor: SensorState | None = None
        self._seen = -1
        self._best: tuple = ()
        self._since = 0

    # ---------------------------------------------------------------------------------------- state

    def start(self, view: EpisodeState) -> None:
        self.active, self.started, self.status = True, time.perf_counter(), "open"
        self.fold_check = self.settings.checks_folds(view.config.table_z)
        self.update(view)

    def update(self, view: EpisodeState) -> None:
        """The estimate of the data so far (rebuilt when they changed), and the learning's status."""
        if len(view.cum_cost) == self._seen:
            return
        self._seen = len(view.cum_cost)
        self.components = dict(view.components)
        if not self.convex:
            self._update_boundary()
            return
        try:
            est = convex_estimate(self.components, table_z=view.config.table_z)
        except LearnError as exc:  # the measured planes bound no convex solid: the object is not convex
            self.estimate, self.convex, self.nonconvex = None, False, str(exc)
            self._update_boundary()
            return
        bad = convexity_violation(self.components, est.planes, est.bounds)
        if bad is not None:
            self.estimate, self.convex = est, False
            self.nonconvex = f"a measured point lies {bad[1] * 1e3:.2f} mm outside measured plane {bad[0]}"
            self._update_boundary()
            return
        self.estimate = est
        self._check_folds(est.closed, {f: k for k, p in enumerate(est.planes) for f in p.faces})
        c = est.counts()
        progress = (c["planes"], c["vertices_measured"], -c["open_faces"])
        if progress > self._best or est.closed:
            self._best, self._since = progress, self.moves
        elif self.moves - self._since >= self.settings.stall:
            # the estimate's faces and vertices are not where the moves find the object: not convex, though no
            # measured point shows it yet
            self.convex = False
            self.nonconvex = f"the convex estimate measured nothing new in {self.settings.stall} moves"
            self._update_boundary()

    def _fold_faces(self) -> tuple[np.ndarray, list[tuple[int, list[int]]], dict[int, np.ndarray]]:
        """The closed surface's vertices, its faces ``(plane, vertex loop)`` and the planes' normals: of the
        convex estimate over its vertex groups, or of the traced boundary."""
        if self.convex:
            est = self.estimate
            vertices, loops = grouped_loops(est.polytope, est.group_of(), len(est.groups))
            return vertices, sorted(loops.items()), {k: est.polytope.normals[k] for k in loops}
        b = self.boundary
        faces = [(p, loop) for p, ls in sorted(b.loops.items()) for loop in ls]
        return b.positions, faces, {p: b.planes[p].normal for p, _ in faces}

    def _check_folds(self, closed: bool, plane_of: Mapping[int, int]) -> None:
        """The fold check of a closed surface (:attr:`folds`), and the learning's status: closed when no
        diagonal is left to cross, or when none was crossed in :attr:`LearnSettings.stall` moves (closed with
        those unchecked, the record says how many faces)."""
        self.folds = {}
        if closed:
            vertices, faces, normals = self._fold_faces()
            self.folds = unchecked_diagonals(vertices, faces, normals, plane_of, self.strokes)
        left = sum(map(len, self.folds.values()))
        self._folds_only = bool(closed and self.fold_check and left and not self._folds_given_up)
        if not self._folds_only:
            self._fold_best = None
        else:
            if self._fold_best is None or left < self._fold_best[0]:
                self._fold_best = (left, self.moves)
            elif self.moves - self._fold_best[1] >= self.settings.stall:
                self._folds_only, self._folds_given_up = False, True
        self.status = "closed" if closed and not self._folds_only else "open"

    def fold_targets(self) -> list[tuple[int, np.ndarray, np.ndarray]]:
        """While only the fold check keeps the surface open: ``(plane, one end, the other)`` of each diagonal
        left to cross [m]."""
        if not self._folds_only:
            return []
        vertices, faces, _ = self._fold_faces()
        return [(faces[f][0], vertices[i], vertices[j]) for f, ds in sorted(self.folds.items()) for i, j in ds]

    def _update_boundary(self) -> None:
        try:
            self.boundary = boundary_estimate(self.components)
        except LearnError as exc:
            self.boundary, self.status, self.detail = None, "no solid", str(exc)
            return
        self._check_folds(self.boundary.closed, self.boundary.plane_of)

    @property
    def bounds(self) -> LearnBounds | None:
        """The error bounds of the data the model is learned from."""
        est = self.estimate if self.convex else self.boundary
        return est.bounds if est is not None else None

    def ending(self, view: EpisodeState) -> Ending | None:
        """The learning's end (the episode's outcome stays ``no-match``), or None while it goes on."""
        self.update(view)
        if self.status in ("closed", "no solid"):
            return Ending(NO_MATCH, f"learning: {self.status}" + (f" ({self.detail})" if self.detail else ""))
        s = self.settings
        if self.cost > s.budget or self.moves >= s.max_moves:
            self.status = "budget"
            return Ending(NO_MATCH, f"learning: budget ({self.moves} moves, cost {self.cost:.1f})")
        return None

    # ---------------------------------------------------------------------------------------- moves

    def propose(self, view: EpisodeState) -> Move | None:
        if not self.active or view.sensor is None:
            return None
        if not self.convex:
            if self.boundary is None:
                return None
            walk = BoundaryWalk(self.boundary, self.components, view.config)
            if self._folds_only:
                stalled = self.moves - self._fold_best[1] if self._fold_best is not None else 0
                return walk.fold_move(view.sensor, tuple(view.failed_here), self.fold_targets(),
                                      turn=self.moves + len(view.failed_here), stalled=stalled)  # fmt: skip
            move = walk.best_move(view.sensor, tuple(view.failed_here), turn=self.moves + len(view.failed_here))
            return move
        if self.estimate is None:
            return None
        folds: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}
        for k, a, b in self.fold_targets():
            folds.setdefault(k, []).append((a, b))
        plan = ClosurePlan.of(self.estimate, self.components, view.config, folds)
        if plan is None:
            return None
        move = plan.best_move(view.sensor, tuple(view.failed_here), self.settings.depth)
        return move

    def on_result(self, view: EpisodeState, move: Move, result: MoveResult) -> None:
        """Every move made while the learning is under way counts against its budget, whichever source chose it
        (when none of the learning's measures anything new, the episode's other sources move on). Every face
        move's path is kept for the fold check (not one that slid over an edge too shallow to feel onto another face
        before the edge it stopped at: its path left the face it started on)."""
        before, self._sensor = self._sensor, view.sensor
        if isinstance(move, FaceMove) and result.ok and before is not None and result.state is not None \
                and "crossed_face" not in result.info:  # fmt: skip
            self.strokes.append(Stroke(start_state(move, before).face, np.array(before.position, float),
                                       np.array(result.state.position, float)))  # fmt: skip
        if not self.active:
            return
        self.moves += 1
        self.cost += result.cost
        self.failed += 0 if result.ok else 1
        self.fold_moves += int(self._folds_only)

    def record(self) -> dict:
        """The learning's part of the episode record."""
        est = self.estimate
        out = {
            "status": self.status, "moves": self.moves, "failed_moves": self.failed, "path_cost": round(self.cost, 6),
            "wall_time_s": round(time.perf_counter() - self.started, 4) if self.started else 0.0,
            "budget": self.settings.budget, "max_moves": self.settings.max_moves,
        }  # fmt: skip
        out["convex"] = self.convex
        out["fold_check"] = bool(self.fold_check)
        out["fold_moves"] = self.fold_moves
        if self.status == "closed":
            out["folds_unchecked"] = len(self.folds)
        if not self.convex:
            out["not_convex"] = self.nonconvex
            if self.boundary is not None:
                out["estimate"] = self.boundary.counts()
        elif est is not None:
            out["estimate"] = est.counts()
        if self.detail:
            out["detail"] = self.detail
        return out


# -------------------------------------------------------------------------------------------- planning


@dataclass(eq=False)
class ClosurePlan:
    """The convex estimate as a world to predict moves in: a hypothesis whose model is the estimate (box faces
    and all, at the identity pose), and what of it is unmeasured."""

    hypothesis: Hypothesis
    """The estimate as a hypothesis (data ids → the estimate's faces, edges and vertices)."""
    open_faces: frozenset[int]
    """Faces of the estimate's model that are the box's (unmeasured boundary)."""
    unmeasured_edges: frozenset[int]
    """Edges of the model neither traced nor between two measured vertices."""
    vertex_group: dict[int, int]
    """Model vertex → its group (the object's vertex)."""
    unmeasured_groups: frozenset[int]
    """Groups no data vertex was met at."""
    config: PlannerConfig
    """Costs and the vertex circle's radius."""
    components: Mapping[int, DataComponent]
    """The data the estimate was made from."""
    folds: tuple[tuple[int, np.ndarray, np.ndarray], ...] = ()
    """Diagonals no move crossed yet: ``(model face, one end, the other)`` [m] (the fold check)."""

    @classmethod
    def of(cls, est: ConvexEstimate, components: Mapping[int, DataComponent], config: PlannerConfig,
           folds: Mapping[int, list[tuple[np.ndarray, np.ndarray]]] | None = None):
        """The plan of estimate ``est`` over ``components``; None when its solid is no valid model (noise).
        ``folds``: plane → the ends of its face's diagonals no move crossed yet."""
        poly = est.polytope
        vertices, loops, group = poly.vertices, poly.loops, est.group_of()
        vertex_of = dict(est.vertex_data)
        try:
            model = Polyhedron.from_faces(vertices, [loops[j] for j in sorted(loops)], name="estimate")
        except ModelError:
            # planes through one point in fours (a fold through a corner) leave the half-space intersection
            # vertices a round-off apart: the estimate's vertex groups as the model's vertices
            vertices, loops = grouped_loops(poly, group, len(est.groups))
            vertex_of = {d: group[k] for d, k in vertex_of.items()}
            group = {g: g for g in range(len(est.groups))}
            try:
                model = Polyhedron.from_faces(vertices, [loops[j] for j in sorted(loops)], name="estimate")
            except ModelError:
                return None
        order = sorted(loops)
        face_of_plane = {j: i for i, j in enumerate(order)}
        plane_of = {f: k for k, p in enumerate(est.planes) for f in p.faces}
        faces = {f: face_of_plane[k] for f, k in plane_of.items() if k in face_of_plane}
        sides = zip(model.edge_left_face, model.edge_right_face, strict=True)
        edge_of = {frozenset((int(a), int(b))): e for e, (a, b) in enumerate(sides)}
        edges = {}
        for eid, fs in edge_faces(components).items():
            pair = frozenset(faces[f] for f in fs if f in faces)
            if len(pair) == 2 and pair in edge_of:
                edges[eid] = edge_of[pair]
        unmeasured = frozenset(est.unmeasured_vertices())
        traced = set(edges.values())
        un_edges = frozenset(
            e for e in range(model.n_edges)
            if e not in traced and (group[int(model.edges[e, 0])] in unmeasured or group[int(model.edges[e, 1])]
                                    in unmeasured)
        )  # fmt: skip
        open_faces = frozenset(face_of_plane[j] for j in est.open_faces() if j in face_of_plane)
        h = Hypothesis("estimate", model, SE3.identity(), faces, edges, vertex_of)
        diag = tuple((face_of_plane[k], a, b) for k, ends in (folds or {}).items() if k in face_of_plane
                     for a, b in ends)  # fmt: skip
        return cls(h, open_faces, un_edges, group, unmeasured, config, dict(components), diag)

    def gain(self, before: Hypothesis, after: Hypothesis, counted: set) -> float:
        """What a move measures: a new plane (an open face met), edges and vertices not measured before (each
        counted once in a sequence, ``counted``)."""
        g = 0.0
        for f in set(after.faces.values()) - set(before.faces.values()):
            if f in self.open_faces and ("f", f) not in counted:
                counted.add(("f", f))
                g += FACE_GAIN
        for e in set(after.edges.values()) - set(before.edges.values()):
            if e in self.unmeasured_edges and ("e", e) not in counted:
                counted.add(("e", e))
                g += 1.0
        for v in set(after.vertices.values()) - set(before.vertices.values()):
            grp = self.vertex_group.get(v)
            if grp in self.unmeasured_groups and ("v", grp) not in counted:
                counted.add(("v", grp))
                g += 1.0
        return g

    def crossed(self, h: Hypothesis, move: Move, before: SensorState, after: SensorState, counted: set) -> float:
        """What a face move's crossing of diagonals not crossed before is worth (each counted once, ``counted``)."""
        if not self.folds or not isinstance(move, FaceMove):
            return 0.0
        f = h.faces.get(start_state(move, before).face)
        g = 0.0
        for i, (face, a, b) in enumerate(self.folds):
            if face == f and ("d", i) not in counted and crosses(before.position, after.position, a, b,
                                                                   h.poly.face_normals[f]):
                counted.add(("d", i))
                g += FOLD_GAIN
        return g

    def candidates(self, state: SensorState, components: Mapping[int, DataComponent], h: Hypothesis) -> list[Move]:
        """The seed's moves from ``state``: edge and vertex moves, and face moves toward the middle of each edge of
        the face under the sensor (in the estimate), kept where they cross it clear of its vertices."""
        moves = [m for m in candidate_moves(state, components, replace(self.config, n_directions=4))
                 if not isinstance(m, FaceMove)]  # fmt: skip
        f = h.faces.get(state.face)
        if f is None:
            return moves
        model = h.poly
        for e in model.face_edges[f]:
            if state.edge is not None and h.edges.get(state.edge) == e:
                continue
            a, b = model.vertices[model.edges[e]]
            d = 0.5 * (a + b) - state.position
            n = model.face_normals[f]
            d = d - (d @ n) * n
            norm = float(np.linalg.norm(d))
            if norm < 1e-9:
                continue
            move = FaceMove(d / norm)
            tr = trace_in(h, move, state)
            if tr is None or tr.hit.distance < self.config.min_face_travel:
                continue
            if tr.clearance(model) < self.config.min_vertex_clearance:
                continue
            moves.append(move)
        return moves

    def cost(self, h: Hypothesis, move: Move, state: SensorState, after: SensorState) -> float:
        """The move's predicted path cost in the estimate's world [units]."""
        c = self.config.costs
        if isinstance(move, FaceMove):
            tr = trace_in(h, move, state)
            return c.face_move(tr.hit.distance if tr is not None else float(np.linalg.norm(after.position
                                                                                          - state.position)))
        if isinstance(move, EdgeMove):
            return c.edge_move(float(np.linalg.norm(after.position - state.position)))
        return c.vertex_move(self.config.vertex_radius * np.pi / 2)

    def best_move(self, state: SensorState, avoid: tuple[Move, ...], depth: int) -> Move | None:
        """The first move of the sequence (up to ``depth`` moves) with the most gain per unit cost; None when
        none gains anything."""
        comps = dict(self.components)
        best: tuple[float, Move | None] = (0.0, None)
        for d in range(1, depth + 1):
            best = self._search(self.hypothesis, state, comps, d, avoid)
            if best[1] is not None:
                break
        return best[1]

    def _search(self, h, state, comps, depth, avoid) -> tuple[float, Move | None]:
        best_rate, best_move = 0.0, None
        stack = [(h, state, comps, 0.0, 0.0, None, 0, frozenset())]
        while stack:
            h0, s0, c0, gain, cost, first, level, counted = stack.pop()
            for move in self.candidates(s0, c0, h0):
                if level == 0 and any(same_move(move, bad) for bad in avoid):
                    continue
                out = simulate(h0, move, s0, c0, self.config)
                if out is None:
                    continue
                h1, s1, c1 = out
                seen = set(counted)
                g = gain + self.gain(h0, h1, seen) + self.crossed(h0, move, s0, s1, seen)
                c = cost + self.cost(h0, move, s0, s1)
                f = first if first is not None else move
                if g > 0 and g / c > best_rate:
                    best_rate, best_move = g / c, f
                met_open = any(x in self.open_faces for x in h1.faces.values())
                if level + 1 < depth and not met_open:
                    stack.append((h1, s1, c1, g, c, f, level + 1, frozenset(seen)))
        return best_rate, best_move


def grouped_loops(poly, group: Mapping[int, int], n_groups: int) -> tuple[np.ndarray, dict[int, list[int]]]:
    """The vertices of polytope ``poly`` merged by ``group`` (each group's mean) and its faces' loops over them
    (a vertex repeated in a row dropped; a face left with fewer than three, dropped)."""
    members: list[list[int]] = [[] for _ in range(n_groups)]
    for k, g in group.items():
        members[g].append(k)
    vertices = np.array([poly.vertices[ks].mean(axis=0) for ks in members])
    loops: dict[int, list[int]] = {}
    for j, loop in poly.loops.items():
        out: list[int] = []
        for k in loop:
            if not out or out[-1] != group[k]:
                out.append(group[k])
        while len(out) > 1 and out[0] == out[-1]:
            out.pop()
        if len(out) >= 3:
            loops[j] = out
    return vertices, loops


def learning_endings(source: ClosureMoves):
    """The loop's ending conditions for a learning episode: as the loop's own, except that a ``no-match``
    verdict starts the learning (:attr:`ClosureMoves.active`) and the learning's own end and budget then apply;
    moves that fail in a row end the learning, not as a failed episode."""

    def failing(view: EpisodeState, spec) -> Ending | None:
        end = failed_in_a_row(view, spec)
        if end is not None and source.active:
            source.status = "failed"
            return Ending(NO_MATCH, f"learning: {end.detail}")
        return end

    def judged(view: EpisodeState, spec) -> Ending | None:
        if source.active:
            return source.ending(view)
        end = verdict(view, spec)
        if end is None or end.outcome != NO_MATCH:
            return end
        source.start(view)
        return source.ending(view)

    def budget(view: EpisodeState, spec) -> Ending | None:
        return None if source.active else out_of_budget(view, spec)

    return (failing, judged, budget, too_many_interpretations)


def run_learning(
    episode, settings: LearnSettings, policy=None, observer=None
) -> tuple[EpisodeRecord, Polyhedron | None]:
    """Run ``episode`` (:class:`~haptic.episode.worlds.Episode`) with the learning (:class:`ClosureMoves` first
    among the sources, :func:`learning_endings`); when it closes the surface, the learned model, written into
    ``settings.directory`` when given. The record's ``learned`` says how the learning went."""
    from haptic.episode.loop import chain_observers, drive
    from haptic.learning.boundary import boundary_model
    from haptic.learning.library import learned_name, write_learned
    from haptic.learning.reconstruct import learned_model
    from haptic.planning.registry import make_policy

    spec = episode.spec
    source = ClosureMoves(settings)
    sources = [source, *episode_sources(episode.library, episode.config, episode.policy_rng)]
    steps = loop_steps(
        spec, episode.library, episode.true_model, episode.world_from_model, episode.executor, episode.noise,
        episode.config, episode.policy_rng, chain_observers(observer, episode.observer), sources=sources,
        endings=learning_endings(source),
    )  # fmt: skip
    chooser = policy or make_policy(spec.policy)
    record = drive(steps, lambda point: chooser.choose(point.context, point.rng))
    if episode.finish is not None:
        episode.finish(record)
    learned = source.record() if source.active else None
    model = None
    if source.status == "closed":
        name = settings.name or learned_name(spec)
        try:
            if source.convex:
                model = learned_model(source.estimate, name)
            else:
                model = boundary_model(source.boundary, name)
        except LearnError as exc:
            learned["status"], learned["detail"] = "invalid", str(exc)
        else:
            learned.update(name=name, V=model.n_vertices, E=model.n_edges, F=model.n_faces,
                           volume_cm3=round(model.volume * 1e6, 4), precision_m=model.precision)  # fmt: skip
            if settings.directory is not None:
                path = write_learned(model, settings.directory, spec, source.bounds, learned)
                learned["path"] = str(path)
    record.learned = learned
    return record, model
