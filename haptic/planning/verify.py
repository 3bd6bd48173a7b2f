"""Verification moves: once one pose class is left, measure what its model predicts and the data lack.

The planner's scoring (seed §4.1) with one hypothesis left has nothing to eliminate; what a move is worth then
is what it *measures* of the remaining model that has not been measured yet: each model face, edge or vertex
still missing from the coverage target (:mod:`haptic.matching.verify`) that the move is predicted to reach, in
the hypothesis's world (:func:`~haptic.planning.search.simulate`), per unit of predicted cost, discounted by the
same risks as the planner's moves (the table, a steep descent). A move that measures nothing new now is scored
by the best two-move sequence it starts (the look-ahead of :mod:`haptic.planning.search`), and, when no such
sequence measures anything, the move that ends nearest a missing feature is taken.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3
from haptic.matching.components import DataComponent, DataEdge, DataFace, SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import FaceMove, Move, SensorState
from haptic.planning.predict import candidate_moves, predict
from haptic.planning.table import descent_risk

STALL_MOVES = 8
"""Verification moves in a row that measure no missing feature after which the verification ends with what it
has measured (status "incomplete": the episode ends as ambiguous, its record says what was not measured)."""
MAX_VERIFY_MOVES = 40
"""Verification moves after which the verification ends with what it has measured (status "incomplete").
Verification moves do not count against the episode's move budget (``EpisodeSpec.max_moves``, the budget of
recognition) but against this one: a vertex costs about two moves (an aimed face move and a short edge move, or
a vertex move and an edge trace), and the seed library's largest models have 16 vertices."""
MAX_CHECKED_LEAVES = 16
"""Interpretations of the pose class tried by the pose check (the first that passes counts)."""
MIN_SAMPLES = 3
"""A face counts as reachable on the table when at least this many of its sample points are touchable."""
AIM_NEAR_VERTEX = 6e-3
"""An aimed face move (:func:`aimed_face_moves`) ends on an edge of the current face this far from a missing
vertex [m] (at most a quarter of the edge), so that a short edge move (``c_e`` × 6 mm + ``c_k`` = 1.6 units)
measures the vertex, instead of tracing the whole edge to it (§3.1: a face costs half an edge per cm)."""


def reachable_features(
    poly: Polyhedron, world_from_model: SE3, config: PlannerConfig
) -> tuple[frozenset[int], frozenset[int], frozenset[int]]:
    """The faces, edges and vertices of ``poly`` at ``world_from_model`` that a verification can measure: all of
    them without a table; on the table (``config.table_z``), the faces the pad can touch
    (:mod:`haptic.planning.reach`), the edges between two of them and the vertices of two of them."""
    allf = frozenset(range(poly.n_faces))
    if config.table_z is None:
        return allf, frozenset(range(poly.n_edges)), frozenset(range(poly.n_vertices))
    from haptic.planning.reach import SPACING, TRACE_ROOM, _touchable

    faces = set()
    for f in range(poly.n_faces):  # interior sample points of the face's triangles
        tris = poly.triangles[poly.triangle_faces == f]
        pts = []
        for i, j, k in tris:
            a, b, c = poly.vertices[i], poly.vertices[j], poly.vertices[k]
            n = max(1, int(np.ceil(max(np.linalg.norm(b - a), np.linalg.norm(c - a)) / SPACING)))
            u, v = np.meshgrid(np.arange(1, n), np.arange(1, n), indexing="ij")
            keep = u + v < n
            pts.append(a + (u[keep] / n)[:, None] * (b - a) + (v[keep] / n)[:, None] * (c - a))
        p = np.concatenate(pts) if pts else np.zeros((0, 3))
        if not len(p):
            continue
        nrm = np.broadcast_to(poly.face_normals[f], p.shape)
        ok = _touchable(poly, world_from_model, world_from_model.apply(p), world_from_model.rotate(nrm), config,
                        TRACE_ROOM)  # fmt: skip
        if int(ok.sum()) >= MIN_SAMPLES:
            faces.add(f)
    edges = {e for e in range(poly.n_edges) if {int(poly.edge_left_face[e]), int(poly.edge_right_face[e])} <= faces}
    vertices = {v for v in range(poly.n_vertices) if sum(f in faces for f in poly.vertex_faces[v]) >= 2}
    return frozenset(faces), frozenset(edges), frozenset(vertices)


