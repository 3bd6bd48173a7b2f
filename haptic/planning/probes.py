"""Candidate free-space probes and their predicted outcomes under each hypothesis (seed §1.1, §4.1).

A probe is a line (:class:`~haptic.planning.moves.ProbeMove`) the sensor approaches along until contact or the
line's end. Candidates aim at the hypotheses' surfaces: for every pose class and every face that class puts
in the world, the face's centre approached from a discrete set of directions within :attr:`ProbeConfig.
max_incidence` of head-on, each line starting just before the first ball holding a hypothesis's object that it
meets and ending just past the last (:attr:`ProbeConfig.standoff`), clear of the table. Lines that nearly
coincide (same direction, targets within :attr:`ProbeConfig.target_spacing` across it) are one candidate.

Each hypothesis predicts, through its pose, whether the line hits its object, the face hit and the distance
along the line (one vectorised line–triangle intersection per model over every candidate and pose class), and
how deep a miss-line would run inside it. From those, ``eliminates[i, j]`` says whether hypothesis ``j`` is
eliminated if ``i`` is true, and the efficiency is computed as for the tracing moves
(:func:`~haptic.planning.efficiency.efficiency_of`: expected pose classes eliminated per expected cost), so one
planner can rank probes and tracing moves together.

The elimination rule mirrors the matcher (:mod:`haptic.matching.probes`). If ``i`` predicts a miss, ``j`` is
eliminated when the line runs inside it deeper than the free segment's margin ``ε = ρ + δ_p + a ‖x − c‖``
(the matcher's, with the pose tolerance ``δ_p``, ``a`` of :class:`~haptic.matching.recognition.PoseTolerance`).
The depth is the matcher's measure, the largest distance from the surface of points of the first inside chord
(three, at its quarters; the matcher samples more, so the prediction never says deeper than it finds). The
depth of the chord's midpoint below its entry and exit faces, ``½ · chord · min(|n_in·u|, |n_out·u|)``, would
overstate it wherever a third face runs near the chord (a line past a corner), predicting a miss to eliminate
poses the matcher keeps. If ``i`` predicts a hit, ``j`` is eliminated when it predicts
a miss, a contact farther along the line than the two contact margins allow, or a normal farther than the
angle bound: the matcher refits each pose with the contact and checks it within ``POSE_SAFETY`` times its
bounds (:func:`~haptic.matching.verify.pose_check`), so a contact margin is ``(1 + POSE_SAFETY) ρ + δ r``
(``δ`` the normal bound, ``r`` the contact's distance from the centroid), turned into a distance along the
line by the incidence ``|n·u|`` (at least :data:`MIN_INCIDENCE`), and the angle bound ``(1 + POSE_SAFETY) δ``.
Like every prediction of §4.1 these are expectations, not guarantees (``scripts/bench_probes.py`` compares
them with what the matcher then eliminates).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from haptic.errors import PlanningError
from haptic.geometry.distance import surface_distance
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.raycast import line_hits
from haptic.matching.components import DataComponent, DataFace, SensorNoise
from haptic.matching.recognition import PoseTolerance
from haptic.matching.verify import POSE_SAFETY
from haptic.planning.efficiency import efficiency_of, expected_eliminated
from haptic.planning.handpath import HandStart, foot_near_boundary, pad_touches_first, pad_touches_path
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import CostModel, ProbeMove

BEHIND = 0.05
"""Opening probes head along every known face's normal, or across it within this (``u · n ≥ −0.05``)."""
DEPTH_FRACTIONS = np.array([0.25, 0.5, 0.75])
"""Where along a predicted miss-line's first inside chord its depth is sampled (fractions of the chord)."""
MIN_INCIDENCE = 0.2
"""Smallest ``|n·u|`` used to turn a surface offset into a distance along a line (a grazing approach)."""
FINGER_LIFT = 0.08
"""Height above the pad's centre through which the finger above it must be free [m] (as
:data:`haptic.planning.reach.LIFT`)."""


