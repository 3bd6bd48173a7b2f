"""The outcome each hypothesis predicts for a candidate probe, and its efficiency (seed §1.1, §4.1).

Each hypothesis predicts, through its pose, whether the line hits its object, the face hit and the distance
along the line (one vectorised line–triangle intersection per model over every candidate and pose class), and
how deep a miss-line would run inside it. From those, ``eliminates[i, j]`` says whether hypothesis ``j`` is
eliminated if ``i`` is true, and the efficiency is computed as for the tracing moves
(:func:`~haptic.planning.efficiency.efficiency_of`: expected pose classes eliminated per expected cost), so one
planner can rank probes and tracing moves together.

The elimination rule mirrors the matcher (:mod:`haptic.matching.free_space`). If ``i`` predicts a miss, ``j`` is
eliminated when the line runs inside it deeper than the free segment's margin ``ε = ρ + δ_p + a ‖x − c‖``
(the matcher's, with the pose tolerance ``δ_p``, ``a`` of :class:`~haptic.matching.recognition.PoseTolerance`).
The depth is the matcher's measure, the largest distance from the surface of points of the first inside chord
(three, at its quarters; the matcher samples more, so the prediction never says deeper than it finds). The
depth of the chord's midpoint below its entry and exit faces, ``½ · chord · min(|n_in·u|, |n_out·u|)``, would
overstate it wherever a third face runs near the chord (a line past a corner), predicting a miss to eliminate
poses the matcher keeps. If ``i`` predicts a hit, ``j`` is eliminated when it predicts
a miss, a contact farther along the line than the two contact margins allow, or a normal farther than the
angle bound: the matcher refits each pose with the contact and checks it within ``POSE_SAFETY`` times its
bounds (:func:`~haptic.matching.acceptance.pose_check`), so a contact margin is ``(1 + POSE_SAFETY) ρ + δ r``
(``δ`` the normal bound, ``r`` the contact's distance from the centroid), turned into a distance along the
line by the incidence ``|n·u|`` (at least :data:`MIN_INCIDENCE`), and the angle bound ``(1 + POSE_SAFETY) δ``.
Like every prediction of §4.1 these are expectations, not guarantees (``scripts/bench_probes.py`` compares
them with what the matcher then eliminates).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from haptic.errors import PlanningError
from haptic.geometry.distance import surface_distance
from haptic.geometry.raycast import line_hits
from haptic.matching import kernels
from haptic.matching.acceptance import POSE_SAFETY
from haptic.matching.components import DataComponent, SensorNoise
from haptic.matching.recognition import PoseTolerance
from haptic.planning.efficiency import move_score
from haptic.planning.handpath import HandStart, foot_near_boundary, pad_touches_first, pad_touches_path
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import CostModel, ProbeMove

DEPTH_FRACTIONS = np.array([0.25, 0.5, 0.75])
"""Where along a predicted miss-line's first inside chord its depth is sampled (fractions of the chord)."""


MIN_INCIDENCE = 0.2
"""Smallest ``|n·u|`` used to turn a surface offset into a distance along a line (a grazing approach)."""


