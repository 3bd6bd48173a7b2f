"""Candidate resting probes: another finger probing a neighbouring face while the exploring pad rests where the last
move left it (seed §5's several fingers; the hand's arm does not travel).

A resting probe (:class:`~haptic.planning.moves.ProbeMove` with ``resting``) is a free-space probe (§1.1) carried out
by one of the hand's other fingers, its joints alone moving: the arm and the exploring finger stay where they are,
the pad on its face. What that finger can reach is the hand's to say (the episode's reach test,
``PlannerConfig.resting_reach``: the fingers' places now, and whether one can close along a line, with the
hypothesised model placed for collisions); the lines come from the hypotheses: for each finger, points on the
pose classes' faces within its reach (each face's middle and half-way to each corner), other than the face the pad
rests on, each approached along the face's inward normal from a standoff. They are predicted per pose class as
probes are (:func:`~haptic.planning.probe_prediction.predict_probes`) and cost the finger's closing alone
(:meth:`~haptic.planning.moves.CostModel.resting_probe`: its pad's way to the line, along it and back, a stroke when
it touched; no ``c_m``, no arm travel), so they are ranked with every other move by eliminations per unit cost.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import CostModel, ProbeMove
from haptic.planning.probe_prediction import ProbePrediction


@dataclass(frozen=True, eq=False)
class RestingFinger:
    """Where one of the hand's other fingers is while the hand rests, as the robot knows it (its encoders)."""

    finger: str
    """Its name (``haptic.planning.moves.FINGER_NAMES``)."""
    pad: np.ndarray
    """Its pad's centre now (3,) [m]."""
    base: np.ndarray
    """Its first joint (3,) [m] ..."""
    reach: float
    """... and how far from it its pad's centre can be [m] ..."""
    lowest: float = -np.inf
    """... and the lowest its pad's centre can go (the finger straight) [m]: the fingers hang side by side from one
    palm, so another finger's pad goes no lower than about where the exploring pad rests."""
    workspace: np.ndarray | None = None
    """Where its pad's centre can be, its joints alone moving (points over a grid of its joints' ranges, (K, 3))
    [m]; None: anywhere within ``reach``."""


@dataclass(frozen=True)
class RestingConfig:
    """Options of resting-probe candidates."""

    standoff: float = 0.012
    """A line starts with the pad this far off the face [m] ..."""
    overshoot: float = 0.012
    """... and runs this far past it (a miss beyond) [m]."""
    same_face_cos: float = float(np.cos(np.deg2rad(20.0)))
    """A face whose normal is within 20° of the resting pad's face's ..."""
    same_face_offset: float = 0.004
    """... and whose plane passes this close to the pad's contact is the face the pad rests on: not probed [m]."""
    hypotheses: int = 3
    """Lines are aimed at the faces of this many of the most likely pose classes."""
    checks: int = 8
    """Most lines of one decision the reach test is asked about, the most efficient first."""
    inset: float = 0.5
    """Points on a face: its middle, and this fraction of the way from it to each corner."""
    oblique: float = float(np.deg2rad(45.0))
    """Lines come head-on onto a face and turned by this from its normal (:func:`approaches`) [rad]."""
    workspace_tol: float = 0.01
    """A line is offered to the reach test only when its finger's pad, at the line's start and where it touches,
    lies this close to a point of the finger's sampled workspace (:attr:`RestingFinger.workspace`) [m]."""


