"""Polyhedral models (seed §2.2): the winged-edge solid, its validation, import/export, symmetry.

Pure numpy (plus trimesh for mesh files); no simulator imports.
"""

from haptic.geometry.decompose import convex_decomposition
from haptic.geometry.io import (
    DEFAULT_LIBRARY,
    MODEL_SUFFIXES,
    LibraryScan,
    atomic_write,
    export_mesh,
    load_library,
    load_model,
    model_files,
    polyhedron_from_triangles,
    resolve_model,
    save_model,
    scan_library,
)
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3, random_rotation, rotation_angle
from haptic.geometry.symmetry import are_congruent, congruences, library_twin, symmetry_group
from haptic.geometry.tolerances import Tolerances, tol

__all__ = [
    "DEFAULT_LIBRARY",
    "MODEL_SUFFIXES",
    "SE3",
    "Polyhedron",
    "Tolerances",
    "are_congruent",
    "atomic_write",
    "congruences",
    "convex_decomposition",
    "export_mesh",
    "library_twin",
    "LibraryScan",
    "load_library",
    "load_model",
    "model_files",
    "polyhedron_from_triangles",
    "random_rotation",
    "resolve_model",
    "rotation_angle",
    "save_model",
    "scan_library",
    "symmetry_group",
    "tol",
]
