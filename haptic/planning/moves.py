"""The seed's three admissible moves (§4), the free-space probe of §1.1, the sensor state they start from, their
results, and their costs (§3.1).

A move is chosen by the planner and carried out by an executor (geometric or physics); both return the same
:class:`MoveResult`. Distances are in metres; costs are in cost units.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from enum import StrEnum

import numpy as np

from haptic.matching.components import DataComponent
from haptic.matching.free_space import FreeSegment
from haptic.matching.trace import ContactTrace

MOVE_SETS = ("tracing", "probing", "all")
"""The admissible kinds of move a planner may be given: tracing moves, free-space probes, or both."""
DEFAULT_MOVES = "all"
"""The move set of the command line's episodes unless one is asked for (``--moves``), on the geometric executor:
with the default verification it recognises every episode of the seed and look-alike benchmarks, as ``tracing``
does, for less path cost (README, "The command line")."""
HAND_DEFAULT_MOVES = "tracing"
"""The same on the simulated hand (``--executor physics``): there the verification's tracing moves, started
from the face a probe left the pad on, confirm fewer recognitions than after the seed's tracing (README)."""


DEFAULT_FINGERS = 1
"""Fingers at once unless asked for (``--fingers``), on the geometric executor (README, "Several fingers at
once")."""
HAND_DEFAULT_FINGERS = 1
"""The same on the simulated hand: the index finger alone (its placements of several fingertips are carried out,
but the planner never found one more efficient than a tracing move there: README, "Several fingers at once")."""


def default_fingers(executor: str) -> int:
    """The command line's fingers at once for ``executor`` when ``--fingers`` is not given."""
    return HAND_DEFAULT_FINGERS if executor == "physics" else DEFAULT_FINGERS


def default_moves(executor: str) -> str:
    """The command line's move set for ``executor`` when ``--moves`` is not given."""
    return HAND_DEFAULT_MOVES if executor == "physics" else DEFAULT_MOVES


@dataclass(frozen=True)
class CostModel:
    """Cost constants of seed §3.1. ``c_f``, ``c_e``, ``c_v`` multiply distance; the rest are per event.

    Defaults: 1 unit per cm across a face, 2 per cm along an edge (more care), 1.5 per cm around a vertex.
    A free-space probe (§1.1) costs a constant ``c_p`` per probe, as in the free-space work that counted
    probes, plus ``c_s`` per metre travelled through free space (0.2 per cm: free motion needs no care).
    """

    c_f: float = 100.0
    """Tracing across a face [units/m]."""
    c_e: float = 200.0
    """Tracing along an edge [units/m]."""
    c_v: float = 150.0
    """Circling a vertex [units/m]."""
    c_j: float = 0.4
    """Detecting contact with an edge while on a face [units]."""
    c_k: float = 0.4
    """Detecting a vertex while on an edge [units]."""
    c_n: float = 0.5
    """Acquiring a face normal (a short 2-D stroke) [units]."""
    c_b: float = 0.5
    """Acquiring an edge direction [units]."""
    c_p: float = 2.0
    """Per free-space probe: leaving the surface, the guarded approach and its contact (or its end) [units]."""
    c_s: float = 20.0
    """Moving through free space, to a probe's line and along it [units/m]."""
    c_m: float = 3.0
    """Per placement of several fingertips at once: setting the hand's posture for all its fingers and bringing
    it to the placement -- more than one probe's ``c_p``, less than two: the fingers close together, in one
    approach [units]."""
    c_q: float = 0.5
    """Per finger of a placement: its own guarded closing to contact (or to the end of its line) [units]."""

    def face_move(self, s: float) -> float:
        """``c_f s + c_j + c_b + c_n`` (§4, face move)."""
        return self.c_f * s + self.c_j + self.c_b + self.c_n

    def edge_move(self, s: float) -> float:
        """``c_e s + c_k`` (§4, edge move)."""
        return self.c_e * s + self.c_k

    def vertex_move(self, s: float) -> float:
        """``c_v s + c_j + c_b + c_n`` (§4, vertex move)."""
        return self.c_v * s + self.c_j + self.c_b + self.c_n

    def probe_move(self, s: float) -> float:
        """``c_p + c_s s`` (§3.1 in the manner of the tracing moves; ``s``: the distance travelled in free space,
        to the line's start, along it to contact or its end, and back to the surface after a miss)."""
        return self.c_p + self.c_s * s

    def placement_move(self, s: float, fingers: int, strokes: int) -> float:
        """``c_m + c_s s + fingers · c_q + strokes · c_n``: a placement of several fingertips at once (seed §5's
        multi-finger move, costed in the manner of §3.1): the fixed ``c_m``, the hand's travel ``s`` through free
        space (to the placement and the longest finger's closing), each finger's closing, and the brief stroke
        that measures the normal of each face a pad touched (``strokes``: none for a point sensor, which has the
        normal at contact, as its probes do). Two fingers cost ``4 + c_s s`` with a point sensor, against
        ``4 + c_s (s_1 + s_2)`` for two probes; on the hand, touching, ``5 + c_s s`` against ``5 + c_s (s_1 + s_2)``;
        four cost ``5 + c_s s`` against ``8 + c_s Σ s_i`` with a point sensor."""
        return self.c_m + self.c_s * s + fingers * self.c_q + strokes * self.c_n


