"""One home for the geometric tolerances of model construction and import.

Sensor error bounds (what the matcher uses) are *not* here: they derive from the sensor model in
:mod:`haptic.matching`. These are the numerical tolerances for representing models, and they follow the data:
a model's size (its bounding-box diagonal) and the precision of the file it came from (the decimals of an OBJ,
float32 for an STL). :meth:`Tolerances.for_model` derives them; :data:`tol` holds the floor used for exact
models (a native JSON file, a formula solid) of up to about a metre.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FLOAT32_QUANTUM = 2.0**-24
"""Half a unit in the last place of a float32, relative to the number's magnitude."""

RELATIVE_NOISE = 1e-9
"""Float64 round-off a model's coordinates carry from its construction, relative to its size."""


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

    @classmethod
    def for_model(cls, size: float, quantum: float = 0.0) -> Tolerances:
        """Tolerances for a model of bounding-box diagonal ``size`` [m] whose coordinates were rounded to
        within ``quantum`` [m] (half a unit of the last decimal written; 0 for exact data).

        A rounded vertex lies within ``δ = √3·quantum`` of the true point, so: points of one face stay within
        ``2δ`` of its plane (planar), two written copies of one point within ``2δ`` (merge), and a rigid map
        of the model onto itself carries each vertex within ``2δ`` of another (match, after a least-squares
        fit). Each is at least the floor of :data:`tol` and a size-relative float64 allowance.
        """
        size = float(size)
        delta = np.sqrt(3.0) * float(quantum) + RELATIVE_NOISE * size
        floor = cls()
        return cls(
            merge=float(max(floor.merge, 2 * delta)),
            planar=float(max(floor.planar, 4 * delta)),
            area=float(max(floor.area, (4 * delta) ** 2)),
            angle=float(max(floor.angle, 8 * delta / max(size, 1e-12))),
            match=float(max(floor.match, 1e-5 * size, 4 * delta)),
        )


def decimal_quantum(decimals: int) -> float:
    """Half a unit in the last place of a number written with ``decimals`` digits after the point."""
    return 0.5 * 10.0 ** (-decimals)


tol = Tolerances()
