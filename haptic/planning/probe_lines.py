"""Candidate free-space probes aimed at the hypotheses' surfaces (seed §1.1, §4.1).

A probe is a line (:class:`~haptic.planning.moves.ProbeMove`) the sensor approaches along until contact or the
line's end. Candidates aim at the hypotheses' surfaces: for every pose class and every face that class puts
in the world, the face's centre approached from a discrete set of directions within :attr:`ProbeConfig.
max_incidence` of head-on, each line starting just before the first ball holding a hypothesis's object that it
meets and ending just past the last (:attr:`ProbeConfig.standoff`), clear of the table. Lines that nearly
coincide (same direction, targets within :attr:`ProbeConfig.target_spacing` across it) are one candidate.

The outcome each hypothesis predicts for a candidate is :mod:`haptic.planning.probe_prediction`'s; the lines
of the opening, before any hypothesis has a pose, are :mod:`haptic.planning.opening_probes`'.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from haptic.planning.finger_clearance import finger_clear
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import ProbeMove


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


BATCHED = True
"""Whether :func:`candidate_probes` computes a hypothesis's lines together (:func:`_probe_lines`, the same bits) rather
than line by line (:func:`_probe_line`, the reference) where there is no table."""


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
    batch = BATCHED and config.table_z is None and config.pad_radius == 0.0
    for h in posed:
        t = h.world_from_model
        targets, normals = t.apply(face_targets(h.poly)), t.rotate(h.poly.face_normals)
        facing = (dirs @ normals.T) <= -cos_max  # (D, F)
        if config.max_undercut is not None:
            facing &= (normals[:, 2] >= -np.sin(config.max_undercut))[None, :]
        if batch:  # every line of this hypothesis at once (:func:`_probe_lines`)
            out += _probe_lines(dirs, targets, np.nonzero(facing), seen, centre, big, balls, config)
            continue
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


def _probe_lines(dirs: np.ndarray, targets: np.ndarray, pairs: tuple[np.ndarray, np.ndarray], seen: set[tuple],
                 centre: np.ndarray, big: float, balls, config: ProbeConfig) -> list[ProbeMove]:  # fmt: skip
    """:func:`_probe_line` for each ``(direction, target)`` pair of ``pairs`` whose cell is not in ``seen`` (added
    to it), in their order, without a table or a pad: the lines of :func:`line_through` and :func:`clip_to_balls`
    for all the pairs in a few array operations, each in the arithmetic of its line by line form (a 3-vector's dot
    product summed left to right, the balls' by one matrix product per line), so the same bits."""
    di, fi = pairs
    if not len(di):
        return []
    u, p = dirs[di], targets[fi]
    pu = _dot(p, u)
    cells = np.round((p - pu[:, None] * u) / config.target_spacing).astype(int).tolist()
    keep = []
    for k, (d, cell) in enumerate(zip(di.tolist(), cells, strict=True)):
        key = (d, *cell)
        if key not in seen:
            seen.add(key)
            keep.append(k)
    if not keep:
        return []
    u, p = u[keep], p[keep]
    # line_through: the chord of the region's sphere through each target
    w = p - centre
    b = _dot(w, u)
    disc = b * b - (_dot(w, w) - big * big)
    ok = disc > 0.0
    root = np.sqrt(np.where(ok, disc, 0.0))
    back = b + root
    start = p - back[:, None] * u
    length = 2.0 * root
    ok &= ~(length <= back)
    # clip_to_balls (union): the part of each chord within the margin of some hypothesis's ball
    centres, radii = balls
    wb = centres[None] - start[:, None]  # (K, N, 3)
    bb = np.matmul(wb, u[:, :, None])[..., 0]
    ww = (wb[..., 0] * wb[..., 0] + wb[..., 2] * wb[..., 2]) + wb[..., 1] * wb[..., 1]  # np.einsum("ij,ij->i")'s order
    d = bb * bb - (ww - (radii + config.standoff) ** 2)
    meets = d > 0.0
    rb = np.sqrt(np.where(meets, d, 0.0))
    ok &= meets.any(axis=1)
    t0 = np.maximum(np.where(meets, bb - rb, np.inf).min(axis=1), 0.0)
    t1 = np.minimum(np.where(meets, bb + rb, -np.inf).max(axis=1), length)
    ok &= ~(t1 <= t0)
    return [ProbeMove(start[k] + t0[k] * u[k], u[k], float(t1[k] - t0[k])) for k in np.flatnonzero(ok)]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row by row dot products of two (K, 3) arrays, summed left to right as ``float(x @ y)`` of 3-vectors."""
    return (a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]) + a[:, 2] * b[:, 2]


def _probe_line(p: np.ndarray, u: np.ndarray, centre: np.ndarray, big: float, radius: float, balls,
                config: ProbeConfig) -> ProbeMove | None:  # fmt: skip
    """The candidate line along ``u`` through ``p`` (:func:`line_through` the region's sphere), cut to the balls
    that hold the hypotheses' objects; None when there is none."""
    move = line_through(p, u, centre, big, config, radius)
    if move is None:
        return None
    clipped = clip_to_balls(move, balls, config.standoff, union=True)
    if clipped is not None and config.pad_radius > 0.0:
        # the hand comes down to the line's start from above, clear of every hypothesis's object: the start stays
        # there, only the end is cut
        clipped = ProbeMove(move.start, u, float((clipped.end - move.start) @ u))
    return clipped


def aimed_probes(
    h: Hypothesis, targets: Sequence[tuple[np.ndarray, int]], config: ProbeConfig | None = None,
    keep: Callable[[ProbeMove], bool] | None = None, most: int | None = None,
) -> list[tuple[ProbeMove, int]]:
    """Probe lines at chosen points of hypothesis ``h``'s posed model: for each ``(point, face)`` (model frame,
    the point on that face), the line through the point head-on (along the face's inward normal) or, where that
    one is not admissible (the table, the hand's way down, the finger above the pad, :func:`candidate_probes`'
    rules), along the admissible one of the discrete directions within ``max_incidence`` of head-on nearest to
    it; at most one line per target, with its target's index. A verification uses them to carry the sensor to
    a part of the model still to be measured (:mod:`haptic.planning.verify`). ``keep`` (None: every line) and
    ``most`` (None: no limit): of those lines, the first ``most`` that ``keep`` keeps, in the targets' order (the
    targets after them are not aimed at where the lines are made target by target)."""
    config = config or ProbeConfig()
    if h.world_from_model is None or not len(targets):
        return []
    t = h.world_from_model
    centre, radius = _region([h])
    big = radius + config.standoff
    balls = _hypothesis_balls([h])
    dirs = fibonacci_directions(config.n_directions)
    cos_max = np.cos(config.max_incidence)
    # with a pad over a table the finger's clearance below may set a target's first lines aside, so every line is
    # made; else a target's first admissible line is the one kept, and the directions after it are not tried
    every = config.pad_radius > 0.0 and config.table_z is not None
    lines: list[tuple[ProbeMove, int]] = []

    def directions(n: np.ndarray):
        yield -n
        near = dirs[dirs @ -n >= cos_max]
        yield from near[np.argsort(-(near @ -n))]

    for k, (point, f) in enumerate(targets):
        if not every and most is not None and len(lines) >= most:
            break
        n = t.rotate(h.poly.face_normals[f])
        if config.max_undercut is not None and n[2] < -np.sin(config.max_undercut):
            continue
        p = t.apply(point)
        for u in directions(n):
            if config.table_z is not None and u[2] > config.max_climb:
                continue
            move = _probe_line(p, u, centre, big, radius, balls, config)
            if move is not None:
                if every or keep is None or keep(move):
                    lines.append((move, k))
                if not every:
                    break
    if lines and every:
        clear = finger_clear([h], [mv for mv, _ in lines], config.pad_radius)
        lines = [x for x, ok in zip(lines, clear, strict=True) if ok]
    out, seen = [], set()
    for mv, k in lines:  # the first admissible line of each target (head-on first)
        if k not in seen:
            seen.add(k)
            out.append((mv, k))
    if every:
        out = [x for x in out if keep is None or keep(x[0])]
    return out[:most] if most is not None else out


def _hypothesis_balls(hypotheses: Sequence[Hypothesis]) -> tuple[np.ndarray, np.ndarray]:
    """Centre (posed centroid) and radius (to the farthest vertex) of each hypothesis's object, (N, 3), (N,)."""
    centres = np.array([h.world_from_model.apply(h.poly.centroid) for h in hypotheses])
    radii = np.array([float(np.linalg.norm(h.poly.vertices - h.poly.centroid, axis=1).max()) for h in hypotheses])
    return centres, radii


def clip_to_balls(move: ProbeMove, balls: tuple[np.ndarray, np.ndarray], margin: float, union: bool):
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


def line_through(
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


__all__ = ["ProbeConfig", "aimed_probes", "candidate_probes", "clip_to_balls", "face_targets", "fibonacci_directions",
           "line_through"]  # fmt: skip
