"""The free-space probe on the ideal sensor: cast the line at the posed true model, add noise within bounds.

The geometric counterpart of a guarded approach (seed §1.1): from where the sensor is, move through free space
to the line's start and along the line until the first contact with the true model or the line's end. A hit
is reported as a face data component (:func:`~haptic.matching.probes.probe_face`: the contact point and the
face's normal, perturbed like every face the executor reports) and the sensor then rests on that face, so the
tracing moves can go on from it; a miss leaves the sensor where it was (it returns to its last contact, which
the cost counts). Either way the path travelled along the line is reported free
(:class:`~haptic.matching.probes.FreeSegment`), displaced as a whole by a position error within its bound.
"""

from __future__ import annotations

import numpy as np

from haptic.executor.geometric import GeometricExecutor
from haptic.geometry.raycast import line_hits
from haptic.matching.probes import FreeSegment
from haptic.planning.moves import MoveResult, ProbeMove


def execute_probe(ex: GeometricExecutor, move: ProbeMove) -> MoveResult:
    """Carry out ``move`` with the geometric executor ``ex`` (after its ``start()``); never raises for a bad move
    (status "invalid", or "unreachable" for a line that starts inside the object)."""
    if ex.state is None:
        return MoveResult(move=move, status="invalid", info={"reason": "call start() first"})
    start = np.asarray(move.start, dtype=float)
    u = np.asarray(move.direction, dtype=float)
    length = float(move.length)
    if start.shape != (3,) or u.shape != (3,) or not (np.all(np.isfinite(start)) and np.all(np.isfinite(u))):
        return _invalid(ex, move, "start and direction must be finite 3-vectors")
    if abs(float(np.linalg.norm(u)) - 1.0) > 1e-6 or not np.isfinite(length) or length <= 0.0:
        return _invalid(ex, move, "direction must be a unit vector and length a positive number of metres")
    inv = ex.world_from_model.inverse()
    s_m, u_m = inv.apply(start), inv.rotate(u)
    if bool(ex.model.contains(s_m[None])[0]):
        return MoveResult(move=move, status="unreachable", state=ex.state,
                          info={"reason": "the line starts inside the object"})  # fmt: skip
    here = np.asarray(ex.state.position, dtype=float)
    transfer = float(np.linalg.norm(start - here))
    hits = line_hits(ex.model, s_m[None], u_m[None])
    t_hit, face = float(hits.first[0]), int(hits.face[0])
    rho = ex.noise.k * ex.noise.position_sigma
    if t_hit <= length:
        free = FreeSegment(start + ex._vec3(ex.noise.position_sigma), u, t_hit, rho)
        point_m = s_m + t_hit * u_m
        comp = ex._face(face, point_m[None], ())
        ex.components.append(comp)
        ex._pos = point_m
        ex.state = ex._state(face=comp.id)
        s = transfer + t_hit
        return MoveResult(move=move, status="ok", components=(comp,), distance=s, cost=ex.costs.probe_move(s),
                          state=ex.state, free_space=(free,), info={"contact": t_hit})  # fmt: skip
    free = FreeSegment(start + ex._vec3(ex.noise.position_sigma), u, length, rho)
    s = transfer + length + float(np.linalg.norm(move.end - here))
    return MoveResult(move=move, status="ok", distance=s, cost=ex.costs.probe_move(s), state=ex.state,
                      free_space=(free,), info={"contact": None})  # fmt: skip


def _invalid(ex: GeometricExecutor, move: ProbeMove, reason: str) -> MoveResult:
    return MoveResult(move=move, status="invalid", state=ex.state, info={"reason": reason})


__all__ = ["execute_probe"]
