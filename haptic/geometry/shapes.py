"""Constructors for the kinds of solid the model libraries are made of.

Each returns a validated :class:`Polyhedron` in metres.
"""

from __future__ import annotations

import numpy as np

from haptic.errors import ModelError
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import plane_basis


def box(lx: float, ly: float, lz: float, name: str = "box") -> Polyhedron:
    """An axis-aligned box with one corner at the origin [m]."""
    return prism([(0, 0), (lx, 0), (lx, ly), (0, ly)], lz, name=name)


def prism(profile, height: float, name: str = "prism") -> Polyhedron:
    """Extrude a simple counter-clockwise polygon in the xy-plane along +z by ``height`` [m]."""
    p = np.asarray(profile, dtype=float)
    area2 = np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
    if area2 < 0:
        p = p[::-1]
    n = len(p)
    verts = [(x, y, 0.0) for x, y in p] + [(x, y, height) for x, y in p]
    bottom = tuple(reversed(range(n)))
    top = tuple(range(n, 2 * n))
    sides = [(i, (i + 1) % n, n + (i + 1) % n, n + i) for i in range(n)]
    return Polyhedron.from_faces(verts, [bottom, top, *sides], name=name)


def extrusion_xz(profile, depth: float, name: str = "extrusion") -> Polyhedron:
    """Extrude a counter-clockwise polygon given in the xz-plane along +y by ``depth`` [m].

    The profile's first coordinate is x, the second z (so ``[(0,0),(L,0),(L,H),(0,H)]`` is an L×depth×H box).
    """
    base = prism(profile, depth, name=name)
    # prism built in (x, y=z_profile, z=depth); map (x, y, z) -> (x, z, y) is a reflection, so mirror back
    v = base.vertices[:, [0, 2, 1]]
    faces = [tuple(reversed(f)) for f in base.faces]
    return Polyhedron.from_faces(v, faces, name=name)


def pyramid(base_x: float, base_y: float, height: float, apex_xy=(0.0, 0.0), name: str = "pyramid") -> Polyhedron:
    """A pyramid on a rectangle centred at the origin, apex at ``(apex_xy, height)`` [m]."""
    hx, hy = base_x / 2, base_y / 2
    verts = [(-hx, -hy, 0), (hx, -hy, 0), (hx, hy, 0), (-hx, hy, 0), (apex_xy[0], apex_xy[1], height)]
    faces = [(3, 2, 1, 0), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]
    return Polyhedron.from_faces(verts, faces, name=name)


def tetrahedron(a, b, c, d, name: str = "tetrahedron") -> Polyhedron:
    """The tetrahedron on four points; face orientation is fixed so that normals point outward."""
    verts = np.array([a, b, c, d], dtype=float)
    faces = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (2, 0, 3)]
    if np.dot(np.cross(verts[1] - verts[0], verts[2] - verts[0]), verts[3] - verts[0]) < 0:
        faces = [tuple(reversed(f)) for f in faces]
    return Polyhedron.from_faces(verts, faces, name=name)


def frame(outer: float, inner: float, height_out: float, height_in: float, name: str = "frame") -> Polyhedron:
    """A square frame with a square hole (genus 1), bars of trapezoid section so that no face has a hole.

    ``outer``/``inner`` are the half-widths of the outer and inner squares; the outer walls are ``height_out``
    tall and the inner walls ``height_in``, centred on the same mid-plane, so the top and bottom of each bar slope
    toward the hole and meet their neighbours along mitre edges [m].
    """
    A, B = outer, inner
    zo0, zo1 = 0.0, height_out
    zi0, zi1 = (height_out - height_in) / 2, (height_out + height_in) / 2
    corners = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    verts = (
        [(A * sx, A * sy, zo0) for sx, sy in corners]  # 0-3 outer bottom
        + [(A * sx, A * sy, zo1) for sx, sy in corners]  # 4-7 outer top
        + [(B * sx, B * sy, zi0) for sx, sy in corners]  # 8-11 inner bottom
        + [(B * sx, B * sy, zi1) for sx, sy in corners]  # 12-15 inner top
    )
    faces = []
    for i in range(4):
        j = (i + 1) % 4
        faces.append((i, j, 4 + j, 4 + i))  # outer wall, normal outward
        faces.append((8 + j, 8 + i, 12 + i, 12 + j))  # inner wall, normal toward the hole
        faces.append((4 + i, 4 + j, 12 + j, 12 + i))  # top of the bar
        faces.append((j, i, 8 + i, 8 + j))  # bottom of the bar
    return Polyhedron.from_faces(verts, faces, name=name)