@dataclass(frozen=True)
class ProbeConfig:
    """Options of probe candidate generation."""

    n_directions: int = 26
    """Approach directions, spread evenly over the sphere (a Fibonacci lattice) (§4.1.3: discrete angles)."""
    max_incidence: float = np.deg2rad(50.0)
    """A face is approached from directions within this of its inward normal [rad]."""
    target_spacing: float = 0.01
    """Targets closer than this across a common direction make one candidate [m]."""
    standoff: float = 0.01
    """Lines start this far before the first sphere they meet that holds a hypothesis's posed object (at its
    centroid, through its farthest vertex), and a miss runs this far past the last one: free space farther out
    tells nothing and costs ``c_s`` per metre [m]."""
    max_candidates: int = 64
    """Most candidates offered (an even subsample of them beyond it)."""
    table_z: float | None = None
    """Height of the table top in the world frame (a workspace prior; None: no table) [m]."""
    table_clearance: float = 0.004
    """Every point of a line stays at least this above the table top; lines are cut short there [m]."""
    max_climb: float = 0.5
    """With a table, the approach may rise at most this steeply (the z of its unit direction): the hand comes
    from above or the side, never from under the object."""
    pad_radius: float = 0.0
    """Radius of a fingertip pad whose leading point (its centre plus the radius along the line) travels the
    line (0: a point sensor). With a table, the pad's lowest point -- up to a radius below the line -- stays
    ``table_clearance`` above the top, and the line's start can be reached from above: the pad centre there is
    outside the sphere holding every hypothesis's object by the radius, and so is the vertical column above it
    (the hand descends to the start from over the object); the finger above the pad stays clear of every
    hypothesis's object along the line (:func:`finger_clear`) [m]."""
    max_undercut: float | None = None
    """Faces whose outward normal leans under (points down) by more than this are not aimed at: the pad of a
    finger pointing down cannot press on them (its phalanx meets the object first) [rad]. None: no limit."""


def fibonacci_directions(n: int) -> np.ndarray:
    """``n`` unit vectors spread evenly over the sphere, shape (n, 3)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + np.sqrt(5.0)) * k
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, 1.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def face_targets(poly) -> np.ndarray:
    """A point inside each face (model frame): the centroid of its largest triangle, shape (F, 3)."""
    tri = poly.vertices[poly.triangles]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    out = np.zeros((poly.n_faces, 3))
    best = np.full(poly.n_faces, -1.0)
    for k, f in enumerate(poly.triangle_faces):
        if area[k] > best[f]:
            best[f], out[f] = area[k], tri[k].mean(axis=0)
    return out


def _region(hypotheses: Sequence[Hypothesis]) -> tuple[np.ndarray, float]:
    """Centre and radius of a sphere holding every hypothesis's posed object [m]."""
    pts = np.concatenate([h.world_from_model.apply(h.poly.vertices) for h in hypotheses])
    centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    return centre, float(np.linalg.norm(pts - centre, axis=1).max())


def candidate_probes(hypotheses: Sequence[Hypothesis], config: ProbeConfig | None = None) -> list[ProbeMove]:
    """Probe lines toward the hypotheses' surfaces (see the module docstring); hypotheses without a pose are
    skipped, and none are offered when no hypothesis has one."""
    config = config or ProbeConfig()
    posed = [h for h in hypotheses if h.world_from_model is not None]
    if not posed:
        return []
    centre, radius = _region(posed)
    big = radius + config.standoff
    dirs = fibonacci_directions(config.n_directions)
    if config.table_z is not None:
        dirs = dirs[dirs[:, 2] <= config.max_climb]
    cos_max = np.cos(config.max_incidence)
    balls = _hypothesis_balls(posed)
    seen: set[tuple] = set()
    out: list[ProbeMove] = []
    for h in posed:
        t = h.world_from_model
        targets, normals = t.apply(face_targets(h.poly)), t.rotate(h.poly.face_normals)
        facing = (dirs @ normals.T) <= -cos_max  # (D, F)
        if config.max_undercut is not None:
            facing &= (normals[:, 2] >= -np.sin(config.max_undercut))[None, :]
        for di, fi in zip(*np.nonzero(facing), strict=True):
            u, p = dirs[di], targets[fi]
            # the target's position across the direction, snapped to the grid: one candidate per cell
            across = p - (p @ u) * u
            key = (int(di), *np.round(across / config.target_spacing).astype(int).tolist())
            if key in seen:
                continue
            seen.add(key)
            move = _probe_line(p, u, centre, big, radius, balls, config)
            if move is not None:
                out.append(move)
    if len(out) > config.max_candidates:
        pick = np.linspace(0, len(out) - 1, config.max_candidates).round().astype(int)
        out = [out[i] for i in pick]
    if out and config.pad_radius > 0.0 and config.table_z is not None:
        clear = finger_clear(posed, out, config.pad_radius)
        out = [mv for mv, ok in zip(out, clear, strict=True) if ok]
    return out


