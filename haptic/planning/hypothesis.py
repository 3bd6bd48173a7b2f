"""A hypothesis: one pose class of one model, as the planner sees it, and a face move traced in its world.

A hypothesis is a model, its pose ``world_from_model`` and the correspondence of data components to model
components. Through the pose it predicts what a move would meet "in its world" (:func:`trace_in`): the
predictions of :mod:`haptic.planning.predict` and the table checks of :mod:`haptic.planning.table` start here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.se3 import SE3
from haptic.geometry.tracing import FaceHit, trace_face
from haptic.planning.moves import FaceMove, SensorState, start_state


@dataclass(frozen=True, eq=False)
class Hypothesis:
    """One pose class of one model, as the planner sees it."""

    model: str
    """Model name."""
    poly: Polyhedron
    """The model."""
    world_from_model: SE3 | None
    """Pose (None until the data fix it)."""
    faces: Mapping[int, int]
    """Data face id → model face id."""
    edges: Mapping[int, int]
    """Data edge id → model edge id."""
    vertices: Mapping[int, int]
    """Data vertex id → model vertex id."""
    size: int = 1
    """Interpretations in this pose class."""
    leaves: tuple[int, ...] = ()
    """The matcher's leaf indices of this pose class's interpretations (when known)."""

    @cached_property
    def model_from_world(self) -> SE3 | None:
        """The inverse pose (computed once)."""
        return None if self.world_from_model is None else self.world_from_model.inverse()


@dataclass(frozen=True, eq=False)
class FaceTrace:
    """A face move traced in one hypothesis's world (model frame)."""

    face: int
    """The model face traced."""
    start: np.ndarray
    """The sensor's position projected onto it."""
    direction: np.ndarray
    """The move's direction."""
    hit: FaceHit
    """Where it meets the face's boundary."""

    def clearance(self, poly: Polyhedron) -> float:
        """Distance of the crossing point from the nearer end of the edge met [m]."""
        e = self.hit.edge
        s_hit = float((self.hit.point - poly.edge_points[e]) @ poly.edge_directions[e])
        return min(s_hit, float(poly.edge_lengths[e]) - s_hit)


def trace_in(h: Hypothesis, move: FaceMove, state: SensorState) -> FaceTrace | None:
    """Face move ``move`` from ``state`` traced in hypothesis ``h``'s world; None when ``h`` cannot say (no
    pose, the current face not matched, no single edge met)."""
    state = start_state(move, state)
    f_m = h.faces.get(state.face)
    if h.world_from_model is None or f_m is None:
        return None
    model_from_world = h.model_from_world
    poly, p_m = h.poly, model_from_world.apply(state.position)
    n = poly.face_normals[f_m]
    p_m = p_m - (p_m @ n - poly.face_offsets[f_m]) * n
    d_m = model_from_world.rotate(move.direction)
    hit = trace_face(poly, f_m, p_m, d_m)
    return None if hit is None else FaceTrace(f_m, p_m, d_m, hit)

