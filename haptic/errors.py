"""The exception hierarchy: one root, one subclass per concern.

Every message names the file or element at fault and what would be valid, so that the CLI can print it as
one line and a library user can act on it.
"""


class HapticError(Exception):
    """Root of every error this package raises on purpose."""


class ModelError(HapticError):
    """A model file or polyhedron is missing, unreadable or not a valid closed polyhedral solid."""


class SceneError(HapticError):
    """A simulation scene cannot be composed, exported or loaded."""


class MatchError(HapticError):
    """Data components or matcher input are inconsistent (bad adjacency, unknown ids, wrong types)."""


class PlanningError(HapticError):
    """A planner or policy was configured with invalid options."""


class BenchError(HapticError):
    """A benchmark or results file cannot be written or read."""


class RecordingError(HapticError):
    """A recording cannot be written, or the viewer cannot be opened."""