def _probe_line(p: np.ndarray, u: np.ndarray, centre: np.ndarray, big: float, radius: float, balls,
                config: ProbeConfig) -> ProbeMove | None:  # fmt: skip
    """The candidate line along ``u`` through ``p`` (:func:`_line_through` the region's sphere), cut to the balls
    that hold the hypotheses' objects; None when there is none."""
    move = _line_through(p, u, centre, big, config, radius)
    if move is None:
        return None
    clipped = _clip_to_balls(move, balls, config.standoff, union=True)
    if clipped is not None and config.pad_radius > 0.0:
        # the hand comes down to the line's start from above, clear of every hypothesis's object: the start stays
        # there, only the end is cut
        clipped = ProbeMove(move.start, u, float((clipped.end - move.start) @ u))
    return clipped


def aimed_probes(
    h: Hypothesis, targets: Sequence[tuple[np.ndarray, int]], config: ProbeConfig | None = None
) -> list[tuple[ProbeMove, int]]:
    """Probe lines at chosen points of hypothesis ``h``'s posed model: for each ``(point, face)`` (model frame,
    the point on that face), the line through the point head-on (along the face's inward normal) or, where that
    one is not admissible (the table, the hand's way down, the finger above the pad, :func:`candidate_probes`'
    rules), along the admissible one of the discrete directions within ``max_incidence`` of head-on nearest to
    it; at most one line per target, with its target's index. A verification uses them to carry the sensor to
    a part of the model still to be measured (:mod:`haptic.planning.verify`)."""
    config = config or ProbeConfig()
    if h.world_from_model is None or not len(targets):
        return []
    t = h.world_from_model
    centre, radius = _region([h])
    big = radius + config.standoff
    balls = _hypothesis_balls([h])
    dirs = fibonacci_directions(config.n_directions)
    cos_max = np.cos(config.max_incidence)
    lines: list[tuple[ProbeMove, int]] = []
    for k, (point, f) in enumerate(targets):
        n = t.rotate(h.poly.face_normals[f])
        if config.max_undercut is not None and n[2] < -np.sin(config.max_undercut):
            continue
        p = t.apply(point)
        near = dirs[dirs @ -n >= cos_max]
        near = near[np.argsort(-(near @ -n))]
        for u in (-n, *near):
            if config.table_z is not None and u[2] > config.max_climb:
                continue
            move = _probe_line(p, u, centre, big, radius, balls, config)
            if move is not None:
                lines.append((move, k))
    if lines and config.pad_radius > 0.0 and config.table_z is not None:
        clear = finger_clear([h], [mv for mv, _ in lines], config.pad_radius)
        lines = [x for x, ok in zip(lines, clear, strict=True) if ok]
    out, seen = [], set()
    for mv, k in lines:  # the first admissible line of each target (head-on first)
        if k not in seen:
            seen.add(k)
            out.append((mv, k))
    return out


FINGER_SAMPLES = 8
"""Points along a line's pad path at which :func:`finger_clear` checks the finger above the pad (and points up
the finger at each)."""
FINGER_RADIUS = 0.0085
"""Radius of the finger's links above the pad (the index finger's capsules) [m]: a line into a slot the pad
fits in but the finger slanting after it does not is blocked."""


