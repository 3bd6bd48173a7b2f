"""Rigid transforms as rotation matrix plus translation: ``w_d = R w_m + t`` (seed §2.1).

A transform named ``a_from_b`` maps coordinates in frame b to frame a.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class SE3:
    """A proper rigid transform ``x ↦ R x + t``."""

    rotation: np.ndarray
    """Proper rotation matrix R, shape (3, 3)."""
    translation: np.ndarray
    """Translation t, shape (3,) [m]."""

    @classmethod
    def identity(cls) -> SE3:
        return cls(np.eye(3), np.zeros(3))

    @classmethod
    def random(cls, rng: np.random.Generator, translation_scale: float = 0.0) -> SE3:
        """A uniformly random rotation and a translation drawn uniformly in a cube of half-size ``scale``."""
        return cls(random_rotation(rng), rng.uniform(-translation_scale, translation_scale, 3))

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Map points (…, 3)."""
        return np.asarray(points) @ self.rotation.T + self.translation

    def rotate(self, vectors: np.ndarray) -> np.ndarray:
        """Map free vectors (…, 3) (normals, directions)."""
        return np.asarray(vectors) @ self.rotation.T

    def inverse(self) -> SE3:
        return SE3(self.rotation.T, -self.rotation.T @ self.translation)

    def __matmul__(self, other: SE3) -> SE3:
        return SE3(self.rotation @ other.rotation, self.rotation @ other.translation + self.translation)

    @classmethod
    def from_matrix(cls, matrix) -> SE3:
        """The transform of a homogeneous matrix (4, 4) (its last row is not checked)."""
        m = np.asarray(matrix, dtype=float)
        if m.shape != (4, 4):
            raise ValueError(f"a rigid transform matrix has shape (4, 4), got {m.shape}")
        return cls(m[:3, :3].copy(), m[:3, 3].copy())

    def as_matrix(self) -> np.ndarray:
        """The homogeneous matrix (4, 4)."""
        m = np.eye(4)
        m[:3, :3] = self.rotation
        m[:3, 3] = self.translation
        return m


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross`` of 3-vectors along the last axis, broadcast, with the same arithmetic (so the same bits) and
    without its axis handling, which dominates on the small arrays of the planner's inner loops."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape == b.shape == (3,) and a.dtype == b.dtype == np.float64:  # two vectors: in Python floats, the same bits
        a0, a1, a2 = a.tolist()
        b0, b1, b2 = b.tolist()
        return np.array((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype=np.result_type(a, b))
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def rotation_angle(r: np.ndarray) -> float:
    """Angle of a rotation matrix [rad]."""
    return float(np.arccos(np.clip((np.trace(r) - 1.0) / 2.0, -1.0, 1.0)))


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A rotation drawn uniformly from SO(3) (unit quaternion from a 4-D Gaussian)."""
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    return quat_to_matrix(q)


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat(r: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z), w ≥ 0, of a rotation matrix."""
    m = np.asarray(r, dtype=float)
    tr = np.trace(m)
    if tr > 0:
        s = np.sqrt(tr + 1.0) * 2
        q = np.array([0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s])
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = np.array([(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s])
    elif m[1, 1] > m[2, 2]:
        s = np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = np.array([(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s])
    else:
        s = np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = np.array([(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s])
    q /= np.linalg.norm(q)
    return q if q[0] >= 0 else -q


def frame_from_edge(direction: np.ndarray, face_normal: np.ndarray) -> np.ndarray:
    """Orthonormal frame (columns b, n⊥, b × n⊥) from an edge direction and an adjacent face normal."""
    b = direction / np.linalg.norm(direction)
    n = face_normal - (face_normal @ b) * b
    n /= np.linalg.norm(n)
    return np.column_stack([b, n, np.cross(b, n)])


_X, _Y = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
"""The x and y axes (read only)."""
_X.flags.writeable = _Y.flags.writeable = False


def plane_basis(normal: np.ndarray, assume_unit: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors ``(u, w)`` spanning the plane normal to ``normal``, with ``u × w = n``: ``u`` is
    ``n × x̂`` normalised (``n × ŷ`` when ``n`` is within ~6° of x̂). With ``assume_unit``, ``normal`` is taken
    as a unit vector as it is (not normalised again)."""
    n = np.asarray(normal, dtype=float)
    if not assume_unit:
        n = n / np.linalg.norm(n)
    u = cross(n, _X)
    if np.linalg.norm(u) < 0.1:
        u = cross(n, _Y)
    u /= np.linalg.norm(u)
    return u, cross(n, u)


def perpendicular(v: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to unit vector ``v`` (the first of :func:`plane_basis`)."""
    return plane_basis(v, assume_unit=True)[0]


def finite3(v: np.ndarray) -> bool:
    """``np.isfinite(v).all()`` of a (3,) vector, without numpy's per-call overhead (a control loop asks it every
    tick)."""
    return math.isfinite(v[0]) and math.isfinite(v[1]) and math.isfinite(v[2])


def unit(v: np.ndarray) -> np.ndarray:
    """``v`` normalised (``v`` itself when it is zero)."""
    n = math.sqrt(float(v.dot(v)))  # numpy's product as v @ v, at less overhead (the primitives ask every tick)
    return v / n if n > 0 else v


def angle(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between unit vectors [rad]. (``a.dot(b)`` of an array is ``a @ b``'s product, at less overhead: the
    primitives ask every tick.)"""
    return math.acos(max(-1.0, min(1.0, float(a.dot(b) if type(a) is np.ndarray else a @ b))))