@dataclass(frozen=True, eq=False)
class SensorState:
    """Where the sensor is, in data terms: what a robot knows without the model."""

    position: np.ndarray
    """Sensor (contact) position in the world frame, shape (3,) [m]."""
    face: int
    """Id of the data face the sensor is on or nearest."""
    edge: int | None = None
    """Id of the data edge the sensor is on or near, else None."""
    vertex: int | None = None
    """Id of the data vertex the sensor is at or near, else None."""
    edge_faces: tuple[int, ...] = ()
    """Ids of the data faces on either side of ``edge`` (those acquired)."""


@dataclass(frozen=True, eq=False)
class FaceMove:
    """Trace straight across the current face in ``direction`` until an edge; acquire its direction; step
    onto the next face for its normal; end near that edge (§4 item 1)."""

    direction: np.ndarray
    """Unit direction of travel in the world frame, in the plane of the face traced, shape (3,)."""
    face: int | None = None
    """The data face traced when it is not the current one: the other face of the edge the sensor is on (one of
    :attr:`SensorState.edge_faces`); None: the current face ..."""
    start: np.ndarray | None = None
    """... and the point of it, beside that edge, the sensor moves to first and traces from (world frame, shape (3,);
    required with ``face``: the executors refuse a move across another face without it)."""

    kind = "face"


@dataclass(frozen=True)
class EdgeMove:
    """Trace along the current edge in a sense until a vertex (§4 item 2)."""

    sense: int
    """+1 along the data edge's direction ``b_d``, −1 against it."""

    kind = "edge"


@dataclass(frozen=True)
class VertexMove:
    """Circle the current vertex across one face of the current edge until the next edge; acquire its
    direction; step onto the next face for its normal; end near the new edge and the vertex (§4 item 3)."""

    across_face: int
    """Id of the data face (one of the current edge's two faces) that the circular path crosses."""

    kind = "vertex"


VERTEX_RADIUS = 0.008
"""Radius of a vertex move's circle round the vertex [m], the hand's: the physics executor circles the contact
point this far from the vertex (its pad, of 12 mm radius, touching the face there, not the edges round the
vertex). Both executors' settings default to it, and each world gives its executor's to the planner."""

MIN_IN_PLANE = 0.1
"""A face move's direction must keep at least this fraction of its length in the plane of the face [-]."""
ZERO_LENGTH = 1e-12
"""A direction shorter than this has no length (round-off) [-]."""


