"""What the physics executor knows of its workspace, and the geometry it checks against it.

The robot's priors are the table top's height and the region over which objects are placed
(:data:`~haptic.sim.scene.TABLE_TOP_Z`, :data:`~haptic.sim.scene.OBJECT_REGION`), and its own fingertip pad,
whose radius the toucher refines from the sensed contacts. From them: how high above the table the pad's lowest
point would be touching a point of a face, whether a sensed contact is the table, how far a vertex circle can
sweep before it would put the pad on the table (the planner's computation, :mod:`haptic.planning.table`, with
the executor's own limit), where an edge move can touch its face again off the table, the landing grid of the
start, and the admissible moves of the current state. Nothing here reads the object.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from haptic.executor.primitives import Toucher
from haptic.executor.segment import EdgeRecord, Segmenter
from haptic.geometry.se3 import perpendicular
from haptic.planning.moves import EdgeMove, FaceMove, Move, SensorState, VertexMove
from haptic.planning.table import circle_sweep_off_table, pad_height
from haptic.sim.physics import FingertipContact
from haptic.sim.scene import OBJECT_REGION, TABLE_TOP_Z

GRID_END = 1e-9
"""The landing grid reaches its far end despite round-off [m]."""


@dataclass(frozen=True)
class ReentrySearch:
    """Where an edge move touches its face again when the place beside the last contact is within the pad's reach
    of the table: the nearest place further along the edge that is not."""

    distance: float = 0.0301
    """Places up to this far on along the edge are tried [m] ..."""
    step: float = 0.002
    """... in steps of this [m] ..."""
    slack: float = 1e-3
    """... within this beyond the explored interval [m] ..."""
    margin: float = 0.001
    """... the first where the pad stays this much above its limit over the table [m]."""


class Workspace:
    """The table, the object region and the pad, as the executor's moves and start check them.

    ``toucher`` gives the pad's radius (refined as it senses contacts); the limits are those of
    :class:`~haptic.executor.physics.PhysicsSettings`: ``table_margin`` (a contact this close above the table
    top with an upward normal is the table), ``pad_limit`` (a touch whose pad would come closer than this to the
    table top is out of reach), ``vertex_radius`` and ``vertex_start_angle`` (the vertex circle)."""

    def __init__(
        self,
        toucher: Toucher,
        table_margin: float,
        pad_limit: float,
        vertex_radius: float,
        vertex_start_angle: float,
        *,
        table_normal_cos: float,
        table_contact_cos: float,
    ) -> None:
        self.toucher = toucher
        self.table_z = TABLE_TOP_Z
        self.table_margin = table_margin
        self.pad_limit = pad_limit
        self.vertex_radius = vertex_radius
        self.vertex_start_angle = vertex_start_angle
        self.table_normal_cos = table_normal_cos
        self.table_contact_cos = table_contact_cos

    def pad_clearance(self, point: np.ndarray, normal: np.ndarray) -> float:
        """Height above the table top of the pad's lowest point when it touches ``point`` of a face of
        ``normal`` (fingers pointing down) [m]."""
        return pad_height(point, normal, self.toucher.pad_radius, self.table_z)

    def is_table(self, normal: np.ndarray, point: np.ndarray | None) -> bool:
        """Whether a contact at ``point`` with ``normal`` is the table top (not the object)."""
        return point is not None and normal[2] > self.table_normal_cos and point[2] < self.table_z + self.table_margin

    def touching_table(self, contacts: Sequence[FingertipContact]) -> bool:
        """Whether one of a fingertip's sensed contacts is with the table top."""
        return any(
            c.point_in_world[2] < self.table_z + self.table_margin and c.normal_in_world[2] > self.table_contact_cos
            for c in contacts
        )

    def circle_sweep_off_table(self, vtx: np.ndarray, n_f: np.ndarray, u: np.ndarray, w_f: np.ndarray) -> float:
        """Angle [rad] the vertex circle round ``vtx`` on the face of normal ``n_f`` (``u`` along the edge
        toward the vertex, ``w_f`` into the face) can sweep from its start before the pad would come onto the
        table (2π: never; 0: not even its start is reachable)."""
        return circle_sweep_off_table(
            vtx, u, w_f, n_f, self.vertex_radius, self.table_z, self.toucher.pad_radius, self.pad_limit,
            self.vertex_start_angle,
        )  # fmt: skip

    def reentry_point(
        self, rec: EdgeRecord, n: np.ndarray, inward: np.ndarray, s0: float, u: np.ndarray, reentry: float,
        search: ReentrySearch,
    ) -> np.ndarray | None:  # fmt: skip
        """Where an edge move touches the face of normal ``n`` again ``reentry`` in from edge ``rec`` (``inward``
        into the face) before following it along ``u``: beside the last contact (parameter ``s0`` on the
        edge), or -- when that is within the pad's reach of the table -- the nearest point further along ``u``
        (inside the explored interval) that is not, by ``search``. None: no such point."""
        lo, hi = rec.interval
        sense = 1.0 if float(u @ rec.direction) > 0 else -1.0
        for shift in np.arange(0.0, search.distance, search.step):
            s_k = s0 + sense * shift
            if shift > 0 and not (lo - search.slack <= s_k <= hi + search.slack):
                break
            p = rec.at(s_k) + reentry * inward
            if self.pad_clearance(p, n) >= self.pad_limit + search.margin:
                return p
        return None


