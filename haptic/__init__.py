"""haptic: a testbed for recognising and localising polyhedral objects by active touch."""

from haptic.errors import HapticError

__version__ = "0.1.0"
__all__ = ["HapticError", "__version__"]