TABLE_CONTACT = 2e-3
"""A model vertex within this of the table's plane at the fitted pose rests on the table [m] (the fitted pose is
off by the noise of its data, about 1 mm on the simulated hand)."""


def hidden_vertices(poly: Polyhedron, world_from_model: SE3, cov, config: PlannerConfig) -> list[int]:
    """Vertices of ``poly`` that the verification can neither measure (not in ``cov``'s reachable vertices) nor
    take from the table (farther than :data:`TABLE_CONTACT` above it): a vertex under an overhang, or on a face
    turned to the table that rests on other vertices. An object that differs from the model there (a corner
    moved 4 mm) is not told apart by anything the hand can touch, so a verification with one is incomplete, not
    confirmed. Without a table every vertex is reachable and none is hidden."""
    if config.table_z is None:
        return []
    z = world_from_model.apply(poly.vertices)[:, 2] - config.table_z
    return [v for v in range(poly.n_vertices) if v not in cov.reachable_vertices and z[v] > TABLE_CONTACT]


def _new_features(before: Hypothesis, after: Hypothesis) -> tuple[set[int], set[int], set[int]]:
    return (
        set(after.faces.values()) - set(before.faces.values()),
        set(after.edges.values()) - set(before.edges.values()),
        set(after.vertices.values()) - set(before.vertices.values()),
    )


def _gain(new: tuple[set[int], set[int], set[int]], missing: tuple[frozenset[int], ...]) -> int:
    return sum(len(n & m) for n, m in zip(new, missing, strict=True))


def aimed_face_moves(
    h: Hypothesis,
    state: SensorState,
    components: Mapping[int, DataComponent],
    missing: tuple[frozenset[int], frozenset[int], frozenset[int]],
) -> list[FaceMove]:
    """Face moves across the current face aimed, in hypothesis ``h``'s world, at what of it is missing: a point
    :data:`AIM_NEAR_VERTEX` from each missing vertex of the face on either edge at it, and the midpoint of each
    missing edge of the face. The planner's fixed directions (§4.1) rarely end near a vertex; these do, so
    that the vertex costs a short edge move rather than an edge's length."""
    face = components.get(state.face)
    f_m = h.faces.get(state.face)
    if not isinstance(face, DataFace) or f_m is None or h.world_from_model is None:
        return []
    poly, t = h.poly, h.world_from_model
    loop = [int(v) for v in poly.faces[f_m]]
    targets = []
    for k, v in enumerate(loop):
        if v not in missing[2]:
            continue
        for nb in (loop[k - 1], loop[(k + 1) % len(loop)]):
            d = poly.vertices[nb] - poly.vertices[v]
            length = float(np.linalg.norm(d))
            if length > 0:
                targets.append(poly.vertices[v] + min(AIM_NEAR_VERTEX, 0.25 * length) * d / length)
    for e in poly.face_edges[f_m]:
        if int(e) in missing[1]:
            targets.append(poly.edge_points[e] + 0.5 * poly.edge_lengths[e] * poly.edge_directions[e])
    edge = components.get(state.edge) if state.edge is not None else None
    along = edge.direction if isinstance(edge, DataEdge) else None
    out = []
    for p in targets:
        d = t.apply(p) - state.position
        d = d - (d @ face.normal) * face.normal
        n = float(np.linalg.norm(d))
        if n < 2 * AIM_NEAR_VERTEX or (along is not None and abs(d @ along) > 0.95 * n):
            continue  # at hand, or along the edge the sensor is on (an edge move's business)
        out.append(FaceMove(d / n))
    return out