def finger_clear(hypotheses: Sequence[Hypothesis], moves: Sequence[ProbeMove], pad_radius: float,
                 lift: float = FINGER_LIFT, finger_radius: float = FINGER_RADIUS) -> np.ndarray:  # fmt: skip
    """Whether the finger above the pad -- pointing down, the column from the pad's top to ``lift`` above its
    centre, ``finger_radius`` thick -- stays clear of every hypothesis's object while the pad travels each line
    up to where that hypothesis predicts its contact (or to the line's end), shape (M,) bool. A line passing
    under an overhang of a hypothesis (a slot's ceiling, a ledge), or slanting into a slot the pad fits in and
    the finger after it does not, would have the finger's phalanx meet the object before the pad:
    a blocked move, no contact sensed."""
    m = len(moves)
    ok = np.ones(m, dtype=bool)
    if m == 0:
        return ok
    r = pad_radius
    starts = np.array([mv.start for mv in moves], dtype=float)
    dirs = np.array([mv.direction for mv in moves], dtype=float)
    lengths = np.array([mv.length for mv in moves], dtype=float)
    frac = np.linspace(0.0, 1.0, FINGER_SAMPLES)
    up = np.array([0.0, 0.0, 1.0])
    for h in hypotheses:
        inv = h.model_from_world
        t_end = np.minimum(line_hits(h.poly, inv.apply(starts), inv.rotate(dirs)).first, lengths)  # (M,)
        centres = (starts - r * dirs)[:, None, :] + (frac[None, :] * t_end[:, None])[..., None] * dirs[:, None, :]
        tops = inv.apply((centres + lift * up).reshape(-1, 3))
        down = np.broadcast_to(inv.rotate(-up), tops.shape)
        hit = line_hits(h.poly, tops, down).first <= lift - r
        # the finger is a capsule about the column: its points stay a finger's radius off the surface
        column = tops[:, None, :] + np.linspace(0.0, lift - r, FINGER_SAMPLES)[None, :, None] * down[:1, None, :]
        thick = surface_distance(h.poly, column.reshape(-1, 3)).reshape(len(tops), -1).min(axis=1) < finger_radius
        blocked = hit | thick | h.poly.contains(tops)
        ok &= ~blocked.reshape(m, FINGER_SAMPLES).any(axis=1)
    return ok


def _hypothesis_balls(hypotheses: Sequence[Hypothesis]) -> tuple[np.ndarray, np.ndarray]:
    """Centre (posed centroid) and radius (to the farthest vertex) of each hypothesis's object, (N, 3), (N,)."""
    centres = np.array([h.world_from_model.apply(h.poly.centroid) for h in hypotheses])
    radii = np.array([float(np.linalg.norm(h.poly.vertices - h.poly.centroid, axis=1).max()) for h in hypotheses])
    return centres, radii


def _clip_to_balls(move: ProbeMove, balls: tuple[np.ndarray, np.ndarray], margin: float, union: bool):
    """``move`` shortened to the part of its line within ``margin`` of the balls (``union``: of any of them,
    where one of several objects may be; else of all of them, where one object within each must be); None when
    that part is empty. The start moves forward, the end back; the line is never lengthened."""
    centres, radii = balls
    s, u = np.asarray(move.start, dtype=float), np.asarray(move.direction, dtype=float)
    w = centres - s
    b = w @ u
    disc = b * b - (np.einsum("ij,ij->i", w, w) - (radii + margin) ** 2)
    meets = disc > 0.0
    root = np.sqrt(np.where(meets, disc, 0.0))
    if union:
        if not meets.any():
            return None
        t0, t1 = float((b - root)[meets].min()), float((b + root)[meets].max())
    else:
        if not meets.all():
            return None
        t0, t1 = float((b - root).max()), float((b + root).min())
    t0, t1 = max(t0, 0.0), min(t1, float(move.length))
    if t1 <= t0:
        return None
    return ProbeMove(s + t0 * u, u, t1 - t0)


