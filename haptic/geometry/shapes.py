"""Constructors for the kinds of solid the model libraries are made of.

Each returns a validated :class:`Polyhedron` in metres.
"""

from __future__ import annotations

import numpy as np

from haptic.geometry.polyhedron import Polyhedron


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
