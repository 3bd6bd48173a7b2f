"""What a fingertip can touch of an object resting on the table, and whether two hypotheses differ there.

The fingers point down and end in a pad of radius ``config.pad_radius``. A surface point ``p`` of outward
normal ``n`` is *reachable* when the pad touching it, centred at ``c = p + r n``,

- stays clear of the table with room to trace (its lowest point ``config.table_clearance`` plus
  :data:`TRACE_ROOM` above the top),
- does not dig into the object elsewhere (``c`` is at least ``r`` from the whole surface, within a margin, and
  :data:`~haptic.planning.table.PAD_GAP` more from a face turned towards the point's),
- can be lowered there from above (the vertical line over ``c`` stays outside the object), and
- meets a face it can press on (the normal leans under by no more than ``config.max_undercut``).

A convex edge between a face the pad reaches (with room to roll :data:`~haptic.planning.table.EDGE_ROLL`
before the limit) and one leaning under past ``config.max_undercut`` is *observable* where the pad can slide
to it on the first face and roll over it to that limit clear of the table, away from its ends
(:data:`~haptic.planning.table.EDGE_ONLY_CLEARANCE`): a face move there reports the edge alone.

Two hypotheses (model and pose) that agree on every reachable point and observable edge -- each one's
reachable surface lies on the other's surface, and its observable edges on the other's edges, within
``tol`` -- cannot be told apart by any move: their difference faces the table. The episode then ends as
ambiguous instead of exploring without end.
"""

from __future__ import annotations

import numpy as np

from haptic.geometry import SE3, Polyhedron
from haptic.geometry.distance import point_triangle_distance, surface_distance, surface_samples_on_faces
from haptic.planning.config import PlannerConfig
from haptic.planning.table import EDGE_ONLY_CLEARANCE, EDGE_ROLL, MARGIN, clear_of_facing

SPACING = 0.004
"""Spacing of the sample points over the faces [m]."""
LIFT = 0.08
"""Height over the pad through which the finger must be free [m]."""
TRACE_ROOM = 0.006
"""Room a trace needs: a point of an upright face the pad could touch only within this of its limit above the
table counts as out of reach (a face move there would be refused as too close to the table); of a sloping face, this
times the sine of its slope, and of a level face none (a trace across it stays as high as it touched: an L bracket's
foot, 10 mm high, is touched from above or by sliding down the upright leg into the corner) [m]."""
MEASURE_ROOM = 0.0
"""Room the verification asks of a face, beyond the pad's clearance of the table, to count it in reach
(:func:`haptic.planning.verify.reachable_features`): none. Its vertices are measured at the ends of edge moves along
ridges and by circles high on the face, not by traces across it (prism_05 of the formula corpus at 34 mm, 20 mm tall
lying on an end: with :data:`TRACE_ROOM` its sides counted as out of reach and its top vertices as hidden, and the
verification ended incomplete at once; the hand measures every one of them) [m]."""


def surface_samples(poly: Polyhedron, spacing: float = SPACING) -> tuple[np.ndarray, np.ndarray]:
    """Points over every face (a barycentric grid per triangle, corners and edges included) and their faces'
    outward normals, model frame: shapes (P, 3), (P, 3)."""
    pts, faces = surface_samples_on_faces(poly, spacing)
    return pts, poly.face_normals[faces]


FACING = np.cos(np.deg2rad(20.0))
"""A touched point's sensed normal agrees with a face's when their angle is under 20° (a pose class's error
and the pad's compliance are a few degrees; distinct faces of the library differ by far more)."""


