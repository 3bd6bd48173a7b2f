"""One home for the geometric tolerances of model construction and import.

Sensor error bounds (what the matcher uses) are *not* here: they derive from the sensor model in
:mod:`haptic.matching`. These are the numerical tolerances for representing exact models.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Tolerances:
    """Numerical tolerances of model geometry."""

    merge: float = 1e-7
    """Two vertices closer than this are the same point; shorter edges are degenerate [m]."""
    planar: float = 1e-6
    """Largest distance of a face's vertex from the face's plane [m]."""
    area: float = 1e-10
    """Faces of smaller area are degenerate [m^2]."""
    angle: float = 1e-5
    """Two normals closer than this are parallel (coplanar faces, symmetry checks) [rad]."""
    match: float = 1e-6
    """Distance within which two points coincide when testing a rigid map of a model onto itself [m]."""


tol = Tolerances()
