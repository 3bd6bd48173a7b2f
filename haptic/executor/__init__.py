"""Executors: carry out the seed's moves (§4) and report data components.

The geometric (ideal-sensor) executor is pure numpy. Nothing here imports a simulator at import time: names
are resolved lazily, so ``import haptic.executor`` never loads mujoco.
"""

from __future__ import annotations

_GEOMETRIC = ("GeometricExecutor", "GeometricSettings", "random_walk")


def __getattr__(name: str):
    if name in _GEOMETRIC:
        from haptic.executor import geometric

        return getattr(geometric, name)
    raise AttributeError(f"module 'haptic.executor' has no attribute {name!r}")


__all__ = list(_GEOMETRIC)