def regular_prism(sides: int, circumradius: float, height: float, name: str = "prism") -> Polyhedron:
    """A right prism on a regular polygon [m]."""
    ang = 2 * np.pi * np.arange(sides) / sides
    return prism(np.column_stack([circumradius * np.cos(ang), circumradius * np.sin(ang)]), height, name=name)


# ------------------------------------------------------------------------------------------- formula solids

PLATONIC = ("tetrahedron", "cube", "octahedron", "dodecahedron", "icosahedron")
"""The five Platonic solids, by the names :func:`platonic` takes."""


def convex_hull(points, name: str = "hull") -> Polyhedron:
    """The convex hull of points [m], with coplanar hull triangles merged into one polygonal face.

    Points inside the hull or inside a face or edge of it are not vertices of the result.
    """
    from scipy.spatial import ConvexHull, QhullError

    p = np.asarray(points, dtype=float)
    try:
        hull = ConvexHull(p)
    except (QhullError, ValueError) as exc:
        raise ModelError(f"{name}: the points span no solid ({str(exc).splitlines()[0]})") from None
    scale = float(np.linalg.norm(np.ptp(p, axis=0)))
    eps = 1e-9 * scale
    # hull facets in one plane: their (n, d) agree (qhull's outward unit normals and offsets n·w + d = 0)
    planes: list[np.ndarray] = []
    members: list[set[int]] = []
    for simplex, eq in zip(hull.simplices, hull.equations, strict=True):
        for k, q in enumerate(planes):
            if np.linalg.norm(q[:3] - eq[:3]) < 1e-9 and abs(q[3] - eq[3]) < eps:
                members[k].update(int(i) for i in simplex)
                break
        else:
            planes.append(eq)
            members.append({int(i) for i in simplex})
    faces = []
    for eq, ids in zip(planes, members, strict=True):
        loop = _ccw_corners(p, sorted(ids), eq[:3])
        faces.append(loop)
    used = sorted({i for f in faces for i in f})
    index = {old: new for new, old in enumerate(used)}
    return Polyhedron.from_faces(p[used], [[index[i] for i in f] for f in faces], name=name)


def _ccw_corners(points: np.ndarray, ids: list[int], normal: np.ndarray) -> list[int]:
    """The corners of a convex planar point set, counter-clockwise seen from the side ``normal`` points to."""
    from scipy.spatial import ConvexHull

    u, w = plane_basis(normal)
    q = points[ids]
    flat = np.column_stack([q @ u, q @ w])
    if len(ids) == 3:
        order = [0, 1, 2]
        a, b, c = flat
        if (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0:
            order = [0, 2, 1]
        return [ids[k] for k in order]
    return [ids[int(k)] for k in ConvexHull(flat).vertices]  # 2-D hull vertices are counter-clockwise


def platonic(kind: str, circumradius: float, name: str | None = None) -> Polyhedron:
    """A Platonic solid centred at the origin with its vertices at ``circumradius`` from the centre [m]."""
    from itertools import product

    phi = (1 + 5**0.5) / 2
    signs = list(product((-1.0, 1.0), repeat=3))
    if kind == "tetrahedron":
        pts = [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)]
    elif kind == "cube":
        pts = signs
    elif kind == "octahedron":
        pts = [tuple(s * e for e in row) for row in np.eye(3) for s in (-1.0, 1.0)]
    elif kind == "dodecahedron":
        pts = list(signs)
        for a, b in product((-1.0, 1.0), repeat=2):
            pts += [(0, a / phi, b * phi), (a / phi, b * phi, 0), (b * phi, 0, a / phi)]
    elif kind == "icosahedron":
        pts = []
        for a, b in product((-1.0, 1.0), repeat=2):
            pts += [(0, a, b * phi), (a, b * phi, 0), (b * phi, 0, a)]
    else:
        raise ModelError(f"unknown Platonic solid {kind!r}; valid: {', '.join(PLATONIC)}")
    p = np.asarray(pts, dtype=float)
    p *= circumradius / np.linalg.norm(p[0])
    return convex_hull(p, name=name or kind)


def _ring(sides: int, radius: float, z: float, phase: float = 0.0) -> np.ndarray:
    ang = phase + 2 * np.pi * np.arange(sides) / sides
    return np.column_stack([radius * np.cos(ang), radius * np.sin(ang), np.full(sides, z)])


def antiprism(sides: int, circumradius: float, height: float, name: str = "antiprism") -> Polyhedron:
    """Two regular ``sides``-gons a half-step apart in angle, joined by triangles [m]."""
    return convex_hull(
        np.vstack([_ring(sides, circumradius, 0.0), _ring(sides, circumradius, height, np.pi / sides)]), name=name
    )