FACE_RETURN_FAILED = "could not return to the current face"
"""How the reason of a face move that failed touching its face again, before tracing it, begins: every face move
across that face from there would fail the same way."""


VERTEX_FACE_FAILED = "could not reach the face next to the vertex"
"""... and that of a vertex move that failed touching the face it circles across."""


def start_state(move: Move, state: SensorState) -> SensorState:
    """The sensor state ``move`` starts from: ``state``, or on the face a face move names (:attr:`FaceMove.face`), at
    its start."""
    face = getattr(move, "face", None)
    if face is None or face == state.face:
        return state
    start = getattr(move, "start", None)
    return replace(state, face=face, position=state.position if start is None else np.asarray(start, float))


def in_plane(direction: np.ndarray, normal: np.ndarray) -> np.ndarray | None:
    """The component of a face move's ``direction`` in the plane of unit ``normal``, or None when it is shorter
    than :data:`MIN_IN_PLANE` of the direction's length (the direction is not in the plane of the face)."""
    inplane = direction - (direction @ normal) * normal
    if np.linalg.norm(inplane) < MIN_IN_PLANE * max(np.linalg.norm(direction), ZERO_LENGTH):
        return None
    return inplane


@dataclass(frozen=True, eq=False)
class ProbeMove:
    """Leave the surface, move through free space to ``start`` and approach along the line until contact (a
    guarded move) or until ``length`` (a miss): the free-space move of seed §1.1. A hit yields a face data
    component (a point and a normal, adjacent to nothing known); either way the path is free of the object."""

    start: np.ndarray
    """Start of the line in the world frame, shape (3,) [m]."""
    direction: np.ndarray
    """Unit direction of the approach in the world frame, shape (3,)."""
    length: float
    """How far along the line the approach goes before it counts as a miss [m]."""
    finger: str | None = None
    """Which fingertip carries the probe out (a name of ``haptic.sim.scene.FINGERS``), pointing along the line;
    None: the exploring one, the hand in its tracing posture (the fingers pointing down). A face that the exploring
    pad cannot come to that way (under an overhang, the back of a slot) may be touched by another finger with the
    wrist turned (:func:`haptic.executor.placement.finger_probe`)."""
    path: np.ndarray | None = None
    """With ``finger``: the hand's way to the line's start as the planner's reach test found it, clear of the
    hypothesised object -- joint configurations (K, n) from the tracing posture to that finger's pad at the start,
    pointing along the line [rad]; None: the executor finds its own."""
    room: float | None = None
    """With ``finger``: how far the hypothesised face the line is aimed at extends around where the pad is to touch
    it (its contact's distance to the face's rim) [m]: the finger's stroke on it is kept within (a face leaning under
    is pressed clear of the table only near its top, often a narrow corner); None: the executor's own stroke. Where
    the face is steep enough for the level stroke (:attr:`room_up` given), how far the pad can slide level either way
    from there touching the face alone."""
    room_up: float | None = None
    """With ``room`` on a face steep enough for the level stroke: how far the pad can slide up the face from its
    contact touching it alone (the L's second leg) [m]."""

    kind = "probe"

    @property
    def end(self) -> np.ndarray:
        """``start + length · direction`` [m]."""
        return np.asarray(self.start) + self.length * np.asarray(self.direction)

    def problem(self) -> str | None:
        """Why the line cannot be carried out as given (an executor's "invalid" reason), or None."""
        start, u = np.asarray(self.start, dtype=float), np.asarray(self.direction, dtype=float)
        if start.shape != (3,) or u.shape != (3,) or not (np.all(np.isfinite(start)) and np.all(np.isfinite(u))):
            return "start and direction must be finite 3-vectors"
        length = float(self.length)
        if abs(float(np.linalg.norm(u)) - 1.0) > 1e-6 or not np.isfinite(length) or length <= 0.0:
            return "direction must be a unit vector and length a positive number of metres"
        if self.finger is not None and self.finger not in FINGER_NAMES:
            return f"unknown finger {self.finger!r}; valid fingers: {', '.join(FINGER_NAMES)}"
        return None


