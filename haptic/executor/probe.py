"""The free-space probe on the ideal sensor (seed §1.1): :meth:`GeometricExecutor.execute` carries out a
:class:`~haptic.planning.moves.ProbeMove` (``GeometricExecutor._probe_move``) by casting the line at the posed
true model; a hit is a face data component with the executor's noise, a miss leaves the sensor where it was, and
either way the path along the line is reported free (:class:`~haptic.matching.probes.FreeSegment`).
"""

from __future__ import annotations

from haptic.executor.geometric import GeometricExecutor
from haptic.planning.moves import MoveResult, ProbeMove


def execute_probe(ex: GeometricExecutor, move: ProbeMove) -> MoveResult:
    """Carry out ``move`` with the geometric executor ``ex`` (after its ``start()``); never raises for a bad move
    (status "invalid", or "unreachable" for a line that starts inside the object)."""
    return ex.execute(move)


__all__ = ["execute_probe"]
