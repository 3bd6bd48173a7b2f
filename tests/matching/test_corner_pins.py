"""A vertex no move touches, placed by the planes of its faces measured within their corners at it
(:func:`haptic.matching.acceptance.placed_near`): placed only when every face at it is measured there and each edge
at it has itself or its other end measured; and a corner moved 3 mm tilts what is measured there past its bounds."""

from __future__ import annotations

import math

import numpy as np

from haptic.geometry import SE3
from haptic.geometry.distance import surface_distance
from haptic.geometry.perturb import move_vertex
from haptic.geometry.shapes import box
from haptic.matching.acceptance import (
    POSE_SAFETY,
    corner_spans,
    corner_triangle,
    faces_measured_near,
    in_corner,
    placed_near,
    residual_ratios,
)
from haptic.matching.components import DataFace
from haptic.matching.tree import Interpretation

SIZE = 0.04
NORMAL_BOUND = math.radians(1.0)
"""About the hand's bound of a face's normal (3 × its systematic 0.25° and its scatter) [rad]."""
POSITION_BOUND = 8e-4
"""About the hand's bound of a face's points (3 × its 0.25 mm systematic floor) [m]."""


def _corner_face(poly, v: int, f: int, at: float = 0.4, spread: float = 0.004, fid: int = 0) -> DataFace:
    """A data face of ``poly``'s face ``f`` touched round the point ``at`` of the way from vertex ``v`` to the middle
    of the far side of its corner triangle (model frame = world)."""
    tri = corner_triangle(poly, v, f)
    centre = tri[0] + at * ((tri[1] + tri[2]) / 2.0 - tri[0])
    n = poly.face_normals[f]
    a = np.cross(n, [1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.cross(n, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    pts = np.array([centre + spread * (x * a + y * b) for x in (-1, 0, 1) for y in (-1, 0, 1)])
    return DataFace(fid, n, pts, NORMAL_BOUND, POSITION_BOUND)


def _interpretation(poly, faces: dict[int, int]) -> Interpretation:
    return Interpretation(poly, 0, faces, {}, {}, {}, SE3.identity(), 0)


def _box_corner():
    poly = box(SIZE, SIZE, SIZE, name="cube")
    v = int(np.argmin(np.linalg.norm(poly.vertices - [SIZE, SIZE, SIZE], axis=1)))
    return poly, v, [int(f) for f in poly.vertex_faces[v]]


def test_a_vertex_is_placed_by_every_face_measured_within_its_corner():
    poly, v, faces = _box_corner()
    data = [_corner_face(poly, v, f, fid=i) for i, f in enumerate(faces)]
    it = _interpretation(poly, {i: f for i, f in enumerate(faces)})
    others = frozenset(int(sum(poly.edges[e])) - v for e in poly.vertex_edges[v])
    assert corner_spans(poly, v)
    assert faces_measured_near(poly, data, it, SE3.identity(), v) == set(faces)
    assert placed_near(poly, data, it, SE3.identity(), v, frozenset(), others)
    # its edges measured in place of their other ends do as well
    assert placed_near(poly, data, it, SE3.identity(), v, frozenset(poly.vertex_edges[v]), frozenset())


def test_a_vertex_is_not_placed_with_a_face_left_out_or_measured_away_from_it():
    poly, v, faces = _box_corner()
    others = frozenset(int(sum(poly.edges[e])) - v for e in poly.vertex_edges[v])
    two = [_corner_face(poly, v, f, fid=i) for i, f in enumerate(faces[:2])]
    assert not placed_near(poly, two, _interpretation(poly, {0: faces[0], 1: faces[1]}), SE3.identity(), v,
                           frozenset(), others)  # fmt: skip
    # the third face touched in the corner diagonally opposite on the face: its plane, not near this vertex
    far = [*two, _corner_face(poly, v, faces[2], at=1.6, fid=2)]
    it = _interpretation(poly, {i: f for i, f in enumerate(faces)})
    assert faces_measured_near(poly, far, it, SE3.identity(), v) == set(faces[:2])
    assert not placed_near(poly, far, it, SE3.identity(), v, frozenset(), others)
    # every face within the corner, but an edge at the vertex with neither itself nor its other end measured: a
    # chamfer of that edge would leave the planes near the vertex in place
    near = [*two, _corner_face(poly, v, faces[2], fid=2)]
    assert not placed_near(poly, near, it, SE3.identity(), v, frozenset(), frozenset(list(others)[:2]))


def test_the_corner_is_the_triangle_of_the_vertex_and_its_neighbours_on_the_face():
    poly, v, faces = _box_corner()
    for f in faces:
        tri = corner_triangle(poly, v, f)
        assert np.allclose(tri[0], poly.vertices[v])
        n = poly.face_normals[f]
        middle = tri.mean(axis=0)
        assert in_corner(middle[None], tri, n)[0]
        # the far corner of the face (a square's) lies outside the triangle
        opposite = poly.vertices[list(poly.faces[f])].sum(axis=0) - tri.sum(axis=0)
        assert not in_corner(opposite[None], tri, n)[0]
        assert in_corner(opposite[None], tri, n, slack=SIZE)[0]


def test_a_corner_moved_3_mm_tilts_its_faces_measured_within_the_corner_past_their_bounds():
    poly, v, faces = _box_corner()
    moved = move_vertex(poly, v, 0.003)
    # the object's surface within each face's corner at the vertex: the tilted corner triangle of the variant
    worst = []
    for f in faces:
        tri = corner_triangle(poly, v, f).copy()
        tri[0] = moved.vertices[v]
        n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
        n /= np.linalg.norm(n)
        centre = tri[0] + 0.4 * ((tri[1] + tri[2]) / 2.0 - tri[0])
        a = np.cross(n, tri[1] - tri[2])
        a /= np.linalg.norm(a)
        b = np.cross(n, a)
        pts = np.array([centre + 0.004 * (x * a + y * b) for x in (-1, 0, 1) for y in (-1, 0, 1)])
        face = DataFace(0, n, pts, NORMAL_BOUND, POSITION_BOUND)
        ratios = residual_ratios(poly, [face], _interpretation(poly, {0: f}), SE3.identity())
        worst.append(max(r for r, _, _ in ratios))
    # each of the three faces sees the move (a box corner moved along its normal tilts all three alike)
    assert min(worst) > POSE_SAFETY
    # the same faces measured beyond their corner triangles (the variant keeps their planes there) see nothing
    data = [_corner_face(poly, v, f, at=1.6, fid=i) for i, f in enumerate(faces)]
    it = _interpretation(poly, {i: f for i, f in enumerate(faces)})
    assert all(float(np.abs(surface_distance(moved, c.points)).max()) < 1e-9 for c in data)  # on the object
    assert max(r for r, _, _ in residual_ratios(poly, data, it, SE3.identity())) < 1e-3
