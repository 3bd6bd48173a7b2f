"""The verification's tour: an order in which to measure the features still missing, and what it will cost.

Once one pose class is left, a verification must measure the features of its model that the data lack (the
vertices under ``full``, the faces and edges under ``fast``: :data:`~haptic.matching.acceptance.TARGETS`). Which
one next is a travelling-salesman problem over those features, with the cost of getting from one to the next
(seed §3.1, by the cheapest admissible way) as the distance: a closed tour by nearest neighbour and 2-opt
(:func:`plan_tour`), entered where it is cheapest from wherever a move leaves the sensor and left open before
the entry (:meth:`Tour.cost_from`). The verification (:mod:`haptic.planning.verify`) scores each candidate
move by its own predicted cost plus the tour's from where the move ends, without what the move measures, and
plans afresh after every result.

The leg costs (:class:`LegCosts`) are estimates in the cost model's units of the moves the verification makes:
a vertex is measured by an edge move that ends at it; from the vertex before it, along the edge between them
(a vertex move onto that edge, then the edge), or across a face they share (a face move aimed beside the vertex,
then a short edge move), or by a free-space probe to the face beside it (where probes are admitted) and the same
two short moves. A lower bound (:func:`tour_lower_bound`) says how far from the best possible a verification is.
Pure numpy (the exact least path's table also compiled, :mod:`haptic.planning.kernels`, the numpy form the reference).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.planning import kernels
from haptic.planning.config import PlannerConfig

FACE, EDGE, VERTEX = 0, 1, 2
"""Kinds of feature a tour visits (the order of the coverage's ``missing`` triple)."""
DETOUR = 1.2
"""A path traced over faces between two features that share no face is this many times the straight line
between them (the cheapest surface path bends round at least one edge) [-]."""
AIM_NEAR_VERTEX = 6e-3
"""An aimed face move (:func:`haptic.planning.verify.aimed_face_moves`) ends on an edge of the current face this
far from a missing vertex [m] (at most a quarter of the edge), so that a short edge move (``c_e`` × 6 mm + ``c_k``
= 1.6 units) measures the vertex, instead of tracing the whole edge to it (§3.1: a face costs half an edge per
cm)."""
CONCAVE_STEP_OFF = 3e-3
"""On the hand a face move that starts on a concave edge starts where the pad rests in the corner, touching both
faces: its contact on the current face lies the pad's radius in from the edge's line. The verifier aims such a
move from there, this much farther in (:func:`haptic.planning.verify.aimed_face_moves`) [m]."""
PROBE_INSET = 0.01
"""A verification probe aims at a point of a face this far from both edges at the missing vertex [m]: the hand's
contact stays clear of the face's boundary (:func:`~haptic.planning.handpath.foot_near_boundary`), and an aimed
face move then reaches an edge :data:`AIM_NEAR_VERTEX` from the vertex."""
MAX_TWO_OPT_PASSES = 400
"""Most 2-opt improvements of one tour (each the best reversal of all): a bound on the time of a large model's
first tour; later tours start from the last one and need few."""


@dataclass(frozen=True)
class LegCosts:
    """What it costs to measure a feature, by the way of getting there, in the cost model's units (§3.1)."""

    face_rate: float
    """``c_f``: tracing across a face [units/m]."""
    edge_rate: float
    """``c_e``: tracing along an edge [units/m]."""
    probe_rate: float
    """``c_s``: moving through free space [units/m]; 0 where probes are not admitted."""
    probe_fixed: float
    """``c_p``: per probe [units]."""
    face_events: float
    """``c_j + c_b + c_n``: a face move's edge contact, edge direction and next normal [units]."""
    vertex_event: float
    """``c_k``: detecting a vertex at the end of an edge move [units]."""
    turn: float
    """A vertex move onto the next edge at a vertex: a quarter circle at the vertex radius, and its events
    [units]."""
    probes: bool
    """Whether free-space probes are admitted (``config.moves`` not tracing, and no table: the hand verifies by
    tracing)."""

    @classmethod
    def of(cls, config: PlannerConfig, probes: bool = True) -> LegCosts:
        """The leg costs under ``config``; with ``probes`` False, tracing only whatever ``config`` admits."""
        c = config.costs
        return cls(
            face_rate=c.c_f, edge_rate=c.c_e, probe_rate=c.c_s, probe_fixed=c.c_p,
            face_events=c.c_j + c.c_b + c.c_n, vertex_event=c.c_k,
            turn=c.c_v * config.vertex_radius * np.pi / 2 + c.c_j + c.c_b + c.c_n,
            probes=probes and config.moves != "tracing" and config.table_z is None,
        )  # fmt: skip

    def finish(self, kinds: np.ndarray) -> np.ndarray:
        """Cost of measuring a feature of each kind once on a face beside it: a vertex, a face move aimed beside
        it and a short edge move; an edge, a face move to it; a face, nothing more [units]."""
        vertex = self.face_events + self.edge_rate * AIM_NEAR_VERTEX + self.vertex_event
        return np.select([kinds == VERTEX, kinds == EDGE], [vertex, self.face_events], 0.0)

    def by_probe(self, distance: np.ndarray, kinds: np.ndarray, finish: np.ndarray | None = None) -> np.ndarray:
        """A probe to the face beside the feature (from ``distance`` away), then :meth:`finish` from ``PROBE_INSET``
        in (``finish``: :meth:`finish` of ``kinds`` when already computed); inf where probes are not admitted
        [units]."""
        if not self.probes:
            return np.full(np.shape(distance), np.inf)
        inset = np.where(kinds == FACE, 0.0, self.face_rate * PROBE_INSET)
        fin = self.finish(kinds) if finish is None else finish
        return self.probe_fixed + self.probe_rate * distance + inset + fin

    def by_tracing(
        self, distance: np.ndarray, kinds: np.ndarray, cofacial: np.ndarray, finish: np.ndarray | None = None
    ) -> np.ndarray:
        """Across a face shared with the feature (straight), else over faces (:data:`DETOUR`, one face move more),
        then :meth:`finish` (``finish``: that of ``kinds`` when already computed) [units]."""
        fin = self.finish(kinds) if finish is None else finish
        straight = self.face_rate * distance + fin
        return np.where(cofacial, straight, DETOUR * self.face_rate * distance + self.face_events + fin)


@dataclass(frozen=True, eq=False)
class Features:
    """Every face, edge and vertex of a model as a point to visit (model frame), with which faces each is on."""

    kinds: np.ndarray
    """:data:`FACE`, :data:`EDGE` or :data:`VERTEX` per feature, shape (K,)."""
    ids: np.ndarray
    """The model's index of each feature among those of its kind, shape (K,)."""
    points: np.ndarray
    """Where a move measures it: a point inside the face, the edge's midpoint, the vertex, shape (K, 3) [m]."""
    on_face: np.ndarray
    """Whether feature k lies on (is, bounds, or is a corner of) model face f, shape (K, F) bool."""
    edge_between: np.ndarray
    """The model edge between two vertices (−1: none; -1 for every pair not of two vertices), shape (K, K)."""

    def index(self, missing: tuple[frozenset[int], frozenset[int], frozenset[int]]) -> np.ndarray:
        """Feature indices of the ``(faces, edges, vertices)`` of ``missing``, in that order, each sorted."""
        start = {FACE: 0, EDGE: int((self.kinds == FACE).sum()), VERTEX: int((self.kinds != VERTEX).sum())}
        return np.array([start[k] + i for k, ids in enumerate(missing) for i in sorted(ids)], dtype=np.int64)


_FEATURES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def features(poly: Polyhedron) -> Features:
    """:class:`Features` of ``poly`` (computed once per model)."""
    if poly in _FEATURES:
        return _FEATURES[poly]
    from haptic.planning.probe_lines import face_targets

    nf, ne, nv = poly.n_faces, poly.n_edges, poly.n_vertices
    kinds = np.concatenate([np.full(nf, FACE), np.full(ne, EDGE), np.full(nv, VERTEX)])
    ids = np.concatenate([np.arange(nf), np.arange(ne), np.arange(nv)])
    mids = poly.edge_points + 0.5 * poly.edge_lengths[:, None] * poly.edge_directions
    points = np.concatenate([face_targets(poly), mids, poly.vertices])
    on = np.zeros((nf + ne + nv, nf), dtype=bool)
    on[np.arange(nf), np.arange(nf)] = True
    on[nf + np.arange(ne), poly.edge_left_face] = True
    on[nf + np.arange(ne), poly.edge_right_face] = True
    for f in range(nf):
        on[nf + ne + np.asarray(poly.faces[f], dtype=np.int64), f] = True
    between = np.full((len(kinds), len(kinds)), -1, dtype=np.int64)
    a, b = nf + ne + poly.edges[:, 0], nf + ne + poly.edges[:, 1]
    between[a, b] = between[b, a] = np.arange(ne)
    out = Features(kinds, ids, points, on, between)
    _FEATURES[poly] = out
    return out


def leg_matrix(poly: Polyhedron, targets: np.ndarray, legs: LegCosts) -> np.ndarray:
    """Cost of measuring target ``j`` after target ``i`` (feature indices of :func:`features`), the cheapest of:
    along the edge between two vertices (a vertex move onto it, the edge, the vertex's detection), across a face
    they share or over faces (:meth:`LegCosts.by_tracing`), by a probe (:meth:`LegCosts.by_probe`); shape
    (n, n), symmetric, 0 on the diagonal [units]."""
    feats = features(poly)
    p, kinds = feats.points[targets], feats.kinds[targets]
    d = np.linalg.norm(p[:, None] - p[None], axis=2)
    on = feats.on_face[targets].astype(np.int64)
    cofacial = (on @ on.T) > 0
    to_kind = np.broadcast_to(kinds[None, :], d.shape)
    cost = np.minimum(legs.by_tracing(d, to_kind, cofacial), legs.by_probe(d, to_kind))
    edge = feats.edge_between[np.ix_(targets, targets)]
    along = legs.turn + legs.edge_rate * d + legs.vertex_event
    cost = np.where(edge >= 0, np.minimum(cost, along), cost)
    cost = np.minimum(cost, cost.T)  # the cheaper way either way round
    np.fill_diagonal(cost, 0.0)
    return cost


def start_costs(
    poly: Polyhedron, position: np.ndarray, face: int | None, edge: int | None, targets: np.ndarray, legs: LegCosts
) -> np.ndarray:
    """Cost of measuring each target first from a sensor at ``position`` (model frame) on model ``face`` and,
    when known, model ``edge``: by tracing (along the edge to a vertex at its end, or across the face, or over
    faces) or by a probe; shape (n,) [units]."""
    return StartCosts(poly, targets, legs)(position, face, edge)


class StartCosts:
    """:func:`start_costs` of fixed targets from wherever the sensor is: what depends on the targets alone (their
    points, kinds, faces and the cost of finishing each) gathered once, for a verification decision that prices
    the tour from where each of its candidate moves would end."""

    def __init__(self, poly: Polyhedron, targets: np.ndarray, legs: LegCosts) -> None:
        feats = features(poly)
        self.poly, self.targets, self.legs = poly, targets, legs
        self.points, self.kinds = feats.points[targets], feats.kinds[targets]
        self.on_face = feats.on_face[targets]
        self.finish = legs.finish(self.kinds)
        self.vertex_base = feats.kinds.size - poly.n_vertices
        """Feature index of the model's vertex 0."""

    def __call__(self, position: np.ndarray, face: int | None, edge: int | None) -> np.ndarray:
        """The costs from a sensor at ``position`` (model frame) on model ``face`` and, when known, ``edge``,
        shape (n,) [units]."""
        legs, kinds, fin = self.legs, self.kinds, self.finish
        d = np.linalg.norm(self.points - np.asarray(position), axis=1)
        cofacial = self.on_face[:, face] if face is not None else np.zeros(len(self.targets), dtype=bool)
        cost = np.minimum(legs.by_tracing(d, kinds, cofacial, fin), legs.by_probe(d, kinds, fin))
        if edge is not None:
            a, b = self.vertex_base + self.poly.edges[edge]
            at_end = (self.targets == a) | (self.targets == b)
            cost = np.where(at_end, np.minimum(cost, legs.edge_rate * d + legs.vertex_event), cost)
        return cost


@dataclass(frozen=True)
class Tour:
    """A closed tour over the targets (feature indices), its legs' costs and its total."""

    order: tuple[int, ...]
    """Targets in the tour's order (feature indices of :func:`features`)."""
    legs: np.ndarray
    """The leg matrix over ``sorted(order)`` (:func:`leg_matrix`)."""
    cost: float
    """Sum of the legs round the tour [units]."""

    def cost_from(self, start: np.ndarray, without: frozenset[int] = frozenset()) -> float:
        """The least cost of visiting every target but ``without`` in the tour's order, either way round, entered
        at any of them from a sensor whose cost to each is ``start`` (over ``sorted(order)``) and left open
        before the entry: ``start[k] + tour − (the larger leg at k)`` [units]; 0 with nothing to visit."""
        keys = sorted(self.order)
        pos = {t: i for i, t in enumerate(keys)}
        ring = [pos[t] for t in self.order if t not in without]
        if not ring:
            return 0.0
        if len(ring) == 1:
            return float(start[ring[0]])
        r = np.array(ring)
        leg = self.legs[r, np.concatenate((r[1:], r[:1]))]  # (np.roll's values, without its axis handling)
        total = float(leg.sum())
        drop = np.maximum(leg, np.concatenate((leg[-1:], leg[:-1])))  # the leg after each target, or the one before
        return float((start[r] + total - drop).min())


def _two_opt(order: np.ndarray, legs: np.ndarray) -> np.ndarray:
    """Closed-tour 2-opt: reverse the stretch whose reversal saves the most, while one saves anything."""
    n = len(order)
    if n < 4:
        return order
    i, j = np.triu_indices(n, 1)
    keep = ~((i == 0) & (j == n - 1))
    i, j = i[keep], j[keep]
    for _ in range(MAX_TWO_OPT_PASSES):
        a, b = order[i - 1], order[i]
        c, d = order[j], order[(j + 1) % n]
        gain = legs[a, b] + legs[c, d] - legs[a, c] - legs[b, d]
        k = int(np.argmax(gain))
        if gain[k] <= 1e-9:
            break
        order = np.concatenate([order[: i[k]], order[i[k] : j[k] + 1][::-1], order[j[k] + 1 :]])
    return order


def plan_tour(poly: Polyhedron, targets: np.ndarray, legs: LegCosts, previous: Tour | None = None) -> Tour:
    """A closed tour over ``targets`` (feature indices): the previous tour's order without the targets measured
    since, with any new targets inserted where they cost least, or nearest neighbour from the first target; then
    2-opt (:func:`_two_opt`)."""
    keys = np.array(sorted(int(t) for t in targets), dtype=np.int64)
    m = leg_matrix(poly, keys, legs) if len(keys) else np.zeros((0, 0))
    pos = {int(t): i for i, t in enumerate(keys)}
    if previous is not None:
        order = [pos[t] for t in previous.order if t in pos]
        for t in keys:
            if pos[int(t)] in order:
                continue
            if len(order) < 2:
                order.append(pos[int(t)])
                continue
            r = np.array(order)
            extra = m[r, pos[int(t)]] + m[pos[int(t)], np.roll(r, -1)] - m[r, np.roll(r, -1)]
            order.insert(int(np.argmin(extra)) + 1, pos[int(t)])
    else:
        order, left = [], set(range(len(keys)))
        while left:
            k = min(left, key=lambda j: m[order[-1], j]) if order else min(left)
            order.append(k)
            left.discard(k)
    o = _two_opt(np.array(order, dtype=np.int64), m)
    cost = float(m[o, np.roll(o, -1)].sum()) if len(o) > 1 else 0.0
    return Tour(tuple(int(keys[k]) for k in o), m, cost)


HELD_KARP_MOST = 16
"""Vertices to measure up to which :func:`tour_lower_bound` takes the least path through them exactly (Held-Karp
dynamic programming, ``2^n n^2`` steps: about 1.5 ms of CPU time at 10 vertices, 23 at 14, 100 at 16 in numpy,
0.1, 2 and 10 ms compiled; once per verification and once for its record); beyond, the minimum spanning tree
(:func:`spanning_tree_bound`)."""


def _bound_legs(poly: Polyhedron, position: np.ndarray, vertex_ids: np.ndarray, legs: LegCosts) -> np.ndarray:
    """The lower-bounding legs of :func:`tour_lower_bound` between the sensor at ``position`` (row and column 0)
    and the vertices ``vertex_ids`` (the rest): the straight line ``d`` at the cheapest way of covering it,
    ``min(c_f d, c_p + c_s d)`` (probes where admitted), shape (n + 1, n + 1) [units]."""
    p = np.vstack([np.asarray(position, float)[None], poly.vertices[vertex_ids]])
    d = np.linalg.norm(p[:, None] - p[None], axis=2)
    w = legs.face_rate * d
    if legs.probes:
        w = np.minimum(w, legs.probe_fixed + legs.probe_rate * d)
    np.fill_diagonal(w, 0.0)
    return w


def least_path(w: np.ndarray, enter: np.ndarray, first: np.ndarray) -> float:
    """The least cost of a path from node 0 through every other node of ``w`` (shape (n + 1, n + 1)), each step
    from ``i`` to ``j`` costing ``w[i, j] + enter[j - 1]``, but the first ``w[0, j] + first[j - 1]``: Held-Karp
    dynamic programming over the subsets of nodes visited and the last of them, exact; 0 with no node but 0."""
    n = len(w) - 1
    if n <= 0:
        return 0.0
    step = w[1:, 1:] + enter[None, :]  # step[j, k]: from node j + 1 to node k + 1
    if kernels.COMPILED:  # the same table in one compiled loop, without the arrays of subsets
        start = np.ascontiguousarray(w[0, 1:] + first, float)
        return float(kernels.least_path(start, np.ascontiguousarray(step, float)))
    masks = np.arange(1 << n, dtype=np.int64)
    count = np.zeros(1 << n, dtype=np.int64)
    for k in range(n):
        count += (masks >> k) & 1
    best = np.full((1 << n, n), np.inf)
    best[1 << np.arange(n), np.arange(n)] = w[0, 1:] + first
    for size in range(1, n):
        layer = masks[count == size]
        here = best[layer]  # (m, n): inf where the last node is not in the subset
        for k in range(n):
            out = (layer >> k) & 1 == 0
            best[layer[out] | (1 << k), k] = (here[out] + step[:, k][None, :]).min(axis=1)
    return float(best[-1].min())


def tour_lower_bound(
    poly: Polyhedron,
    position: np.ndarray,
    targets: np.ndarray,
    legs: LegCosts,
    first: frozenset[int] | None = None,
    middles: np.ndarray | None = None,
    reach: float = 0.0,
) -> float:
    """A lower bound of the cost of measuring every vertex among ``targets`` from a sensor at ``position`` (model
    frame) [units]: each is measured by an edge move that ends at it (``c_k`` each), and the sensor's path passes
    through all of them in some order, from where it is; a stretch of that path from one contact to the next, of
    length at least the straight line ``d`` between them, costs at least ``min(c_f d, c_p + c_s d)`` (tracing at
    the face rate, the cheapest, or at least one probe: ``c_s`` < ``c_f``; probes where admitted). Features that
    are not vertices add nothing.

    Each vertex's edge move also starts on an edge at it, which the move before it brought the sensor onto
    (:func:`arrival_costs`): every vertex adds the least cost of that arrival beyond the path's length at the face
    rate, but for the first vertex measured the sensor may start on that edge already: ``first`` are the model
    vertices it may measure first without arriving (the ends of the model edge the sensor is on; an empty set
    when it is on none; None, as by default, when that is not known: any).

    ``middles`` (shape (m, 3), model frame) are points the path must also touch, each within ``reach``, by a
    probe's contact (that no other move touches them is the caller's to show): the stretch into one ends with a
    probe, at least ``c_p + c_s (d - reach)``, the stretch out of it is a leg as above over ``d - reach``, and it
    adds no detection nor arrival. Those beyond :data:`HELD_KARP_MOST` nodes in all are left out of the exact path
    and count what taking each out of a path at least saves (:func:`_least_insertion`, the least over every two
    nodes it could lie between): taking them out one by one leaves a path over the rest, itself at least the
    exact one's (or the spanning tree's) cost.

    The least path through the vertices and middles in any order over those legs is a lower bound, and it is
    found exactly for up to :data:`HELD_KARP_MOST` of them (:func:`least_path`); beyond that many vertices,
    :func:`spanning_tree_bound` (and the middles as beyond the exact path)."""
    feats = features(poly)
    vertex_ids = feats.ids[targets[feats.kinds[targets] == VERTEX]]
    if not len(vertex_ids):
        return 0.0
    n = len(vertex_ids)
    mids = np.zeros((0, 3)) if middles is None else np.asarray(middles, float).reshape(-1, 3)
    arrive = arrival_costs(poly, legs)[vertex_ids]
    free = np.ones(n, dtype=bool) if first is None else np.isin(vertex_ids, sorted(first))
    w = _bound_legs(poly, position, vertex_ids, legs)
    if not len(mids):
        if n > HELD_KARP_MOST:
            return spanning_tree_bound(poly, position, targets, legs, first)
        return least_path(w, arrive, np.where(free, 0.0, arrive)) + legs.vertex_event * n
    p = np.vstack([np.asarray(position, float)[None], poly.vertices[vertex_ids], mids])
    d = np.linalg.norm(p[:, None] - p[None], axis=2)
    is_mid = np.arange(len(p)) > n
    # each middle is touched within reach: the legs out of it and into it are that much shorter
    d = np.maximum(d - reach * (is_mid[:, None].astype(float) + is_mid[None, :]), 0.0)
    w = legs.face_rate * d
    if legs.probes:
        w = np.minimum(w, legs.probe_fixed + legs.probe_rate * d)
    w[:, is_mid] = legs.probe_fixed + legs.probe_rate * d[:, is_mid]  # into a middle: a probe
    np.fill_diagonal(w, 0.0)
    # the middles beyond the exact path's room: each at least the least a path's cost drops when it is taken out
    # between any two nodes (or at the path's end), the weakest kept in the exact path
    gain = _least_insertion(w, np.flatnonzero(is_mid))
    room = max(HELD_KARP_MOST - n, 0)
    kept = np.sort(np.argsort(gain, kind="stable")[:room])
    out = float(np.delete(gain, kept).sum())
    if n > HELD_KARP_MOST:
        return spanning_tree_bound(poly, position, targets, legs, first) + out
    nodes = np.concatenate([np.arange(n + 1), n + 1 + kept])
    w = w[np.ix_(nodes, nodes)]
    enter = np.concatenate([arrive, np.zeros(len(kept))])
    start = np.concatenate([np.where(free, 0.0, arrive), np.zeros(len(kept))])
    return least_path(w, enter, start) + legs.vertex_event * n + out


def _least_insertion(w: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Per node ``k`` of ``nodes`` (indices of ``w``, node 0 the start), the least ``w[a, k] + w[k, b] - w[a, b]``
    over the other nodes ``a`` before it and ``b`` after it (not the start), or ``w[a, k]`` with none after: what a
    path over ``w`` at least saves when ``k`` is taken out of it, between whichever nodes it then lies [units]."""
    out = np.empty(len(nodes))
    size = len(w)
    for i, k in enumerate(nodes):
        through = w[:, k][:, None] + w[k, :][None, :] - w
        ok = np.ones((size, size), dtype=bool)
        ok[k, :] = ok[:, k] = False
        ok[:, 0] = False
        np.fill_diagonal(ok, False)
        last = np.delete(w[:, k], k)
        out[i] = min(float(through[ok].min()) if ok.any() else np.inf, float(last.min()))
    return out


def spanning_tree_bound(
    poly: Polyhedron, position: np.ndarray, targets: np.ndarray, legs: LegCosts, first: frozenset[int] | None = None
) -> float:
    """:func:`tour_lower_bound` with the path's legs bounded by the minimum spanning tree of the sensor and the
    vertices (any path through them is a spanning tree) and the arrivals by every vertex's but the dearest of
    those that may be first (``first``, None: any) [units]; a weaker bound, for many vertices."""
    from scipy.sparse.csgraph import minimum_spanning_tree

    feats = features(poly)
    vertex_ids = feats.ids[targets[feats.kinds[targets] == VERTEX]]
    if not len(vertex_ids):
        return 0.0
    arrive = arrival_costs(poly, legs)[vertex_ids]
    free = np.ones(len(vertex_ids), dtype=bool) if first is None else np.isin(vertex_ids, sorted(first))
    w = _bound_legs(poly, position, vertex_ids, legs)
    # a zero (or, to scipy's dense input, a near-zero) entry is no edge of the spanning tree: coincident points are
    # joined at a floor that the sum then leaves out
    floor = 1e-3
    w = np.maximum(w, floor)
    np.fill_diagonal(w, 0.0)
    tree = minimum_spanning_tree(w).data
    path = float(tree[tree > floor].sum())
    spared = float(arrive[free].max()) if free.any() else 0.0
    return path + legs.vertex_event * len(vertex_ids) + float(arrive.sum()) - spared


def arrival_costs(poly: Polyhedron, legs: LegCosts) -> np.ndarray:
    """Per vertex of ``poly``, the least cost, beyond its length at the face rate, of the move that brings the sensor
    onto an edge at the vertex before the edge move that measures it, shape (V,) [units]: a face move that ends on
    the edge, or a vertex move onto it at its other end, detect the edge, its direction and the next face's normal
    (``c_j + c_b + c_n``); an edge move that ends at the other end (the sensor then goes back along the edge) traces
    the whole edge at the edge rate, ``(c_e - c_f)`` per metre more than across a face; a probe ends on a face,
    never on an edge. The least of these, over the edges at the vertex."""
    shortest = np.full(poly.n_vertices, np.inf)
    np.minimum.at(shortest, poly.edges[:, 0], poly.edge_lengths)
    np.minimum.at(shortest, poly.edges[:, 1], poly.edge_lengths)
    return np.minimum(legs.face_events, max(legs.edge_rate - legs.face_rate, 0.0) * shortest)


__all__ = [
    "EDGE",
    "FACE",
    "VERTEX",
    "Features",
    "LegCosts",
    "StartCosts",
    "Tour",
    "arrival_costs",
    "features",
    "leg_matrix",
    "plan_tour",
    "least_path",
    "spanning_tree_bound",
    "start_costs",
    "tour_lower_bound",
]
