"""The physics executor: the seed's three moves (§4) carried out by the simulated hand under force control.

:class:`PhysicsExecutor` has the interface of the geometric executor -- ``start()`` and ``execute(move)``
returning :class:`~haptic.planning.moves.MoveResult` records with the same components, ids, adjacency and
sensor states -- so the matcher and the planner do not know which executor they talk to. It is built on the
primitives of :mod:`haptic.executor.primitives` and the segmenter of :mod:`haptic.executor.segment`, starts
with the landing search of :mod:`haptic.executor.landing` and checks its workspace (the table) with
:mod:`haptic.executor.workspace`; and it is given a :class:`~haptic.sim.robot.RobotInterface` only: joint
encoders / forward kinematics and the fingertip's sensed contact. It never sees the simulation, the scene, the
object or its pose; the only prior it uses is the workspace (the table's height and the region where objects
are placed).

Costs are computed from the distances actually travelled by each move's main trace (seed §3.1). Faults --
contact lost, joint limit / unreachable target, blocked motion, timeout, simulation instability -- end the
move with a status; no exception escapes :meth:`PhysicsExecutor.execute`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from haptic.errors import HapticError
from haptic.executor.landing import LandingSearch
from haptic.executor.physics_probe import probe_move
from haptic.executor.placement import finger_probe_move, placement_move
from haptic.executor.primitives import OPPOSED, PrimitiveResult, Toucher
from haptic.executor.segment import (
    AT_END,
    MEDIAN_EFFICIENCY,
    MM,
    FaceFit,
    LineFit,
    SegmentBounds,
    Segmenter,
    face_rows,
    fit_face,
    lean_widened,
    line_from_points,
    steady_rows,
)
from haptic.executor.touch_config import TouchConfig
from haptic.executor.workspace import ReentrySearch, Workspace, admissible_moves, toward_vertex
from haptic.geometry.se3 import angle, perpendicular, unit
from haptic.matching.acceptance import BoundFloors
from haptic.matching.components import DataComponent
from haptic.matching.trace import PHASES, ContactTrace
from haptic.planning.moves import (
    FACE_RETURN_FAILED,
    VERTEX_FACE_FAILED,
    VERTEX_RADIUS,
    CostModel,
    EdgeMove,
    FaceMove,
    HandLinks,
    HandTouch,
    Move,
    MoveResult,
    MoveStatus,
    PlacementMove,
    ProbeMove,
    SensorState,
    Touches,
    VertexMove,
    in_plane,
)
from haptic.planning.table import VERTEX_START_ANGLE, level_heading
from haptic.sim.robot import RobotInterface
from haptic.sim.scene import TABLE_TOP_Z

MOVE_STATUSES = frozenset(MoveStatus)
"""The statuses a move result may carry."""

RIDGE_PROBE = 0.004
"""An edge measured from a roll alone is followed this far each way from where the roll ended [m] ..."""
RIDGE_MIN_SPAN = 0.003
"""... and its ridge contacts must span at least this along it [m]."""
RETURN_FAILED = "could not return next to the edge: "
"""How a failed return next to an edge before an edge move begins its reason."""
NEXT_FACE_LOST = ("too few contacts on the next face", "stepping onto the next face, the pad reached the rim")
"""How a crossing that rolled over the edge but measured too little of a face past it ends
(:meth:`PhysicsExecutor._cross_and_acquire`). A stroke on the next face that was blocked is not among them: that is
the finger held back in a slot (BOX01N seed 1), no vertex's doing; crossed again farther along the slot's wall, the
episode went on to fail four moves in a row at the slot (with ``--verify none``, recognised without it)."""


FROM_TOUCHED = ", from where the face was touched"
"""Said of a crossing made again from a point the face was touched at, its start beside the first lying off the face."""
TABLE_BEFORE_NEXT = "the pad reached the table's clearance before the next face"
"""How a roll over a convex edge that the table stopped ends (:meth:`PhysicsExecutor._cross_and_acquire`)."""
STEP_AT_TABLE = "stepping onto the next face, the pad met the table at the edge"
"""How a crossing ends whose roll settled but whose step in off the edge the table stopped (a face move then gives the
edge alone, from the roll)."""


TOUCH_PHASES = ("face", "circle")
"""Trace phases whose contacts count as touches: the pad sliding on one face (rolling over an edge, or resting
on an edge or a vertex, it may touch two faces at once, and the sensed point is their mean)."""


HAND_SPACING = 0.001
"""A link's contacts with the object are kept one per this much of their way (the readout is watched every few
ticks; a link resting on the object gives one point) [m]."""


def hand_touches(contacts, radii: dict[str, float]) -> tuple[HandTouch, ...]:
    """The links' contacts with the object watched through a move (:class:`~haptic.executor.primitives.HandContact`,
    in order), one group per link, thinned to one per :data:`HAND_SPACING`, each link's bound its radius
    (``radii``)."""
    kept: dict[str, list] = {}
    for c in contacts:
        rows = kept.setdefault(c.link, [])
        if not rows or float(np.linalg.norm(c.point_in_world - rows[-1].point_in_world)) >= HAND_SPACING:
            rows.append(c)
    return tuple(HandTouch(link, np.array([c.point_in_world for c in rows]), radii.get(link, 0.0),
                           np.array([c.time for c in rows])) for link, rows in kept.items())  # fmt: skip


def touches_of(trace: ContactTrace) -> tuple[Touches, ...]:
    """The contacts of ``trace`` sensed while sliding on a face, one group per phase of :data:`TOUCH_PHASES`."""
    out = []
    for ph in TOUCH_PHASES:
        ok = trace.in_contact & (trace.phase == PHASES.index(ph))
        out.append(Touches(trace.point_in_world[ok], trace.normal_in_world[ok]))
    return tuple(out)


@dataclass(frozen=True)
class PhysicsSettings:
    """Geometry of the moves and of the start (workspace prior)."""

    touch: TouchConfig = field(default_factory=TouchConfig)
    """Forces, speeds and detection thresholds of the primitives."""
    approach_height: float = 0.11
    """Start: the pad centre descends from this height above the table [m]."""
    search_floor: float = 0.018
    """Start: ... down to this height of the pad centre above the table (nothing touched: no object there) [m]."""
    low_search_floor: float = 0.015
    """Start: ... and in the passes over the landing grid after the first, down to this (the pad's radius and
    ``pad_clearance`` and 1 mm): descending to ``search_floor`` the pad touches a low object's sloping faces only
    near its top, where a ridge or an apex leaves no room for the L stroke (the public polyhedra's pentagonal
    pyramid at 30 mm, 9.8 mm high, its sides sloping 39°: every touch within 1.1 mm of the apex's height) [m]."""
    search_speed: float = 0.10
    """Start: speed of the fast guarded descent [m/s]."""
    search_spacing: float = 0.025
    """Start: spacing of the landing grid over the object region [m]."""
    search_margin: float = 0.04
    """Start: the grid extends this far beyond the object region [m]."""
    search_passes: int = 2
    """Start: passes over the landing grid while no face is found, the second (and every other) at the centres of
    its cells (shifted by half the spacing along both axes): the pad, descending to
    ``search_floor``, catches a low object within about its radius of its centre, and a 30 mm object standing on
    a 15 mm foot (the elongated triangular pyramid upright) or lying 10 mm high stood between the points of the
    25 mm grid."""
    max_landings: int | None = None
    """Start: landing attempts before giving up (None: every point of the landing grid -- the object may rest
    anywhere over the region, out to its corners -- plus ``edge_retries`` landings close to an edge touched)."""
    edge_retries: int = 20
    """Start: landings beyond the grid for trying again close by after touching the object near an edge."""
    approach_raise: float = 0.03
    """Start: when the object reaches up to the approach height (the move across above it is blocked, or the
    descent touches at once), the approach height is raised by this and the landing tried again [m]."""
    max_approach_height: float = 0.20
    """Start: ... up to this height of the pad centre above the table (the hand's reach over the region) [m]."""
    normal_stroke: float = 0.004
    """Start: length of each leg of the L stroke for the first face's normal [m]."""
    max_face_trace: float = 0.25
    """Longest trace across a face before a face move gives up [m]."""
    max_edge_trace: float = 0.25
    """Longest trace along an edge [m]."""
    vertex_radius: float = VERTEX_RADIUS
    """Radius of the circle around a vertex (contact point) [m]."""
    vertex_start_angle: float = VERTEX_START_ANGLE
    """The circle starts this far from the current edge [rad]."""
    vertex_standoff: float = 0.004
    """After an edge move the pad rests on the current face this far back along the edge and in from it [m]."""
    table_margin: float = 0.003
    """A contact below the table top plus this, with an upward normal, is the table [m]."""
    pad_clearance: float = 0.002
    """A touch (a repositioning target, a point of a vertex circle) is out of reach when the pad's lowest
    point would come closer than this to the table top; a slide heading down stops there [m]."""
    corner_lean: float = math.radians(15.0)
    """A ridge acquisition that did not settle, its last normals leaning along the edge by more than this, met a
    third face at the edge's end: the pad tries once more a pad's radius from there [rad] ..."""
    corner_rows: int = 20
    """... judged on its last this many rows in contact [-]."""
    edge_reentry: float = 0.004
    """An edge move that must first return next to its edge touches the face this far in from the edge [m] ..."""
    return_shift: float = 0.004
    """... beside the last contact; when that fails, beside the middle of what is known of the edge if that lies at
    least this far from it (``PhysicsExecutor._return_next_to_edge``) [m]."""
    reentry: ReentrySearch = field(default_factory=ReentrySearch)
    """... and, when that is within the pad's reach of the table, searches further along the edge."""
    edge_reach: float = 0.03
    """An edge move starts where the pad is when it rests on one of the edge's faces within this of its line;
    farther, it returns next to the edge first [m]."""
    ridge_offset: float = 0.002
    """A convex edge's ridge, acquired, holds the pad's contact on the edge's line: a contact farther than this from
    it is on another edge (one parallel to it between faces of the same normals: BOX01P's back face meets the
    plateau's top and the lower top 12 mm apart at 60 mm) [m]."""
    vertex_hold: float = 0.05
    """At the end of an edge the pad presses in place this long before the vertex is located [s]."""
    rim_hold: float = 0.1
    """At the end of a concave edge, where the surface fell away, the pad then presses in place this long more,
    reading its contacts on the faces' rims apart (``PhysicsExecutor._concave_end``) [s] ..."""
    valley_margin: float = 0.002
    """A vertex move's circle about the end of a valley starts where the pad, resting on the face it circles, clears
    the valley's other face by this (``PhysicsExecutor._valley_circle``) [m] ..."""
    valley_start_angle: float = math.radians(60.0)
    """... at this angle from the valley, at least [rad] ..."""
    valley_max_radius: float = 0.02
    """... and at most this far from the vertex; farther, the move fails [m]."""
    rim_plane: float = 0.001
    """... a contact within this of a face's plane is on it (or on its rim) [m] ..."""
    min_rim_samples: int = 10
    """... at least this many such contacts per face ..."""
    rim_tilt: float = math.radians(10.0)
    """... whose mean normal has turned off the face by more than this (the pad rests on the rim), and the rim
    crosses the edge's line at more than this [rad]."""
    min_vertex_rows: int = 3
    """The vertex is located from the rows whose normal leans along the edge (at least this many) ..."""
    lost_vertex_rows: int = 5
    """... or, contact lost, from this many last contacts [-]."""
    vertex_lean_sigmas: float = 3.0
    """A row's normal leans along the edge (the pad rolling on the vertex) when it leans by more than the touch's
    ``loss_lean_sin`` (5°) and by more than this many σn of the sensor: at noise level 4 (σn 4°) a sixth of the rows
    on the ridge leaned 5° by noise alone, and the vertex put at their median lay 14 mm short of the edge's end (BOX01
    at 150 mm, seed 1: 2.55 times its bound; LBLOCK01 13 mm, 3.08) [-]."""
    min_block_cos: float = 0.2
    """A blocking contact locates a vertex only when its normal has at least this component along the edge [-] ..."""
    gap_rows: int = 15
    """... and when the pad's last contacts on the ridge before it (at most this many) lie at its radius (the pad did
    not span a gap in the ridge, ``PhysicsExecutor._spans_a_gap``) [-]."""
    roll_lead_rows: int = 8
    """The last rows of a trace on a face before a roll count with the roll (for the edge between) [-]."""
    stroke_headings: int = 4
    """An L stroke for a face's normal is tried in up to this many headings, a quarter turn apart."""
    reacquire_turns: tuple[float, ...] = tuple(math.radians(a) for a in (90.0, 60.0, 120.0, 40.0, 140.0))
    """A crossing that lost the next face (contact lost, the roll's limit, too few contacts on it) touches it
    afresh, lifted off: at these guessed turns of its normal about the edge, the roll's own last normal first [rad]."""
    reacquire_inset: float = 0.005
    """... at a point this far from the edge on the guessed face [m] ..."""
    reacquire_cone: float = math.radians(12.0)
    """... skipping a guess within this of one tried [rad]."""
    rim_reading_cone: float = math.radians(30.0)
    """A face touched afresh along the edge after a first touch past it that read the rims at the edge's end is
    the same face when its normal lies within this of that reading, turned as far from the face crossed from
    (``PhysicsExecutor._same_next_face``) [rad]."""
    square_crossing: float = math.radians(25.0)
    """A face move whose travel crossed the convex edge it reports within this of square to it follows the ridge
    first: crossing square, a roll round a vertex onto a face sharing only it turns the normals about the same axis
    as a roll over an edge, and leans along it no more (antiprism_07 at 60 mm, seed 3: a trace heading into the
    apex of a triangle rolled round it onto a heptagon, 12° off square, the normals' mean lean 0.1°; the "edge"
    lay 25.7 bounds off every true edge and the object was recognised as another model). Crossing at a slant,
    such a roll leans along the line between the faces and the normals tell it [rad]."""
    crossing_clearance: float = 0.006
    """The planner's least distance from a face move's crossing to the nearest vertex on the hand
    (``PlannerConfig.min_vertex_clearance``, preferred where a move that keeps it exists): nearer, the pad
    (12 mm) rolls round the edge's end or drops into a concave corner past it [m]."""
    recross_shift: float = 0.006
    """A face move whose roll went round the edge's end (its normals leaning along the edge) crosses again this
    much farther inside the edge (plus how far the pad overshot the end) ... [m]"""
    recross_back: float = 0.008
    """... starting this far back on the face from where it met the edge [m]."""
    recross_side_cos: float = 0.3
    """A face move whose crossing found no next face crosses again shifted square to its travel, to the side away
    from the vertex the roll went round, when the edge's way from that vertex has at least this component there
    [-]."""
    recrosses: int = 2
    """A face move crosses again at most this many times (a crossing made again may roll round the vertex too, less
    far from it) [-]."""
    recross_glancing: float = math.radians(20.0)
    """A face move whose slide met its edge within this of along it, and rolled round the edge's end, crosses again
    square to the edge: slid again along the same heading from a start shifted along the edge, the pad rides the
    edge's rim at that glancing angle back to the same end (prism_09 of the formula corpus, seed 1: slides 11° from
    the edge met it at the vertex, 0.2 mm from its end, and two crossings made again 9 mm inside it met the same vertex
    again, 0.3 mm from it) [rad]."""
    recross_slant: float = math.radians(60.0)
    """A crossing made again from a point the face was touched at (the start beside the first crossing off the face,
    on a face narrowing to a vertex) heads at least this far from along the edge: at 30° such a slanted crossing
    measured the next face 1.03 bounds off (bipyramid_06 of the formula corpus at 60 mm, seed 1) [rad]."""
    circle_recross: float = 0.024
    """A vertex move whose circle's roll went round the end of the edge it met crosses again so (``recross_shift``,
    ``recross_back``), sliding at most this far to the edge [m]."""
    reacquire_step_in: float = 0.003
    """... and measuring it by an L whose first leg, away from the edge, is this long: a face must span both legs
    (a stroke along a ridge keeps one normal too) [m]."""
    approach_slack: float = 0.01
    """Start: a pad more than this below the approach height lifts straight up first [m]."""
    touched_at_once: float = 0.006
    """Start: a landing touch within this (plus the pad radius) below the approach height touched the side of
    something reaching up to it [m]."""
    landing_back_off: float = 0.005
    """Start: after the fast descent the pad backs off this far up ...[m]"""
    landing_touch: float = 0.015
    """... and touches again slowly, over at most this [m]."""
    landing_jitter: float = 0.012
    """Start: after touching near an edge, landings are tried again this close by (σ) [m] ..."""
    near_landings: int = 2
    """... this many of them."""
    search_jitter: float = 0.3
    """Start: the landing grid's points are jittered by up to this fraction of its spacing [-] ..."""
    search_order_jitter: float = 0.01
    """... and their order (nearest the region's centre first) by up to this distance [m]."""
    table_normal_cos: float = 0.99
    """A contact is the table when its normal's vertical component exceeds this (and it is below the table top
    plus ``table_margin``) [-] ..."""
    table_contact_cos: float = 0.95
    """... a fingertip's contact, as sensed during a move, when it exceeds this [-]."""
    tilt_step_in: float = 0.006
    """A link that met the object where no tilt of the hand lands the pad back on the face (within the retouch
    cone: it lands on the rim of the edge the link met) tilts it again this far farther in on the face, away from
    the link's contact, then (a face move) on along the slide [m] ..."""
    tilt_step_in_sin: float = 0.2
    """... when the link's contact normal has at least this component in the face's plane [-]."""
    upright_retract: float = 0.12
    """After a move made tilted, the pad below the highest point touched backs out along the finger's axis at
    most this far before the hand turns upright [m]."""


@dataclass
class _FaceData:
    points: np.ndarray
    normals: np.ndarray
    anchor: np.ndarray  # a contact point known to be on the face
    rotation: np.ndarray | None = None  # the hand's rotation when it touched the face tilted (None: upright)


class PhysicsExecutor(LandingSearch):
    """Executes face, edge and vertex moves with the simulated hand and segments what it senses."""

    def __init__(
        self,
        robot: RobotInterface,
        bounds: SegmentBounds | None = None,
        costs: CostModel | None = None,
        rng: np.random.Generator | None = None,
        settings: PhysicsSettings | None = None,
        finger: str = "index",
    ) -> None:
        if not isinstance(robot, RobotInterface):
            raise TypeError(
                f"PhysicsExecutor takes a RobotInterface (sensors and commands only), not {type(robot).__name__}; "
                "wrap a Simulation as RobotInterface(sim)"
            )
        self.robot = robot
        self.bounds = bounds or SegmentBounds()
        self.costs = costs or CostModel()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        s = settings or PhysicsSettings()
        self.settings = s
        self.toucher = Toucher(robot, s.touch, finger, self.bounds)
        self.toucher.floor_z = TABLE_TOP_Z + s.pad_clearance
        self.workspace = Workspace(self.toucher, s.table_margin, s.pad_clearance, s.vertex_radius,
                                   s.vertex_start_angle, table_normal_cos=s.table_normal_cos,
                                   table_contact_cos=s.table_contact_cos)  # fmt: skip
        self.segmenter = Segmenter(self.bounds)
        self.state: SensorState | None = None
        """Sensor state after the last move (None before :meth:`start`)."""
        self.traces: list[ContactTrace] = []
        """Every contact trace recorded, one per move (start included)."""
        self._faces: dict[int, _FaceData] = {}
        self.recoveries: list[str] = []
        """What the move under way did to recover instead of failing (in its result's ``info["recoveries"]``)."""
        self.on_face: int | None = None
        """The data face the pad is known to rest on (None: not known)."""
        self._finger = finger
        self._why = ""  # detail of the last repositioning failure
        self._stroke_blocked = False  # the last stroke on a next face met an edge along both of its legs
        self._rolled_round: np.ndarray | None = None  # where a circle's crossing made again rolled round the vertex
        self._met: PrimitiveResult | None = None  # the last crossing a link of the finger stopped
        self._roll: ContactTrace | None = None  # the last crossing's roll (or climb) over the edge
        self._past: list[np.ndarray] = []  # normals the last crossing's touches afresh met past the edge
        self._crossed: tuple[FaceFit, ContactTrace] | None = None  # the face the last slide crossed onto, unfelt
        self._links_until: float | None = None  # sim time of the last hand-link sample reported
        self._radii: dict[str, float] | None = None  # per link, the bound of a point its readout reports

    @property
    def components(self) -> list[DataComponent]:
        """Every component reported so far, in order (re-reported edges appear again)."""
        return self.segmenter.components

    @property
    def bound_floors(self) -> BoundFloors:
        """How the components' bounds are made (the segmenter's floors), for the acceptance test."""
        return self.bounds.floors()

    # ------------------------------------------------------------------------------------------ plumbing
    def _run(self, move: Move, body) -> MoveResult:
        t0, w0 = self.robot.time, time.perf_counter()
        pieces: list[PrimitiveResult] = []
        self.recoveries = []
        self.toucher.take_links()  # drop samples taken outside a move
        self.toucher.take_hand()
        self.toucher.take_wrist()
        if self.robot.time != self._links_until:  # the pose at the start, unless the last move reported it
            self.toucher.sample_links()
        try:
            res = body(pieces)
            if not np.array_equal(self.toucher.hand_rotation, self.toucher.config.hand_rotation):
                self._upright(pieces)
        except (HapticError, FloatingPointError, ValueError, np.linalg.LinAlgError) as exc:
            self.on_face = None
            res = MoveResult(move=move, status="unstable", state=self.state, reason=str(exc))
        except Exception as exc:  # noqa: BLE001 -- mujoco raises plain exceptions on a diverged state
            self.on_face = None
            res = MoveResult(move=move, status="unstable", state=self.state,
                             reason=f"{type(exc).__name__}: {exc}")  # fmt: skip
        trace = ContactTrace.concatenate([p.trace for p in pieces])
        self.traces.append(trace)
        links = self._hand_links()
        hand = hand_touches(self.toucher.take_hand(), self._link_radii())
        info = {**res.info, "recoveries": list(self.recoveries)} if self.recoveries else dict(res.info)
        wrist = self.toucher.take_wrist()
        if wrist["watched"]:
            info["wrist"] = wrist
        return MoveResult(move=res.move, status=res.status, components=res.components, distance=res.distance,
                          cost=res.cost, state=res.state, touches=touches_of(trace), trace=trace, reason=res.reason,
                          links=links, hand=hand, sim_time=self.robot.time - t0, wall_time=time.perf_counter() - w0,
                          free_space=res.free_space,
                          info=info)

    def _upright(self, pieces: list[PrimitiveResult]) -> None:
        """After a move made with the hand tilted: lift the pad off along the sensed normal and turn the hand back
        to the tracing posture there; the pad no longer rests on a face (the next move touches it again). Kept
        tilted, later rolls onto faces leaning under ended elsewhere than upright, and the edges taken from them
        lay outside their bounds (hull_05 and trapezohedron_07 of the formula corpus)."""
        t, cfg = self.toucher, self.toucher.config
        n = t.normal if t.normal is not None else np.array([0.0, 0.0, 1.0])
        lifted = t.tip + cfg.lift * n
        pieces.append(t.move_free(lifted, timeout=cfg.lift_timeout, tol=cfg.lift_tol, retry=False))
        # below the highest point touched (in a hole, under a rim), turned upright there the finger's links would
        # sweep through the object: first back out along the finger's own axis, through where its links are
        back = -(t.hand_rotation @ np.array([0.0, 0.0, 1.0]))
        rise = self._highest_touch() + t.pad_radius + cfg.lift - float(t.tip[2])
        if rise > 0.0 and float(back[2]) > 0.5:
            out = t.tip + min(rise / float(back[2]), self.settings.upright_retract) * back
            pieces.append(t.move_free(out, timeout=cfg.via_timeout, tol=cfg.via_tol, retry=False))
        t.hand_rotation = np.array(cfg.hand_rotation, dtype=float)
        pieces.append(t.move_free(t.tip.copy(), timeout=cfg.via_timeout, tol=cfg.via_tol))
        self.on_face = None

    def _highest_touch(self) -> float:
        """Height of the highest contact kept on any data face [m] (the table top before any)."""
        tops = [float(fd.points[:, 2].max()) for fd in self._faces.values() if len(fd.points)]
        return max(tops, default=TABLE_TOP_Z)

    def _tilt_away(self, met: PrimitiveResult, fid: int, target: np.ndarray, pieces: list[PrimitiveResult],
                   ahead: np.ndarray | None = None) -> bool:
        """After a link of the finger met the object (``met``, event ``"hand"``): tilt the hand, the finger leaning
        away from that contact, by the first of :attr:`TouchConfig.tilt_angles` at which the pad still reaches data
        face ``fid`` and touches it at ``target``; where none lands on the face there, the same a little farther in
        (:attr:`PhysicsSettings.tilt_step_in`): away from the link's contact, then on along the slide's heading
        ``ahead`` (a face move's). True when the pad rests on the face, tilted; else the hand is upright again."""
        n = self.segmenter.faces[fid].component.normal
        ln = np.asarray(met.info["link_normal"], dtype=float)
        for where, at in self._tilt_targets(target, n, ln, ahead):
            for a, _ in self._tilted_touches(ln, at, n, pieces):
                self.on_face = fid
                self.recoveries.append(f"the finger's {met.info['link']} met the object: the hand tilted "
                                       f"{math.degrees(a):.0f}° away{where}")  # fmt: skip
                return True
        self.toucher.hand_rotation = np.array(self.toucher.config.hand_rotation, dtype=float)
        return False

    def _tilt_targets(self, target: np.ndarray, n: np.ndarray, link_normal: np.ndarray, ahead: np.ndarray | None):
        """For :meth:`_tilt_away`: where the tilted pad touches the face of normal ``n`` again, in turn, each with
        what its recovery adds. First ``target``. Then :attr:`PhysicsSettings.tilt_step_in` farther in, away from the
        link's contact (``link_normal``'s part in the face's plane): where the link met the edge above a face leaning
        under, the pad resting just under that edge, tilted at ``target`` it lands on the edge's rim. Then as far on
        along ``ahead`` (a face move's heading): where the link's contact lay beside the slide (on the edge with the
        next lateral face), farther in from it the pad lands on that face's rim again."""
        yield "", target
        step = self.settings.tilt_step_in
        away = link_normal - float(link_normal @ n) * n
        size = math.sqrt(float(away @ away))
        if size >= self.settings.tilt_step_in_sin:
            yield f", {step * 1000:.0f} mm farther in from it", target - step * away / size
        if ahead is not None:
            way = np.asarray(ahead, dtype=float) - float(np.asarray(ahead, dtype=float) @ n) * n
            if float(way @ way) > 1e-6:
                yield f", {step * 1000:.0f} mm on along the slide", target + step * way / math.sqrt(float(way @ way))

    def _tilted_touches(self, link_normal: np.ndarray, target: np.ndarray, n: np.ndarray,
                        pieces: list[PrimitiveResult], held: np.ndarray | None = None):  # fmt: skip
        """The hand tilted away from a link's contact (its normal ``link_normal``) by each of
        :attr:`TouchConfig.tilt_angles` in turn at which the pad reaches a face of normal ``n`` (but the rotation
        ``held``, if given: the hand's already), the pad touching the face again at ``target``: yields each angle
        and touch that landed on the face (within the retouch cone of ``n``), the hand left tilted; stops where the
        pad has no clearance at ``target``, no tilt is left, or the state went unstable. The caller puts the hand's
        rotation back when it takes none."""
        t = self.toucher
        if self.workspace.pad_clearance(target, n) < self.settings.pad_clearance:
            return
        above = target + (t.config.lift + t.pad_radius) * n
        floor = TABLE_TOP_Z + t.pad_radius + self.settings.table_margin
        for a in t.config.tilt_angles:
            rot = t.tilted(link_normal, a)
            if rot is None:
                return
            if (held is not None and np.allclose(rot, held, atol=1e-6)) or not t.reaches(n, rot) \
                    or not self.robot.reachable(t.finger, above, rot).reachable:  # fmt: skip
                continue
            t.hand_rotation = rot
            r = t.lift_and_approach(target, n, floor_z=floor)
            pieces.append(r)
            if r.ok and angle(r.info["normal"], n) <= self.bounds.retouch_cone:
                yield a, r
            elif r.status == "unstable":
                return

    def _link_radii(self) -> dict[str, float]:
        if self._radii is None:
            self._radii = self.robot.link_radii()
        return self._radii

    def _hand_links(self) -> HandLinks:
        """The hand's link poses sampled during the move (the robot's own forward kinematics), for
        recordings, with the skeleton's chains and the robot's collision geometry per link (and the table top)."""
        self.toucher.sample_links()  # the pose at the end of the move
        times, pos = self.toucher.take_links()
        self._links_until = float(times[-1]) if len(times) else self._links_until
        names = self.robot.link_names
        return HandLinks({name: pos[:, j] for j, name in enumerate(names)}, times, self.robot.link_chains,
                         self.robot.link_geoms())  # fmt: skip

    def _edge_between(self, face: int, trace: ContactTrace, phase: str, roll: ContactTrace, fit_b: FaceFit,
                      kind: str, corner: np.ndarray) -> tuple[FaceFit, LineFit | None, str]:  # fmt: skip
        """The fit of data face ``face`` from the ``phase`` rows of ``trace``, and the line of the edge the pad
        rolled over (the last rows on the face, then ``roll``) onto the face of ``fit_b``; no line, and why,
        when the roll cannot have been over an edge between the two faces.

        A slide that went over an edge too shallow to feel onto another face before the roll
        (:meth:`~haptic.executor.segment.Segmenter.face_crossed`) rolled off that face: the fit returned is then
        that face's (no data face yet), the line that of its edge with the face of ``fit_b`` when the roll can have
        been over it, and :attr:`_crossed` holds the face's fit and rows (None otherwise). The shallow edge itself
        was not located: nothing joins that face to ``face``. When the roll cannot have been over that edge, no line
        and why, with that face's fit: a move that crosses again takes its way from the roll's lean off the face it
        rolled off (sphenomegacorona of the public collection of Johnson solids, seed 1: from a triangle over an
        8.3° edge onto the next, and on round a vertex onto a face sharing neither an edge). A next face within the
        edge angle of that face was met over another shallow edge: face ``face``'s test then says so."""
        seg = self.segmenter
        self._crossed = None
        fit_a = self._face_fit(face, trace)
        slide = trace.select(trace.phase == PHASES.index(phase))
        lead = slide.tail(self.settings.roll_lead_rows)
        roll_all = ContactTrace.concatenate([lead, roll])
        convex = kind == "convex"
        crossed = seg.face_crossed(slide, fit_a) if convex else None
        if crossed is not None and angle(crossed[0].normal, fit_b.normal) >= self.bounds.min_edge_angle:
            # (closer, the roll went over another shallow edge, and face a's test names it)
            why = seg.edge_inconsistency(crossed[0], fit_b, convex, roll_all)
            if why is not None:
                return crossed[0], None, f"no edge between the faces: {why}"
            self._crossed = crossed
            return crossed[0], seg.edge_line(crossed[0], fit_b, convex, roll_all, corner), ""
        why = seg.edge_inconsistency(fit_a, fit_b, convex, roll_all)
        if why is not None:
            return fit_a, None, f"no edge between the faces: {why}"
        return fit_a, seg.edge_line(fit_a, fit_b, convex, roll_all, corner), ""

    def _rolled_onto(
        self, move: Move, left: int, line: LineFit, kind: str, normals: tuple[np.ndarray, np.ndarray], fit: FaceFit,
        stroke: ContactTrace, distance: float, cost: float, vertex: tuple[int, float] | None = None,
    ) -> MoveResult:  # fmt: skip
        """The result of a face or vertex move that rolled over an edge (``line``, ``kind``, the faces' ``normals``)
        from face ``left`` and stroked the next face (``fit`` from ``stroke``): the face its slide crossed onto over
        an edge too shallow to feel first, when it did (:meth:`_add_crossed`; the edge was then rolled over from
        that face), the edge, adjacent to the face it was rolled over from and to ``vertex`` (the data vertex the
        move circled and its parameter along the line), and the next face, where the sensor now rests."""
        seg = self.segmenter
        crossed = self._add_crossed()
        left = left if crossed is None else crossed
        new_face = seg.next_id + 1
        adjacent = (left,) if vertex is None else (vertex[0], left)
        edge = seg.add_edge(line, (left, new_face), kind == "convex", normals, adjacent=adjacent, vertex=vertex)
        face = seg.add_face(fit, adjacent=(edge.id,))
        self.store_face(face.id, stroke, fit)
        self.on_face = face.id
        self.state = SensorState(position=self.contact_point(), face=face.id, edge=edge.id,
                                 vertex=None if vertex is None else vertex[0], edge_faces=(left, face.id))  # fmt: skip
        comps = (edge, face) if crossed is None else (seg.faces[crossed].component, edge, face)
        info = {"kind": kind} if crossed is None else {"kind": kind, "crossed_face": crossed}
        return MoveResult(move=move, status="ok", components=comps, distance=distance, cost=cost, state=self.state,
                          info=info)  # fmt: skip

    def _add_crossed(self) -> int | None:
        """Report the face a move's slide crossed onto over an edge too shallow to feel (:attr:`_crossed`), adjacent
        to nothing yet, and keep its rows; its id (None when the slide crossed none)."""
        if self._crossed is None:
            return None
        fit, rows = self._crossed
        face = self.segmenter.add_face(fit)
        self.store_face(face.id, rows, fit)
        return face.id

    def failed_result(self, move: Move, res: PrimitiveResult | str, reason: str) -> MoveResult:
        """A failed move: the status of ``res`` (a primitive's result, or a status), the state before the move;
        the pad is no longer known to rest on a face. An outcome that is no :class:`MoveStatus` (a primitive that
        ended "ok" short of the move, an event such as "undercut" that one move recovers from and another
        cannot) counts as "unreachable"."""
        status = res if isinstance(res, str) else res.status
        if status == "ok" or status not in MOVE_STATUSES:
            status = "unreachable"
        self.on_face = None
        return MoveResult(move=move, status=status, state=self.state, reason=reason)

    def _face_fit(self, fid: int, extra: ContactTrace | None = None) -> FaceFit:
        """The fit of a data face from all rows recorded on it (plus rows of ``extra`` that agree with it).

        The rows of ``extra`` count only when their mean normal agrees with the face's own fit within the bound
        of their difference: a stroke that slid along the rim of an edge holds a steady normal turned off the face
        by less than the face cone (prism_12 at 150 mm, seed 3: 556 rows 2.3° off the face, a fit of 675 rows
        claiming 0.04°, and the edge crossed next 2.3° off, 2.6 bounds)."""
        fd = self._faces[fid]
        b = self.bounds
        base = lean_widened(fit_face(fd.points, fd.normals, b), fd.normals, b)
        if extra is None or not len(extra):
            return base
        n0 = self.segmenter.faces[fid].component.normal
        ok = extra.in_contact
        keep = ok & (np.where(ok[:, None], extra.normal_in_world, 0.0) @ n0 > math.cos(b.row_cone))
        keep &= extra.phase != PHASES.index("roll")
        keep = steady_rows(extra, keep, b)
        if not keep.sum():
            return base
        nrm = extra.normal_in_world[keep]
        s_extra = b.normal_sigma / math.sqrt(len(nrm))
        if angle(unit(nrm.sum(axis=0)), base.normal) > b.bound(math.hypot(base.normal_sigma, s_extra), b.normal_floor):
            return base
        normals = np.vstack([fd.normals, nrm])
        return lean_widened(fit_face(np.vstack([fd.points, extra.point_in_world[keep]]), normals, b), normals, b)

    def store_face(self, fid: int, trace: ContactTrace, fit: FaceFit) -> None:
        """Keep the rows of ``trace`` on data face ``fid`` (those within the face cone of its fit ``fit`` whose
        normal holds steady, :func:`~haptic.executor.segment.steady_rows`)."""
        mask = face_rows(trace, fit.normal, self.bounds.row_cone, self.bounds.min_refine_rows)
        mask = steady_rows(trace, mask, self.bounds)
        pts, nrm = trace.point_in_world[mask], trace.normal_in_world[mask]
        rot = self.toucher.hand_rotation
        tilted = None if np.array_equal(rot, self.toucher.config.hand_rotation) else rot.copy()
        self._faces[fid] = _FaceData(pts, nrm, pts[-1].copy(), tilted)

    def _finger_contacts(self):
        """The exploring fingertip's sensed contacts now."""
        return self.robot.read().contacts[self.robot.fingers.index(self._finger)]

    def contact_point(self) -> np.ndarray:
        """The sensed contact point now, or the pad centre when there is no contact [m]."""
        t = self.toucher
        return t.contact[2].copy() if t.contact[2] is not None else t.tip.copy()

    # ------------------------------------------------------------------------------------------ start
    def start(self) -> MoveResult:
        """Descend from above the object region (a workspace prior; the object's pose is unknown) until the
        pad touches the object -- searching a grid of landing points, nearest the region's centre first --,
        then acquire the touched face's normal with a short L stroke. Reports one data face."""
        move = FaceMove(np.zeros(3))
        return self._run(move, lambda pieces: self._start(move, pieces))

    # ------------------------------------------------------------------------------------------ moves
    def execute(self, move: Move) -> MoveResult:
        """Carry out a move from the current state; a failure is a status, never an exception."""
        if self.state is None:
            return MoveResult(move=move, status="invalid", reason="call start() first")
        if isinstance(move, FaceMove):
            return self._run(move, lambda pieces: self._face_move(move, pieces))
        if isinstance(move, EdgeMove):
            return self._run(move, lambda pieces: self._edge_move(move, pieces))
        if isinstance(move, VertexMove):
            return self._run(move, lambda pieces: self._vertex_move(move, pieces))
        if isinstance(move, ProbeMove) and move.finger is not None:
            # a named fingertip (the exploring one too), the wrist turned to point it along the line, the hand's way
            # the planner's: haptic.executor.placement
            return self._run(move, lambda pieces: finger_probe_move(self, move, pieces))
        if isinstance(move, ProbeMove):  # the free-space probe: haptic.executor.physics_probe
            return self._run(move, lambda pieces: probe_move(self, move, pieces))
        if isinstance(move, PlacementMove):  # several fingertips at once: haptic.executor.placement
            return self._run(move, lambda pieces: placement_move(self, move, pieces))
        return MoveResult(move=move, status="invalid", state=self.state, reason=f"unknown move {move!r}")

    def invalid_result(self, move: Move, reason: str) -> MoveResult:
        """A move that cannot be made from the current state (status ``invalid``, the state unchanged)."""
        return MoveResult(move=move, status="invalid", state=self.state, reason=reason)

    def _ensure_on_face(self, fid: int, pieces: list[PrimitiveResult], near: np.ndarray | None = None,
                        retilt: bool = False) -> str:  # fmt: skip
        """Put the pad on data face ``fid`` (at ``near`` when given, else where it last touched it); ``retilt``: as
        :meth:`_touch_face` does."""
        t = self.toucher
        n = self.segmenter.faces[fid].component.normal
        if (near is None and self.on_face == fid and t.contact[1] is not None
                and angle(t.normal, n) < self.bounds.resting_cone):  # fmt: skip
            return "ok"
        if near is not None:
            targets = [near]
        else:  # where it last touched the face, else the middle of what it touched of it
            fd = self._faces[fid]
            middle = fd.points.mean(axis=0)
            targets = [fd.anchor, middle - float((middle - fd.anchor) @ n) * n]
        status = "unreachable"
        for k, target in enumerate(targets):
            status = self._touch_face(fid, n, target, pieces, retilt=retilt)
            if status == "ok" and k:
                self.recoveries.append("the face touched again at the middle of its contacts")
            if status == "ok" or status == "unstable":
                break
        return status

    def _touch_face(self, fid: int, n: np.ndarray, target: np.ndarray, pieces: list[PrimitiveResult],
                    retilt: bool = False) -> str:  # fmt: skip
        """Lift off and touch data face ``fid`` (normal ``n``) at ``target``; "ok", or a failure with the reason
        in ``self._why``. A face measured with the hand tilted is touched again tilted the same way where the upright
        approach fails, and with ``retilt`` (a face move's return to its face) where the upright touch reads a normal
        off the face too."""
        t = self.toucher
        if self.workspace.pad_clearance(target, n) < self.settings.pad_clearance:
            self._why = "the touch would put the pad on the table"
            return "unreachable"
        floor = TABLE_TOP_Z + t.pad_radius + self.settings.table_margin
        r = t.lift_and_approach(target, n, floor_z=floor)
        pieces.append(r)
        if not r.ok and r.status != "unstable" and not np.array_equal(t.hand_rotation, t.config.hand_rotation):
            # tilted away from where a link met the object, the hand may not reach here: upright again
            t.hand_rotation = np.array(t.config.hand_rotation, dtype=float)
            r = t.lift_and_approach(target, n, floor_z=floor)
            pieces.append(r)
        tilt = self._faces[fid].rotation if fid in self._faces else None
        off = retilt and r.ok and angle(r.info["normal"], n) > self.bounds.retouch_cone
        if (off or (not r.ok and r.status != "unstable")) and tilt is not None and t.reaches(n, tilt) \
                and np.array_equal(t.hand_rotation, t.config.hand_rotation):
            # a face the pad reached only with the hand tilted (the wall of a hole, a link of the finger meeting the
            # object upright): touched again tilted the same way. So too where the upright touch read a normal off the
            # face (bipyramid_08 of the formula corpus, seed 1: a face leaning 17° under, measured tilted 30° after a
            # link met the object, touched upright 3 mm from its upper edge read 13-18° off, and two face moves from it
            # failed). Not for a vertex move: its circle made tilted measured the next face 1.8 bounds off
            # (bipyramid_12, seed 1)
            first = r
            t.hand_rotation = tilt.copy()
            r = t.lift_and_approach(target, n, floor_z=floor)
            pieces.append(r)
            if r.ok and angle(r.info["normal"], n) <= self.bounds.retouch_cone:
                self.recoveries.append("the face touched again with the hand tilted as it was measured")
            elif r.status != "unstable":
                t.hand_rotation = np.array(t.config.hand_rotation, dtype=float)
                r = first if off else r  # the upright touch's reading says why
        if not r.ok:
            self._why = f"{r.status}/{r.event}"
            return r.status
        if angle(r.info["normal"], n) > self.bounds.retouch_cone:
            self._why = f"touched a normal {math.degrees(angle(r.info['normal'], n)):.0f}° off the face"
            return "unreachable"
        self.on_face = fid
        return "ok"

    def _cross_and_acquire(
        self, kind: str, n_a: np.ndarray, direction: np.ndarray, pieces: list[PrimitiveResult], away_from=None,
        overhang: bool = False,
    ):
        """Roll over / climb out of the edge just met, then stroke on the next face. Returns (status, reason,
        roll trace, stroke trace, next face fit). ``overhang``: a stroke whose step in a link of the finger held back
        ends the crossing (:meth:`_overhung`) instead of touching the next face afresh."""
        t = self.toucher
        self._roll, self._past = None, []
        if kind == "concave" and self.workspace.touching_table(self._finger_contacts()):
            return "unreachable", "the finger met the table", None, None, None
        corner = self.contact_point()
        r = t.cross_edge(kind, n_a, direction)
        pieces.append(r)
        self._roll = r.trace
        if not r.ok:
            if r.event == "hand":
                self._met = r
                return "hand", f"crossing the {kind} edge: the finger's {r.info['link']} met the object", None, \
                    None, None
            if r.event in ("undercut", "table"):  # the next face out of the pad's reach: the roll gives the edge
                why = ("the next face leans under, out of the pad's reach" if r.event == "undercut"
                       else TABLE_BEFORE_NEXT)  # fmt: skip
                return "undercut", f"crossing the {kind} edge: {why}", r.trace, None, None
            if r.event == "face":
                return "face", f"crossing the {kind} edge: the pad stayed on the face", None, None, None
            if r.event != "lost":  # the roll went on turning (limit), or the state is bad: nothing to touch afresh
                return r.status, f"crossing the {kind} edge: {r.event}", None, None, None
            return self._reacquire(kind, n_a, direction, corner, r.trace, None, pieces, away_from,
                                   f"crossing the {kind} edge: {r.event}")  # fmt: skip
        n_b = r.info["normal"]
        if self.workspace.is_table(n_b, t.contact[2]):
            return "unreachable", "the edge lies on the table", None, None, None
        along = r.info["edge_direction"]
        if away_from is not None and float((t.tip - away_from) @ along) < 0:
            along = -along
        st = t.stroke(n_b, r.info["away"], along)
        pieces.append(st)
        self._stroke_blocked = st.ok and st.info["blocked"]
        if kind == "convex" and st.ok and st.info["at_table"]:
            # the table may have stopped the roll short of the next face (one leaning under, the edge low): the pad
            # settled on the ridge, its normal partway round (bipyramid_06 at 60 mm: 7-9° short of the face, the pad
            # 1 mm above the table), and the legs along the edge, never off it, rode the ridge with that normal. The
            # next face is as good as hidden by the table, and a face move gives the edge from the roll alone, as
            # where the roll itself reached the table's clearance (the planner predicts so: its strip above the table
            # narrower than the pad's step onto it, on the polyhedra at 30 mm the side faces under a low edge)
            return "undercut", STEP_AT_TABLE, r.trace, None, None
        if overhang and st.info.get("held"):
            return self._overhung(kind, st.info["held"], r.trace)
        rim = st.ok and st.info["rim"]
        fit = self.segmenter.fit_face_trace(st.trace, st.info["normal"]) if st.ok and not rim else None
        if fit is None and st.ok and not rim and st.info["link_normal"] is not None:
            tilted = self._stroke_tilted(st, r.info["away"], along, pieces)
            if tilted is not None:
                fit, st = tilted
        if fit is None:
            why = (f"stroke on the next face failed: {st.event}" if not st.ok
                   else "stepping onto the next face, the pad reached the rim of another edge" if rim
                   else f"too few contacts on the next face ({self.segmenter.face_refusal})")  # fmt: skip
            if st.status == "unstable":
                return st.status, why, None, None, None
            out = self._reacquire(kind, n_a, direction, corner, r.trace, n_b, pieces, away_from, why)
            if out[0] == "unreachable" and out[1] == why and st.ok and not rim:
                again = self._reacquire_rolled(kind, n_a, direction, corner, r, pieces, away_from, why)
                if again is not None:
                    return again
            return out
        return "ok", "", r.trace, st.trace, fit

    def _reacquire_rolled(self, kind: str, n_a: np.ndarray, direction: np.ndarray, corner: np.ndarray,
                          roll: PrimitiveResult, pieces: list[PrimitiveResult], away_from, why: str):  # fmt: skip
        """For :meth:`_cross_and_acquire`: a roll that settled on the next face, a stroke there that measured too
        little of it (``why``), and touches afresh past the edge in the frame of the travel (``direction``) that
        found no face either: the face touched afresh once more in the roll's frame, the edge as the roll measured
        it (``edge_direction``, from its settled normal) and that normal the first guess. :meth:`_reacquire` takes
        the edge square to the travel, and a travel crossing at a slant puts it off the edge by as much (hull_06 of
        the formula corpus, seed 1: a slide 20° off the edge's line, the edge so taken 70° off, the normal guessed
        from the roll's turned the wrong way, and six touches afresh read the rims at the corner beyond; the roll had
        read the next face 0.7° off and the edge 0.5° off). Only after the travel's frame failed: the roll's normal
        may itself be a rim's or a corner's reading (cad_lbracket, seed 1: the pad in an inner corner between two
        walls), where the travel's frame finds the face and the roll's would not. What :meth:`_reacquire` returns
        when it measured the face so; None when it did not, or when the two frames' edges lie within
        :attr:`PhysicsSettings.reacquire_cone` of each other (tried already)."""
        d = in_plane(np.asarray(direction, dtype=float), n_a)
        square = in_plane(np.cross(roll.info["edge_direction"], n_a), n_a)
        if d is None or square is None:
            return None
        d, square = unit(d), unit(square)
        if float(square @ d) < 0:
            square = -square
        if float(square @ d) > math.cos(self.settings.reacquire_cone):
            return None
        out = self._reacquire(kind, n_a, square, corner, roll.trace, roll.info["normal"], pieces, away_from,
                              f"{why}, the edge as the roll measured it")  # fmt: skip
        return out if out[0] == "ok" else None

    def _stroke_tilted(self, st: PrimitiveResult, away: np.ndarray, along: np.ndarray, pieces: list[PrimitiveResult],
                       step_in: float | None = None) -> tuple[FaceFit, PrimitiveResult] | None:  # fmt: skip
        """For :meth:`_cross_and_acquire`: a stroke on the next face (``st``) whose legs a link of the finger
        stopped, lifting the pad off, and which measured too little of the face. On a face leaning under,
        the finger's links meet the edge above it as the pad slides (antiprism_03 of the formula corpus at 78 mm,
        seed 1: the face 24° under, every leg stopped within a millimetre, five touches afresh past the edge the
        same, four moves failed "too few contacts on the next face"). The hand tilts away from the link's contact
        by the first of :attr:`TouchConfig.tilt_angles` at which the pad still reaches the face, touches it again
        :attr:`PhysicsSettings.reacquire_inset` in from where the stroke began (``away`` from the edge) and strokes
        there (``along`` the edge). A hand already tilted (away from a link's contact earlier in the move) tilts
        anew from the upright posture, away from this link's (antiprism_05, seed 1: tilted away from the distal
        link's contact on the face traced, the medial link met the edge as the pad stepped onto the next face). The
        fit and the stroke, the hand left tilted (the move turns it upright when it ends); None, the hand as it
        was, when no tilt measures the face. ``step_in``: the L's first leg, as :meth:`Toucher.stroke` takes it (an L
        touched afresh past the edge, :meth:`_touch_next`: it then measures the face both ways)."""
        t, s = self.toucher, self.settings
        rows = np.flatnonzero(st.trace.in_contact)
        if not len(rows):
            return None
        held = t.hand_rotation.copy()
        n = unit(st.info["normal"])
        target = st.trace.point_in_world[rows[0]] + s.reacquire_inset * unit(away - float(away @ n) * n)
        for a, r in self._tilted_touches(st.info["link_normal"], target, n, pieces, held):
            again = t.stroke(r.info["normal"], away, along, step_in=step_in)
            pieces.append(again)
            if not again.ok or again.info["rim"]:
                continue
            fit = self.segmenter.fit_face_trace(again.trace, again.info["normal"], two_d=step_in is not None)
            if fit is not None:
                self.recoveries.append(f"stepping onto the next face, the finger's {st.info['link']} met the object: "
                                       f"the hand tilted {math.degrees(a):.0f}° away")  # fmt: skip
                return fit, again
        t.hand_rotation = held
        return None

    def _overhung(self, kind: str, link: str, roll: ContactTrace):
        """For :meth:`_cross_and_acquire`: the stroke on the next face held back as it stepped in, a link of the
        finger (``link``) touching the object -- under an overhang, the finger has no room on the next face (BOX01N
        seed 1 on an end, its slot sideways: the pad rolled onto the slot's floor, 30 mm under its ceiling, and
        touched afresh there, five times a move, every stroke stopped within a millimetre or ran away, upright or
        tilted). The legs along the edge from such a step may ride the ridge (:meth:`Toucher.stroke`): over a convex
        edge the roll gives the edge alone (status ``"overhang"``, as over one onto a face leaning under out of
        reach), else the crossing fails with that reason."""
        why = f"crossing the {kind} edge: stepping onto the next face, the finger's {link} met the object"
        if kind == "convex":
            return "overhang", why, roll, None, None
        return "unreachable", why, None, None, None

    def _reacquire(self, kind: str, n_a: np.ndarray, direction: np.ndarray, corner: np.ndarray, roll: ContactTrace,
                   n_roll: np.ndarray | None, pieces: list[PrimitiveResult], away_from, why: str):  # fmt: skip
        """The next face after a crossing that lost it (``why``): lifted off, touch it afresh a little past the
        edge at ``corner``, its normal guessed as turned about the edge (the roll's settled normal ``n_roll``
        first, then :attr:`PhysicsSettings.reacquire_turns`); a touched normal that turned about the edge is the
        next face's, and an L stroke on it measures it. An L that measures too little of a face touched past the
        edge (met near its end, the pad rides the rim of the face beyond that end too) is made again
        :attr:`PhysicsSettings.recross_shift` (plus the touched normal's lean times the pad's radius) farther along
        the edge, away from where that normal leans first, once. Ls that each measured too little of one face
        measure it together (:meth:`_joined_ls`). Returns what :meth:`_cross_and_acquire` returns; the failure
        ``why`` when no guess gives the face."""
        t, s = self.toucher, self.settings
        d = in_plane(np.asarray(direction, dtype=float), n_a)
        if d is None:
            return "unreachable", why, None, None, None
        e = unit(np.cross(n_a, d))
        sign = 1.0 if kind == "convex" else -1.0
        guesses = [] if n_roll is None else [unit(n_roll - float(n_roll @ e) * e)]
        guesses += [math.cos(a) * n_a + sign * math.sin(a) * d for a in s.reacquire_turns]
        tried: list[np.ndarray] = []
        shifted = False
        short: list[PrimitiveResult] = []  # the Ls that measured too little of a face past the edge
        for n_b in guesses:
            if any(angle(n_b, m) < s.reacquire_cone for m in tried):
                continue
            tried.append(n_b)
            if float(n_b[2]) < -math.sin(t.config.max_undercut):  # a face leaning under: not from above
                continue
            away_b = unit(np.cross(e, n_b))  # on the next face, away from the edge: down past a convex one
            if sign * float(away_b @ n_a) > 0:
                away_b = -away_b
            target = corner + s.reacquire_inset * away_b
            if self.workspace.pad_clearance(target, n_b) < s.pad_clearance:
                continue
            out = self._touch_next(kind, n_a, d, corner, target, n_b, pieces, away_from)
            if isinstance(out, str):
                if out == "table":
                    return "unreachable", "the edge lies on the table", None, None, None
                continue
            n, fit, st = out
            self._short_l(short, st, fit)
            if fit is None and not shifted:
                # the face is there but the L measured too little of it: the pad touched the rim of the face
                # beyond the edge's end too (met near a vertex). Touched again farther along the edge, away from
                # where the touched normal leans first
                shifted = True
                lean = float(n @ e)
                step = s.recross_shift + t.pad_radius * abs(lean)
                for k in (1.0, -1.0):
                    moved = target - k * math.copysign(step, lean) * e
                    if self.workspace.pad_clearance(moved, n) < s.pad_clearance:
                        continue
                    again = self._touch_next(kind, n_a, d, corner, moved, n, pieces, away_from)
                    if again == "table":
                        return "unreachable", "the edge lies on the table", None, None, None
                    if not isinstance(again, str):
                        self._short_l(short, again[2], again[1])
                    if not isinstance(again, str) and again[1] is not None and self._same_next_face(n_a, n, again[0]):
                        self.recoveries.append(f"{why}: the next face touched afresh {step * 1000:.0f} mm along the "
                                               "edge, clear of its end")  # fmt: skip
                        return "ok", "", roll, again[2].trace, again[1]
            if fit is not None:
                self.recoveries.append(f"{why}: the next face touched afresh")
                return "ok", "", roll, st.trace, fit
        joined = self._joined_ls(short)
        if joined is not None:
            fit, trace, k = joined
            self.recoveries.append(f"{why}: the next face measured by {k} Ls touched afresh together")
            return "ok", "", roll, trace, fit
        return "unreachable", why, None, None, None

    @staticmethod
    def _short_l(short: list[PrimitiveResult], st: PrimitiveResult, fit: FaceFit | None) -> None:
        """For :meth:`_reacquire`: keep the L ``st`` on a face touched afresh past the edge when it measured too little
        of it (``fit`` None) but slid on the face: not failed, its first leg not onto a rim, its legs along the edge
        not both stopped by edges (the pad on a narrow strip or a rim)."""
        if fit is None and st.ok and not st.info["rim"] and not st.info["blocked"]:
            short.append(st)

    def _joined_ls(self, short: list[PrimitiveResult]) -> tuple[FaceFit, ContactTrace, int] | None:
        """For :meth:`_reacquire`: the face measured by the Ls of ``short`` together, each of which measured too little
        of it alone, touched afresh at different points past the edge: those whose mean normals lie within
        :attr:`~SegmentBounds.row_cone` of one L's (the latest first), two at least. A face leaning under next to a
        face that rises above it lets the pad slide only a millimetre or three before a link of the finger meets the
        object (HEXPRISM01 seed 3, a vertex move from an end onto a side leaning under 30°: five touches afresh past
        the edge read the side's normal, each L's legs along the edge stopped by the distal link on the ridge above,
        three L's first legs 1-3 mm long 5-10 mm apart, and the move failed "stroke on the next face failed:
        blocked"): their rows together span the face both ways. The fit, the rows and how many Ls; None when no two
        agree or their rows together measure no face (:meth:`Segmenter.fit_face_trace` judges them as one L's)."""
        seg = self.segmenter
        for st in reversed(short):
            n = st.info["normal"]
            same = [o for o in short if angle(o.info["normal"], n) <= seg.bounds.row_cone]
            if len(same) < 2:
                continue
            trace = ContactTrace.concatenate([o.trace for o in same])
            fit = seg.fit_face_trace(trace, unit(np.sum([o.info["normal"] for o in same], axis=0)), two_d=True)
            if fit is not None:
                return fit, trace, len(same)
        return None

    def _same_next_face(self, n_a: np.ndarray, n: np.ndarray, again: np.ndarray) -> bool:
        """For :meth:`_reacquire`: whether normal ``again``, touched farther along the edge where an L measured the
        face, is that of the face touched first past the edge (normal ``n``; ``n_a`` the face crossed from): within
        :attr:`PhysicsSettings.reacquire_cone` of it; or, the first touch having read the rims at the edge's end
        (its L measured no face), turned from ``n_a`` as far as ``n`` within that cone and no farther from ``n``
        than :attr:`PhysicsSettings.rim_reading_cone`. On the rims of the faces round the vertex the pad reads a
        normal partway between them, turned about the edge about as far as the next face (platonic_dodecahedron of
        the formula corpus, seed 1: the first touches read 58° and 59° turns 24° and 21° off the next face, which
        the touches along the edge measured at the solid's 63.4°, and the crossings failed "too few contacts on the
        next face"). Or the first touch read the ridge of the edge crossed, its normal turned only partway about the
        edge, and ``again`` is turned farther about the same axis (off the plane of ``n_a`` and ``n`` by no more than
        ``reacquire_cone``), within ``rim_reading_cone`` of ``n`` (HEXPRISM01 seed 2: past an end's edge the first
        touch read 76.6° of the side's 90°, the links held on the ridge above the side leaning under; touched 5 mm
        along the edge the pad read the side 13.4° farther round, in that plane). A face turned less far than
        the reading, or about another axis, is another face's."""
        s = self.settings
        if angle(again, n) <= s.reacquire_cone:
            return True
        if angle(again, n) > s.rim_reading_cone:
            return False
        if abs(angle(again, n_a) - angle(n, n_a)) <= s.reacquire_cone:
            return True
        axis = np.cross(n_a, n)
        if float(axis @ axis) < math.sin(self.bounds.min_edge_angle) ** 2:
            return False
        return abs(float(again @ unit(axis))) <= math.sin(s.reacquire_cone) and angle(again, n_a) > angle(n, n_a)

    def _touch_next(self, kind: str, n_a: np.ndarray, d: np.ndarray, corner: np.ndarray, target: np.ndarray,
                    n_guess: np.ndarray, pieces: list[PrimitiveResult], away_from):  # fmt: skip
        """For :meth:`_reacquire`: lifted off, touch the face past the edge at ``target`` (its normal guessed
        ``n_guess``) and measure it by an L. An L whose legs a link of the finger stopped, measuring too little, is
        made again with the hand tilted away from that link (:meth:`_stroke_tilted`, the step in as long): on a face
        leaning under, the ridge above it holds the links (HEXPRISM01 seed 2, a vertex move from an end onto a side
        leaning under 29°: touched afresh, the side's Ls stopped within 2.5 mm, the distal link on the ridge between
        the side and the next, and the move failed "stroke on the next face failed: runaway"; tilted 30° away the L
        measures the side). "miss" when nothing past the edge was touched, "table" when the table was; else the
        touched normal, the face's fit (None: the L measured too little) and the stroke."""
        t, s, seg = self.toucher, self.settings, self.segmenter
        floor = TABLE_TOP_Z + t.pad_radius + s.table_margin
        sign = 1.0 if kind == "convex" else -1.0
        r = t.lift_and_approach(target, n_guess, floor_z=floor)
        pieces.append(r)
        if not r.ok:
            return "miss"
        n = r.info["normal"]
        # a face past the edge: turned from n_a toward the travel (a convex edge met at a slant turns it about
        # another axis than n_a x d; the edge's line then comes from the two planes)
        if sign * float(n @ d) <= 0 or angle(n, n_a) < seg.bounds.min_edge_angle:
            return "miss"
        if self.workspace.is_table(n, t.contact[2]):
            return "table"
        self._past.append(n)
        e_n = unit(np.cross(n_a, n))
        away = unit(np.cross(n, e_n))
        if float(away @ (t.tip - corner)) < 0:
            away = -away
        along = e_n if away_from is None or float((t.tip - away_from) @ e_n) >= 0 else -e_n
        # an L as wide as long enough to tell a face from a ridge (along an edge the normal holds too)
        st = t.stroke(n, away, along, step_in=s.reacquire_step_in)
        pieces.append(st)
        fit = seg.fit_face_trace(st.trace, st.info["normal"], two_d=True) if st.ok else None
        if fit is None and st.ok and st.info["link_normal"] is not None:
            tilted = self._stroke_tilted(st, away, along, pieces, step_in=s.reacquire_step_in)
            if tilted is not None:
                fit, st = tilted
        return n, fit, st

    def _face_move(self, move: FaceMove, pieces: list[PrimitiveResult]) -> MoveResult:
        st, t, seg = self.state, self.toucher, self.segmenter
        d = np.asarray(move.direction, dtype=float)
        if d.shape != (3,) or not np.all(np.isfinite(d)):
            return self.invalid_result(move, "direction must be a finite 3-vector")
        near = None
        if move.face is not None and move.face != st.face:  # across the other face of the edge the pad is on
            rec = seg.edges.get(st.edge) if st.edge is not None else None
            if rec is None or move.face not in rec.faces or move.face not in seg.faces:
                return self.invalid_result(move, f"face {move.face} is not a face of the current edge (faces "
                                                 f"{st.edge_faces})")  # fmt: skip
            if move.start is None:
                return self.invalid_result(move, "a face move across another face needs its start")
            near = np.asarray(move.start, dtype=float)
        n_a = seg.faces[st.face if near is None else move.face].component.normal
        inplane = in_plane(d, n_a)
        if inplane is None:
            return self.invalid_result(move, "direction is not in the plane of the current face")
        if near is not None:  # the pad goes onto that face
            self.state = st = replace(st, face=move.face)
        status = self._ensure_on_face(st.face, pieces, near=near, retilt=True)
        if status != "ok":
            return self.failed_result(move, status, f"{FACE_RETURN_FAILED}: {self._why}")
        recrosses, tilted, levelled, resumed = 0, False, False, False
        lead = 0.0
        heading = inplane  # crossed again from a point the face was touched at, the slide heads from there
        while True:
            r = t.trace_face(heading, n_a, self.settings.max_face_trace)
            pieces.append(r)
            level = level_heading(heading, n_a) if r.event == "table" and not levelled else None
            if level is not None:
                # the slide heading down came within the pad's reach of the table before any edge: it goes on across
                # the face nearly level, toward the side it was heading, to the edge there (the planner predicts so)
                levelled, heading, lead = True, level, r.distance
                self.recoveries.append("the finger would meet the table before an edge: the slide went on level")
                r = t.trace_face(heading, n_a, self.settings.max_face_trace)
                pieces.append(r)
            held = self._held_from_above(r, heading)
            level = level_heading(heading, n_a) if held is not None and not levelled else None
            if level is not None:
                # down a face taller than the hand reaches below the top, the other fingers came to rest on the top
                # face and held the hand: the slide goes on nearly level, as the table's would
                levelled, heading, lead = True, level, lead + r.distance
                self.recoveries.append(f"the hand's {held.link} rested on the object above: the slide went on level")
                r = t.trace_face(heading, n_a, self.settings.max_face_trace)
                pieces.append(r)
                held = self._held_from_above(r, heading)
            if r.event == "hand":
                why = f"trace across the face: the finger's {r.info['link']} met the object"
                if tilted or not self._tilt_away(r, st.face, self._last_on(r.trace, st.face, heading), pieces,
                                                 ahead=heading):
                    return self.failed_result(move, r, why)
                tilted = True
                continue
            if not r.ok:
                if r.event == "table":
                    return self.failed_result(move, r, "the finger would meet the table before an edge")
                on = f", the hand's {held.link} resting on the object above" if held is not None else ""
                return self.failed_result(move, r, f"trace across the face: {r.event}{on}")
            if r.event == "done":
                return self.failed_result(move, "unreachable", "no edge within the longest trace")
            kind = r.info["kind"]
            corner = self.contact_point()
            self._stroke_blocked = False
            status, reason, roll, stroke, fit_b = self._cross_and_acquire(kind, r.info["face_normal"],
                                                                          r.info["direction"], pieces,
                                                                          overhang=True)  # fmt: skip
            if status in ("undercut", "overhang"):
                alone = self._edge_only(move, r, roll, reason, pieces)
                at_table = reason.endswith(TABLE_BEFORE_NEXT) or reason == STEP_AT_TABLE
                if alone.ok or not at_table or recrosses >= self.settings.recrosses:
                    return alone
                # met near the edge's end, the pad rolled round the vertex and down the faces there to the table's
                # clearance, high above it where the crossing met the edge (platonic_octahedron and bipyramid_04 of
                # the formula corpus, seed 1: from a level top face, 4 mm from a vertex, 15-20 mm above the table),
                # or settled there and its step in met the table (the polyhedra at 30 mm): crossed again farther
                # inside the edge, away from that vertex, as after a roll that gave no edge
                shift = self._round_the_vertex(r.info["face_normal"], roll)
                way = None
                if shift is not None:  # as far back as aside: inside the face narrowing to the vertex
                    back = self.settings.recross_back + float(np.linalg.norm(shift))
                    way = self._recross_start(st.face, n_a, corner, heading, shift, back, r.trace, pieces)
                if way is None:
                    return alone
                recrosses += 1
                self.recoveries.append(f"{alone.reason}: crossed again {np.linalg.norm(shift) * 1000:.0f} mm along "
                                       f"the edge{'' if way is heading else FROM_TOUCHED}")  # fmt: skip
                heading = way
                continue
            if status == "face" and not resumed:
                # the slide's contact weakened where no edge was: the roll came back onto the face, and the slide
                # goes on from there, once
                resumed = True
                self.recoveries.append(f"{reason}: the slide went on")
                continue
            if status == "hand" and not tilted:
                tilted = True
                if self._tilt_away(self._met, st.face, corner - self.settings.recross_back * heading, pieces):
                    continue
            if status != "ok" and not recrosses and reason.startswith(NEXT_FACE_LOST) and self._past_spread():
                # the pad rolled over the edge and touched no one face past it: met near the edge's end, it rolled
                # round the vertex onto the rims of the faces there. Cross again beside the first crossing, on the
                # side away from that vertex, as after a roll that gave no edge
                recrosses += 1
                shift = self._shift_from_roll(r.info["face_normal"], heading, self._roll)
                if shift is not None:  # as far back as aside: inside the face however the edge slants; nearer
                    # the edge when that would put the pad by the table
                    back = self.settings.recross_back + float(np.linalg.norm(shift))
                    if self.workspace.pad_clearance(corner - back * heading + shift, n_a) < self.settings.pad_clearance:
                        back = self.settings.recross_back
                    way = self._recross_start(st.face, n_a, corner, heading, shift, back, r.trace, pieces)
                    if way is not None:
                        where = "" if way is heading else FROM_TOUCHED
                        self.recoveries.append(f"{reason}: crossed again {np.linalg.norm(shift) * 1000:.0f} mm aside, "
                                               f"away from the vertex{where}")  # fmt: skip
                        heading = way
                        continue
            if status != "ok":
                return self.failed_result(move, status, reason)
            fit_a, line, why = self._edge_between(st.face, r.trace, "face", roll, fit_b, kind, corner)
            travel = unit(r.info["direction"])
            square = line is not None and abs(float(line.direction @ travel)) < math.sin(self.settings.square_crossing)
            if line is not None and kind == "convex" and (self._stroke_blocked or square):
                # a roll round a vertex onto a face sharing only the vertex gives the same normals and contacts as
                # one over an edge when the crossing is square to the line between the faces (the next face narrow
                # along it where the pad met it, or the travel square to it): the ridge along that line is there
                # only over an edge
                ridge = self._probe_ridge(line, fit_a.normal, fit_b.normal, pieces)
                if isinstance(ridge, str):
                    line, why = None, f"no edge between the faces: {ridge}"
            if line is not None:
                break
            shift, across = None, heading
            if recrosses < self.settings.recrosses:
                shift = self._past_the_vertex(fit_a.normal, fit_b, roll, corner)
                if shift is not None:  # the next face met lies round the vertex: crossed again square to the edge
                    across = self._square_to(heading, shift, n_a)
                else:
                    shift = self._away_from_vertex(fit_a.normal, fit_b.normal, roll)
                    if shift is not None and abs(float(unit(shift) @ unit(heading))) > math.cos(
                        self.settings.recross_glancing
                    ):  # slid at a glancing angle, the pad rode the rim to the edge's end: crossed again square to it
                        across = self._square_to(heading, shift, n_a)
            recrosses += 1
            if shift is None:
                return self.failed_result(move, "unreachable", why)
            # the roll went round the edge's end: cross again farther along the edge, inside it
            way = self._recross_start(st.face, n_a, corner, across, shift, self.settings.recross_back, r.trace,
                                      pieces)  # fmt: skip
            if way is None:
                return self.failed_result(move, "unreachable", why)
            square = " square to it" if across is not heading and way is across else ""
            self.recoveries.append(f"{why}: crossed again {np.linalg.norm(shift) * 1000:.0f} mm along the edge"
                                   f"{square}{'' if way is across else FROM_TOUCHED}")  # fmt: skip
            heading = way
        run = lead + r.distance
        return self._rolled_onto(move, st.face, line, kind, (fit_a.normal, fit_b.normal), fit_b, stroke, run,
                                 self.costs.face_move(run))  # fmt: skip

    def _held_from_above(self, r: PrimitiveResult, heading: np.ndarray):
        """The link contact that held a slide heading down across a face (``r`` stalled, event ``"blocked"``): a
        link of the hand resting on the object above the pad, its contact's normal upward (the middle and ring
        fingers on the top face as the index slid down a side face 100 mm below it: BOX01, BOX01N and BOX01P at
        150 mm, seed 1); None when the slide was not so held."""
        t = self.toucher
        if r.event != "blocked" or float(heading[2]) >= 0.0:
            return None
        c = t.link_touch()
        if c is None or float(c.normal_in_world[2]) < t.config.table_link_cos or float(c.point_in_world[2]) <= t.tip[2]:
            return None
        return c

    def _last_on(self, trace: ContactTrace, fid: int, d: np.ndarray) -> np.ndarray:
        """Where to touch data face ``fid`` again after a slide along ``d`` that a link of the finger stopped:
        ``recross_back`` back from the slide's last contact on the face (its anchor when there is none)."""
        n = self.segmenter.faces[fid].component.normal
        nn = np.where(trace.in_contact[:, None], trace.normal_in_world, 0.0)
        ok = np.flatnonzero(nn @ n > math.cos(self.bounds.face_cone))
        last = trace.point_in_world[ok[-1]] if len(ok) else self._faces[fid].anchor
        return last - self.settings.recross_back * d

    def _recross_start(self, fid: int, n: np.ndarray, corner: np.ndarray, heading: np.ndarray, shift: np.ndarray,
                       back: float, trace: ContactTrace, pieces: list[PrimitiveResult]) -> np.ndarray | None:
        """Put the pad on data face ``fid`` (normal ``n``) to cross its edge again at ``corner + shift`` (``shift``
        along the edge, away from the vertex the first crossing rolled round): ``back`` before that point against
        ``heading``; else, that start lying off the face (a face narrowing to the vertex: the pad touched a normal
        turned off it), at the point the face was touched at (``trace``'s rows on it, then its stored contacts; that
        point and the crossing beyond the pad's radius from a concave edge of the face) nearest that start from which
        the way to the new crossing runs at least ``recross_back`` over the face and
        :attr:`PhysicsSettings.recross_slant` from along the edge. Returns the heading of the slide to cross again
        (``heading``, or the way from that point), or None when the pad rests on neither (the reason in
        ``self._why``)."""
        s = self.settings
        target = corner + shift
        # summed as the plain crossing again sums it: a start a few ulps apart may end a slide millimetres apart, and
        # the episode's later moves with it
        start = corner - back * heading + shift
        status = self._touch_face(fid, n, start, pieces)
        if status == "ok":
            return heading
        if status == "unstable" or self._why.startswith("the touch would put the pad on the table"):
            return None
        e = unit(shift)
        across = heading - float(heading @ e) * e
        if float(across @ across) < OPPOSED:
            return None
        across = unit(across)
        ok = trace.in_contact & (np.where(trace.in_contact[:, None], trace.normal_in_world, 0.0) @ n
                                 > math.cos(self.bounds.row_cone))  # fmt: skip
        known = np.vstack([trace.point_in_world[ok], self._faces[fid].points]) if fid in self._faces \
            else trace.point_in_world[ok]
        # neither from nor toward a concave corner of the face: a slide there meets the face across first. The
        # model's radius at least: a touch that met both faces of the corner (the start above, timed out) reads its
        # contact between the two patches, inside the pad, and the refined radius dips (BOX01N seed 2: 8.7 mm for
        # 12, and the slide set off 10 mm from a slot's floor met the floor)
        clear = max(self.toucher.pad_radius, self.toucher.pad_model_radius)
        for rec in self.segmenter.edges.values():
            if not rec.convex and fid in rec.faces and len(known):
                rel = np.vstack([known, target]) - rec.point
                off = np.linalg.norm(rel - np.outer(rel @ rec.direction, rec.direction), axis=1)
                if off[-1] < clear:
                    return None
                known = known[off[:-1] >= clear]
        if not len(known):
            return None
        way = target - known
        way -= np.outer(way @ n, n)
        dist = np.linalg.norm(way, axis=1)
        fit = (dist >= s.recross_back) & (way @ across >= math.sin(s.recross_slant) * dist)
        if not fit.any():
            return None
        i = int(np.flatnonzero(fit)[np.argmin(np.linalg.norm(known[fit] - start, axis=1))])
        if self._touch_face(fid, n, known[i], pieces) != "ok":
            return None
        return way[i] / dist[i]

    def _past_spread(self) -> bool:
        """Whether the last crossing's touches afresh past the edge met no one face: none touched, or normals more
        than :attr:`PhysicsSettings.reacquire_cone` apart -- the rims of the faces round a vertex (PYR01 seed 1:
        seven touches up to 88° apart). Touches that all met one face found it there, too small for the stroke or out of
        its reach, and a crossing farther along the edge meets the same (trapezohedron_04 of the sized corpus,
        seed 1: four touches within 8° of each other, each stroke cut short)."""
        if not self._past:
            return True
        n = np.array(self._past)
        return float((n @ n.T).min()) < math.cos(self.settings.reacquire_cone)

    def _shift_from_roll(self, n_a: np.ndarray, d: np.ndarray, roll: ContactTrace | None) -> np.ndarray | None:
        """After a slide along ``d`` on face ``n_a`` whose crossing found no next face: the sideways shift, square to
        ``d`` in the face, of a slide that crosses the same boundary clear of the vertex the roll went round; None
        when the roll has no contacts, did not turn, or its edge runs too near along ``d`` to tell a side.

        The way is that of :meth:`_away_from_vertex` about the axis the roll first turned about (its normals where
        they first turned twice the edge angle from face a's stand for the next face's): rolling on round the
        vertex, onto the ridge of two other faces, its last normals turn about another axis (PYR01 seed 1: a
        slanted edge met at its foot, the roll ending on the ridge along the base). The shift is
        ``recross_shift`` plus the pad's radius: the crossing may have been at the vertex, and a pad past a concave
        corner there touches its other wall until a radius away (LBLOCK01 seed 1: met 4 mm from the corner, crossed
        again 6 mm farther, the pad wedged between the walls). Square to the travel (and as far back), the new start
        stays on the face where a shift along a misjudged edge left it (PYR01 seed 1: on the ridge of the edge met)."""
        side = np.cross(n_a, d)
        if roll is None or not roll.in_contact.any() or float(side @ side) < OPPOSED:
            return None
        side = unit(side)
        n_b = self._first_turn(n_a, roll)
        e = np.cross(n_a, n_b)
        if float(e @ e) < math.sin(self.bounds.min_edge_angle) ** 2:
            return None
        away = self._away_from_vertex(n_a, n_b, roll)
        if away is None or abs(float(unit(away) @ side)) < self.settings.recross_side_cos:
            return None
        return math.copysign(self.settings.recross_shift + self.toucher.pad_radius, float(away @ side)) * side

    def _round_the_vertex(self, n_a: np.ndarray, roll: ContactTrace | None) -> np.ndarray | None:
        """After a roll off face ``n_a`` that the table stopped and that gave no edge alone: the shift along the edge
        it first turned about (:meth:`_first_turn`) back inside the edge, away from the vertex its normals lean from
        (:meth:`_away_from_vertex`); None when it has no contacts or turned about no axis (the pad stood turned at
        the table's clearance next to the edge, a crossing farther along it no higher)."""
        if roll is None or not roll.in_contact.any():
            return None
        n_t = self._first_turn(n_a, roll)
        e = np.cross(n_a, n_t)
        if float(e @ e) < math.sin(self.bounds.min_edge_angle) ** 2:
            return None
        return self._away_from_vertex(n_a, n_t, roll)

    def _first_turn(self, n_a: np.ndarray, roll: ContactTrace) -> np.ndarray:
        """The normal a roll (in contact somewhere) off face ``n_a`` first turned to: the mean of its normals where they
        first turned twice the edge angle from ``n_a`` (else of its last), which stands for the next face's over the
        edge the pad met, whatever it rolled on to round a vertex."""
        n = roll.normal_in_world[roll.in_contact]
        k = self.bounds.steady_window
        turned = np.flatnonzero(n @ n_a < math.cos(2.0 * self.toucher.config.edge_angle))
        i = int(turned[0]) if len(turned) else len(n) - k
        return unit(n[max(0, i):i + k].sum(axis=0))

    @staticmethod
    def _square_to(heading: np.ndarray, edge: np.ndarray, n: np.ndarray) -> np.ndarray:
        """``heading`` turned in the plane of normal ``n`` square to ``edge``, still toward it, a unit vector
        (``heading`` itself when it runs along the edge)."""
        e = unit(edge)
        across = in_plane(heading - float(heading @ e) * e, n)
        return heading if across is None else unit(across)

    def _past_the_vertex(self, n_a: np.ndarray, fit_b: FaceFit, roll: ContactTrace | None, corner: np.ndarray
                         ) -> np.ndarray | None:  # fmt: skip
        """After a crossing from face ``n_a`` at ``corner`` whose next face (``fit_b``, stroked or touched afresh)
        is not the face the roll settled on (its normal more than :attr:`PhysicsSettings.reacquire_cone` from the
        roll's first turn, :meth:`_first_turn`): the pad settled on a face too narrow there for the stroke (a kite
        or a triangle near its acute corner), stepped onto the rim of its other edge, and the face stroked or
        touched afresh past that rim lies round the vertex where the two edges meet. That face's plane cuts the
        edge the roll turned about at the vertex, on the side the face leans to (every face at a convex vertex leans
        toward it along an edge leaving it), and meets the settled face along the other edge: the shift along the
        edge, away from the vertex, puts the crossing where the settled face is
        :attr:`PhysicsSettings.reacquire_inset` wide, ``recross_shift`` at least (trapezohedron_12 of the sized
        corpus, seed 1: kites of 20° at the apex crossed 4.6-7.4 mm from it, where they are 1.7-2.7 mm wide; the roll
        turned about the edge to 0.8°, and the lean of its own normals, noise alone, shifted the crossing on past the
        apex). None when the roll turned about no axis, ``fit_b`` is the face it settled on, leans too little along
        the edge (within :attr:`SegmentBounds.sample_cone`) to tell a side, or its plane cuts the edge behind the
        crossing or beyond the pad's radius plus ``recross_shift``, or the shift would be longer than that (not a
        face round a vertex the pad reached: the start's slide along an edge into the apex, the roll over it); None
        too when the roll did not settle on the face it first turned to (a roll round the vertex itself, its first
        turn about no edge: prism_09 of the sized corpus, seed 1, met an edge 0.2 mm from its end)."""
        if roll is None or not roll.in_contact.any():
            return None
        s, n_b = self.settings, fit_b.normal
        n_t = self._first_turn(n_a, roll)
        n = roll.normal_in_world[roll.in_contact]
        settled = unit(n[-self.bounds.steady_window:].sum(axis=0))
        e = np.cross(n_a, n_t)
        if float(e @ e) < math.sin(self.bounds.min_edge_angle) ** 2 or angle(n_b, n_t) <= s.reacquire_cone \
                or angle(settled, n_t) > s.reacquire_cone:  # fmt: skip
            return None
        e = unit(e)
        lean = float(n_b @ e)
        if abs(lean) < math.sin(self.bounds.sample_cone):
            return None
        to_vertex = (fit_b.offset - float(n_b @ corner)) / lean  # along e, from the crossing to the vertex
        if not 0.0 < math.copysign(1.0, lean) * to_vertex <= self.toucher.pad_radius + s.recross_shift:
            return None
        other = np.cross(n_t, n_b)  # the settled face's other edge, from the vertex
        wedge = float(np.linalg.norm(np.cross(unit(other), e)))  # sine of the face's angle at the vertex
        need = max(s.recross_shift + self.toucher.pad_radius * abs(lean), s.reacquire_inset / max(wedge, 1e-3)
                   - abs(to_vertex))  # fmt: skip
        if need > self.toucher.pad_radius + s.recross_shift:
            return None
        return -math.copysign(need, lean) * e

    def _away_from_vertex(self, n_a: np.ndarray, n_b: np.ndarray, roll: ContactTrace) -> np.ndarray | None:
        """After a roll whose normals leaned along the edge between faces ``n_a`` and ``n_b`` (the pad rolled
        round the edge's end, its centre past the vertex, so the normals lean from the vertex toward it): the
        shift along the edge back inside it, ``recross_shift`` plus the overshoot; None when the roll's normals
        do not lean one way."""
        e = np.cross(n_a, n_b)
        if float(e @ e) < 1e-6 or not roll.in_contact.any():
            return None
        e = unit(e)
        n = roll.normal_in_world[roll.in_contact]
        c = math.cos(self.bounds.sample_cone)
        between = (n @ n_a < c) & (n @ n_b < c)
        if not between.any():
            return None
        lean = float(np.median(n[between] @ e))
        if abs(lean) < 1e-3:
            return None
        over = self.toucher.pad_radius * abs(lean)
        return -math.copysign(1.0, lean) * (self.settings.recross_shift + over) * e

    def _edge_only(
        self, move: FaceMove | VertexMove, r: PrimitiveResult, roll: ContactTrace, reason: str,
        pieces: list[PrimitiveResult], circled: tuple[int, np.ndarray] | None = None,
    ) -> MoveResult:
        """A face move that rolled over a convex edge onto a face leaning under, out of the pad's reach: the
        edge alone, from the face and the roll, checked and refined by following it a little each way (a
        roll round a vertex turns about one axis too, but no edge runs along it); the sensor stays on the face
        it traced. ``circled``: a vertex move's face and the data vertex it circled (its position), the roll from
        the circle: the edge is then one leaving that vertex, within the bounds :meth:`_at_circled` allows, or
        the move fails."""
        st, seg = self.state, self.segmenter
        face = st.face if circled is None else circled[0]
        fit_a = self._face_fit(face, r.trace)
        phase = PHASES.index("face" if circled is None else "circle")
        lead = r.trace.select(r.trace.phase == phase).tail(self.settings.roll_lead_rows)
        got = seg.edge_from_roll(fit_a, ContactTrace.concatenate([lead, roll]))
        if isinstance(got, str):
            return self.failed_result(move, "unreachable", f"{reason}; no edge from the roll: {got}")
        line, n_last = got
        # the roll's axis is fitted to its normals alone: rolling where the pad's centre passed the edge's end, they
        # turned round the vertex too and tilted the axis (HEXPRISM01 at 30 mm, seed 2: 2.1° off, 2.1 bounds, the
        # vertex 0.4 mm from the roll); a vertex closer to the roll than its own bound cannot be told from one the
        # pad rolled on
        b = seg.bounds
        ridge = self._probe_ridge(line, fit_a.normal, n_last, pieces,
                                  end_clearance=b.bound(b.point_sigma, b.vertex_floor))  # fmt: skip
        if isinstance(ridge, str):
            return self.failed_result(move, "unreachable", f"{reason}; {ridge}")
        ridge = self._on_roll_line(ridge, line)
        if ridge is None:
            return self.failed_result(move, "unreachable", f"{reason}; the ridge followed left the roll's line (the "
                                                           "pad met the table or a face round the edge's end)")
        line = line_from_points(ridge, line.direction, line.direction_sigma, seg.bounds)
        vertex = None
        if circled is not None:
            vertex = self._at_circled(line, circled[1])
            if isinstance(vertex, str):
                return self.failed_result(move, "unreachable", f"{reason}; {vertex}")
            vertex = (st.vertex, vertex)
        adjacent = (face,) if vertex is None else (vertex[0], face)
        edge = seg.add_edge(line, (face, None), True, (fit_a.normal, n_last), adjacent=adjacent, vertex=vertex)
        self.on_face = None
        self.state = SensorState(position=line.point + line.direction * 0.5 * sum(line.s_range), face=face)
        cost = self.costs.face_move(r.distance) if circled is None else self.costs.vertex_move(r.distance)
        return MoveResult(move=move, status="ok", components=(edge,), distance=r.distance, cost=cost,
                          state=self.state, info={"kind": "convex", "next_face": "out of reach"})  # fmt: skip

    def _at_circled(self, line, vtx: np.ndarray) -> float | str:
        """Where the vertex a vertex move circled (at ``vtx``, located on an earlier edge) lies along the ``line``
        its circle met (its parameter), or why that line leaves another vertex: it passes farther from ``vtx`` than
        their bounds allow. The vertex and the line are independent estimates, so their bounds add in quadrature.
        Added up, they let through an edge 1.9 mm off the vertex on trapezohedron_10 at 30 mm (a kite's edge 4.2 mm
        long inside the 8 mm circle, the edge beyond it met), whose errors were 0.16 and 0.14 mm against bounds of
        1.2 and 0.75 mm; the tree pruned the truth (no-match)."""
        seg, b = self.segmenter, self.bounds
        s_vtx = float((vtx - line.point) @ line.direction)
        off = float(np.linalg.norm(vtx - line.point - s_vtx * line.direction))
        lever = abs(s_vtx - float(np.clip(s_vtx, *line.s_range)))  # from the explored interval to the vertex
        allowed = math.hypot(seg.vertices[self.state.vertex].position_bound,
                             b.bound(line.position_sigma, b.position_floor),
                             lever * b.bound(line.direction_sigma, b.direction_floor))  # fmt: skip
        if off > allowed:
            # the circle crossed an edge that does not leave the vertex (on a face narrower than the circle)
            return f"the edge met passes {off * MM:.1f} mm from the vertex circled: it leaves another vertex"
        return s_vtx

    def _on_roll_line(self, ridge: np.ndarray, line) -> np.ndarray | None:
        """The contacts of ``ridge`` on the line of the roll that gave an edge alone (within a point's bound of it);
        None when too few of them remain, or they span too little, for a line. Followed from a roll next to the table,
        or near the edge's end, the pad touches the table or the faces round the end too (BOX01N seed 3, its slot
        against the table: ridge contacts down to the table 20 mm below the edge, the line fitted to them 6.6 mm low,
        2.4 bounds off)."""
        b = self.segmenter.bounds
        off = ridge - line.point
        off = off - np.outer(off @ line.direction, line.direction)
        near = ridge[np.linalg.norm(off, axis=1) <= b.bound(b.point_sigma, b.vertex_floor)]
        if len(near) < self.bounds.min_line_points or float(np.ptp(near @ line.direction)) < RIDGE_MIN_SPAN:
            return None
        return near

    def _on_ridge(self, rows: ContactTrace, u: np.ndarray) -> np.ndarray:
        """Rows of a ridge-following trace in contact on the ridge itself: the sensed normal within
        ``ridge_row_cone`` of perpendicular to the edge direction ``u`` (not rolling on a vertex at its end)."""
        ok = rows.in_contact & (rows.phase == PHASES.index("ridge"))
        along = np.where(ok[:, None], rows.normal_in_world, 0.0) @ u
        return ok & (np.abs(along) < math.sin(self.bounds.ridge_row_cone))

    def _probe_ridge(
        self, line: LineFit, n_a: np.ndarray, n_b: np.ndarray, pieces: list[PrimitiveResult],
        end_clearance: float = 0.0,
    ) -> np.ndarray | str:  # fmt: skip
        """From a roll over the edge ``line`` (direction ``e``) between face ``n_a`` and the normal ``n_b`` the roll
        ended at, follow the ridge ``RIDGE_PROBE`` along ``e`` and back past the start as far again: the
        contact points on the ridge, or why there is no edge along ``e`` (they span less than
        ``RIDGE_MIN_SPAN``, or a vertex lies within ``end_clearance`` of where the roll ended).

        The pad acquires the ridge where the stroke on the next face left it, and the stroke's leg along the edge
        may end near a corner where a third face rises (a wall of a slot 30 mm wide, for the 24 mm pad). An
        acquisition that fails with its last normals leaning along the edge by more than
        :attr:`PhysicsSettings.corner_lean` met that face (:meth:`_third_face`; cad_slotted of the formula corpus, seed
        1: moves up the floor of its slot crossed the top edge 12.6 mm from a wall, the stroke left the pad 7 mm from
        it, and rolling back onto the ridge the pad met the wall's rim: four moves failed "acquiring the ridge:
        limit"). As an edge move does (:meth:`_off_the_corner`), the pad acquires the ridge again a pad's radius from
        where it met that face, back toward where the roll crossed the edge (``line``'s point, the mean of its
        contacts), where the edge runs on (:meth:`_acquire_beside`). The way out may end within the pad's reach of such
        a wall's rim, and the pad's contact, on the rim, never settles on the bisector on the way back (BOX01N seed 2
        at the top of its upright slot: the way out met a wall after 1.5 mm, the way back pressed on the wall's rim
        until its time ran out, and two moves failed "no edge along the roll's axis (the ridge spans 1.5 mm: a
        vertex?)"; cad_slotted: the way back left the pad on the rim, and the edge move after it, setting off beside
        that contact, failed "acquiring the ridge: limit"): a way back that found no ridge sets off again,
        ``RIDGE_PROBE`` long, from the ridge acquired again where the way out began. A check that fails after a leg
        heading down took the pad into the table's clearance is made again from the ridge acquired again where the
        roll ended, no leg going lower than that clearance (:meth:`_ridge_reach`)."""
        t, e = self.toucher, line.direction
        # sideways toward face a: into face a away from the edge, and on face b toward the edge (as an edge move's
        # frame); into face a alone has no component on face b across a square edge, and a pad resting on face b
        # after its stroke never reached the ridge
        in_a, in_b = unit(np.cross(n_a, e)), unit(np.cross(n_b, e))
        in_a = -in_a if float(in_a @ n_b) > 0 else in_a
        in_b = -in_b if float(in_b @ n_a) > 0 else in_b
        toward_a = unit(in_a - in_b)
        frame = (n_a, n_b, toward_a, ((n_b, in_b), (n_a, in_a)))  # the pad rests on face b after its stroke
        acq = t.follow_edge(e, n_a, n_b, toward_a, 0.0, acquire_only=True)
        pieces.append(acq)
        met = None if acq.ok else self._third_face(acq, line)
        if met is not None:
            acq = self._acquire_beside(line, met - math.copysign(t.pad_radius, met), frame, pieces)
            if isinstance(acq, str):
                return f"acquiring the ridge, the pad met a face at the edge's end: {acq}"
            if acq.ok:
                self.recoveries.append("acquiring the ridge, the pad met a face at the edge's end: acquired again a "
                                       "pad's radius from it")  # fmt: skip
        if not acq.ok:
            return f"acquiring the ridge: {acq.event}"
        # where the roll ended: the last contact of the acquisition (else the first of the ridge's); the way back
        # starts from where the way out stopped, so a vertex's distance from the roll is measured from here
        origin = acq.trace.point_in_world[acq.trace.in_contact][-1] if acq.trace.in_contact.any() else None
        got, low = self._ridge_legs(line, frame, origin, pieces, end_clearance)
        if isinstance(got, str) and low and origin is not None:
            # a leg heading down took the pad into the table's clearance, resting on the table and the ridge at once:
            # acquired again where the roll ended, the ridge is followed down no farther than that clearance
            again = self._acquire_beside(line, float((origin - line.point) @ e), frame, pieces)
            if not isinstance(again, str) and again.ok:
                clear, _ = self._ridge_legs(line, frame, origin, pieces, end_clearance, above_table=True)
                if not isinstance(clear, str):
                    self.recoveries.append(f"{got}, the pad down at the table: followed again no lower than the "
                                           "table's clearance")  # fmt: skip
                    got = clear
        return got

    def _ridge_legs(self, line: LineFit, frame, origin: np.ndarray | None, pieces: list[PrimitiveResult],
                    end_clearance: float, above_table: bool = False) -> tuple[np.ndarray | str, bool]:  # fmt: skip
        """For :meth:`_probe_ridge`, the pad on the ridge of edge ``line`` (``frame`` as for :meth:`_acquire_beside`;
        ``origin``: where the roll ended): the way out and the way back. Their contacts on the ridge, or why there is
        no edge (as :meth:`_probe_ridge`); and whether a leg heading down ended with the pad within the table's
        clearance (:meth:`Toucher.below_floor`). With ``above_table`` a leg heading down goes no farther than that
        clearance (:meth:`_ridge_reach`)."""
        t, e = self.toucher, line.direction
        n_a, n_b, toward_a, _ = frame
        pts, low = [], False
        for sense, reach in ((1.0, RIDGE_PROBE), (-1.0, 2.0 * RIDGE_PROBE)):
            f = t.follow_edge(sense * e, n_a, n_b, toward_a, self._ridge_reach(sense * e, reach) if above_table
                              else reach)  # fmt: skip
            pieces.append(f)
            low = low or t.below_floor(sense * e)
            on = self._on_ridge(f.trace, e)
            if sense < 0 and not on.any() and origin is not None:
                again = self._acquire_beside(line, float((origin - line.point) @ e), frame, pieces)
                if not isinstance(again, str) and again.ok:
                    f = t.follow_edge(sense * e, n_a, n_b, toward_a, RIDGE_PROBE)
                    pieces.append(f)
                    on = self._on_ridge(f.trace, e)
                    if on.any():
                        self.recoveries.append("following the ridge back, the pad found none: acquired again where "
                                               "it set off")  # fmt: skip
            pts.append(f.trace.point_in_world[on])
            if origin is None and f.trace.in_contact.any():
                origin = f.trace.point_in_world[f.trace.in_contact][0]
            if not f.ok and f.event != "limit":
                return f"following the edge: {f.event}", low
            if end_clearance > 0.0 and f.event == "vertex" and origin is not None and f.trace.in_contact.any():
                gap = float((f.trace.point_in_world[f.trace.in_contact][-1] - origin) @ (sense * e))
                if gap < end_clearance:
                    return (f"the roll crossed the edge {max(gap, 0.0) * MM:.1f} mm from its end: its normals "
                            "turned round the vertex too"), low  # fmt: skip
        pts = np.concatenate(pts)
        span = float(np.ptp(pts @ e)) if len(pts) else 0.0
        if len(pts) < self.bounds.min_line_points or span < RIDGE_MIN_SPAN:
            return f"no edge along the roll's axis (the ridge spans {span * MM:.1f} mm: a vertex?)", low
        return pts, low

    def _ridge_reach(self, u: np.ndarray, reach: float) -> float:
        """For :meth:`_ridge_legs`: how far the pad may follow the ridge along ``u`` from where it is, ``reach`` at
        most, heading down no farther than the table's clearance (:attr:`Toucher.floor_z`). Followed on down, the pad
        rests on the table and the ridge at once, and the way back may lose the ridge (HEXPRISM01 seed 1, lying on a
        side: an end's edge running down at 60° to the table, the way out went on 4.7 mm, the pad's lowest point at
        the table top, the way back lost the contact after 1.9 mm, and the move failed "no edge between the faces:
        following the edge: lost")."""
        t = self.toucher
        down = -float(u[2])
        if t.floor_z is None or down <= 0.0:
            return reach
        return float(np.clip((float(t.tip[2]) - t.pad_radius - t.floor_z) / down, 0.0, reach))

    def _third_face(self, r: PrimitiveResult, line: LineFit) -> float | None:
        """For :meth:`_probe_ridge`: where along edge ``line`` (from its point) a ridge acquisition ``r`` that failed
        met a third face at the edge's end: its last contact, when its last normals
        (:attr:`PhysicsSettings.corner_rows`) lean along the edge by more than :attr:`PhysicsSettings.corner_lean`;
        None when they do not (or it has no contact there, or went unstable)."""
        s, tr = self.settings, r.trace
        rows = np.flatnonzero(tr.in_contact)[-s.corner_rows:]
        if r.status == "unstable" or not len(rows):
            return None
        e = line.direction
        if abs(float(np.median(tr.normal_in_world[rows] @ e))) < math.sin(s.corner_lean):
            return None
        met = float((tr.point_in_world[rows[-1]] - line.point) @ e)
        return met if met != 0.0 else None

    def _acquire_beside(self, line: LineFit, along: float, frame, pieces: list[PrimitiveResult]
                        ) -> PrimitiveResult | str:  # fmt: skip
        """For :meth:`_probe_ridge`: lifted off, touch the face the pad rested on next to edge ``line`` (else the
        other; ``frame``: the faces' normals, the sideways way toward face a, each face's normal with its way in from
        the edge) :attr:`PhysicsSettings.edge_reentry` in from the edge, ``along`` it from its point, and acquire the
        ridge there. The acquisition, or why the pad reached neither face there."""
        t, s = self.toucher, self.settings
        n_a, n_b, toward_a, faces = frame
        floor = TABLE_TOP_Z + t.pad_radius + s.table_margin
        why = "the touch would put the pad on the table"
        for n, inward in faces:
            target = line.point + along * line.direction + s.edge_reentry * inward
            if self.workspace.pad_clearance(target, n) < s.pad_clearance:
                continue
            r = t.lift_and_approach(target, n, floor_z=floor)
            pieces.append(r)
            if not r.ok:
                why = f"touching a face next to the edge: {r.status}/{r.event}"
                if r.status == "unstable":
                    return why
                continue
            if angle(r.info["normal"], n) > self.bounds.retouch_cone:
                why = f"touched a normal {math.degrees(angle(r.info['normal'], n)):.0f}° off a face next to the edge"
                continue
            acq = t.follow_edge(line.direction, n_a, n_b, toward_a, 0.0, acquire_only=True)
            pieces.append(acq)
            return acq
        return why

    def _edge_frame(self, eid: int):
        rec = self.segmenter.edges[eid]
        fa, fb = rec.faces
        n_a = self.segmenter.faces[fa].component.normal
        n_b = self.segmenter.faces[fb].component.normal
        toward_a = rec.inward.get(fa, np.zeros(3)) - rec.inward.get(fb, np.zeros(3))
        return rec, n_a, n_b, toward_a

    def _return_next_to_edge(
        self, rec, u: np.ndarray, face: int, pieces: list[PrimitiveResult], s0: float | None = None
    ) -> str:
        """Put the pad on a face of edge ``rec`` next to it (beside parameter ``s0`` when given, else beside the
        last contact), before following it along ``u``: on the current face ``face`` when it is one of the edge's,
        else on the other; when that touch fails, on the other face. Beside the last contact, the pad may rest at a
        vertex the edge ends at, where a touch next to the edge meets the faces round that vertex too (trapezohedron_06
        of the formula corpus at seed 1: an edge move setting off from the vertex a vertex move had just reached
        touched normals 7° and 24° off the edge's faces, and the vertex at its other end was never measured): when
        the touches there fail, the pad returns beside the middle of what is known of the edge behind the end the
        move runs to (:meth:`_known_middle`) instead, if that lies at least :attr:`PhysicsSettings.return_shift`
        away (there the last contact lay 5 mm past that end)."""
        last = s0 is None
        if last:  # beside the last contact: the pad may be far off in free space (backed out after a tilted move)
            s0 = rec.param(self.contact_point() if self.toucher.contact[2] is not None else self.state.position)
        status = self._return_beside(rec, u, face, pieces, s0)
        middle = self._known_middle(rec, u)
        if not last or status in ("ok", "unstable") or abs(middle - s0) < self.settings.return_shift:
            return status
        why = self._why
        again = self._return_beside(rec, u, face, pieces, middle)
        if again == "ok":
            self.recoveries.append(f"{why}: returned beside the middle of the edge behind its end, "
                                   f"{abs(middle - s0) * 1000:.0f} mm from the last contact")  # fmt: skip
            return again
        if again != "unstable":
            self._why = f"{why}; beside the middle of the edge: {self._why.removeprefix(RETURN_FAILED)}"
        return again

    def _known_middle(self, rec, u: np.ndarray) -> float:
        """The parameter on edge ``rec`` halfway between the far end of its explored interval along ``u`` and, behind
        it, the vertex the move sets off from (the state's, when it is one of the edge's), else the interval's other
        end. An interval may reach over the end the move runs to (trapezohedron_06: an 8 mm edge from vertex to
        vertex, its interval from the vertex move's roll 1.4 mm long and 0.7 mm over its far end), and its middle
        then lies at that end: an edge move set off there locates the vertex behind its start, and fails."""
        sign = 1.0 if float(u @ rec.direction) > 0 else -1.0
        far = rec.interval[1] if sign > 0 else rec.interval[0]
        back = rec.interval[0] if sign > 0 else rec.interval[1]
        v = self.state.vertex
        if v is not None and v in rec.vertices and sign * (rec.vertices[v] - back) < 0:
            back = rec.vertices[v]
        return 0.5 * (far + back)

    def _return_beside(self, rec, u: np.ndarray, face: int, pieces: list[PrimitiveResult], s0: float) -> str:
        """For :meth:`_return_next_to_edge`: the pad on a face of edge ``rec`` beside parameter ``s0``."""
        s, seg = self.settings, self.segmenter
        first = face if face in rec.faces else rec.faces[1]
        if not rec.convex and None not in rec.faces:
            return self._touch_corner(rec, s0, u, first, pieces)
        status, why = "unreachable", "the edge next to the table is out of the pad's reach"
        for fid in (first, *(f for f in rec.faces if f != first and f in rec.inward)):
            n = seg.faces[fid].component.normal
            near = self.workspace.reentry_point(rec, n, rec.inward[fid], s0, u, s.edge_reentry, s.reentry)
            if near is None:
                continue
            status = self._ensure_on_face(fid, pieces, near=near)
            if status == "ok" and fid != first:
                self.recoveries.append("the edge approached from its other face")
            if status in ("ok", "unstable"):
                return status
            why = f"{RETURN_FAILED}{self._why}"
        self._why = why
        return status

    def _touch_corner(self, rec, s0: float, u: np.ndarray, face: int, pieces: list[PrimitiveResult]) -> str:
        """Put the pad in the corner of concave edge ``rec``, touching both its faces, beside parameter ``s0`` (or
        further along ``u`` where that is within the pad's reach of the table): approached along the bisector of
        the faces' normals. A touch of either face next to the edge meets the other face first, nearer than the
        pad's radius (BOX01N's upright slot: 16 of 16 returns next to its concave edges touched the face across and
        failed). "ok" with the pad on ``face``, or a failure with the reason in ``self._why``."""
        t, seg = self.toucher, self.segmenter
        n_a, n_b = (seg.faces[f].component.normal for f in rec.faces)
        b = n_a + n_b
        if float(b @ b) < 1e-6:
            self._why = "could not return into the concave corner: its faces are opposed"
            return "unreachable"
        b = unit(b)
        # the pad's point along -b when it rests touching both faces: its centre lies r / cos(half the angle
        # between the normals) out along b from the edge's line
        depth = t.pad_radius / max(float(b @ n_a), 1e-3) - t.pad_radius
        s = self.settings
        target = self.workspace.reentry_point(rec, b, b, s0, u, depth, s.reentry)
        if target is None:
            self._why = "the concave edge next to the table is out of the pad's reach"
            return "unreachable"
        r = t.lift_and_approach(target, b, floor_z=TABLE_TOP_Z + t.pad_radius + s.table_margin)
        pieces.append(r)
        if not r.ok:
            self._why = f"could not return into the concave corner: {r.status}/{r.event}"
            return r.status
        n = unit(np.asarray(r.info["normal"], dtype=float))
        # the sensed normal, a force-weighted mean of the two faces' normals, lies on the arc between them
        if angle(n, n_a) + angle(n, n_b) > angle(n_a, n_b) + self.bounds.retouch_cone:
            self._why = f"returning into the concave corner touched a normal {math.degrees(angle(n, b)):.0f}° off it"
            return "unreachable"
        self.on_face = face
        return "ok"

    def _edge_move(self, move: EdgeMove, pieces: list[PrimitiveResult]) -> MoveResult:
        st, t = self.state, self.toucher
        if st.edge is None:
            return self.invalid_result(move, "no current edge: an edge move starts on or near an edge")
        if move.sense not in (1, -1):
            return self.invalid_result(move, f"sense must be +1 or -1, got {move.sense!r}")
        rec = self.segmenter.edges[st.edge]
        if st.vertex is not None and st.vertex in rec.vertices:
            s_v = rec.vertices[st.vertex]
            lo, hi = rec.interval
            if (move.sense > 0 and s_v >= hi - AT_END) or (move.sense < 0 and s_v <= lo + AT_END):
                return self.invalid_result(move, "the sensor is already at the vertex in that sense")
        u = move.sense * rec.direction
        on_clean = t.normal is not None and any(
            angle(t.normal, self.segmenter.faces[f].component.normal) < self.bounds.face_cone for f in rec.faces
        )
        if self.on_face not in rec.faces or self._line_distance(rec, t.tip) > self.settings.edge_reach or not on_clean:
            status = self._return_next_to_edge(rec, u, st.face, pieces)
            if status != "ok":
                return self.failed_result(move, status, self._why)
        res = self._trace_edge(move, rec, u, pieces)
        if isinstance(res, MoveResult):
            return res
        # the pad set off where the edge is not (past one of its ends, or beside another edge): it returns next to
        # the edge in the middle of its explored interval, where the edge was sensed, and sets off again from there
        # (antiprism_12 of the formula corpus: nine moves along one edge each acquired a ridge 2.2-3.0 mm off its line
        # and failed; trapezohedron_10: six moves set off past the end they ran toward)
        status, why = res
        mid = 0.5 * (rec.interval[0] + rec.interval[1])
        back = self._return_next_to_edge(rec, u, self.on_face if self.on_face in rec.faces else st.face, pieces,
                                         mid)  # fmt: skip
        if back != "ok":
            return self.failed_result(move, status, f"{why}; {self._why}")
        res = self._trace_edge(move, rec, u, pieces)
        if isinstance(res, MoveResult):
            if res.ok:
                self.recoveries.append(f"{why}: set off again from the middle of the edge's explored interval")
            return res
        return self.failed_result(move, res[0], f"{why}; set off again from the middle of the edge's explored "
                                                f"interval: {res[1]}")  # fmt: skip

    def _trace_edge(self, move: EdgeMove, rec, u: np.ndarray, pieces: list[PrimitiveResult]) -> MoveResult | tuple:
        """From a pad resting next to edge ``rec``: acquire its ridge, follow it along ``u`` and locate the vertex
        at its end. The move's result (done, or failed where setting off elsewhere would not help), or (status,
        reason) when the pad set off where the edge is not: the ridge it acquired lies off the edge's line, or the
        vertex it located lies behind where it set off."""
        st, t, seg, s = self.state, self.toucher, self.segmenter, self.settings
        _, n_a, n_b, toward_a = self._edge_frame(st.edge)
        ridge = {"concave": not rec.convex, "strict": True}
        acq = t.follow_edge(u, n_a, n_b, toward_a, 0.0, acquire_only=True, **ridge)
        pieces.append(acq)
        shift = self._off_the_corner(acq, rec) if not acq.ok else None
        if shift is not None:
            # the pad rolling onto the ridge met a third face, where the edge ends at a corner: it tries once more
            # from a pad's radius farther from that corner
            status = self._return_next_to_edge(rec, u, self.on_face if self.on_face in rec.faces else st.face,
                                               pieces, shift)  # fmt: skip
            if status != "ok":
                return self.failed_result(move, status, f"acquiring the ridge: {acq.event}; {self._why}")
            acq = t.follow_edge(u, n_a, n_b, toward_a, 0.0, acquire_only=True, **ridge)
            pieces.append(acq)
            if acq.ok:
                self.recoveries.append("acquiring the ridge, the pad met a face at the edge's end: acquired again "
                                       "a pad's radius from it")  # fmt: skip
        if not acq.ok:
            return self.failed_result(move, acq, f"acquiring the ridge: {acq.event}")
        off = self._line_distance(rec, self.contact_point())
        s_acq = rec.param(self.contact_point())
        past = max(rec.interval[0] - s_acq, s_acq - rec.interval[1], 0.0)  # the line extrapolated this far
        slack = past * math.sin(self.bounds.bound(rec.direction_sigma, self.bounds.direction_floor))
        if rec.convex and off > s.ridge_offset + slack:
            return "unreachable", f"the ridge acquired lies {off * MM:.1f} mm off the edge's line: another edge"
        if past > t.pad_radius:
            # the pad set off beyond what of the edge was sensed by more than its radius: the ridge there may be
            # another edge on the same line, past a gap (cad_slotted of the formula corpus: an edge move returned next
            # to the edge 40 mm past its explored interval, beyond a 30 mm slot, on the collinear edge across it, and
            # the edge's interval, extended to the vertex there, spanned the slot, 21 bounds past its end)
            return "unreachable", f"the ridge acquired lies {past * MM:.0f} mm past the edge's explored interval"
        s_from = rec.param(self.contact_point())
        r = t.follow_edge(u, n_a, n_b, toward_a, s.max_edge_trace, **ridge)
        pieces.append(r)
        if not r.ok:
            return self.failed_result(move, r, f"following the edge: {r.event}")
        if r.info.get("event_sign", 1) < 0 and self.workspace.touching_table(self._finger_contacts()):
            # stopped by the table, not by the object: where the edge line meets the table plane is no vertex
            # (the edge may end above it, or at a chamfer the pad cannot reach)
            return self.failed_result(move, "unreachable", "following the edge: the pad met the table before the "
                                                           "edge's end")  # fmt: skip
        hold = t.hold(s.vertex_hold)
        pieces.append(hold)
        rows = ContactTrace.concatenate([r.trace, hold.trace])
        if not rec.convex and r.info.get("event_sign", 1) > 0:
            s_v, s_sigma = self._concave_end(rec, u, pieces)
        else:
            s_v, s_sigma = self._vertex_param(rec, rows, u, r.info.get("event_sign", 1))
        if s_v is None:
            why = ("could not locate the vertex (no contact there, a concave edge's end, which its faces run past, "
                   "contacts off the edge's line, on an edge turning little from it, or the pad spanning a gap in the "
                   "ridge before what blocked it)")  # fmt: skip
            b = self.bounds
            if past > b.bound(b.point_sigma, b.vertex_floor):
                # the pad acquired the ridge past the edge's explored interval: it may have set off past the end it
                # ran toward, on the next edge there, and rolled off that edge's end (trapezohedron_09, 11 and 12 of
                # the formula corpus, seed 1: four moves along a 7-13 mm edge known from a crossing set off 5-6 mm
                # past its end, acquired the next edge, turning 23-30° from it, 2.4-3.2 mm past the interval, and
                # their contacts at its end lay 1-2 mm off the edge's line)
                return "unreachable", f"{why}, the ridge acquired {past * MM:.1f} mm past the edge's explored interval"
            return self.failed_result(move, "unreachable", why)
        # the vertex lies ahead of what lies behind the move: its start, and with no vertex known behind the explored
        # interval, the interval (BOX01N at 60 mm, seed 2: a move along +e set off 23 mm behind the interval, past the
        # edge's other end, and located that end's vertex behind its start; reported as the end it ran toward, with
        # the interval collapsed onto it, the edge's two ends were one vertex and the true object was pruned;
        # trapezohedron_11 of the formula corpus, seed 1: a move set off 3.2 mm behind the interval, past the edge's
        # other end, and located that end 2.9 mm ahead of its start, 0.3 mm behind the interval;
        # :meth:`Segmenter.behind_interval`)
        sign = 1.0 if float(u @ rec.direction) > 0 else -1.0
        if seg.behind_interval(st.edge, s_v, s_from, int(sign)):
            return "unreachable", "the vertex located lies behind the move's start or the edge's explored interval, " \
                                  "at the edge's other end (the pad set off past it)"
        # ... nor is it, within its bound, the vertex known at the edge's end behind the move: the pad set off past
        # that end and located it as it came onto the edge (trapezohedron_12 of the formula corpus at 77 mm, seed 1: a
        # move set off 2 mm past one end of a 9 mm edge toward the other and put a vertex 0.3 mm from the end it
        # left; reported as the end it ran toward, the edge's interval collapsed onto it, its two ends were one vertex
        # and the true object was pruned: no-match)
        middle = 0.5 * (rec.interval[0] + rec.interval[1])
        for vid, s_known in rec.vertices.items():
            if sign * (s_known - middle) < 0 and abs(s_v - s_known) <= seg.vertices[vid].position_bound:
                return "unreachable", "the vertex located is the edge's other end, which the move set off past"
        if self._acquired_past(rec, acq.trace, u, s_v):
            return "unreachable", "the vertex located lies behind where the pad acquired the ridge (the pad set off " \
                                  "past it)"
        # refine the line with the ridge contacts (convex edges), then extend it to the vertex
        ridge = self._on_ridge(rows, u)
        w_v, w_from = rec.at(s_v), rec.at(s_from)
        seg.refine_edge(st.edge, rows.point_in_world[ridge] if ridge.sum() >= seg.bounds.min_line_points else None,
                        (self._face_fit(rec.faces[0]), self._face_fit(rec.faces[1])))  # fmt: skip
        s_v, s_from = rec.param(w_v), rec.param(w_from)
        edge, vertex = seg.extend_edge(st.edge, s_from, s_v, s_sigma, 1 if float(u @ rec.direction) > 0 else -1)
        # rest on the current face next to the vertex (the state the next move starts from)
        fid = st.face if st.face in rec.faces else rec.faces[1]
        rest = vertex.position - s.vertex_standoff * u + s.vertex_standoff * rec.inward[fid]
        status = self._ensure_on_face(fid, pieces, near=rest)
        position = self.contact_point() if status == "ok" else vertex.position.copy()
        self.state = SensorState(position=position, face=st.face, edge=st.edge, vertex=vertex.id,
                                 edge_faces=st.edge_faces)  # fmt: skip
        return MoveResult(move=move, status="ok", components=(edge, vertex), distance=r.distance,
                          cost=self.costs.edge_move(r.distance), state=self.state,
                          info={"vertex_event": r.info.get("event_sign", 1)})  # fmt: skip

    def _off_the_corner(self, acq: PrimitiveResult, rec) -> float | None:
        """After a ridge acquisition along edge ``rec`` that never settled on the bisector: the parameter along the
        edge a pad's radius from where it ended, away from the face its last normals leaned from (a third face, where
        the edge ends at a corner); None when they did not lean along the edge by more than
        ``PhysicsSettings.corner_lean`` (or it lost contact, or went unstable)."""
        if acq.status == "unstable":
            return None
        tr = acq.trace
        rows = np.flatnonzero(tr.in_contact)[-self.settings.corner_rows:]
        if not len(rows):
            return None
        lean = float(np.median(tr.normal_in_world[rows] @ rec.direction))
        if abs(lean) < math.sin(self.settings.corner_lean):
            return None
        return rec.param(tr.point_in_world[rows[-1]]) + math.copysign(self.toucher.pad_radius, lean)

    def _concave_end(self, rec, u: np.ndarray, pieces: list[PrimitiveResult]) -> tuple[float | None, float]:
        """Parameter of the end of concave edge ``rec``, and its σ, where the surface fell away as the pad ran along
        ``u`` in its corner: the pad rests on the rims where the edge's faces end, and the merged contact it senses
        lies on neither, nor does it stay at the end where the faces' corners there are obtuse (they run on past
        it, and so do the contacts: FRAME01's hole at 40 mm, 3.6 mm past). Each contact is read apart: one on a
        face's plane whose normal has turned along ``u`` off the face's lies on the rim, which runs square to that
        normal within the plane; the rim meets the edge's line at the end. Both faces' rims must be touched and
        meet the line within the bound of a vertex of one another (a rim elsewhere on a face does not); (None, 0)
        otherwise."""
        t, b, s = self.toucher, self.bounds, self.settings
        got = t.hold_reading(s.rim_hold)
        pieces.append(got)
        if not got.ok:
            return None, 0.0
        fits = [self._face_fit(f) for f in rec.faces]
        ends, sigmas = [], []
        for k, fit in enumerate(fits):
            other = fits[1 - k]
            pts, nrm = [], []
            for tick in got.info["contacts"]:
                for c in tick:
                    p, n = c.point_in_world, c.normal_in_world
                    # on this face's plane and not the other's, its normal turned from this face's the least: a
                    # shallow corner's faces lie within the tolerance of one another a few millimetres from it
                    here = abs(float(p @ fit.normal) - fit.offset)
                    there = abs(float(p @ other.normal) - other.offset)
                    if here <= s.rim_plane < there and angle(n, fit.normal) < angle(n, other.normal):
                        pts.append(p)
                        nrm.append(n)
            if len(pts) < s.min_rim_samples:
                return None, 0.0
            p, n = np.mean(pts, axis=0), unit(np.sum(nrm, axis=0))
            if angle(n, fit.normal) < s.rim_tilt or float(n @ u) <= 0.0:
                return None, 0.0  # the pad still rests on the face: it runs on past the end
            d = unit(np.cross(fit.normal, n))  # the rim, in the face's plane square to the rim contact's normal
            e = rec.direction
            cos_ed = float(e @ d)
            if abs(cos_ed) > math.cos(s.rim_tilt):
                return None, 0.0
            w0 = rec.point - p
            s_e = (cos_ed * float(d @ w0) - float(e @ w0)) / (1.0 - cos_ed * cos_ed)
            gap = rec.at(s_e) - (p + float((rec.at(s_e) - p) @ d) * d)
            lever = float(np.linalg.norm(rec.at(s_e) - p))
            sigma = math.hypot(b.point_sigma, lever * b.normal_sigma / angle(n, fit.normal)) / math.sqrt(len(pts))
            if float(np.linalg.norm(gap)) > b.bound(rec.position_sigma, b.position_floor) + s.rim_plane:
                return None, 0.0
            ends.append(s_e)
            sigmas.append(sigma)
        sigma = math.hypot(*sigmas) / 2.0
        if abs(ends[0] - ends[1]) > b.bound(math.hypot(*sigmas), b.vertex_floor):
            return None, 0.0
        return 0.5 * (ends[0] + ends[1]), max(sigma, 0.5 * abs(ends[0] - ends[1]))

    @staticmethod
    def _line_distance(rec, w: np.ndarray) -> float:
        q = w - rec.at(rec.param(w))
        return float(np.linalg.norm(q))

    def _vertex_param(self, rec, rows: ContactTrace, u: np.ndarray, event_sign: int):
        """Parameter of the vertex along the edge line, and its σ. Surface fell away: the contact points
        stayed at the vertex while the normal tilted along the edge. Blocked: where the edge line meets the
        plane of the blocking contact."""
        ok = rows.in_contact
        n = np.where(ok[:, None], rows.normal_in_world, 0.0)
        c = n @ u
        b, s = self.bounds, self.settings
        if event_sign > 0 and not rec.convex:
            # the pad in a concave corner touches the two faces, not the edge: where their corners at its end are
            # obtuse the faces run on past it and so do the contacts, rolling on along the rims (FRAME01's hole
            # at 40 mm: 3.6 mm past): the surface falling away does not locate a concave edge's end
            return None, 0.0
        if event_sign > 0:
            lean = max(s.touch.loss_lean_sin, math.sin(s.vertex_lean_sigmas * b.normal_sigma))
            at_v = ok & (c > lean)  # the pad rolls on the vertex
            if at_v.sum() < s.min_vertex_rows:  # contact was lost: the last contacts
                idx = np.flatnonzero(ok)[-s.lost_vertex_rows :]
                at_v = np.zeros(len(rows), bool)
                at_v[idx] = True
            if not at_v.any():
                return None, 0.0
            rel = rows.point_in_world[at_v] - rec.point
            along = rel @ rec.direction
            if self._off_the_line(rec, rel - along[:, None] * rec.direction):
                # rolling on the vertex the contacts stay on the edge's line; off it, the pad went on round the
                # vertex along an edge turning little from this one (a 12-gon's, 30°): the contacts lie past it
                return None, 0.0
            return float(np.median(along)), max(float(np.std(along)), b.point_sigma) / math.sqrt(len(along))
        if rec.convex and self._spans_a_gap(rows, u):
            return None, 0.0
        contacts = self._finger_contacts()
        if not contacts:
            return None, 0.0
        blk = min(contacts, key=lambda cc: float(cc.normal_in_world @ u))
        denom = float(blk.normal_in_world @ rec.direction)
        if abs(denom) < s.min_block_cos:
            return None, 0.0
        s_v = float((blk.point_in_world - rec.point) @ blk.normal_in_world) / denom
        return s_v, b.point_sigma / abs(denom)

    def _off_the_line(self, rec, across: np.ndarray) -> bool:
        """Whether contacts whose offsets from edge ``rec``'s line are ``across`` (k, 3), square to it, lie off the
        line: their centre (the median offset per axis across the line) farther from it than the line's bound and the
        noise of that centre (each contact off by σp per axis, the median of k by about ``√(π/2) σp / √k``) allow.
        Each contact alone lies off the line by its noise, a 2-D error whose median length is ``1.18 σp``: at noise
        level 4 (σp 0.8 mm) 0.9-1.3 mm where the line's bound was 0.8 mm, and 14 of 17 edge moves of HEXPRISM01 at
        150 mm (seed 1) that rolled on their vertex located none, their contacts' centre 0.04-0.41 mm off the
        line."""
        b = self.bounds
        a = perpendicular(rec.direction)
        c = np.cross(rec.direction, a)
        centre = np.hypot(float(np.median(across @ a)), float(np.median(across @ c)))
        noise = MEDIAN_EFFICIENCY * b.point_sigma / math.sqrt(max(len(across), 1))
        return centre > b.bound(math.hypot(rec.position_sigma, noise), b.position_floor)

    def _acquired_past(self, rec, acq: ContactTrace, u: np.ndarray, s_v: float) -> bool:
        """Whether the pad acquired the ridge past the vertex it then located at ``s_v``: acquiring the ridge short
        of the vertex, its first contacts on the ridge (:attr:`~PhysicsSettings.min_vertex_rows`, their median) lie
        behind it along ``u``; lying ahead of it by more than the bound of a vertex, they came from a pad already
        past the edge's end, whose contacts then slid back toward it (trapezohedron_09 of the formula corpus at
        60 mm, seed 1: the pad acquired the "ridge" 4.4 mm past the end of its edge, on the faces beyond, its tip
        went 0.4 mm along the edge while the contacts slid to 1.3 mm past the vertex, and the vertex was put there,
        1.05 bounds off)."""
        first = np.flatnonzero(acq.in_contact & (acq.phase == PHASES.index("ridge")))[: self.settings.min_vertex_rows]
        if len(first) < self.settings.min_vertex_rows:
            return False
        sign = 1.0 if float(u @ rec.direction) > 0 else -1.0
        ahead = sign * (float(np.median((acq.point_in_world[first] - rec.point) @ rec.direction)) - s_v)
        b = self.bounds
        return ahead > b.bound(b.point_sigma, b.vertex_floor)

    def _spans_a_gap(self, rows: ContactTrace, u: np.ndarray) -> bool:
        """Whether the pad, following a convex ridge along ``u`` until something blocked it, spanned a gap in the
        ridge before the block: its contacts on the ridge (the last :attr:`PhysicsSettings.gap_rows`) lie inside
        the pad, nearer its centre than its model's radius by more than the bound of a contact point (their median;
        not the radius refined from the contacts, which such rows pull in). On a ridge the pad touches one patch at
        its radius; across a gap narrower than the pad it touches the two sides
        at once, and the sensor reads the patches' mean, on the ridge's line but inside the pad (BOX01N at 30 mm,
        seed 1: 1.0 mm inside across a 9 mm slot; the far side blocked the pad, the vertex was put there and the
        edge's interval extended across the slot, 3.2 bounds past the edge's end)."""
        ridge = np.flatnonzero(self._on_ridge(rows, u))[-self.settings.gap_rows :]
        if not len(ridge):
            return False
        b = self.bounds
        d = np.linalg.norm(rows.tip_in_world[ridge] - rows.point_in_world[ridge], axis=1)
        inside = self.toucher.pad_model_radius - float(np.median(d))
        return inside > b.bound(b.point_sigma / math.sqrt(len(ridge)), b.position_floor)

    def _vertex_move(self, move: VertexMove, pieces: list[PrimitiveResult]) -> MoveResult:
        st, t, seg, s = self.state, self.toucher, self.segmenter, self.settings
        if st.vertex is None or st.edge is None:
            return self.invalid_result(move, "no current vertex: a vertex move starts near a vertex on a known edge")
        if move.across_face not in st.edge_faces:
            return self.invalid_result(move, f"face {move.across_face} is not a face of the current edge (faces "
                                       f"{st.edge_faces})")  # fmt: skip
        rec = seg.edges[st.edge]
        f = move.across_face
        if f not in rec.inward or st.vertex not in rec.vertices:
            return self.invalid_result(move, "the current edge does not know that face or vertex")
        vtx = seg.vertices[st.vertex].position
        u = toward_vertex(rec, rec.vertices[st.vertex])
        w_f = rec.inward[f]
        n_f = seg.faces[f].component.normal
        circle = self._valley_circle(rec, f, s.vertex_radius, s.vertex_start_angle)
        if circle is None:
            return self.failed_result(move, "unreachable", "the circle around the vertex lies within the pad's reach "
                                                           "of the valley's other face")  # fmt: skip
        rho, beta = circle
        if rho != s.vertex_radius:
            self.recoveries.append(f"the circle around a valley's end: {rho * MM:.0f} mm from the vertex, clear of "
                                   "the valley's other face")  # fmt: skip
        p0 = vtx + rho * (-math.cos(beta) * u + math.sin(beta) * w_f)
        sweep = self.workspace.circle_sweep_off_table(vtx, n_f, u, w_f)
        if sweep <= 0.0:
            return self.failed_result(move, "unreachable", "the vertex is next to the table: the circle around it "
                                                          "would put the pad on the table")  # fmt: skip
        status = self._ensure_on_face(f, pieces, near=p0)
        if status == "unreachable" and self._why.startswith("touched a normal") and rho == s.vertex_radius:
            # the pad at the circle's start touched the rim of the face's far edge (the face's corner at the vertex
            # narrower than the start angle, or the vertex located a little off): the circle starts halfway to the
            # current edge instead
            beta = 0.5 * beta
            p1 = vtx + rho * (-math.cos(beta) * u + math.sin(beta) * w_f)
            if self.workspace.pad_clearance(p1, n_f) >= s.pad_clearance:
                why = self._why
                status = self._ensure_on_face(f, pieces, near=p1)
                if status == "ok":
                    self.recoveries.append(f"could not reach the face next to the vertex: {why}: the circle started "
                                           "halfway to the edge")  # fmt: skip
                p0 = p1
        if status != "ok":
            return self.failed_result(move, status, f"{VERTEX_FACE_FAILED}: {self._why}")
        tangent = math.sin(beta) * u + math.cos(beta) * w_f
        tilted = False
        while True:
            r = t.circle_vertex(vtx, n_f, tangent, rho, max_sweep=sweep)
            pieces.append(r)
            if r.event == "hand" and not tilted:  # a link of the finger lifted the pad off: tilted, circle again
                tilted = True
                if self._tilt_away(r, f, p0, pieces):
                    continue
            if not r.ok:
                if r.event == "table":
                    return self.failed_result(move, r,
                                              "circling the vertex: no edge before the circle would meet the table")
                if r.event == "hand":
                    return self.failed_result(move, r, f"circling the vertex: the finger's {r.info['link']} met the "
                                                       "object")  # fmt: skip
                return self.failed_result(move, r, f"circling the vertex: {r.event}")
            kind = r.info["kind"]
            corner = self.contact_point()
            status, reason, roll, stroke, fit_g = self._cross_and_acquire(
                kind, r.info["face_normal"], r.info["direction"], pieces, away_from=vtx
            )
            if status == "hand" and not tilted:
                tilted = True
                if self._tilt_away(self._met, f, p0, pieces):
                    continue
            if status != "ok" and reason.startswith(NEXT_FACE_LOST):
                # the circle met the edge where the face past it is too narrow for the pad (an acute corner at the
                # vertex): crossed again farther out along the edge, away from the vertex
                shift = self._outward(n_f, self._roll, corner, vtx)
                again = None if shift is None else self._circle_crossed_again(
                    f, n_f, r.info["direction"], corner, shift, vtx, r.trace, pieces)
                if again is None:
                    return self.failed_result(move, status, reason)
                _, kind, roll, stroke, fit_g, fit_f, line, shifted, touched = again
                self.recoveries.append(f"{reason}: crossed again {shifted * MM:.0f} mm out along the edge"
                                       f"{FROM_TOUCHED if touched else ''}")  # fmt: skip
                break
            if status == "undercut":
                # the next face out of the pad's reach (leaning under, or down to the table's clearance): the edge
                # alone, from the roll, as a face move gives it
                return self._edge_only(move, r, roll, reason, pieces, circled=(f, vtx))
            if status != "ok":
                return self.failed_result(move, status, reason)
            fit_f, line, why = self._edge_between(f, r.trace, "circle", roll, fit_g, kind, corner)
            break
        if line is None:
            heading, where = r.info["direction"], "along the edge"
            self._rolled_round = None
            shift = self._past_the_vertex(fit_f.normal, fit_g, roll, corner)
            narrow = shift is not None
            if narrow:  # the next face met lies round a vertex past a narrow face: square to the edge
                heading = self._square_to(heading, shift, n_f)
                where = "along the edge square to it"
            else:
                shift = self._away_from_vertex(fit_f.normal, fit_g.normal, roll)
            again = None if shift is None else self._circle_crossed_again(
                f, n_f, heading, corner, shift, vtx, r.trace, pieces)
            if again is None:
                # the roll's lean told no way, or a wrong one (the next face touched afresh round the vertex, its
                # normal another face's): the edge met leaves the vertex circled, so out along it, clear of it;
                # crossed again where the narrow face was to be wide enough and round the vertex again, farther out
                shift = self._clear_of_vertex(n_f, corner, vtx, self._rolled_round if narrow else None)
                again = None if shift is None else self._circle_crossed_again(
                    f, n_f, r.info["direction"], corner, shift, vtx, r.trace, pieces)
                where = "out along the edge, clear of the vertex"
            if again is None:
                return self.failed_result(move, "unreachable", why)
            _, kind, roll, stroke, fit_g, fit_f, line, shifted, touched = again
            self.recoveries.append(f"{why}: crossed again {shifted * MM:.0f} mm {where}"
                                   f"{FROM_TOUCHED if touched else ''}")  # fmt: skip
        if seg.beside_parallel_face(st.edge, f, fit_g):
            return self.failed_result(move, "unreachable", "the edge met lies along the current edge's line, the "
                                                           "next face parallel to its other face: it leaves another "
                                                           "vertex")  # fmt: skip
        s_vtx = self._at_circled(line, vtx)
        if isinstance(s_vtx, str):
            return self.failed_result(move, "unreachable", s_vtx)
        return self._rolled_onto(move, f, line, kind, (fit_f.normal, fit_g.normal), fit_g, stroke, r.distance,
                                 self.costs.vertex_move(r.distance), vertex=(st.vertex, s_vtx))  # fmt: skip

    def _outward(self, n_f: np.ndarray, roll: ContactTrace | None, corner: np.ndarray, vtx: np.ndarray
                 ) -> np.ndarray | None:  # fmt: skip
        """After a vertex circle on face ``n_f`` round ``vtx`` that rolled over an edge at ``corner`` and found too
        little of the face past it: the shift along that edge (its direction from the roll's first turn,
        :meth:`_first_turn`) away from the vertex, ``recross_shift`` plus half the pad's radius; None when the roll
        tells no edge."""
        if roll is None or not roll.in_contact.any():
            return None
        e = np.cross(n_f, self._first_turn(n_f, roll))
        if float(e @ e) < math.sin(self.bounds.min_edge_angle) ** 2:
            return None
        e = unit(e)
        out = float((corner - vtx) @ e)
        return math.copysign(self.settings.recross_shift + 0.5 * self.toucher.pad_radius, out) * e

    def _clear_of_vertex(self, n_f: np.ndarray, corner: np.ndarray, vtx: np.ndarray,
                         rolled: np.ndarray | None = None) -> np.ndarray | None:  # fmt: skip
        """After a vertex circle on face ``n_f`` round ``vtx`` that met an edge at ``corner`` and rolled round the
        vertex: the shift along that edge (from the vertex through ``corner``, in the face) that puts the crossing
        the pad's radius plus ``recross_shift`` from the vertex, ``recross_shift`` at least (bipyramid_08 of the
        sized corpus at 130 mm, seed 1: met 8.7 mm from the apex, the pad rolled round it, and the shift told by the
        roll's lean, the next face touched afresh round the apex, ran back toward it); None when the crossing lies
        at the vertex. ``rolled``: where a crossing made again farther out, where the face past the edge was to be
        wide enough (:meth:`_past_the_vertex`, :meth:`_circle_crossed_again`), met the edge and rolled round the
        vertex too; the crossing then lies ``recross_shift`` farther out than that one
        (bipyramid_11 of the formula corpus, seed 1: a circle round an apex of eleven triangles met an edge 7.9 mm from
        it, where the next triangle is 2.7 mm wide, crossed again 18.4 mm out and rolled round the apex again onto the
        triangle beyond; the pad's radius plus ``recross_shift`` from the vertex put the last crossing 18.0 mm out, the
        same, and the move failed; 24.5 mm out it measures the edge and the next triangle)."""
        out = in_plane(np.asarray(corner - vtx, dtype=float), n_f)
        if out is None or float(np.linalg.norm(out)) < self.bounds.position_floor:
            return None
        s = self.settings
        dist = float(np.linalg.norm(out))
        if rolled is None:
            return max(s.recross_shift, self.toucher.pad_radius + s.recross_shift - dist) * (out / dist)
        out = out / dist
        need = max(dist + s.recross_shift, self.toucher.pad_radius + s.recross_shift)
        need = max(need, float((rolled - vtx) @ out) + s.recross_shift)
        return (need - dist) * out

    def _valley_circle(self, rec, f: int, rho: float, beta: float) -> tuple[float, float] | None:
        """The radius and start angle of a vertex move's circle on face ``f`` around a vertex at the end of edge
        ``rec``: ``rho`` and ``beta`` as planned, unless ``rec`` is a valley whose other face (normal ``n_g``) the
        pad would meet at the circle's start: resting on ``f`` at a distance ``x`` from the valley, the pad's centre
        clears that face's plane by its radius only where ``x (w_f · n_g) + r (n_f · n_g) >= r``, ``w_f`` pointing
        into ``f`` from the valley (LBLOCK01 and BOX01N, seed 2: circles of 8 mm about a valley's end timed out
        touching the face, the pad 12 mm across). Then the circle starts at :attr:`PhysicsSettings.valley_start_angle`
        at the radius that puts the pad clear of it by :attr:`PhysicsSettings.valley_margin`; None when that radius
        is over :attr:`PhysicsSettings.valley_max_radius`."""
        if rec.convex or None in rec.faces or f not in rec.inward:
            return rho, beta
        g = rec.faces[1] if rec.faces[0] == f else rec.faces[0]
        n_f = self.segmenter.faces[f].component.normal
        n_g = self.segmenter.faces[g].component.normal
        lean = float(rec.inward[f] @ n_g)
        if lean <= 1e-3:
            return rho, beta
        s, r = self.settings, self.toucher.pad_radius
        need = (r * (1.0 - float(n_f @ n_g)) + s.valley_margin) / lean
        if rho * math.sin(beta) >= need:
            return rho, beta
        beta = max(beta, s.valley_start_angle)
        rho = need / math.sin(beta)
        return (rho, beta) if rho <= s.valley_max_radius else None

    def _circle_crossed_again(self, f: int, n_f: np.ndarray, direction: np.ndarray, corner: np.ndarray,
                              shift: np.ndarray, vtx: np.ndarray, circle: ContactTrace,
                              pieces: list[PrimitiveResult]):  # fmt: skip
        """After a vertex circle whose roll leaned along the edge between face ``f`` and the next face (the pad
        rolled round an end of the edge met), or found too little of the face past it, as a face move does: touch
        face ``f`` again ``recross_back`` before where the circle met the edge and ``shift`` along it (back inside,
        :meth:`_away_from_vertex`, or out from the vertex, :meth:`_outward`), slide on along the circle's heading
        there (``direction``) to the edge, over it and onto the next face; that start off the face, from a point the
        circle (``circle``) or earlier moves touched it at (:meth:`_recross_start`). Returns (the slide, kind, roll,
        stroke, next face's fit, face ``f``'s fit, the line, the shift [m], whether it set off from such a point), or
        None when it gives no edge."""
        t, s = self.toucher, self.settings
        self._rolled_round = None
        d = in_plane(np.asarray(direction, dtype=float), n_f)
        if d is None:
            return None
        way = self._recross_start(f, n_f, corner, d, shift, s.recross_back, circle, pieces)
        if way is None:
            return None
        # from a point the face was touched at, the slide runs as far as it is from the new crossing
        reach = s.circle_recross if way is d else s.circle_recross + float(np.linalg.norm(self.contact_point()
                                                                                            - corner - shift))
        # a link of the finger that meets the object sliding or crossing tilts the hand away once, back at the start
        start, tilted = self.contact_point(), False
        while True:
            r = t.trace_face(way, n_f, reach)
            pieces.append(r)
            if r.event == "hand" and not tilted:
                tilted = True
                if self._tilt_away(r, f, start, pieces):
                    continue
            if not r.ok or r.event == "done":
                return None
            kind, corner = r.info["kind"], self.contact_point()
            status, _, roll, stroke, fit_g = self._cross_and_acquire(kind, r.info["face_normal"], r.info["direction"],
                                                                     pieces, away_from=vtx)  # fmt: skip
            if status == "hand" and not tilted:
                tilted = True
                if self._tilt_away(self._met, f, start, pieces):
                    continue
            break
        if status != "ok":
            return None
        fit_f, line, _ = self._edge_between(f, r.trace, "face", roll, fit_g, kind, corner)
        if line is None:
            self._rolled_round = corner
            return None
        return r, kind, roll, stroke, fit_g, fit_f, line, float(np.linalg.norm(shift)), way is not d

    # ------------------------------------------------------------------------------------------ helpers
    def admissible_moves(self, rng: np.random.Generator, n_directions: int = 8) -> list[Move]:
        """Candidate moves from the current state (:func:`~haptic.executor.workspace.admissible_moves`)."""
        return admissible_moves(self.state, self.segmenter, self.workspace, rng, n_directions)


__all__ = ["PhysicsExecutor", "PhysicsSettings"]