@dataclass(frozen=True, eq=False)
class ProbePrediction:
    """A candidate probe with every hypothesis's predicted outcome and cost."""

    move: ProbeMove
    """The candidate."""
    hit: np.ndarray
    """Per hypothesis: whether the line meets its object before its end, shape (N,) bool."""
    distance: np.ndarray
    """Distance along the line to the contact, NaN for a miss, shape (N,) [m]."""
    face: np.ndarray
    """Model face hit, −1 for a miss, shape (N,)."""
    normal: np.ndarray
    """Outward normal of the face hit in the world frame, NaN for a miss, shape (N, 3)."""
    depth: np.ndarray
    """Estimated depth the line runs inside the object (0 for a miss), shape (N,) [m]."""
    margin: np.ndarray
    """Pose-error margin ``ε`` of a free segment at the contact, or at the object's centre for a miss, shape
    (N,) [m]."""
    contact_margin: np.ndarray
    """How far off a hypothesis's surface a contact may lie and pass the matcher's pose check, at the contact
    (NaN for a miss), shape (N,) [m]."""
    angle_bound: float
    """Bound on the angle between two predicted normals that one measurement cannot tell apart [rad]."""
    costs: np.ndarray
    """Predicted cost per hypothesis, shape (N,) [units]."""
    fails: np.ndarray | None = None
    """Per hypothesis, for the simulated hand's pad: whether it would touch something before the head-on contact
    predicted (an edge or a slot's rim beside the line, a face grazed on a miss,
    :func:`~haptic.planning.handpath.pad_touches_first`) or hit a face leaning under past its reach -- a failed
    move, not the outcome predicted --, shape (N,) bool; None for a point sensor."""

    def risk(self, weights: np.ndarray | None = None) -> float:
        """The weighted share of hypotheses in which the move fails (:attr:`fails`; 0 without)."""
        if self.fails is None:
            return 0.0
        n = len(self.fails)
        w = np.full(n, 1.0 / n) if weights is None else np.asarray(weights, dtype=float) / np.sum(weights)
        return float(self.fails @ w)

    known: np.ndarray | None = None
    """:meth:`eliminates` when already computed (a :meth:`subset` carries its share of the whole's), else None."""

    def subset(self, idx: Sequence[int], position: np.ndarray, costs: CostModel | None = None) -> ProbePrediction:
        """The prediction for hypotheses ``idx`` alone, with the sensor at ``position`` (the costs of getting to
        the line and back from there): what :func:`predict_probes` would predict for them, but for the margins,
        which keep the pose tolerance of the data this prediction was made with, and, for the simulated hand
        (:attr:`fails` set), the costs, which keep those of its path from where this prediction was made (the
        climb over the object, most of the path, changes little with where on the object the pad starts)."""
        idx = np.asarray(idx, dtype=int)
        costs = costs or CostModel()
        here = np.asarray(position, dtype=float)
        start = np.asarray(self.move.start, dtype=float)
        transfer = float(np.linalg.norm(start - here))
        back = float(np.linalg.norm(self.move.end - here))
        hit = self.hit[idx]
        s = transfer + np.where(hit, np.nan_to_num(self.distance[idx]), float(self.move.length) + back)
        return ProbePrediction(
            move=self.move, hit=hit, distance=self.distance[idx], face=self.face[idx], normal=self.normal[idx],
            depth=self.depth[idx], margin=self.margin[idx], contact_margin=self.contact_margin[idx],
            angle_bound=self.angle_bound,
            costs=np.array([costs.probe_move(x) for x in s]) if self.fails is None else self.costs[idx],
            fails=None if self.fails is None else self.fails[idx], known=self.eliminates()[np.ix_(idx, idx)],
        )  # fmt: skip

    def eliminates(self) -> np.ndarray:
        """``D[i, j]``: hypothesis ``j`` is eliminated if ``i`` is true (module docstring), shape (N, N); never
        where the hand's move fails in ``i``'s world or ``j``'s (:attr:`fails`)."""
        if self.known is not None:
            return self.known
        n = len(self.hit)
        u = np.asarray(self.move.direction)
        d = np.zeros((n, n), dtype=bool)
        hi, hj = self.hit[:, None], self.hit[None, :]
        # i misses: j runs deeper than its margin
        d |= ~hi & hj & (self.depth[None, :] > self.margin[None, :])
        # i hits: j misses, meets the line elsewhere, or with another normal
        d |= hi & ~hj
        incid = np.maximum(np.abs(np.nan_to_num(self.normal) @ u), MIN_INCIDENCE)
        along = np.nan_to_num(self.contact_margin) / incid
        with np.errstate(invalid="ignore"):
            far = np.abs(self.distance[:, None] - self.distance[None, :]) > along[:, None] + along[None, :]
            cosang = np.clip(np.nan_to_num(self.normal) @ np.nan_to_num(self.normal).T, -1.0, 1.0)
            turned = np.arccos(cosang) > self.angle_bound
        d |= hi & hj & (far | turned)
        if self.fails is not None:  # where the hand's move fails, its outcome is not the one predicted
            d &= ~self.fails[:, None] & ~self.fails[None, :]
        np.fill_diagonal(d, False)
        object.__setattr__(self, "known", d)
        return d

    def outcome_groups(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """The outcomes one measurement can tell apart, as ``(producers, alive)`` index pairs: ``producers`` the
        hypotheses whose world gives that outcome, ``alive`` every hypothesis it leaves (by :meth:`eliminates`).

        A hit and a miss are always told apart (contact or none). Every predicted miss is one outcome; it
        eliminates the hypotheses it runs deeper than their margin into, and leaves the rest, with the
        hypotheses that predict a hit but too shallow a chord for a miss to rule them out. The hits form groups
        as the tracing outcomes do (:func:`~haptic.planning.efficiency.outcome_groups`): the transitive closure
        of "one does not eliminate the other" (between two hits :meth:`eliminates` is symmetric); no hit leaves
        a hypothesis outside its group alive."""
        d = self.eliminates()
        out = []
        miss = np.flatnonzero(~self.hit)
        if len(miss):
            out.append((miss, np.flatnonzero(~d[miss].any(axis=0))))
        hit = np.flatnonzero(self.hit)
        label = -np.ones(len(self.hit), dtype=int)
        for i in hit:
            if label[i] >= 0:
                continue
            label[i] = i
            stack = [i]
            while stack:
                k = stack.pop()
                near = self.hit & (label < 0) & ~(d[k] & d[:, k])
                for j in np.flatnonzero(near):
                    label[j] = i
                    stack.append(j)
            group = np.flatnonzero(label == i)
            out.append((group, group))
        return out

    def score(self, weights: np.ndarray | None = None) -> tuple[float, float, float]:
        """Efficiency (expected eliminations per expected cost, §4.1.1), expected eliminations and expected
        cost, with ``weights`` over the hypotheses (equal when None)."""
        return move_score(self.eliminates(), self.costs, weights)


def predict_probes(
    hypotheses: Sequence[Hypothesis],
    moves: Sequence[ProbeMove],
    position: np.ndarray,
    components: Mapping[int, DataComponent] | Sequence[DataComponent],
    noise: SensorNoise,
    costs: CostModel | None = None,
    hand: HandStart | None = None,
) -> list[ProbePrediction]:
    """Every hypothesis's predicted outcome and cost for each candidate probe (hypotheses must have poses).

    ``position``: where the sensor is (world) [m], for the free-space distance; ``components``: the data so far,
    whose error bounds set the pose-error margin (:class:`~haptic.matching.recognition.PoseTolerance`).
    ``hand``: where the simulated hand's pad is, when the probe is the hand's: the free-space distance is then
    that of its path up and over the object (:mod:`haptic.planning.handpath`) and a hit adds ``c_n`` for the
    stroke measuring the face's normal; None (a point sensor): a straight transfer to the line's start and,
    after a miss, straight back from its end.
    """
    costs = costs or CostModel()
    comps = list(components.values()) if isinstance(components, Mapping) else list(components)
    tol = PoseTolerance.from_data(comps)
    rho = noise.k * noise.position_sigma
    delta = noise.k * noise.normal_sigma
    ang = (1.0 + POSE_SAFETY) * delta
    n, m = len(hypotheses), len(moves)
    if m == 0:
        return []
    starts = np.array([mv.start for mv in moves], dtype=float)
    dirs = np.array([mv.direction for mv in moves], dtype=float)
    lengths = np.array([mv.length for mv in moves], dtype=float)
    t_hit = np.full((m, n), np.inf)
    face = np.full((m, n), -1, dtype=np.int64)
    normal = np.full((m, n, 3), np.nan)
    depth = np.zeros((m, n))
    fails = np.zeros((m, n), dtype=bool)
    centre_w = np.zeros((n, 3))
    # one line–triangle intersection per model, over every candidate and every pose class of that model
    by_model: dict[int, list[int]] = {}
    for j, h in enumerate(hypotheses):
        if h.world_from_model is None:
            raise PlanningError(f"hypothesis {j} ({h.model}) has no pose: probes are predicted for posed pose classes "
                                "only (leave out those without, as candidate_probes does)")
        by_model.setdefault(id(h.poly), []).append(j)
        centre_w[j] = h.world_from_model.apply(h.poly.centroid)
    for js in by_model.values():
        poly = hypotheses[js[0]].poly
        inv = [hypotheses[j].world_from_model.inverse() for j in js]
        s_m = np.concatenate([t.apply(starts) for t in inv])  # (len(js) * m, 3), hypothesis-major
        u_m = np.concatenate([t.rotate(dirs) for t in inv])
        hits = line_hits(poly, s_m, u_m)
        first = hits.first.reshape(len(js), m).T
        fc = hits.face.reshape(len(js), m).T
        # the exit of the first inside chord: the nearest exit-facing crossing beyond the entry
        tri_n = poly.face_normals[poly.triangle_faces]  # (T, 3)
        leaving = (u_m @ tri_n.T) > 0.0
        with np.errstate(invalid="ignore"):
            beyond = np.where(leaving & (hits.params > hits.first[:, None]), hits.params, np.inf)
        k_out = np.argmin(beyond, axis=1) if beyond.shape[1] else np.zeros(len(s_m), dtype=int)
        t_out = beyond[np.arange(len(s_m)), k_out]
        # the depth as the matcher measures it: distances from the surface of points of the chord (up to the
        # line's end), the largest of DEPTH_FRACTIONS samples
        lens = np.repeat(lengths[None], len(js), axis=0).reshape(-1)
        fin = np.flatnonzero(np.isfinite(t_out) & np.isfinite(hits.first) & (hits.first < lens))
        dep = np.zeros(len(s_m))
        if len(fin):
            lo, hi = hits.first[fin], np.minimum(t_out[fin], lens[fin])
            ts = lo[:, None] + (hi - lo)[:, None] * DEPTH_FRACTIONS
            pts = s_m[fin, None, :] + ts[..., None] * u_m[fin, None, :]
            if kernels.COMPILED:
                tri = np.ascontiguousarray(poly.vertices[poly.triangles], float)
                d = kernels.surface_distance(np.ascontiguousarray(pts.reshape(-1, 3)), tri)
            else:
                d = surface_distance(poly, pts.reshape(-1, 3))
            dep[fin] = d.reshape(len(fin), -1).max(axis=1)
        if hand is not None:  # where the pad would touch before its leading point meets the face
            hit_m = hits.first <= lens
            inc = np.ones(len(s_m))
            inc[hit_m] = np.abs(np.einsum("ij,ij->i", u_m[hit_m], poly.face_normals[hits.face[hit_m]]))
            early = pad_touches_first(poly, s_m, u_m, np.where(hit_m, hits.first, lens), inc, hand.pad_radius)
            # the pad's contact on the face (its centre where it meets the plane, less the radius along the normal)
            r = hand.pad_radius
            k = np.flatnonzero(hit_m)
            tc = hits.first[k] - r * (1.0 / np.clip(inc[k], MIN_INCIDENCE, 1.0) - 1.0)
            feet = s_m[k] + (tc - r)[:, None] * u_m[k] - r * poly.face_normals[hits.face[k]]
            early[k] |= foot_near_boundary(poly, hits.face[k], feet)
            rise = hand.rise()  # the pad's way up from the surface it leaves, the same for every line
            for a, t in enumerate(inv):
                if pad_touches_path(poly, t.apply(rise), hand.pad_radius):
                    early[a * m : (a + 1) * m] = True
        for a, j in enumerate(js):
            if hand is not None:
                fails[:, j] = early[a * m : (a + 1) * m]
            t_hit[:, j] = first[:, a]
            face[:, j] = fc[:, a]
            ok = fc[:, a] >= 0
            normal[ok, j] = hypotheses[j].world_from_model.rotate(poly.face_normals[fc[ok, a]])
            depth[:, j] = dep[a * m : (a + 1) * m]
    here = np.asarray(position, dtype=float)
    if hand is None:
        transfer = np.linalg.norm(starts - here, axis=1)
        back = np.linalg.norm(starts + lengths[:, None] * dirs - here, axis=1)
        normal_cost = 0.0
    else:
        transfer, back = hand.distances(starts, dirs, lengths)
        normal_cost = costs.c_n
    out = []
    for i, mv in enumerate(moves):
        hit = t_hit[i] <= lengths[i]
        dist = np.where(hit, t_hit[i], np.nan)
        at = np.where(hit[:, None], starts[i] + np.nan_to_num(dist)[:, None] * dirs[i], centre_w)
        r = np.linalg.norm(at - centre_w, axis=1)
        margin = rho + tol.distance + tol.angle * r
        contact = np.where(hit, (1.0 + POSE_SAFETY) * rho + delta * r, np.nan)
        s = transfer[i] + np.where(hit, np.nan_to_num(dist), lengths[i] + back[i])
        c = np.array([costs.probe_move(x) for x in s])
        fail = None
        if hand is not None:
            fail = fails[i].copy()
            if hand.max_undercut is not None:
                fail |= hit & (np.nan_to_num(normal[i, :, 2]) < -np.sin(hand.max_undercut))
        out.append(ProbePrediction(
            move=mv, hit=hit, distance=dist, face=np.where(hit, face[i], -1),
            normal=np.where(hit[:, None], normal[i], np.nan), depth=np.where(hit, depth[i], 0.0), margin=margin,
            contact_margin=contact,
            angle_bound=float(ang), costs=c if hand is None else c + np.where(hit, normal_cost, 0.0), fails=fail,
        ))  # fmt: skip
    return out


__all__ = ["DEPTH_FRACTIONS", "MIN_INCIDENCE", "ProbePrediction", "predict_probes"]