def landing_points(
    spacing: float, margin: float, rng: np.random.Generator, jitter: float, order_jitter: float,
    offset: float = 0.0,
) -> list[np.ndarray]:  # fmt: skip
    """The start's landing grid over the object region (a workspace prior), ``spacing`` apart and ``margin``
    beyond the region, jittered by up to ``jitter`` × ``spacing``, nearest the region's centre first (to
    within ``order_jitter`` [m]); ``offset`` (a fraction of ``spacing``) shifts the grid along both axes: 0.5
    puts its points at the centres of the cells of the grid without it."""
    (x0, x1), (y0, y1) = OBJECT_REGION
    xs = np.arange(x0 - margin + offset * spacing, x1 + margin + GRID_END, spacing)
    ys = np.arange(y0 - margin + offset * spacing, y1 + margin + GRID_END, spacing)
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    pts = np.array([[x, y] for x in xs for y in ys])
    pts = pts + rng.uniform(-jitter, jitter, pts.shape) * spacing
    order = np.argsort(np.linalg.norm(pts - centre, axis=1) + rng.uniform(0, order_jitter, len(pts)))
    return [pts[i] for i in order]


def toward_vertex(rec: EdgeRecord, s_v: float) -> np.ndarray:
    """The unit vector along edge ``rec`` toward the vertex at parameter ``s_v`` (the end of the explored
    interval it is nearer)."""
    lo, hi = rec.interval
    return rec.direction if s_v >= 0.5 * (lo + hi) else -rec.direction


def admissible_moves(
    state: SensorState | None, segmenter: Segmenter, workspace: Workspace, rng: np.random.Generator, n_directions: int
) -> list[Move]:
    """Candidate moves from ``state`` (as the geometric executor's): face moves in random in-plane directions,
    edge moves both ways on an edge, vertex moves across either face at a vertex whose circle can start off
    the table (else the move would fail at once with status ``unreachable``)."""
    if state is None:
        return []
    n = segmenter.faces[state.face].component.normal
    a = perpendicular(n)
    b = np.cross(n, a)
    moves: list[Move] = [
        FaceMove(math.cos(x) * a + math.sin(x) * b) for x in rng.uniform(0, 2 * np.pi, n_directions)
    ]
    if state.edge is not None:
        moves.extend([EdgeMove(1), EdgeMove(-1)])
    if state.vertex is not None:
        rec = segmenter.edges.get(state.edge) if state.edge is not None else None

        def off_table(f: int) -> bool:
            if rec is None or f not in rec.inward or state.vertex not in rec.vertices:
                return True
            u = toward_vertex(rec, rec.vertices[state.vertex])
            vtx = segmenter.vertices[state.vertex].position
            return workspace.circle_sweep_off_table(vtx, segmenter.faces[f].component.normal, u, rec.inward[f]) > 0.0

        moves.extend(VertexMove(f) for f in state.edge_faces if off_table(f))
    return moves


__all__ = ["GRID_END", "ReentrySearch", "Workspace", "admissible_moves", "landing_points", "toward_vertex"]