def _moves(
    h: Hypothesis, state: SensorState, components: Mapping[int, DataComponent], noise: SensorNoise,
    config: PlannerConfig, avoid: Sequence[Move],
    missing: tuple[frozenset[int], frozenset[int], frozenset[int]] | None = None,
    fixed_faces: bool = True,
) -> list[tuple[Move, float, float]]:
    """Fresh candidate moves (the planner's, and those aimed at ``missing``) with their predicted cost and risk
    (as the planner scores them), reliable and not predicted to run into the table (unless no other is left).
    The planner's face moves in fixed directions are left out when moves are aimed at something of the current
    face, and always with ``fixed_faces`` False (the second move of a look-ahead): what they can measure the
    aimed moves measure more cheaply, and each costs a prediction."""
    from haptic.planning.policies import refusal, same_move

    out = []
    aimed = aimed_face_moves(h, state, components, missing) if missing is not None else []
    fixed_faces = fixed_faces and not aimed
    planner = [m for m in candidate_moves(state, components, config) if fixed_faces or m.kind != "face"]
    for m in planner + aimed:
        if any(same_move(m, bad) for bad in avoid):
            continue
        pred = predict([h], m, state, components, noise, config)
        risk = 1.0 - (1.0 - refusal(pred, config)) * (1.0 - descent_risk(m, config))
        out.append((m, float(pred.costs[0]), risk, pred.reliable(config)))
    good = [(m, c, r) for m, c, r, rel in out if rel and r < config.table_risk]
    return good or [(m, c, r) for m, c, r, _ in out]


def choose_verification_move(
    h: Hypothesis,
    state: SensorState,
    components: Mapping[int, DataComponent],
    missing: tuple[frozenset[int], frozenset[int], frozenset[int]],
    noise: SensorNoise,
    config: PlannerConfig,
    avoid: Sequence[Move] = (),
) -> Move | None:
    """The move that measures the most missing features (faces, edges, vertices of ``missing``) of hypothesis
    ``h``'s model per unit of predicted cost, looking two moves ahead; None when no move is admissible."""
    from haptic.planning.search import simulate

    first = _moves(h, state, components, noise, config, avoid, missing)
    if not first:
        return None
    best, best_score = None, 0.0
    ends: list[tuple[Move, np.ndarray | None, float]] = []
    for m, c, r in first:
        sim = simulate(h, m, state, components, config)
        if sim is None:
            ends.append((m, None, c))
            continue
        h1, s1, comps1 = sim
        g1 = _gain(_new_features(h, h1), missing)
        score = (1.0 - r) * g1 / max(c, 1e-9)
        left = tuple(x - n for x, n in zip(missing, _new_features(h, h1), strict=True))
        for m2, c2, r2 in _moves(h1, s1, comps1, noise, config, (), left, fixed_faces=False):
            sim2 = simulate(h1, m2, s1, comps1, config)
            if sim2 is None:
                continue
            g2 = _gain(_new_features(h1, sim2[0]), left)
            score = max(score, (1.0 - r) * (1.0 - r2) * (g1 + g2) / max(c + c2, 1e-9))
        if score > best_score:
            best, best_score = m, score
        ends.append((m, h.world_from_model.inverse().apply(s1.position), c))
    if best is not None:
        return best
    # nothing within two moves: head for the nearest missing feature
    targets = _target_points(h.poly, missing)
    if not len(targets):
        return first[0][0]
    scored = [
        (float(np.linalg.norm(targets - p, axis=1).min()) if p is not None else np.inf, c, k)
        for k, (m, p, c) in enumerate(ends)
    ]
    return ends[min(scored)[2]][0]