def touch_distance(poly: Polyhedron, world_from_model: SE3, points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Distance from each touched point (world frame) to the faces of ``poly`` at ``world_from_model`` whose
    outward normal agrees with the point's sensed normal (inf when none does), shape (P,). A point the pad
    touched while sliding on a face lies on a face of that normal: a point on the plane of a face just past
    its edge, near a face at right angles, is far from the truth however close to the surface."""
    inv = world_from_model.inverse()
    p, n = inv.apply(np.atleast_2d(points)), inv.rotate(np.atleast_2d(normals))
    tri = poly.vertices[poly.triangles]
    agree = n @ poly.face_normals[poly.triangle_faces].T >= FACING  # (P, T)
    best = np.full(len(p), np.inf)
    for start in range(0, len(p), 2048):
        d = point_triangle_distance(p[start : start + 2048], tri)
        best[start : start + 2048] = np.where(agree[start : start + 2048], d, np.inf).min(axis=1)
    return best


def touchable(
    poly: Polyhedron, world_from_model: SE3, pts: np.ndarray, nrm: np.ndarray, config: PlannerConfig,
    room: float | np.ndarray,
) -> np.ndarray:
    """Which world points ``pts`` of faces of normals ``nrm`` the pad can touch: clear of the table by
    ``config.table_clearance`` plus ``room`` (one, or one per point), not leaning under past
    ``config.max_undercut``, the pad clear of the rest of the object and free to come down from above. Shape (P,)
    bool."""
    r = config.pad_radius
    ok = np.ones(len(pts), dtype=bool)
    centre = pts + r * nrm
    if config.table_z is not None:
        ok &= centre[:, 2] - r - config.table_z >= config.table_clearance + room
    if config.max_undercut is not None:
        ok &= nrm[:, 2] >= -np.sin(config.max_undercut)
    idx = np.flatnonzero(ok)
    if len(idx):
        model_from_world = world_from_model.inverse()
        c_m = model_from_world.apply(centre[idx])
        clear = surface_distance(poly, c_m) >= r - MARGIN
        if clear.any():  # and clear of a face turned towards it by PAD_GAP (a slot as wide as the pad)
            clear[clear] = clear_of_facing(poly, c_m[clear], model_from_world.rotate(nrm[idx][clear]), r)
        up = model_from_world.rotate(np.array([0.0, 0.0, 1.0]))
        for h in np.linspace(r, LIFT, 6):
            above = c_m + h * up
            clear &= ~poly.contains(above)
        ok[idx] = clear
    return ok


def reachable(
    poly: Polyhedron, world_from_model: SE3, config: PlannerConfig, spacing: float = SPACING
) -> tuple[np.ndarray, np.ndarray]:
    """The reachable sample points of ``poly`` at ``world_from_model``, world frame, and their normals."""
    pts_m, nrm_m = surface_samples(poly, spacing)
    pts, nrm = world_from_model.apply(pts_m), world_from_model.rotate(nrm_m)
    # a trace needs the room where it heads down a sloping face; on a level one it stays as high as it touched
    room = TRACE_ROOM * np.sqrt(np.clip(1.0 - nrm[:, 2] ** 2, 0.0, 1.0))
    ok = touchable(poly, world_from_model, pts, nrm, config, room)
    return pts[ok], nrm[ok]


def observable_edges(
    poly: Polyhedron, world_from_model: SE3, config: PlannerConfig, spacing: float = SPACING
) -> np.ndarray:
    """Sample points (world frame, shape (P, 3)) of the convex edges a face move can report alone: from a
    face the pad touches there, rolling over onto a face that leans under past ``config.max_undercut`` (none
    without that limit or a table)."""
    if config.max_undercut is None or config.table_z is None:
        return np.zeros((0, 3))
    r, lean = config.pad_radius, np.sin(config.max_undercut)
    normals = world_from_model.rotate(poly.face_normals)
    out = []
    for e in np.flatnonzero(poly.edge_convexity > 0):
        a_b = (poly.edge_left_face[e], poly.edge_right_face[e])
        for a, b in (a_b, a_b[::-1]):
            n_a, n_b = normals[a], normals[b]
            if n_b[2] >= -lean or n_a[2] < -np.sin(config.max_undercut - EDGE_ROLL):
                continue
            p0, p1 = world_from_model.apply(poly.vertices[poly.edges[e]])
            length = float(np.linalg.norm(p1 - p0))
            if length <= 2 * EDGE_ONLY_CLEARANCE:
                continue
            k = max(2, int(np.ceil((length - 2 * EDGE_ONLY_CLEARANCE) / spacing)) + 1)
            ts = np.linspace(EDGE_ONLY_CLEARANCE / length, 1.0 - EDGE_ONLY_CLEARANCE / length, k)
            pts = p0 + ts[:, None] * (p1 - p0)
            ok = touchable(poly, world_from_model, pts, np.broadcast_to(n_a, pts.shape), config, 0.0)
            # the roll to the limit (the normal turned toward n_b until it leans under by max_undercut) clears
            # the table
            m = _limit_normal(n_a, n_b, lean)
            ok &= pts[:, 2] + r * m[2] - r - config.table_z >= 0.0
            out.append(pts[ok])
    return np.concatenate(out) if out else np.zeros((0, 3))


def _limit_normal(n_a: np.ndarray, n_b: np.ndarray, lean: float) -> np.ndarray:
    """The unit normal on the arc from ``n_a`` to ``n_b`` (about their edge) whose z is ``-lean``."""
    th = np.arccos(np.clip(n_a @ n_b, -1.0, 1.0))
    ts = np.linspace(0.0, 1.0, 64)
    arc = (np.sin((1 - ts) * th)[:, None] * n_a + np.sin(ts * th)[:, None] * n_b) / max(np.sin(th), 1e-9)
    i = int(np.argmax(arc[:, 2] <= -lean))
    return arc[i]


def _edge_distance(poly: Polyhedron, points: np.ndarray) -> np.ndarray:
    """Distance from each point (model frame) to the nearest edge segment of ``poly``, shape (P,)."""
    a, b = poly.vertices[poly.edges[:, 0]], poly.vertices[poly.edges[:, 1]]
    ab = b - a
    q = points[:, None, :] - a[None]
    t = np.clip(np.einsum("pek,ek->pe", q, ab) / np.einsum("ek,ek->e", ab, ab), 0.0, 1.0)
    return np.linalg.norm(q - t[..., None] * ab[None], axis=2).min(axis=1)


def indistinguishable(
    a: Polyhedron, a_pose: SE3, b: Polyhedron, b_pose: SE3, config: PlannerConfig, tol: float = 0.0015
) -> bool:
    """Whether every reachable point of each hypothesis lies on the other's surface, and every observable
    edge point on the other's edges, within ``tol`` (their difference is out of reach). A coarse pass first,
    since most pairs differ grossly."""
    for spacing in (3 * SPACING, SPACING):
        for (p, pp), (q, qp) in (((a, a_pose), (b, b_pose)), ((b, b_pose), (a, a_pose))):
            pts, _ = reachable(p, pp, config, spacing)
            if len(pts) == 0:
                return False
            d = surface_distance(q, qp.inverse().apply(pts))
            if float(d.max()) > tol:
                return False
            ridge = observable_edges(p, pp, config, spacing)
            if len(ridge) and float(_edge_distance(q, qp.inverse().apply(ridge)).max()) > tol:
                return False
    return True