def resting_lines(hypotheses: Sequence[Hypothesis], weights: np.ndarray, fingers: Sequence[RestingFinger],
                  contact: np.ndarray, normal: np.ndarray, config: RestingConfig, table_z: float | None = None,
                  pad_radius: float = 0.0, table_clearance: float = 0.0) -> list[ProbeMove]:  # fmt: skip
    """Lines for ``fingers`` onto the faces of the most likely ``hypotheses`` (module docstring), the resting pad's
    ``contact`` and face ``normal`` (world) telling the face it rests on. One :class:`ProbeMove` per finger and
    point, ``finger`` and ``resting`` set, no path (the reach test gives it)."""
    order = np.argsort(-np.asarray(weights, dtype=float), kind="stable")[: config.hypotheses]
    n_rest = np.asarray(normal, dtype=float)
    p_rest = np.asarray(contact, dtype=float)
    out: list[ProbeMove] = []
    for k in order:
        h = hypotheses[int(k)]
        if h.world_from_model is None:
            continue
        for f in range(h.poly.n_faces):
            n = h.world_from_model.rotate(h.poly.face_normals[f])
            corners = h.world_from_model.apply(h.poly.vertices[list(h.poly.face_vertices(f))])
            offset = abs(float((p_rest - corners[0]) @ n))
            if float(n @ n_rest) > config.same_face_cos and offset < config.same_face_offset:
                continue  # the face the pad rests on
            middle = corners.mean(axis=0)
            points = [middle, *(middle + config.inset * (c - middle) for c in corners)]
            for p in points:
                if table_z is not None and float(p[2]) < table_z + pad_radius + table_clearance:
                    continue
                centre = p + pad_radius * n  # the pad's centre touching there
                for u in approaches(n, config.oblique):
                    along = config.standoff / max(float(-u @ n), 0.1)  # the pad's surface ``standoff`` off the face
                    start = centre - along * u
                    for rf in fingers:
                        if float(np.linalg.norm(centre - rf.base)) > rf.reach or float(centre[2]) < rf.lowest:
                            continue
                        if rf.workspace is not None and not _within(rf.workspace, (centre, start),
                                                                    config.workspace_tol):  # fmt: skip
                            continue
                        move = ProbeMove(start + pad_radius * u, u, along + config.overshoot, finger=rf.finger,
                                         resting=True)  # fmt: skip
                        if not any(_same(move, m) for m in out):
                            out.append(move)
    return out


def approaches(normal: np.ndarray, oblique: float) -> list[np.ndarray]:
    """Directions of approach onto a face of outward ``normal``: head-on, and turned by ``oblique`` [rad] toward
    each of four directions in the face (down its slope, up it and across both ways; a horizontal face: along the
    world's axes) -- a finger whose joints cannot bring its pad head-on may close across."""
    n = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    down = np.array([0.0, 0.0, -1.0]) + n[2] * n  # straight down, in the face
    a = down / np.linalg.norm(down) if float(np.linalg.norm(down)) > 0.1 else np.cross(n, [0.0, 1.0, 0.0])
    a = a / np.linalg.norm(a)
    b = np.cross(n, a)
    out = [-n]
    if oblique > 0.0:
        out += [-np.cos(oblique) * n + np.sin(oblique) * w for w in (a, -a, b, -b)]
    return [u / np.linalg.norm(u) for u in out]


def _within(workspace: np.ndarray, points: Sequence[np.ndarray], tol: float) -> bool:
    """Whether every one of ``points`` is within ``tol`` of a point of ``workspace``."""
    return all(float(np.min(np.linalg.norm(workspace - p, axis=1))) <= tol for p in points)


def _same(a: ProbeMove, b: ProbeMove, tol: float = 0.005) -> bool:
    return (a.finger == b.finger and float(np.dot(a.direction, b.direction)) > 0.99
            and float(np.linalg.norm(np.asarray(a.start) - np.asarray(b.start))) < tol)  # fmt: skip


def resting_costs(pred: ProbePrediction, finger: RestingFinger, costs: CostModel,
                  pad_radius: float = 0.0) -> np.ndarray:  # fmt: skip
    """Each hypothesis's cost of ``pred``'s resting probe by ``finger``: its pad from where it rests to the line's
    start, along the line to contact (or its end) and back to where it rests, a stroke when it touched."""
    start = np.asarray(pred.move.start, dtype=float) - pad_radius * np.asarray(pred.move.direction, dtype=float)
    there = float(np.linalg.norm(start - finger.pad))
    closing = np.where(pred.hit, np.nan_to_num(pred.distance), float(pred.move.length))
    s = 2.0 * there + 2.0 * closing
    return np.array([costs.resting_probe(float(x), bool(h)) for x, h in zip(s, pred.hit, strict=True)])


__all__ = ["RestingConfig", "RestingFinger", "resting_costs", "resting_lines"]