def _target_points(poly: Polyhedron, missing: tuple[frozenset[int], frozenset[int], frozenset[int]]) -> np.ndarray:
    """A point of each missing feature, model frame: face centroids, edge midpoints, vertices; shape (K, 3)."""
    f, e, v = missing
    pts = [poly.vertices[list(poly.faces[i])].mean(axis=0) for i in sorted(f)]
    pts += [poly.edge_points[i] + 0.5 * poly.edge_lengths[i] * poly.edge_directions[i] for i in sorted(e)]
    pts += [poly.vertices[i] for i in sorted(v)]
    return np.array(pts).reshape(-1, 3)


__all__ = ["aimed_face_moves", "choose_verification_move", "hidden_vertices", "reachable_features"]


class Verifier:
    """The verification stage of an episode (``mode`` "fast" or "full", :data:`~haptic.matching.verify.TARGETS`):
    once one pose class is left, :meth:`verdict` says whether the data confirm it, contradict it, or must
    go on; :meth:`choose` picks the next verification move; :meth:`record` is what the episode reports."""

    def __init__(self, mode: str, noise: SensorNoise, config: PlannerConfig, k_sigma: float | None = None) -> None:
        from haptic.matching.verify import K_SIGMA, check_verify_mode

        self.mode = check_verify_mode(mode)
        self.noise, self.config = noise, config
        self.k_sigma = K_SIGMA if k_sigma is None else k_sigma
        """Bounds over σ of the data components, for the acceptance test."""
        self.started_at: float | None = None
        """Path cost when the verification began [units] (None: not begun)."""
        self.moves = 0
        """Verification moves made."""
        self.status = "not needed"
        """"confirmed" (recognised), "mismatch" (a component off its hard bounds: no-match), "rejected" (the
        acceptance test failed: no-match), "incomplete" (no progress in :data:`STALL_MOVES` moves, or
        :data:`MAX_VERIFY_MOVES` made: ambiguous between the model and an object outside the library),
        "verifying", or "not needed" (no pose class was ever left alone)."""
        self._progress = (-1, 0)  # (features measured, verification moves then)
        self.check = None
        self.accept = None
        self.coverage = None
        self._hyp: Hypothesis | None = None
        self.hidden: list[int] = []
        """Model vertices out of the hand's reach and off the table (:func:`hidden_vertices`)."""
        self._model_name: str | None = None
        self._model: Polyhedron | None = None
        self._reach: dict[str, tuple[frozenset[int], frozenset[int], frozenset[int]]] = {}

    def verdict(self, tree, rec, cost: float) -> str:
        """"confirmed", "mismatch", "incomplete" or "verifying" for a recognition ``rec`` (status recognized)
        of ``tree``, at path cost ``cost``."""
        from haptic.matching.verify import acceptance, coverage, pose_check

        cls = rec.classes[0]
        if self.started_at is None:
            self.started_at = cost
        # the class's interpretations put the model at one pose; they may pair a component with different model
        # components that the data cannot tell apart (coplanar faces, collinear edges): the best one counts
        best = None
        for leaf in cls.leaves[:MAX_CHECKED_LEAVES]:
            cand = tree.interpretation(leaf, with_pose=True, refine=True)
            chk = pose_check(cls.model, tree.data, cand)
            if best is None or chk.worst < best[1].worst:
                best = (cand, chk)
            if chk.ok:
                break
        it, self.check = best
        # the moves are chosen in this interpretation's world: the class's others number the model's features
        # differently (a symmetric model), and the missing ones are this one's
        self._hyp = Hypothesis(cls.name, cls.model, self.check.world_from_model, it.faces, it.edges, it.vertices,
                               len(cls.leaves), tuple(cls.leaves))  # fmt: skip
        if self.check.world_from_model is not None:
            if cls.name not in self._reach:
                self._reach[cls.name] = reachable_features(cls.model, self.check.world_from_model, self.config)
            self.coverage = coverage(cls.model, it, self._reach[cls.name])
        self._model_name, self._model = cls.name, cls.model
        if not self.check.ok:
            self.status = "mismatch"
        elif self.coverage is not None and self.coverage.met(self.mode):
            self.hidden = hidden_vertices(cls.model, self.check.world_from_model, self.coverage, self.config)
            self.status = "incomplete" if self.mode == "full" and self.hidden else "confirmed"
        else:
            self.status = "verifying"
            got = self.coverage.measured() if self.coverage is not None else 0
            if got > self._progress[0]:
                self._progress = (got, self.moves)
            elif self.moves - self._progress[1] >= STALL_MOVES:
                self.status = "incomplete"
            if self.moves >= MAX_VERIFY_MOVES:
                self.status = "incomplete"
        if self.status in ("confirmed", "incomplete"):  # the final word: the statistical acceptance test
            self.accept = acceptance(cls.model, tree.data, it, self.check.world_from_model, k_sigma=self.k_sigma)
            if not self.accept.ok:
                self.status = "rejected"
        return self.status

    def outcome(self) -> str:
        """The episode's outcome for a final verdict: recognized (confirmed), no-match (mismatch, rejected),
        ambiguous (incomplete: the data fit the model and could fit an object that differs where they have not
        measured)."""
        from haptic.matching.recognition import AMBIGUOUS, NO_MATCH, RECOGNIZED

        return {"confirmed": RECOGNIZED, "incomplete": AMBIGUOUS}.get(self.status, NO_MATCH)

    def detail(self) -> str:
        """The episode's detail line for the verdict ("" when confirmed)."""
        if self.status == "mismatch" and self.check is not None:
            c = self.check
            return (f"verification: data component {c.component} ({c.what}) off the recognised pose by "
                    f"{c.worst:.2f} bounds")  # fmt: skip
        if self.status == "rejected" and self.accept is not None:
            a = self.accept
            return (f"verification: residuals {a.statistic:.1f} over the noise model's {a.threshold:.1f} "
                    f"(chi-square, {a.dof} dof)")  # fmt: skip
        if self.status == "incomplete" and self.hidden:
            return (f"verification incomplete: {len(self.hidden)} vertices of {self._model_name} out of the hand's "
                    "reach and off the table (a difference there cannot be measured)")  # fmt: skip
        if self.status == "incomplete" and self.coverage is not None:
            f, e, v = (len(x) for x in self.coverage.missing(self.mode))
            return (f"verification incomplete after {self.moves} moves: {f} faces, {e} edges, {v} vertices of "
                    f"{self._model_name} not measured")  # fmt: skip
        return ""

    def choose(
        self, h: Hypothesis, state: SensorState, components: Mapping[int, DataComponent], avoid: Sequence[Move]
    ) -> Move | None:
        """The next verification move for hypothesis ``h`` — in the world of the interpretation whose coverage
        counts, when it has a pose (None: no move admissible)."""
        self.moves += 1
        if self._hyp is not None and self._hyp.world_from_model is not None:
            h = self._hyp
        missing = self.coverage.missing(self.mode) if self.coverage is not None else (frozenset(),) * 3
        return choose_verification_move(h, state, components, missing, self.noise, self.config, avoid)

    def record(self, cost: float) -> dict:
        """What was verified: the mode, the verdict, the verification's moves and cost, the pose check's worst
        residual ratio, and the coverage of the recognised model (counts and fractions)."""
        out: dict = {"mode": self.mode, "status": self.status, "moves": self.moves,
                     "cost": round(cost - self.started_at, 6) if self.started_at is not None else 0.0}  # fmt: skip
        if self.check is not None:
            out.update(model=self._model_name, pose_residual=round(float(self.check.worst), 4),
                       pose_component=self.check.component, pose_what=self.check.what)  # fmt: skip
        if self.accept is not None:
            out.update(chi2=round(self.accept.statistic, 3), chi2_dof=self.accept.dof,
                       chi2_threshold=round(self.accept.threshold, 3))  # fmt: skip
        if self.coverage is not None:
            out.update(self.coverage.record(self._model))
            out["vertices_hidden"] = len(self.hidden)
        return out