FINGER_NAMES = ("index", "middle", "ring", "thumb")
"""The hand's fingertips by name (``haptic.sim.scene.FINGERS``, which the pure core does not import)."""

FINGER_COUNTS = (1, 2, 4)
"""The fingers an episode may use at once (``--fingers``): the index finger alone, or placements of up to two or
four fingertips."""


@dataclass(frozen=True, eq=False)
class FingerApproach:
    """One fingertip's part of a placement: a guarded closing along a line, as a probe's (seed §1.1), ending at
    contact (then a brief press and stroke for the face's normal) or at the line's end (free space)."""

    finger: str
    """Which finger (a name of ``haptic.sim.scene.FINGERS``: index, middle, ring, thumb)."""
    start: np.ndarray
    """Start of the finger's line in the world frame, shape (3,) [m]."""
    direction: np.ndarray
    """Unit direction of its closing in the world frame, shape (3,)."""
    length: float
    """How far along the line it closes before it counts as a miss [m]."""

    @property
    def line(self) -> ProbeMove:
        """The finger's line as a probe (:class:`ProbeMove`)."""
        return ProbeMove(np.asarray(self.start, dtype=float), np.asarray(self.direction, dtype=float),
                         float(self.length))  # fmt: skip

    @property
    def end(self) -> np.ndarray:
        """``start + length · direction`` [m]."""
        return self.line.end


@dataclass(frozen=True, eq=False)
class PlacementMove:
    """Two to four fingertips placed at once, in one approach of the hand, each closing along its own line onto a
    different predicted face (:class:`FingerApproach`); each finger that touches yields a face component (its
    contact point and normal), and one that meets nothing its line as free space. A finger that fails does not
    fail the others (seed §5: the multi-finger move the paper left for further work)."""

    fingers: tuple[FingerApproach, ...]
    """The fingers' approaches, at most one per finger."""
    path: np.ndarray | None = None
    """The hand's way to the fingers' lines as the planner's reach test found it, clear of the hypothesised object:
    joint configurations (K, n) from the tracing posture to every pad at its line's start [rad]; None: the executor
    finds its own (the ideal sensor needs none)."""
    travel: float | None = None
    """The farthest way a finger's pad goes along ``path`` (the longest of the placement's fingers' pads' ways,
    each its pad centre's polyline through the path's configurations) [m]; None without a path."""
    home: np.ndarray | None = None
    """Where the exploring pad's centre is at the path's start (the tracing posture), shape (3,) [m]: the hand
    goes there from its face before it follows the path; None without a path."""

    kind = "placement"

    def problem(self) -> str | None:
        """Why the placement cannot be carried out as given (an executor's "invalid" reason), or None."""
        if not 2 <= len(self.fingers) <= 4:
            return f"a placement takes 2 to 4 fingers, got {len(self.fingers)}"
        if len({f.finger for f in self.fingers}) != len(self.fingers):
            return "a placement uses each finger at most once"
        for f in self.fingers:
            why = f.line.problem()
            if why is not None:
                return f"finger {f.finger}: {why}"
        return None


Move = FaceMove | EdgeMove | VertexMove | ProbeMove | PlacementMove


class MoveStatus(StrEnum):
    """How a move ended: ``ok``, or why it failed. A ``str``, so records and messages show the bare value."""

    OK = "ok"
    NO_CONTACT = "no-contact"
    UNREACHABLE = "unreachable"
    TIMEOUT = "timeout"
    UNSTABLE = "unstable"
    INVALID = "invalid"


