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
from haptic.matching.components import DataComponent, SensorNoise
from haptic.planning.moves import Move, SensorState
from haptic.planning.predict import Hypothesis, PlannerConfig, candidate_moves, descent_risk, predict

STALL_MOVES = 6
"""Verification moves in a row that measure no missing feature after which the verification ends with what it
has measured (status "incomplete": the episode is recognised, its record says how much was verified)."""
MAX_VERIFY_MOVES = 24
"""Verification moves after which the verification ends with what it has measured (status "incomplete"), so
that an object in the library is not left unrecognised for features the moves reach only slowly (concave
corners): measured, 5 of 20 seed-library episodes ran out of their 40-move budget without it."""
MAX_CHECKED_LEAVES = 16
"""Interpretations of the pose class tried by the pose check (the first that passes counts)."""
MIN_SAMPLES = 3
"""A face counts as reachable on the table when at least this many of its sample points are touchable."""


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


def _new_features(before: Hypothesis, after: Hypothesis) -> tuple[set[int], set[int], set[int]]:
    return (
        set(after.faces.values()) - set(before.faces.values()),
        set(after.edges.values()) - set(before.edges.values()),
        set(after.vertices.values()) - set(before.vertices.values()),
    )


def _gain(new: tuple[set[int], set[int], set[int]], missing: tuple[frozenset[int], ...]) -> int:
    return sum(len(n & m) for n, m in zip(new, missing, strict=True))


def _moves(
    h: Hypothesis, state: SensorState, components: Mapping[int, DataComponent], noise: SensorNoise,
    config: PlannerConfig, avoid: Sequence[Move],
) -> list[tuple[Move, float, float]]:
    """Fresh candidate moves with their predicted cost and risk (as the planner scores them), reliable and not
    predicted to run into the table (unless no other is left)."""
    from haptic.planning.policies import refusal, same_move

    out = []
    for m in candidate_moves(state, components, config):
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

    first = _moves(h, state, components, noise, config, avoid)
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
        for m2, c2, r2 in _moves(h1, s1, comps1, noise, config, ()):
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


__all__ = ["choose_verification_move", "reachable_features"]


class Verifier:
    """The verification stage of an episode (``mode`` "fast" or "full", :data:`~haptic.matching.verify.TARGETS`):
    once one pose class is left, :meth:`verdict` says whether the data confirm it, contradict it, or must
    go on; :meth:`choose` picks the next verification move; :meth:`record` is what the episode reports."""

    def __init__(self, mode: str, noise: SensorNoise, config: PlannerConfig) -> None:
        from haptic.matching.verify import check_verify_mode

        self.mode = check_verify_mode(mode)
        self.noise, self.config = noise, config
        self.started_at: float | None = None
        """Path cost when the verification began [units] (None: not begun)."""
        self.moves = 0
        """Verification moves made."""
        self.status = "not needed"
        """"confirmed", "mismatch", "incomplete" (no progress in :data:`STALL_MOVES` moves, or
        :data:`MAX_VERIFY_MOVES` made), "verifying", or
        "not needed" (no pose class was ever left alone)."""
        self._progress = (-1, 0)  # (features measured, verification moves then)
        self.check = None
        self.coverage = None
        self._model_name: str | None = None
        self._model: Polyhedron | None = None
        self._reach: dict[str, tuple[frozenset[int], frozenset[int], frozenset[int]]] = {}

    def verdict(self, tree, rec, cost: float) -> str:
        """"confirmed", "mismatch", "incomplete" or "verifying" for a recognition ``rec`` (status recognized)
        of ``tree``, at path cost ``cost``."""
        from haptic.matching.verify import coverage, pose_check

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
        if self.check.world_from_model is not None:
            if cls.name not in self._reach:
                self._reach[cls.name] = reachable_features(cls.model, self.check.world_from_model, self.config)
            self.coverage = coverage(cls.model, it, self._reach[cls.name])
        self._model_name, self._model = cls.name, cls.model
        if not self.check.ok:
            self.status = "mismatch"
        elif self.coverage is not None and self.coverage.met(self.mode):
            self.status = "confirmed"
        else:
            self.status = "verifying"
            got = self.coverage.measured() if self.coverage is not None else 0
            if got > self._progress[0]:
                self._progress = (got, self.moves)
            elif self.moves - self._progress[1] >= STALL_MOVES:
                self.status = "incomplete"
            if self.moves >= MAX_VERIFY_MOVES:
                self.status = "incomplete"
        return self.status

    def choose(
        self, h: Hypothesis, state: SensorState, components: Mapping[int, DataComponent], avoid: Sequence[Move]
    ) -> Move | None:
        """The next verification move for hypothesis ``h`` (None: none admissible)."""
        self.moves += 1
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
        if self.coverage is not None:
            out.update(self.coverage.record(self._model))
        return out