def bipyramid(sides: int, circumradius: float, half_height: float, name: str = "bipyramid") -> Polyhedron:
    """Two pyramids on one regular ``sides``-gon, apexes ``half_height`` above and below its centre [m]."""
    apexes = [(0.0, 0.0, half_height), (0.0, 0.0, -half_height)]
    return convex_hull(np.vstack([_ring(sides, circumradius, 0.0), apexes]), name=name)


def trapezohedron(sides: int, circumradius: float, zigzag: float, name: str = "trapezohedron") -> Polyhedron:
    """The ``sides``-gonal trapezohedron (dual of the antiprism): ``2·sides`` congruent kite faces [m].

    Its zigzag of ``2·sides`` vertices lies at ``circumradius`` from the axis, alternately ``zigzag`` above and
    below the middle; the apexes are where the kites close flat, at ``zigzag·(1 + cos(π/n))/(1 − cos(π/n))``.
    """
    c = np.cos(np.pi / sides)
    apex = zigzag * (1 + c) / (1 - c)
    pts = np.vstack(
        [
            _ring(sides, circumradius, zigzag),
            _ring(sides, circumradius, -zigzag, np.pi / sides),
            [(0.0, 0.0, apex), (0.0, 0.0, -apex)],
        ]
    )
    return convex_hull(pts, name=name)


def random_convex_hull(
    rng: np.random.Generator,
    n_points: int,
    radius: float,
    min_turn_deg: float = 10.0,
    min_edge: float | None = None,
    name: str = "hull",
) -> Polyhedron:
    """The hull of ``n_points`` random points on a sphere of ``radius`` [m], drawn until it is well shaped.

    Well shaped: every point is a vertex, neighbouring faces turn by at least ``min_turn_deg`` and no edge is
    shorter than ``min_edge`` (default a fifth of the radius), so the solid survives coordinate rounding far
    below those scales.
    """
    from scipy.spatial import ConvexHull

    min_edge = radius / 5 if min_edge is None else min_edge
    cos_turn = np.cos(np.radians(min_turn_deg))
    spacing = np.sqrt(4 * np.pi / n_points)  # mean angular spacing of n points on the sphere [rad]
    for _ in range(1000):
        # points drawn one by one, each at least half the mean spacing from the others (fewer rejected hulls)
        dirs: list[np.ndarray] = []
        for _ in range(100 * n_points):
            d = rng.normal(size=3)
            d /= np.linalg.norm(d)
            if all(d @ q < np.cos(spacing / 2) for q in dirs):
                dirs.append(d)
                if len(dirs) == n_points:
                    break
        if len(dirs) < n_points:
            continue
        pts = radius * np.array(dirs)
        hull = ConvexHull(pts)
        if len(hull.vertices) != n_points:
            continue
        normals = hull.equations[:, :3]
        turn = np.einsum("ij,ikj->ik", normals, normals[hull.neighbors])  # each facet against its 3 neighbours
        tri = pts[hull.simplices]
        edges = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2)
        if turn.max() <= cos_turn and edges.min() >= min_edge:
            return convex_hull(pts, name=name)
    raise ModelError(f"{name}: no well-shaped hull of {n_points} points in 1000 draws; use fewer points")


def stepped_block(length: float, width: float, height: float, steps: int = 2, name: str = "stepped") -> Polyhedron:
    """A staircase block: ``steps`` equal treads rising along x, ``width`` deep along y [m]."""
    tread, rise = length / steps, height / steps
    profile = [(0.0, 0.0), (length, 0.0)]
    for k in range(steps, 0, -1):
        profile += [(k * tread, k * rise), ((k - 1) * tread, k * rise)]
    return extrusion_xz(profile[:-1] + [(0.0, rise)], width, name=name)


def l_bracket(leg_x: float, leg_z: float, thickness: float, width: float, name: str = "l_bracket") -> Polyhedron:
    """An L-shaped bracket: a foot ``leg_x`` long and an upright ``leg_z`` tall, both ``thickness`` thick [m]."""
    profile = [(0.0, 0.0), (leg_x, 0.0), (leg_x, thickness), (thickness, thickness), (thickness, leg_z), (0.0, leg_z)]
    return extrusion_xz(profile, width, name=name)


def slotted_block(
    length: float, width: float, height: float, slot_width: float, slot_depth: float, name: str = "slotted"
) -> Polyhedron:
    """A block with a slot of ``slot_width`` × ``slot_depth`` across the middle of its top, along y [m]."""
    x0, x1 = (length - slot_width) / 2, (length + slot_width) / 2
    profile = [
        (0.0, 0.0), (length, 0.0), (length, height), (x1, height), (x1, height - slot_depth),
        (x0, height - slot_depth), (x0, height), (0.0, height),
    ]  # fmt: skip
    return extrusion_xz(profile, width, name=name)