def _line_through(
    p: np.ndarray, u: np.ndarray, centre: np.ndarray, radius: float, config: ProbeConfig, hold: float = 0.0
):
    """The chord along ``u`` through ``p`` of the sphere (``centre``, ``radius``), cut short above the table;
    None when it would not reach ``p``, or (with a pad and a table) when the pad could not come down to its
    start clear of the sphere of radius ``hold`` that holds every hypothesis's object."""
    w = p - centre
    b = float(w @ u)
    disc = b * b - (float(w @ w) - radius * radius)
    if disc <= 0.0:
        return None
    back = b + np.sqrt(disc)  # from p back to the sphere
    start = p - back * u
    length = 2.0 * np.sqrt(disc)
    if config.table_z is not None:
        r = config.pad_radius
        floor = config.table_z + config.table_clearance + r * (1.0 + u[2])  # the line's lowest point allowed
        if start[2] < floor or p[2] < floor:
            return None
        if u[2] < 0.0:
            length = min(length, (start[2] - floor) / -u[2])
        if r > 0.0:
            c0 = start - r * u  # the pad centre at the line's start
            w0 = c0 - centre
            if float(np.linalg.norm(w0)) < hold + r:
                return None
            if w0[2] < 0.0 and float(np.hypot(w0[0], w0[1])) < hold + r:  # under the sphere's side
                return None
    if length <= back:
        return None
    return ProbeMove(start, u, float(length))


@dataclass(frozen=True)
class LibraryExtent:
    """How large the library's objects are, for aiming probes before any hypothesis has a pose, and what the
    opening's tracing moves travel on them on average (for choosing between those and a probe)."""

    reach: float
    """The largest distance between two vertices of one model: every point of the object lies within this of
    every contact [m]."""
    depth: float
    """The median over the library of a model's centroid's distance to its nearest face plane: how far behind
    a contact, against its normal, the object's inside is aimed at [m]."""
    face_run: float = 0.0
    """Expected length of a face move from a point of a face to its boundary: half the mean chord of a
    uniform random line across a face, ``π A / (2 P)`` (area ``A``, perimeter ``P``), averaged over the
    library's faces weighted by area (the sensor lands on a face with chance in proportion to it) [m]."""
    edge_run: float = 0.0
    """Expected length of an edge move from where a face move met an edge to the edge's end: half an edge,
    edges weighted by length (a face move meets an edge with chance in proportion to it), ``E[l²] / (2 E[l])``
    over the library's edges [m]."""
    corner_angle: float = 0.0
    """Mean interior angle of the library's face corners: the turn of a vertex move from the edge it starts on
    to the next edge of the face [rad]."""

    @classmethod
    def of(cls, models: Iterable[Polyhedron]) -> LibraryExtent:
        """The extent of a library's models."""
        reach, depths = 0.0, []
        runs, areas, lengths, corners = [], [], [], []
        for poly in models:
            v = poly.vertices
            reach = max(reach, float(np.sqrt(((v[:, None] - v[None]) ** 2).sum(-1)).max()))
            depths.append(float(np.abs(poly.face_offsets - poly.face_normals @ poly.centroid).min()))
            edge_l = poly.edge_lengths
            lengths.extend(edge_l.tolist())
            for f, fe in enumerate(poly.face_edges):
                area = float(poly.face_areas[f])
                runs.append(np.pi * area / (2.0 * float(edge_l[list(fe)].sum())))
                areas.append(area)
                ring = v[list(poly.face_vertices(f))]
                a, b = np.roll(ring, 1, axis=0) - ring, np.roll(ring, -1, axis=0) - ring
                cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
                corners.extend(np.arccos(np.clip(cos, -1.0, 1.0)).tolist())
        if not depths:
            return cls(0.0, 0.0)
        lengths = np.array(lengths)
        return cls(
            reach,
            float(np.median(depths)),
            face_run=float(np.average(runs, weights=areas)),
            edge_run=float((lengths**2).sum() / (2.0 * lengths.sum())),
            corner_angle=float(np.mean(corners)),
        )