@dataclass(frozen=True, eq=False)
class Touches:
    """Contacts sensed while the pad slid on one face during a move, in order (world frame)."""

    point_in_world: np.ndarray
    """Sensed contact points (P, 3) [m]."""
    normal_in_world: np.ndarray
    """Sensed unit normals (P, 3), out of the touched surface."""

    def __len__(self) -> int:
        return len(self.point_in_world)


@dataclass(frozen=True, eq=False)
class HandTouch:
    """Points on the object that one link of the hand other than the exploring pad (another finger, a phalanx, the
    palm) touched during a move, from the link's contact readout (world frame): evidence with the link's own
    bound, never a data component."""

    link: str
    """The link's name."""
    point_in_world: np.ndarray
    """Sensed contact points (P, 3) [m], one per ``spacing`` of the link's way."""
    bound: float
    """How far from the object's surface a sensed point may lie [m]: the link's radius (its readout localises a
    touch within its own thickness, not as the pad's)."""
    time: np.ndarray
    """Time of each point (P,) [s]."""

    def __len__(self) -> int:
        return len(self.point_in_world)


@dataclass(frozen=True, eq=False)
class HandLinks:
    """The hand's link poses sampled during a move (the robot's own forward kinematics, never the object), as
    a recording draws them."""

    poses: Mapping[str, np.ndarray]
    """Link name -> its poses, one row per sample: (n, 7) position [m] and quaternion (w, x, y, z); a
    recording also takes (n, 3) positions or (n, 4, 4) transforms."""
    time: np.ndarray | None = None
    """Time of each sample, shape (n,) [s] (None: unknown)."""
    chains: tuple[tuple[str, ...], ...] = ()
    """The skeleton's polylines of link names (drawn when there is no geometry)."""
    geoms: tuple = ()
    """The robot's collision geometry per link and the table top (:class:`haptic.sim.physics.LinkGeom`)."""


@dataclass(frozen=True, eq=False)
class MoveResult:
    """What a move yielded."""

    move: Move
    """The move as asked."""
    status: MoveStatus
    """:attr:`MoveStatus.OK`, or why it failed (a plain string is accepted and converted)."""
    components: tuple[DataComponent, ...] = ()
    """New components, and re-reported (extended) edges, in order of acquisition."""
    distance: float = 0.0
    """Distance travelled by the move's main trace (``s`` of the cost formula) [m]."""
    cost: float = 0.0
    """Cost of the move by the cost model [units]."""
    state: SensorState | None = None
    """Sensor state after the move (None when the move failed and the state is unknown)."""
    touches: tuple[Touches, ...] = ()
    """The contacts sensed while sliding on a face, one group per stroke (the executor decides which of its
    samples count: none from an executor without a contact trace)."""
    trace: ContactTrace | None = None
    """Everything the fingertip sensed during the move (None: the executor keeps no trace)."""
    free_space: tuple[FreeSegment, ...] = ()
    """Segments the move found free of the object (a probe's path up to its contact or its end)."""
    reason: str = ""
    """Why the move failed, in words ("" when it did not, or the executor does not say)."""
    links: HandLinks | None = None
    """The hand's link poses during the move, for recordings (None: the executor has no hand)."""
    hand: tuple[HandTouch, ...] = ()
    """Where links of the hand other than the exploring pad touched the object during the move, one group per
    link (none from an executor without a hand)."""
    sim_time: float | None = None
    """Simulated time the move took [s] (None: the executor does not simulate)."""
    wall_time: float | None = None
    """Wall time the move took [s] (None: not measured)."""
    info: dict = field(default_factory=dict)
    """Executor-specific details no one downstream relies on: the physics executor's sensed edge ``kind``
    ("convex"/"concave"), ``next_face`` ("out of reach" for an edge reported alone), ``vertex_event`` and the
    start's ``travel``; the geometric executor's probe ``contact`` (distance along the line, or None)."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "status", MoveStatus(self.status))

    @property
    def ok(self) -> bool:
        return self.status == MoveStatus.OK
