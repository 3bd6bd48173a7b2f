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
from haptic.planning.moves import FaceMove, SensorState


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


ON_EDGE_INSIDE = 1e-5
"""A face move from a data edge of the face is traced from at least this far inside the face from the edge's model
line [m]: the sensor on the edge it has just crossed lies as often a noise's width outside it, where the trace would
meet that edge at once, entering the face, in place of the edge it leaves the face by."""


def face_start(h: Hypothesis, f_m: int, state: SensorState) -> np.ndarray:
    """Where a face move from ``state`` starts on model face ``f_m`` of posed hypothesis ``h`` (model frame): the
    sensor's position projected onto the face's plane and, when the sensor is on a data edge that ``h`` pairs with a
    side of the face, moved inside that side by at least :data:`ON_EDGE_INSIDE`."""
    poly, p_m = h.poly, h.model_from_world.apply(state.position)
    n = poly.face_normals[f_m]
    p_m = p_m - (p_m @ n - poly.face_offsets[f_m]) * n
    e_m = h.edges.get(state.edge) if state.edge is not None else None
    if e_m is None or f_m not in (poly.edge_left_face[e_m], poly.edge_right_face[e_m]):
        return p_m
    w = np.cross(n, poly.edge_directions[e_m])
    w = w if poly.edge_left_face[e_m] == f_m else -w  # into the face
    inside = float((p_m - poly.edge_points[e_m]) @ w)
    return p_m + (ON_EDGE_INSIDE - inside) * w if inside < ON_EDGE_INSIDE else p_m


def trace_in(h: Hypothesis, move: FaceMove, state: SensorState) -> FaceTrace | None:
    """Face move ``move`` from ``state`` traced in hypothesis ``h``'s world (from :func:`face_start`); None when
    ``h`` cannot say (no pose, the current face not matched, no single edge met)."""
    f_m = h.faces.get(state.face)
    if h.world_from_model is None or f_m is None:
        return None
    model_from_world = h.model_from_world
    poly, p_m = h.poly, face_start(h, f_m, state)
    d_m = model_from_world.rotate(move.direction)
    hit = trace_face(poly, f_m, p_m, d_m)
    return None if hit is None else FaceTrace(f_m, p_m, d_m, hit)