def region_centre(faces: Sequence[DataFace], extent: LibraryExtent) -> np.ndarray:
    """The estimated centre of the object's region before any pose, ``c = mean(q_i − depth · n_i)`` over the
    data faces (contact points ``q_i``, outward normals ``n_i``) [m]; the opening probes' lines run through it."""
    q = np.array([np.mean(np.atleast_2d(f.points), axis=0) for f in faces])
    n = np.array([f.normal for f in faces])
    return (q - extent.depth * n).mean(axis=0)


def opening_probes(
    faces: Sequence[DataFace], extent: LibraryExtent, config: ProbeConfig | None = None, unmeasured: bool = False
) -> list[ProbeMove]:
    """Probe lines toward the object's region before hypotheses have poses (the opening of ``--moves probing``),
    best first: a fixed spread of approach directions (:attr:`ProbeConfig.n_directions`, a Fibonacci lattice),
    each line through the region's estimated centre ``c = mean(q_i − depth · n_i)`` over the data faces (their
    contact points ``q_i`` and outward normals ``n_i``), running across the region that must hold the object:
    the intersection of the balls of radius ``reach`` about the contacts (plus the standoff). Ranked by how
    nearly the face each would hit is perpendicular to every normal measured so far (smallest
    ``max_i |u · n_i|``): a face whose normal is independent of the known ones is what fixes the rotation (two
    normals) and the translation (three planes), hence the poses. Directions heading against a known face's
    normal (``u · n_i < −``:data:`BEHIND`) come after all the others: such a line may enter through that face
    again, and a convex object's face is never met from behind. With ``unmeasured`` (once the rotation is
    known, under ``--moves probing`` while the tree is too large for the probe matcher to test hits by their
    position) they are ranked instead by how far the approach is from every measured normal (smallest
    ``max_i (−u · n_i)``): the faces not met yet, those opposite the known ones first (whose distance from
    them the tree tests, §2.6)."""
    config = config or ProbeConfig()
    if not faces:
        return []
    q = np.array([np.mean(np.atleast_2d(f.points), axis=0) for f in faces])
    n = np.array([f.normal for f in faces])
    centre = region_centre(faces, extent)
    radius = extent.reach + extent.depth + config.standoff
    dirs = fibonacci_directions(config.n_directions)
    if config.table_z is not None:
        dirs = dirs[dirs[:, 2] <= config.max_climb]
    # from behind every known face first (no such line enters through one again), then the rest
    if unmeasured:
        order = np.argsort((-(dirs @ n.T)).max(axis=1), kind="stable")
    else:
        ahead = ~(dirs @ n.T >= -BEHIND).all(axis=1)
        order = np.lexsort((np.abs(dirs @ n.T).max(axis=1), ahead))
    within = (q, np.full(len(q), extent.reach))  # every point of the object is within reach of every contact
    out = []
    for u in dirs[order]:
        move = _line_through(centre, u, centre, radius, config)
        if move is not None:
            move = _clip_to_balls(move, within, config.standoff, union=False)
        if move is not None:
            out.append(move)
    return out


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
        d = self.eliminates()
        eff, _ = efficiency_of(d, self.costs, weights)
        n = len(self.costs)
        w = np.full(n, 1.0 / n) if weights is None else np.asarray(weights, dtype=float) / np.sum(weights)
        return eff, expected_eliminated(d, weights), float(self.costs @ w)


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
            dep[fin] = surface_distance(poly, pts.reshape(-1, 3)).reshape(len(fin), -1).max(axis=1)
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


__all__ = ["BEHIND", "DEPTH_FRACTIONS", "FINGER_LIFT", "MIN_INCIDENCE", "LibraryExtent", "ProbeConfig",
           "FINGER_RADIUS", "ProbePrediction", "aimed_probes", "candidate_probes", "fibonacci_directions",
           "finger_clear", "opening_probes", "predict_probes", "region_centre"]  # fmt: skip
