"""The sensed contact of a pad: one patch of contact is sensed as its strongest contact, separate patches are
averaged; on a non-convex object, simulated as convex pieces, a face next to a seam reads true."""

import math

import numpy as np

from haptic.sim.physics import merge_patches


def test_a_seam_contact_next_to_a_face_contact_does_not_tilt_the_normal():
    # pressing a face (+z) 1 mm from the seam of two coplanar pieces: the neighbour's edge also touches the
    # pad, at a normal tilted by ~5°, with less force
    tilt = np.array([math.sin(math.radians(5.0)), 0.0, math.cos(math.radians(5.0))])
    points = np.array([[0.0, 0.0, 0.0], [0.001, 0.0, 0.0]])
    point, normal = merge_patches(points, np.array([[0.0, 0.0, 1.0], tilt]), np.array([0.6, 0.4]))
    assert np.allclose(normal, [0.0, 0.0, 1.0]) and np.allclose(point, points[0])


def test_two_faces_of_a_corner_are_averaged():
    # in a concave corner the pad touches two faces 17 mm apart: both count, by force
    points = np.array([[0.0, 0.0, 0.0], [0.012, 0.0, 0.012]])
    normals = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]])
    point, normal = merge_patches(points, normals, np.array([1.0, 1.0]))
    assert np.allclose(normal, np.array([-1.0, 0.0, 1.0]) / math.sqrt(2.0))
    assert np.allclose(point, points.mean(axis=0))


