"""A placement of several fingertips at once (seed §5) on the simulated hand: :meth:`PhysicsExecutor.execute` of a
:class:`~haptic.planning.moves.PlacementMove` (:func:`placement_move`), and the planner's test of whether the hand
can take a placement up (:class:`PlacementReach`).

Every motion is joint-space: the reach solver (:mod:`haptic.sim.reach`, on the robot and the table alone: the
executor never sees the object) gives the arm's and the hand's joint path, and the controller holds each
configuration of it (``hold_posture``) while every fingertip's sensed contact is watched. Step by step:

1. *Leave the surface and rise*: the exploring pad lifts off along the sensed normal and rises straight up to the
   probes' safe height (:func:`~haptic.planning.handpath.safe_height`).
2. *Reach*: every finger's pad is brought above its line's start, the finger pointing along its line, then down to
   the start (each the solver's path, a touch on the way fails the placement: ``unreachable``).
3. *Close*: the fingers advance along their lines together, one :attr:`PlacementSettings.step` at a time, each
   step a configuration the solver finds for every pad's target at once. A finger whose pad touches stops there
   and presses (its target :attr:`PlacementSettings.press` past the contact), while the others close on; one that
   reaches its line's end met nothing (free space); one whose link meets the object, whose pad meets the table,
   or that lags its target (the joints cannot carry it further) fails alone and is held where it is.
4. *Stroke*: every finger that touched strokes an L of two short legs in its tangent plane, pressing, together;
   its contacts alone are fitted into its own face component by the segmenter (the same sensing interface as
   every move: the fingertip's contact point, normal and force). A stroke that turns its normal (an edge or a
   vertex under the pad) fails that finger alone.
5. *Back*: the fingers retract along their lines, the hand rises, turns back to the tracing posture, and the
   exploring pad touches again the first face the placement measured (the sensor state rests there).

Each finger's path along its line up to its touch (or the whole line) is reported free, as a probe's. The cost is
:meth:`~haptic.planning.moves.CostModel.placement_move` of the hand's travel (the farthest pad's way to its line's
start and the longest closing) with a stroke per face measured.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from itertools import permutations
from typing import Any

import mink
import mujoco
import numpy as np

from haptic.executor.physics_probe import _highest_contact, _leading_segment, rise
from haptic.executor.primitives import PrimitiveResult
from haptic.geometry.distance import surface_distance
from haptic.geometry.se3 import perpendicular, unit
from haptic.matching.trace import PHASES, ContactTrace
from haptic.planning.finger_faces import LEVEL_STROKE
from haptic.planning.handpath import CLEARANCE, LIFT, safe_height
from haptic.planning.moves import FingerApproach, MoveResult, PlacementMove, ProbeMove, SensorState
from haptic.sim.reach import FingertipTarget, ReachSettings, ReachSolver
from haptic.sim.scene import ARM_HOME, FINGERS, HAND_TRACE, PAD_RADIUS, TABLE_TOP_Z

PhysicsExecutor = Any
"""The :class:`~haptic.executor.physics.PhysicsExecutor` whose hand carries out the placement; not imported here,
since that module dispatches to this one."""


@dataclass(frozen=True)
class PlacementSettings:
    """Geometry, speeds and tolerances of a placement on the hand."""

    step: float = 0.001
    """The fingers close along their lines by this much per configuration [m] ..."""
    step_ticks: int = 12
    """... each held this many control ticks (with 5 ms ticks, 17 mm/s) [-]."""
    ik_iterations: int = 4
    """QP iterations of the solver per configuration of the closing and the stroke [-]."""
    press: float = 0.001
    """A finger that touched presses with its target this far past its contact, along its line [m]."""
    lag: float = 0.008
    """A closing finger whose pad trails its target by more than this fails (its joints carry it no further) [m]."""
    settle_ticks: int = 30
    """Ticks the touched fingers press in place before they stroke, and before the normal is read [-]."""
    stroke: float = 0.004
    """Length of each leg of a finger's L stroke [m] ..."""
    stroke_step: float = 0.00025
    """... taken in steps of this [m] ..."""
    stroke_ticks: int = 4
    """... each held this many ticks (with 5 ms ticks, 12.5 mm/s) [-]."""
    stroke_press: float = 0.0015
    """While stroking a pad's target starts this far under its face's plane [m] ..."""
    press_gain: float = 0.0002
    """... and goes this much deeper per newton the sensed force falls short of the tracing force, per step
    [m/N] ..."""
    max_press: float = 0.004
    """... down to at most this [m]."""
    dwell_steps: int = 12
    """At the end of each leg the targets stay this many steps (the joints' servo trails them) [-]."""
    stroke_overrun: float = 1.0
    """Above 1, a leg of the L ends once the pad has travelled its length, its targets running on to at most this many
    times it while the pad trails them, then held where the pad is; 1: the targets run the length and the pad follows
    as far as the servo takes it [-]."""
    stroke_headings: int = 4
    """A finger whose stroke finds no face strokes again in up to this many headings in all, a quarter turn
    apart (its stroke may have left a narrow face)."""
    stroke_across: float | None = None
    """Length of the L's second leg [m]; None: :attr:`stroke`."""
    level_stroke: bool = False
    """Whether the L's first leg runs level (along the face, horizontal; the other way at each further heading) and
    its second rises, in place of a random heading: a pad that came in under an overhang, close above the table,
    has room along the face but little up or down."""
    path_step: float = 0.01
    """The solver's path to the lines' starts (a joint moves up to 0.05 rad from one configuration to the next) is
    followed through configurations interpolated in joint space between them, no joint moving by more than this from
    one to the next [rad]: held a configuration of the solver's each, the arm's servo swung the hand off the straight
    way in joint space between them, and a pad passing 4 mm under a face leaning over it touched it (hull_02 of the
    sized formula corpus, seed 1: two probes of three, 0.05 rad behind the path) ..."""
    path_ticks: int = 4
    """... each held at least this many ticks [-] ..."""
    path_tol: float = 0.01
    """... and until every arm joint is within this of it [rad] ..."""
    path_max_ticks: int = 60
    """... for at most this many ticks [-] (the arm's servo trails a moving target: a path followed faster leaves
    it by centimetres) ..."""
    arrive_tol: float = 0.002
    """... then held until every pad is within this of its target [m] ..."""
    arrive_ticks: int = 200
    """... for at most this many ticks [-]."""
    lift: float = LIFT
    """The exploring pad lifts off its face by this before rising; the fingers retract along their lines by it
    after the stroke [m]."""
    clearance: float = CLEARANCE
    """The hand rises this far above the highest contact sensed so far (plus the pad radius) [m]."""
    above: float = 0.02
    """The pads are brought this far above their lines' starts before they go down to them [m]."""
    posture_cost: float = 5e-3
    """Weight of the start configuration in the closing's and the stroke's configurations [-]."""
    reach: ReachSettings = field(default_factory=ReachSettings)
    """The reach solver's settings (the executor's, on the robot and table alone)."""


SETTINGS = PlacementSettings()

TIP_TABLE_CLEARANCE = 0.008
"""Least distance of the placement's fingertips (distal links and pads) from the table in the planner's reach test
[m], where every other link keeps 20 mm: a line closing on a face near the table starts nearer it than the hand's
other links need to come. Measured (``scripts/bench_placement_physics.py --seeds 1,2,3 --fingers 2``): 3 mm and 8 mm
offer the same 26 placements of 121 (20 mm: 21), so the larger, for the servo's lag."""

HOLD_CLEARANCE = 0.015
"""The reach test's path keeps its clearances to within this [m] (``ReachSettings.hold_clearance``): without it the
solver's linearised limits let links pass within a millimetre of the hypothesised object, and the hand, trailing
the path by a few millimetres, touched it on the way. Measured (``scripts/bench_placement_physics.py --seeds 1,2,3
--fingers 2 --hold-clearance MM``): 15 mm offers 21 placements of 121 and 10 mm 18, every one carried out; none,
26, of which 3 touched the object on the way."""

REACH_CLEARANCE = ReachSettings(clearance=0.02, pads_touch=False, tip_table_clearance=TIP_TABLE_CLEARANCE,
                                hold_clearance=HOLD_CLEARANCE)  # fmt: skip
"""The planner's reach test of a placement: every link of the hand, the pads too, at least 20 mm from the
hypothesised object on the way to the lines' starts, and from the table but for the fingertips
(:data:`TIP_TABLE_CLEARANCE`) (the joints' servo trails the path by a few millimetres; the pads' place at the
starts is the lines' standoff from every hypothesis)."""

_SOLVERS: dict[tuple, ReachSolver] = {}
"""Reach solvers by scene (None: the robot and table alone) and settings, built once per process (compiling a
scene takes a while)."""


def hand_solver(settings: ReachSettings | None = None) -> ReachSolver:
    """The reach solver on the robot and the table alone (no object), one per process and settings."""
    from haptic.sim import compose_scene

    settings = settings or ReachSettings()
    key = (None, settings)
    if key not in _SOLVERS:
        _SOLVERS[key] = ReachSolver(compose_scene(None), settings)
    return _SOLVERS[key]


def pad_target(f: FingerApproach, travel: float = 0.0) -> np.ndarray:
    """Where finger ``f``'s pad centre is when its leading point (the centre plus the pad radius along the line)
    has travelled ``travel`` along its line [m]."""
    u = np.asarray(f.direction, dtype=float)
    return np.asarray(f.start, dtype=float) + (travel - PAD_RADIUS) * u


class _Closing:
    """The joint-space servo of a placement: the solver's configuration for every pad's target, held by the
    controller, and every finger's sensed contact recorded per tick."""

    def __init__(self, ex: PhysicsExecutor, move: PlacementMove, settings: PlacementSettings) -> None:
        self.ex, self.move, self.s = ex, move, settings
        self.solver = hand_solver(settings.reach)
        self.model = self.solver.model
        self.cfg = mink.Configuration(self.model)
        self.limits = [mink.ConfigurationLimit(self.model)]
        self.index = {f.finger: FINGERS.index(f.finger) for f in move.fingers}
        self.rows: dict[str, list[tuple]] = {f.finger: [] for f in move.fingers}
        self.rows.setdefault(ex.toucher.finger, [])  # the exploring fingertip's path too, for the move's trace
        self.index.setdefault(ex.toucher.finger, FINGERS.index(ex.toucher.finger))
        self.ticks = 0
        self.posture = self.q_now()
        self.closing_from: dict[str, int] | None = None
        """Each finger's first row of the closing (None before it)."""
        self.back_from: dict[str, int] | None = None
        """Each finger's first row of the way back (None before it)."""
        self.own: set[int] = set()
        """The pieces made of these rows (not counted again in :meth:`way`)."""
        self.pieces_at_back: int | None = None
        """The pieces of the move before the way back (None before it)."""

    def q_now(self) -> np.ndarray:
        r = self.ex.robot.read()
        return np.concatenate([r.arm_q, r.hand_q])

    def solve(self, targets: dict[str, np.ndarray], axes: dict[str, np.ndarray] | None = None) -> np.ndarray:
        """A configuration near the current one putting each finger's pad at its target (pointing along its
        axis, when given)."""
        s = self.s
        self.cfg.update(self.q_now())
        tasks: list[mink.Task] = []
        for f, p in targets.items():
            task = mink.FrameTask(self.solver.site_name(f), "site", position_cost=1.0, orientation_cost=0.0)
            task.set_target(mink.SE3.from_translation(np.asarray(p, dtype=float)))
            tasks.append(task)
            if axes and f in axes:
                align = mink.AxisAlignTask(self.solver.site_name(f), "site", axis=_finger_axis(f),
                                           cost=s.reach.approach_cost, lm_damping=s.reach.approach_damping)  # fmt: skip
                align.set_target(unit(axes[f]))
                tasks.append(align)
        posture = mink.PostureTask(self.model, cost=s.posture_cost)
        posture.set_target(self.posture)
        tasks.append(posture)
        for _ in range(s.ik_iterations):
            vel = mink.solve_ik(self.cfg, tasks, 1.0, solver="daqp", damping=s.reach.damping, limits=self.limits)
            self.cfg.integrate_inplace(vel, 1.0)
        return self.cfg.q.copy()

    def hold(self, q: np.ndarray) -> None:
        n_arm = len(ARM_HOME)
        self.ex.robot.hold_posture(q[:n_arm], q[n_arm:])

    def tick(self, phase: str):
        """One control tick; each finger's row recorded; the reading returned."""
        robot = self.ex.robot
        robot.step(1)
        self.ticks += 1
        if self.ticks % self.ex.toucher.config.link_every == 0:
            self.ex.toucher.sample_links()
        r = robot.read()
        thr = self.ex.toucher.threshold
        rot = self.ex.toucher.hand_rotation
        nan3 = (math.nan, math.nan, math.nan)
        for f in self.rows:
            k = self.index[f]
            cs = [c for c in r.contacts[k] if np.all(np.isfinite(c.normal_in_world))]
            force = float(sum(c.normal_force for c in cs))
            if cs and force > thr:
                w = np.array([max(c.normal_force, 0.0) for c in cs]) + 1e-12
                p = np.average([c.point_in_world for c in cs], axis=0, weights=w)
                n = unit(np.average([c.normal_in_world for c in cs], axis=0, weights=w))
                self.rows[f].append((r.time, r.fingertip_in_world[k].copy(), rot, p, n, force, PHASES.index(phase)))
            else:
                self.rows[f].append((r.time, r.fingertip_in_world[k].copy(), rot, nan3, nan3, force,
                                     PHASES.index(phase)))  # fmt: skip
        return r

    def trace(self, finger: str, first: int = 0) -> ContactTrace:
        rows = self.rows[finger][first:]
        if not rows:
            return ContactTrace.concatenate([])
        t, tip, rot, p, n, f, ph = zip(*rows, strict=True)
        return ContactTrace(np.array(t), np.array(tip), np.array(rot), np.array(p, dtype=float),
                            np.array(n, dtype=float), np.array(f), np.array(ph, dtype=int))  # fmt: skip

    def way(self, finger: str, first: int = 0, last: int | None = None) -> float:
        """The length of ``finger``'s pad centre's path over its rows ``first`` to ``last`` [m]."""
        tips = np.array([row[1] for row in self.rows[finger][first:last]], dtype=float).reshape(-1, 3)
        return float(np.linalg.norm(np.diff(tips, axis=0), axis=1).sum()) if len(tips) > 1 else 0.0

    def touching(self, finger: str, rows: int) -> bool:
        """The finger's last ``rows`` rows all in contact (debounced)."""
        last = self.rows[finger][-rows:]
        return len(last) == rows and all(math.isfinite(x[4][0]) for x in last)

    def link_on_object(self, reading) -> dict[str, str]:
        """Links other than the pads touching anything but the table: {finger or "hand": link}."""
        t = self.ex.toucher
        out: dict[str, str] = {}
        for c in reading.link_contacts:
            on_table = float(c.normal_in_world[2]) > t.config.table_link_cos and (
                t.floor_z is None or float(c.point_in_world[2]) < t.floor_z)  # fmt: skip
            if on_table or c.normal_force <= t.threshold:
                continue
            owner = next((f for f in FINGERS if c.link.startswith(f"{f}_")), "hand")
            out.setdefault(owner, c.link)
        return out

    def follow(self, path: np.ndarray, phase: str = "free") -> str | None:
        """Hold each configuration of ``path`` in turn, watching every fingertip and link; why it stopped (a touch)
        or None."""
        n_arm = len(ARM_HOME)
        path = np.asarray(path, dtype=float)
        dense = [path[:1]] + [_joint_path(a, b, self.s.path_step)[1:] for a, b in zip(path, path[1:], strict=False)]
        for q in np.concatenate(dense)[1:]:
            self.hold(q)
            for k in range(self.s.path_max_ticks):
                r = self.tick(phase)
                why = self._touched_on_the_way(r)
                if why:
                    self.hold(self.q_now())
                    return why
                if (k + 1 >= self.s.path_ticks and float(np.max(np.abs(r.arm_q - q[:n_arm]))) < self.s.path_tol
                        and float(np.max(np.abs(r.hand_q - q[n_arm:]))) < 2.0 * self.s.path_tol):  # fmt: skip
                    break
        return None

    def arrive(self, targets: dict[str, np.ndarray], phase: str = "free") -> str | None:
        """Tick until every pad is within ``arrive_tol`` of its target (or ``arrive_ticks`` pass); why it stopped
        (a touch) or None."""
        for _ in range(self.s.arrive_ticks):
            r = self.tick(phase)
            why = self._touched_on_the_way(r)
            if why:
                self.hold(self.q_now())
                return why
            if all(np.linalg.norm(r.fingertip_in_world[self.index[f]] - p) < self.s.arrive_tol
                   for f, p in targets.items()):  # fmt: skip
                break
        return None

    def _touched_on_the_way(self, reading) -> str | None:
        for k, f in enumerate(FINGERS):
            if sum(c.normal_force for c in reading.contacts[k]) > self.ex.toucher.threshold:
                where = "the table" if self.ex.workspace.touching_table(reading.contacts[k]) else "something"
                return f"the {f} fingertip touched {where}"
        links = self.link_on_object(reading)
        if links:
            return f"the hand's {next(iter(links.values()))} touched something"
        return None


def _joint_path(q0: np.ndarray, q1: np.ndarray, step: float) -> np.ndarray:
    """Configurations from ``q0`` to ``q1`` on the straight line between them in joint space, no joint moving by
    more than ``step`` from one to the next [rad]."""
    n = max(1, int(np.ceil(float(np.max(np.abs(q1 - q0))) / step)))
    return q0 + np.linspace(0.0, 1.0, n + 1)[:, None] * (q1 - q0)


def _finger_axis(finger: str) -> np.ndarray:
    return np.array([0.0, 1.0, 0.0]) if finger == "thumb" else np.array([0.0, 0.0, 1.0])


def placement_move(ex: PhysicsExecutor, move: PlacementMove, pieces: list[PrimitiveResult],
                   settings: PlacementSettings = SETTINGS) -> MoveResult:  # fmt: skip
    """Carry out ``move`` with ``ex``'s hand (module docstring); a failure is a status, never an exception."""
    if (problem := move.problem()) is not None:
        return ex.invalid_result(move, problem)
    return _placement(ex, move, pieces, settings)


def _placement(ex: PhysicsExecutor, move: PlacementMove, pieces: list[PrimitiveResult], settings: PlacementSettings,
               single: bool = False) -> MoveResult:  # fmt: skip
    """:func:`placement_move` of a placement already checked; ``single``: one finger's probe
    (:func:`finger_probe_move`), whose pad backs out along its whole line before the hand rises (it may be under an
    overhang) and after which the exploring pad does not touch the face measured (the other finger reached it where
    the exploring one does not)."""
    t, s = ex.toucher, settings
    starts = np.array([pad_target(f) for f in move.fingers])
    if np.any(starts[:, 2] - PAD_RADIUS < TABLE_TOP_Z + ex.settings.pad_clearance):
        return ex.invalid_result(move, "a finger's line would bring its pad onto the table")
    # 1. leave the surface and rise
    first_piece = len(pieces)  # the placement's way starts here (:func:`_travel`)
    tip0 = t.tip.copy()
    if t.contact[1] is not None and t.normal is not None:
        res = t.move_free(t.tip + s.lift * t.normal, timeout=t.config.lift_timeout, tol=t.config.lift_tol)
        pieces.append(res)
        if not res.ok:
            return ex.failed_result(move, res, f"leaving the surface: {res.event}")
    ex.on_face = None
    z_safe = float(np.max(safe_height(_highest_contact(ex), t.pad_radius, starts, t.tip, s.clearance)))
    z_safe = min(z_safe, TABLE_TOP_Z + ex.settings.max_approach_height)  # the hand's reach over the region
    up = rise(t, z_safe, 0.15, 0.012, pieces)  # round what holds the pad back (a joint's limit, an overhang)
    if not up.ok or up.event != "done":
        return ex.failed_result(move, "unreachable", f"rising above the object: {up.event}")
    c = _Closing(ex, move, s)
    result = _place(ex, move, c, starts, z_safe, pieces, single)
    _restore(ex, c, move, z_safe, pieces, to_start=single)
    if single and float(t.tip[2]) < z_safe and t.finger not in {f.finger for f in move.fingers}:
        # the hand turned back to the tracing posture about another finger's pad, which left the exploring pad
        # wherever that put it: back over where it set out from, straight or else in joint space in its home
        # posture family (trapezohedron_08 of the formula corpus, seed 1: after the thumb's probe of a kite the
        # index lay on the table 25 cm from the object, and every later move failed rising from there)
        over = np.array([tip0[0], tip0[1], z_safe])
        back = t.move_free(over, timeout=t.config.via_timeout, tol=t.config.via_tol)
        pieces.append(back)
        if not back.ok and t.back_to_home_posture(over, at=over):
            pieces.append(t.move_free(over, timeout=t.config.via_timeout, tol=t.config.via_tol))
        t.take_trace()
    if result.status != "ok":
        return result
    touched = [i for i in result.info["fingers"] if i["status"] == "touched"]
    for info in [] if single else touched:  # the sensor rests on the first face measured that the exploring pad
        # touches again
        fid = info["component"]
        if ex._ensure_on_face(fid, pieces, near=np.asarray(info["point"])) == "ok":
            ex.state = SensorState(position=ex.contact_point(), face=fid)
            break
    way = _travel(c, move, pieces, first_piece, max((i.get("travel") or 0.0) for i in result.info["fingers"]))
    dist = float(sum(way.values()))
    cost = ex.costs.placement_move(dist, len(move.fingers), len(touched))
    for info in result.info["fingers"]:
        info.pop("point", None)
    return replace(result, distance=dist, cost=cost, state=ex.state,
                   info={**result.info, "travel": {k: round(v, 4) for k, v in way.items()}})  # fmt: skip


PROBE_SETTINGS = replace(SETTINGS, stroke=0.008, stroke_across=0.003, level_stroke=True, stroke_overrun=3.0)
"""A probe by another finger (:func:`finger_probe_move`) strokes an L of 8 mm level along the face, then 3 mm up: a
pad that came in under an overhang close above the table has room along the face, little up or down (BOX01P, seed 1,
the side under its step, 35 mm high: the pad's centre has 5 mm up to the step and 5 mm down to the table's
clearance). A placement's 4 mm L at a random heading spanned 5.3 × 1.2 mm there, under the 1.5 mm a face's stroke
must span across, in every heading; an 8 mm one put the pad on the table."""


STROKE_ACROSS_MIN = 0.002
"""The least second leg of a probe's L stroke kept within a face's room (:func:`stroke_within`) [m]: 1.5 mm across
the face is what a face's stroke must span (``SegmentBounds.min_face_width``), and the servo trails its targets."""


def stroke_within(settings: PlacementSettings, room: float, room_up: float | None = None) -> PlacementSettings:
    """``settings`` with the L stroke's legs shortened to stay within ``room`` of where the pad touched (the planner's
    ``ProbeMove.room`` of the hypothesised face): the second leg its own or at least :data:`STROKE_ACROSS_MIN`, the
    first what is left of the room; unchanged where the room holds the whole L. The legs are the pad's travel where
    ``settings.stroke_overrun`` runs the targets on (a probe's): cut to the room, targets alone moved the pad less than
    a face's stroke must span (the servo trails them, the pad held back by friction: 1.2-4.7 × 0.7-1.3 mm of an L of
    3.6 × 2 mm on a face of the cuboctahedron of ``assets/libraries/polyhedra`` at 60 mm), and an L commanded longer
    than the room ran off the face where the pad slid freely (hull_04 of the formula corpus). With ``room_up`` (the
    planner's ``ProbeMove.room_up``: the level stroke, ``room`` then how far the pad can slide level either way), each
    leg within its own: level, then up."""
    along = settings.stroke
    across = settings.stroke if settings.stroke_across is None else settings.stroke_across
    if room_up is not None and settings.level_stroke:
        return replace(settings, stroke=min(along, room), stroke_across=min(across, room_up))
    if math.hypot(along, across) <= room:
        return settings
    across = min(across, max(STROKE_ACROSS_MIN, room / 3.0))
    along = math.sqrt(max(room * room - across * across, 0.0))
    return replace(settings, stroke=max(along, across), stroke_across=across)


def finger_probe_move(ex: PhysicsExecutor, move: ProbeMove, pieces: list[PrimitiveResult],
                      settings: PlacementSettings = PROBE_SETTINGS) -> MoveResult:  # fmt: skip
    """Carry out probe ``move`` with the finger it names (``move.finger``, the exploring one too), pointing along its
    line: the hand's joint-space way of a placement of that one finger (module docstring: the planner's path when the
    move has one, else the solver's on the robot and table alone), its closing, press and stroke, and the way back;
    the touched face measured from that fingertip's contacts alone (its pad's sensed points and normals, through the
    same sensing interface as every move). A probe's result and cost (:meth:`~haptic.planning.moves.CostModel.
    probe_move`, plus a stroke when it touched); the sensor state stays where it was (the exploring pad touches the
    face it left again at the next move)."""
    if (problem := move.problem()) is not None:
        return ex.invalid_result(move, problem)
    approach = FingerApproach(str(move.finger), np.asarray(move.start, dtype=float),
                              np.asarray(move.direction, dtype=float), float(move.length))  # fmt: skip
    place = PlacementMove((approach,), path=move.path)
    if move.room is not None:
        settings = stroke_within(settings, float(move.room), None if move.room_up is None else float(move.room_up))
    res = _placement(ex, place, pieces, settings, single=True)
    info = dict(res.info)
    fingers = info.pop("fingers", [])
    mine = fingers[0] if fingers else {}
    info.update(finger=move.finger, finger_status=mine.get("status"))
    if res.status != "ok":
        return replace(res, move=move, info=info)
    touched = bool(res.components)
    if touched:
        info.update(contact=mine.get("contact"), hit_point=res.components[0].points.mean(axis=0).tolist())
    else:
        info["contact"] = None
    cost = ex.costs.probe_move(res.distance) + (ex.costs.c_n if touched else 0.0)
    return replace(res, move=move, cost=cost, state=ex.state, info=info)


def _travel(c: _Closing, move: PlacementMove, pieces: list[PrimitiveResult], first: int,
            closing: float) -> dict[str, float]:  # fmt: skip
    """The hand's way through free space in a placement, as it went [m]: ``to`` the lines' starts (the exploring
    pad's lift, rise and way over to the path's start, then the farthest of the fingers' pads' ways along the
    path), the longest ``closing`` along a line (given), and ``back``: the exploring pad's way as the fingers
    retract, the hand rises and turns back to the tracing posture, and the pad goes to the face it rests on."""
    names = [f.finger for f in move.fingers]
    ends = c.closing_from or {f: len(c.rows[f]) for f in c.rows}
    back = c.back_from or ends
    split = c.pieces_at_back if c.pieces_at_back is not None else len(pieces)
    before = [p for p in pieces[first:split] if id(p) not in c.own]
    after = [p for p in pieces[split:] if id(p) not in c.own]
    to = sum(p.distance for p in before) + max(c.way(f, 0, ends[f]) for f in names)
    home = c.way(c.ex.toucher.finger, back[c.ex.toucher.finger]) + sum(p.distance for p in after)
    return {"to": to, "closing": closing, "back": home}


def _place(ex: PhysicsExecutor, move: PlacementMove, c: _Closing, starts: np.ndarray, z_safe: float,
           pieces: list[PrimitiveResult], single: bool = False) -> MoveResult:  # fmt: skip
    s = c.s
    names = [f.finger for f in move.fingers]
    axes = {f.finger: np.asarray(f.direction, dtype=float) for f in move.fingers}
    # 2. the planner's way to the lines (from the tracing posture, clear of the hypothesised object), else above the
    # lines' starts, then down to them
    if move.path is not None and len(move.path):
        why = _home_then(c, np.asarray(move.path, dtype=float), pieces)
        if why:
            return ex.failed_result(move, "unreachable", f"on the planned way to the lines: {why}")
        why = c.arrive(dict(zip(names, starts, strict=True)))
        if why:
            return ex.failed_result(move, "unreachable", f"on the planned way to the lines: {why}")
    else:
        why = _above_then_down(c, names, axes, starts, z_safe)
        if why:
            return ex.failed_result(move, "unreachable", why)
    c.posture = c.q_now()
    # 3. close
    status: dict[str, str] = {}
    travel: dict[str, float] = {}
    normals: dict[str, np.ndarray] = {}  # each touched pad's sensed normal ...
    contacts: dict[str, np.ndarray] = {}  # ... contact point ...
    radius: dict[str, float] = {}  # ... and radius as sensed (the pad centre's distance from its contact)
    faces: dict[str, int] = {}  # each finger's face component
    held: dict[str, np.ndarray] = {}
    reason: dict[str, str] = {}
    first_row = {f: len(c.rows[f]) for f in names}
    c.closing_from = {f: len(c.rows[f]) for f in c.rows}
    t_cmd = 0.0
    debounce = ex.toucher.config.debounce
    while len(status) < len(names):
        t_cmd += s.step
        targets = {}
        for f in move.fingers:
            if f.finger in status:
                targets[f.finger] = held[f.finger]
            else:
                targets[f.finger] = pad_target(f, min(t_cmd, float(f.length)))
        c.hold(c.solve(targets))
        for _ in range(s.step_ticks):
            r = c.tick("approach")
            links = c.link_on_object(r)
            if "hand" in links:
                for f in names:
                    if f not in status:
                        status[f], reason[f] = "unreachable", f"the hand's {links['hand']} met the object"
                        held[f] = r.fingertip_in_world[c.index[f]].copy()
                break
            for f in move.fingers:
                name = f.finger
                if name in status:
                    continue
                k = c.index[name]
                tip = r.fingertip_in_world[k]
                u = np.asarray(f.direction, dtype=float)
                if name in links:
                    status[name], reason[name] = "unreachable", f"the finger's {links[name]} met the object"
                    held[name] = tip.copy()
                elif c.touching(name, debounce):
                    row = c.rows[name][-1]
                    if ex.workspace.is_table(np.asarray(row[4]), np.asarray(row[3])):
                        status[name], reason[name] = "unreachable", "the pad met the table"
                        held[name] = tip.copy()
                        continue
                    status[name] = "touched"
                    travel[name] = float((tip - pad_target(f)) @ u)
                    rows = c.rows[name][-debounce:]
                    contacts[name] = np.mean([x[3] for x in rows], axis=0)
                    normals[name] = unit(np.mean([x[4] for x in rows], axis=0))
                    radius[name] = float(np.linalg.norm(tip - contacts[name]))
                    held[name] = contacts[name] + (radius[name] - s.press) * normals[name]
                elif t_cmd >= float(f.length) and float((tip - pad_target(f)) @ u) >= float(f.length) - s.arrive_tol:
                    status[name], travel[name] = "missed", float(f.length)
                    held[name] = tip.copy()
                elif float(np.linalg.norm(tip - pad_target(f, min(t_cmd, float(f.length))))) > s.lag + s.step:
                    status[name], reason[name] = "unreachable", "the finger's joints carry it no further along its line"
                    held[name] = tip.copy()
        if t_cmd > max(float(f.length) for f in move.fingers) + 0.02:
            for f in names:  # the closing timed out
                if f not in status:
                    status[f], reason[f] = "timeout", "the finger did not reach its line's end"
                    held[f] = c.ex.robot.read().fingertip_in_world[c.index[f]].copy()
    closing = {f: c.trace(f, first_row[f]) for f in names}
    # 4. stroke: the touched fingers press in place, then an L each in its tangent plane, together
    touched = [f for f in move.fingers if status[f.finger] == "touched"]
    if touched:
        stroke_from = {f: len(c.rows[f]) for f in names}
        depth = {f.finger: s.press for f in touched}
        for _ in range(max(1, s.settle_ticks // s.stroke_ticks)):
            _pressing_step(c, touched, held, normals, contacts, radius, depth, {}, "settle")
        for f in touched:
            tr = c.trace(f.finger, stroke_from[f.finger])
            ok = tr.in_contact
            if ok.sum() < 3:
                status[f.finger], reason[f.finger] = "no-contact", "contact lost pressing"
                continue
            normals[f.finger] = unit(tr.normal_in_world[ok][-10:].mean(axis=0))
            contacts[f.finger] = tr.point_in_world[ok][-10:].mean(axis=0)
            radius[f.finger] = float(np.median(np.linalg.norm(tr.tip_in_world[ok] - tr.point_in_world[ok], axis=1)))
        stroking = [f for f in touched if status[f.finger] == "touched"]
        phi0 = {f.finger: ex.rng.uniform(0.0, 2.0 * math.pi) for f in stroking}
        for heading in range(s.stroke_headings):
            if not stroking:
                break
            if heading:  # back to where each pad touched, pressing, before the next heading
                targets = dict(held)
                for f in stroking:
                    n = normals[f.finger]
                    targets[f.finger] = contacts[f.finger] + (radius[f.finger] - s.stroke_press) * n
                c.hold(c.solve(targets))
                for _ in range(s.settle_ticks):
                    c.tick("settle")
            traces = _stroke(c, stroking, held, normals, contacts, radius,
                             {f: p + heading * math.pi / 2.0 for f, p in phi0.items()})  # fmt: skip
            left = []
            for f in stroking:
                tr = traces[f.finger]
                fit = ex.segmenter.fit_face_trace(tr, normals[f.finger], two_d=True) if ex.on_one_face(tr) else None
                if fit is None or ex.workspace.is_table(fit.normal, contacts[f.finger]):
                    left.append(f)
                    continue
                face = ex.segmenter.add_face(fit, ())
                ex.store_face(face.id, tr, fit)
                faces[f.finger] = face.id
                held[f.finger] = contacts[f.finger] + (radius[f.finger] - s.stroke_press) * normals[f.finger]
            stroking = left
        for f in stroking:
            status[f.finger], reason[f.finger] = "unreachable", "the stroke found no face (an edge or a vertex)"
    # 5. what each finger measured
    bound = ex.bounds.bound(ex.bounds.point_sigma, ex.bounds.position_floor)
    comps, free, fingers = [], [], []
    for f in move.fingers:
        name = f.finger
        u = np.asarray(f.direction, dtype=float)
        info: dict = {"finger": name, "status": status[name], "component": None, "travel": travel.get(name)}
        if status[name] in ("touched", "missed"):
            seg = _leading_segment(closing[name].tip_in_world, u, PAD_RADIUS,
                                   0.0 if status[name] == "missed" else 0.0015, bound)  # fmt: skip
            if seg is not None:
                free.append(seg)
        if status[name] == "touched":
            fid = faces[name]
            comps.append(ex.segmenter.faces[fid].component)
            info.update(component=fid, contact=travel[name], point=contacts[name].tolist())
        elif status[name] != "missed":
            info["reason"] = reason[name]
        fingers.append(info)
    # the exploring pad's way; a probe by another finger: that finger's, whose contacts are the move's
    pieces.append(PrimitiveResult("ok", "done", c.trace(names[0] if single else ex.toucher.finger), 0.0))
    c.own.add(id(pieces[-1]))
    if not comps and not any(i["status"] == "missed" for i in fingers):
        why = "; ".join(f"{i['finger']}: {i.get('reason', i['status'])}" for i in fingers)
        return MoveResult(move=move, status="unreachable", state=ex.state, reason=f"no finger measured: {why}",
                          info={"fingers": fingers})  # fmt: skip
    return MoveResult(move=move, status="ok", components=tuple(comps), state=ex.state,
                      free_space=tuple(free), info={"fingers": fingers})  # fmt: skip


def _above_then_down(c: _Closing, names: list[str], axes: dict[str, np.ndarray], starts: np.ndarray,
                     z_safe: float) -> str | None:
    """Every pad above its line's start (the finger pointing along it), then down to the start, along the
    solver's paths (the robot and table alone); why not, or None."""
    s = c.s
    lift = max(0.0, z_safe - float(starts[:, 2].min())) + s.above
    for what, pts in (("above the lines", starts + np.array([0.0, 0.0, lift])), ("to the lines' starts", starts)):
        targets = [FingertipTarget(f, p, axes[f]) for f, p in zip(names, pts, strict=True)]
        reach = c.solver.solve(targets, start=c.q_now())
        if not reach.ok:  # from the tracing posture, as the planner's test asks, then across to it in joint space
            home = c.solver.solve(targets)
            if home.ok:
                reach = replace(home, path=_joint_path(c.q_now(), home.qpos, s.reach.max_speed * s.reach.dt))
        if not reach.ok and what == "above the lines":
            continue  # (out of reach up there: straight to the starts, the way watched as every way is)
        if not reach.ok:
            return f"reaching {what}: {reach.reason} ({reach.detail})"
        why = c.follow(reach.path) or c.arrive(dict(zip(names, pts, strict=True)))
        if why:
            return f"on the way {what}: {why}"
    return None


def _home_then(c: _Closing, path: np.ndarray, pieces: list[PrimitiveResult]) -> str | None:
    """The pad up and over to where it is in the path's first configuration (the tracing posture), that posture
    taken in joint space, then the path followed; why it stopped, or None. The way up recovers as every rise does
    (:func:`~haptic.executor.physics_probe.rise`: a joint at its limit pulls the pad off its line below a tall
    object's top), and the way over, held back with nothing touching, goes by the arm's home posture above."""
    t = c.ex.toucher
    c.cfg.update(path[0])
    sid = mujoco.mj_name2id(c.model, mujoco.mjtObj.mjOBJ_SITE, c.solver.site_name(t.finger))
    above = c.cfg.data.site_xpos[sid].copy()
    top = max(float(t.tip[2]), float(above[2]))
    if top - float(t.tip[2]) >= t.config.target_tol:
        res = rise(t, top, 0.15, 0.012, pieces)
        if not res.ok or res.event != "done":
            return f"moving over to the tracing posture: {res.event}"
    if float(np.linalg.norm(above - t.tip)) >= t.config.target_tol:
        res = t.move_guarded(above, 0.15, max_lag=0.012)
        pieces.append(res)
        if res.event == "blocked" and t.link_touch() is None and t.back_to_home_posture(above, at=above):
            res = t.move_guarded(above, 0.15, max_lag=0.012)
            pieces.append(res)
        if not res.ok or res.event != "done":
            return f"moving over to the tracing posture: {res.event}"
    return c.follow(_joint_path(c.q_now(), path[0], c.s.reach.max_speed * c.s.reach.dt)) or c.follow(path)


def _stroke(c: _Closing, fingers: Sequence[FingerApproach], held: dict[str, np.ndarray],
            normals: dict[str, np.ndarray], contacts: dict[str, np.ndarray], radius: dict[str, float],
            heading: dict[str, float]) -> dict[str, ContactTrace]:  # fmt: skip
    """An L stroke of each of ``fingers`` together, from its contact in its tangent plane (the first leg at angle
    ``heading`` about its normal), pressing; the other fingers held at ``held``. Each finger's rows."""
    s = c.s
    legs: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for f in fingers:
        n = normals[f.finger]
        a = perpendicular(n)
        phi = heading[f.finger]
        d1 = math.cos(phi) * a + math.sin(phi) * np.cross(n, a)
        level = np.cross(np.array([0.0, 0.0, 1.0]), n)
        if s.level_stroke and float(level @ level) > LEVEL_STROKE:  # the face leans 60° from horizontal, at least
            d1 = unit(level) * (1.0 if math.cos(phi) >= 0.0 else -1.0)
            d2 = np.cross(n, d1)
            legs[f.finger] = (d1, d2 if d2[2] >= 0.0 else -d2)
        else:
            legs[f.finger] = (d1, np.cross(n, d1))
    first = {f.finger: len(c.rows[f.finger]) for f in fingers}
    depth = {f.finger: s.stroke_press for f in fingers}
    along = s.stroke
    across = s.stroke if s.stroke_across is None else s.stroke_across
    if s.stroke_overrun > 1.0:
        _stroke_travelled(c, fingers, held, normals, contacts, radius, depth, legs, (along, across))
        return {f.finger: c.trace(f.finger, first[f.finger]) for f in fingers}
    for leg, length in enumerate((along, across)):
        steps = max(1, int(round(length / s.stroke_step)))
        for k in range(1, steps + 1 + s.dwell_steps):
            k = min(k, steps)  # then dwell at the leg's end: the joints' servo trails its targets
            off = {}
            for f in fingers:
                d1, d2 = legs[f.finger]
                off[f.finger] = (k * s.stroke_step * d1) if leg == 0 else (along * d1 + k * s.stroke_step * d2)
            _pressing_step(c, fingers, held, normals, contacts, radius, depth, off, "stroke")
    return {f.finger: c.trace(f.finger, first[f.finger]) for f in fingers}


def _stroke_travelled(c: _Closing, fingers: Sequence[FingerApproach], held: dict[str, np.ndarray],
                      normals: dict[str, np.ndarray], contacts: dict[str, np.ndarray], radius: dict[str, float],
                      depth: dict[str, float], legs: dict[str, tuple[np.ndarray, np.ndarray]],
                      lengths: tuple[float, float]) -> None:  # fmt: skip
    """:func:`_stroke`'s legs as far as each pad travels: a finger's targets step on along its leg until its pad
    centre has moved the leg's length along it (or the targets ran :attr:`PlacementSettings.stroke_overrun` times
    it), then stay where the pad is; the next leg sets off from there."""
    s = c.s
    base = {f.finger: np.zeros(3) for f in fingers}
    for leg, length in enumerate(lengths):
        cap = max(1, int(round(s.stroke_overrun * length / s.stroke_step)))
        start = {f.finger: np.asarray(c.rows[f.finger][-1][1], dtype=float) for f in fingers}
        steps = {f.finger: 0 for f in fingers}
        stop: dict[str, np.ndarray | None] = {f.finger: None for f in fingers}
        dwell = 0
        while dwell <= s.dwell_steps:
            off = {}
            for f in fingers:
                name, d = f.finger, legs[f.finger][leg]
                if stop[name] is None:
                    moved = float((np.asarray(c.rows[name][-1][1], dtype=float) - start[name]) @ d)
                    if moved >= length or steps[name] >= cap:
                        stop[name] = base[name] + max(moved, 0.0) * d
                    else:
                        steps[name] += 1
                off[name] = stop[name] if stop[name] is not None else base[name] + steps[name] * s.stroke_step * d
            _pressing_step(c, fingers, held, normals, contacts, radius, depth, off, "stroke")
            if all(v is not None for v in stop.values()):
                dwell += 1
        base = {name: v for name, v in stop.items() if v is not None}


def _pressing_step(c: _Closing, fingers: Sequence[FingerApproach], held: dict[str, np.ndarray],
                   normals: dict[str, np.ndarray], contacts: dict[str, np.ndarray], radius: dict[str, float],
                   depth: dict[str, float], offsets: dict[str, np.ndarray], phase: str) -> None:  # fmt: skip
    """One step of ``fingers`` pressing on their faces: each pad's target its contact moved by its offset in the
    tangent plane, ``depth`` under the face; held for :attr:`PlacementSettings.stroke_ticks`; then each depth
    follows the force sensed (deeper when it falls short of the tracing force). The other fingers held at
    ``held``."""
    s = c.s
    targets = dict(held)
    for f in fingers:
        n = normals[f.finger]
        targets[f.finger] = contacts[f.finger] + offsets.get(f.finger, 0.0) + (radius[f.finger] - depth[f.finger]) * n
    c.hold(c.solve(targets))
    for _ in range(s.stroke_ticks):
        c.tick(phase)
    force = c.ex.toucher.config.force
    for f in fingers:
        sensed = float(np.mean([row[5] for row in c.rows[f.finger][-s.stroke_ticks:]]))
        depth[f.finger] = float(np.clip(depth[f.finger] + s.press_gain * (force - sensed), 0.0, s.max_press))


def _restore(ex: PhysicsExecutor, c: _Closing, move: PlacementMove, z_safe: float,
             pieces: list[PrimitiveResult], to_start: bool = False) -> None:  # fmt: skip
    """The fingers back along their lines (by :attr:`PlacementSettings.lift`, or ``to_start``: to their pads'
    places at the lines' starts, the way they came), the hand up to ``z_safe`` and back to the tracing posture."""
    s, t = c.s, ex.toucher
    c.back_from = {f: len(c.rows[f]) for f in c.rows}
    c.pieces_at_back = len(pieces)
    r = ex.robot.read()
    names = [f.finger for f in move.fingers]
    back = {f.finger: r.fingertip_in_world[c.index[f.finger]] - s.lift * np.asarray(f.direction) for f in move.fingers}
    if to_start:  # along the line in steps, as it closed, so that the pad keeps to the way it came
        now = {f.finger: r.fingertip_in_world[c.index[f.finger]].copy() for f in move.fingers}
        back = {f.finger: pad_target(f) for f in move.fingers}
        steps = max(1, int(np.ceil(max(np.linalg.norm(back[f] - now[f]) for f in names) / (3.0 * s.step))))
        for k in range(1, steps):
            c.hold(c.solve({f: now[f] + (back[f] - now[f]) * k / steps for f in names}))
            for _ in range(s.step_ticks):
                c.tick("free")
    c.hold(c.solve(back))
    for _ in range(s.settle_ticks):
        c.tick("free")
    r = ex.robot.read()
    rise = max(0.0, z_safe - float(min(r.fingertip_in_world[c.index[f]][2] for f in names)))
    up = {f: r.fingertip_in_world[c.index[f]] + np.array([0.0, 0.0, rise]) for f in names}
    for _ in range(3):
        c.hold(c.solve(up))
        for _ in range(s.settle_ticks):
            c.tick("free")
    r = ex.robot.read()
    ex.robot.hold_posture(r.arm_q, HAND_TRACE)
    for _ in range(2 * s.settle_ticks):
        t.tick("free")
    t.hand_rotation = np.array(t.config.hand_rotation, dtype=float)
    pieces.append(t.move_free(t.tip.copy(), timeout=t.config.via_timeout, tol=t.config.via_tol))
    t.take_trace()


# -- the planner's test of reach -------------------------------------------------------------------------------
class PlacementReach:
    """Whether the hand can take a placement up, asked by the planner before it offers one: the reach solver with
    the hypothesised model at its hypothesised pose in the scene (never the true pose), each finger's pad at its
    line's start pointing along the line, from the tracing posture. Tries the placement's own fingers, then other
    fingers for its lines (at most :attr:`assignments` in all); the placement with the fingers that reach, the
    path and the ways the pads go along it (``PlacementMove.travel``, ``home``: the planner's cost of it), or None.
    Called with the planner's hypotheses (the most likely first)."""

    def __init__(self, settings: ReachSettings | None = None, assignments: int = 12, cache: int = 4,
                 explorer: str = "index") -> None:
        self.settings = settings or REACH_CLEARANCE
        self.explorer = explorer
        """The exploring finger, whose pad goes to the path's start before the hand follows it."""
        self.assignments = assignments
        self.cache = cache
        self._solvers: dict[tuple, ReachSolver] = {}
        self._answers: dict[tuple, PlacementMove | None] = {}
        self.asked = 0
        """Placements asked about."""
        self.reached = 0
        """... of them reached."""
        self.reasons: dict[str, int] = {}
        """Why the others were not, by the solver's reason (the last assignment's)."""

    def __call__(self, move: PlacementMove, hypotheses: Sequence, own_only: bool = False) -> PlacementMove | None:
        """The placement with the fingers that reach and their path, or None (``own_only``: its own fingers
        alone, no other assignment tried)."""
        h = hypotheses[0]
        key = (h.model, *np.round(h.world_from_model.as_matrix()[:3].ravel(), 3), own_only,
               *(tuple(np.round(np.concatenate([f.start, f.direction]), 4)) for f in move.fingers))
        key = (*key, *(f.finger for f in move.fingers))
        if key in self._answers:
            return self._answers[key]
        solver = self._solver(h)
        self.asked += 1
        answer, why = None, ""
        lines = list(move.fingers)
        tried = 0
        own = tuple(f.finger for f in lines)
        for names in [own] if own_only else _assignments(own):
            if tried >= self.assignments:
                break
            tried += 1
            targets = [FingertipTarget(n, pad_target(f), np.asarray(f.direction, dtype=float))
                       for n, f in zip(names, lines, strict=True)]  # fmt: skip
            r = solver.solve(targets)
            if r.ok:
                travel, home = _path_ways(solver, r.path, names, self.explorer)
                answer = PlacementMove(tuple(replace(f, finger=n) for n, f in zip(names, lines, strict=True)),
                                       path=r.path, travel=travel, home=home)  # fmt: skip
                break
            why = str(r.reason)
        if answer is None:
            self.reasons[why] = self.reasons.get(why, 0) + 1
        else:
            self.reached += 1
        self._answers[key] = answer
        return answer

    def _solver(self, h) -> ReachSolver:
        """A solver with ``h``'s model in its scene, moved to ``h``'s pose (one compiled scene per model: the
        object's body is fixed to the world, so its pose is the model's to set)."""
        from haptic.sim import compose_scene
        from haptic.sim.scene import scene_object_from_polyhedron

        if h.model not in self._solvers:
            if len(self._solvers) >= self.cache:
                self._solvers.pop(next(iter(self._solvers)))
            obj = scene_object_from_polyhedron(h.poly)
            self._solvers[h.model] = ReachSolver(compose_scene(obj, np.eye(4)), self.settings)
        solver = self._solvers[h.model]
        m = solver.model
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "object")
        pose = h.world_from_model.as_matrix()
        m.body_pos[body] = pose[:3, 3]
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, np.ascontiguousarray(pose[:3, :3]).reshape(-1))
        m.body_quat[body] = quat
        return solver


def _path_ways(solver: ReachSolver, path: np.ndarray, fingers: Sequence[str],
               explorer: str) -> tuple[float, np.ndarray]:  # fmt: skip
    """The farthest way of the ``fingers``' pads along the joint ``path`` (each pad centre's polyline through its
    configurations) [m], and the ``explorer``'s pad centre at its start."""
    d = solver.configuration.data
    sites = {f: mujoco.mj_name2id(solver.model, mujoco.mjtObj.mjOBJ_SITE, solver.site_name(f))
             for f in {*fingers, explorer}}  # fmt: skip
    pads = []
    for q in path:
        solver.configuration.update(q)
        pads.append({f: d.site_xpos[k].copy() for f, k in sites.items()})
    travel = max(sum(float(np.linalg.norm(b[f] - a[f])) for a, b in zip(pads, pads[1:], strict=False)) for f in fingers)
    return travel, pads[0][explorer]


def _assignments(own: tuple[str, ...]):
    """The placement's own fingers first, then the others' assignments of fingers to its lines."""
    yield own
    for names in permutations(FINGERS, len(own)):
        if names != own:
            yield names


FINGER_PROBE_REACH = ReachSettings(clearance=0.008, pads_touch=False, tip_table_clearance=TIP_TABLE_CLEARANCE,
                                   hold_clearance=0.004)  # fmt: skip
"""The planner's reach test of a probe by one finger (:func:`finger_probe`): every link 8 mm from the hypothesised
object and the table, the path held to at least 4 mm (a placement's 20 mm leave no finger a way under a 20 mm
overhang: BOX01P, seed 1, the side under its step, which the thumb turned along the line touches with 8 mm)."""


PROBE_TILTS = tuple(math.radians(a) for a in (60.0, 55.0, 50.0, 45.0, 40.0, 35.0, 30.0))
"""Where no finger reaches a probe's line pointing along it, the finger's axis turned from straight down toward the
line's level direction by these angles, in turn, the most first (:func:`finger_probe`): a face leaning under is pressed
level with the finger tilted (trapezohedron_05 of the formula corpus, seed 1, a face leaning under 35.5°: the index
pointing down met it with its medial link, tilted 60° it measured the face within 0.2°). The solver's path to a
line's start may stop short at one tilt and not at the next (antiprism_08 of the formula corpus, seed 1, a face leaning
under 45°: the index reaches the start tilted 55° and 40°, not 60°, 50° or 45°), hence the 5° steps."""


TOUCH_CLEARANCE = 0.003
"""Least distance of the probing finger's links (its pad aside) from the hypothesised object where its pad touches
the face, pointing as it came (:func:`finger_probe`) [m]. The reach test keeps every link 8 mm clear at the line's
start, 30 mm before the touch; a finger tilted less than its face leans under touches it with the back of its pad, the
distal link close above: antiprism_08 of the formula corpus, seed 1, the index tilted 30° toward a face leaning under
45°, its distal link 0.06 mm from the face above at the touch, met that face pressing and stroking (the pad sensed
0.1-0.4 N against the 1 N asked, its stroke spanned 6.5 × 1.4 mm, the probe measured nothing); tilted 55° the link
is 4.9 mm clear. Measured (the formula corpus's twelve episodes that probe, seed 1): 1 mm measures every probe as 3 mm
does (19 of 19, hull_02 along other lines); 6 mm leaves faces no finger reaches and picks postures that fail:
probes 15 of 17, antiprism_05 no longer confirmed."""

TOUCH_REACH = ReachSettings(clearance=0.0, pads_touch=True, tip_table_clearance=0.0)
"""The reach test of a probe's touch (:func:`finger_probe`): the probing pad on the hypothesised object, the finger
pointing as it came, every other link kept out of the object and the table but not held off them, as the closing
does not hold them (its configurations the solver's for the pad's target alone, near the posture it arrived in); their
clearance there is then weighed against :data:`TOUCH_CLEARANCE`. Held off by the solver (its ``clearance`` 3 mm), the
hand turned about the finger to keep the link clear, and the index tilted 30° passed where the closing leaves its
link 0.06 mm from the face above."""

TOUCH_STEP = 2.5e-4
"""The pad's way along a probe's line is swept in steps of this for where it touches the hypothesised object [m]."""


def touch_point(move: ProbeMove, h) -> np.ndarray | None:
    """Where the pad centre is when the pad, following ``move``'s line, first touches hypothesis ``h``'s model at its
    pose (the line's leading point at the start, as :func:`pad_target` puts it), or None when it meets nothing."""
    if h.world_from_model is None:
        return None
    u = np.asarray(move.direction, dtype=float)
    t = np.arange(0.0, float(move.length) + TOUCH_STEP, TOUCH_STEP)
    centres = np.asarray(move.start, dtype=float) + (t - PAD_RADIUS)[:, None] * u
    near = surface_distance(h.poly, h.model_from_world.apply(centres)) <= PAD_RADIUS
    return centres[int(np.argmax(near))] if near.any() else None


def _clear_at_touch(touch: PlacementReach, h, name: str, point: np.ndarray | None, axis: np.ndarray,
                    path: np.ndarray) -> bool:  # fmt: skip
    """Whether finger ``name``, its pad brought from the end of ``path`` to its touch ``point`` pointing along
    ``axis``, keeps its other links :data:`TOUCH_CLEARANCE` clear of hypothesis ``h``'s model (True where the line
    meets nothing)."""
    if point is None:
        return True
    solver = touch._solver(h)
    r = solver.solve([FingertipTarget(name, point, unit(axis))], start=np.asarray(path)[-1])
    return r.ok and solver.object_clearance(r.qpos, [name]) >= TOUCH_CLEARANCE


def finger_probe(move: ProbeMove, hypotheses: Sequence, reach: PlacementReach | None = None,
                 fingers: Sequence[str] = FINGERS, tilts: Sequence[float] = PROBE_TILTS,
                 touch: PlacementReach | None = None) -> ProbeMove | None:  # fmt: skip
    """Probe ``move`` carried out by the first of ``fingers`` whose pad the hand can put at the line's start pointing
    along the line, clear of the most likely of ``hypotheses`` (its model at its pose; the planner's reach test of
    placements, ``reach``, asked for a placement of that one finger); failing that, the first with its axis turned
    from straight down toward the line by one of ``tilts`` [rad] (a line with a level part). A finger counts only if,
    pointing so, it can also follow the line to where its pad touches the model with its other links clear of it
    (``touch``, :data:`TOUCH_REACH`). The move with that finger and the path, or None when no finger reaches. The
    finger and the wrist's turn are the reach solver's choice, the hand's way with them the path the executor follows
    (:func:`finger_probe_move`)."""
    reach = reach if reach is not None else PlacementReach(FINGER_PROBE_REACH)
    touch = touch if touch is not None else PlacementReach(TOUCH_REACH)
    h = hypotheses[0]
    line = (np.asarray(move.start, dtype=float), np.asarray(move.direction, dtype=float), float(move.length))
    point = touch_point(move, h)
    for name in fingers:
        got = reach(PlacementMove((FingerApproach(name, *line),)), hypotheses, own_only=True)
        if got is not None and _clear_at_touch(touch, h, got.fingers[0].finger, point, line[1], got.path):
            return replace(move, finger=got.fingers[0].finger, path=got.path)
    level = line[1] * np.array([1.0, 1.0, 0.0])
    if not tilts or float(np.linalg.norm(level)) < 0.1:
        return None
    level = unit(level)
    solver = reach._solver(h)
    for tilt in tilts:
        axis = math.cos(tilt) * np.array([0.0, 0.0, -1.0]) + math.sin(tilt) * level
        for name in fingers:
            r = solver.solve([FingertipTarget(name, pad_target(FingerApproach(name, *line)), axis)])
            if r.ok and _clear_at_touch(touch, h, name, point, axis, r.path):
                return replace(move, finger=name, path=r.path)
    return None


def finger_reach(fingers: Sequence[str] = FINGERS, tilts: Sequence[float] = PROBE_TILTS) -> Callable:
    """The planner's reach test of a probe by any finger (``PlannerConfig.finger_reach``): :func:`finger_probe` with
    one reach test of the lines' starts (:data:`FINGER_PROBE_REACH`) and one of the touches (:data:`TOUCH_REACH`), their
    compiled scenes kept, for the episode; asked to ``avoid`` some fingers, by the others alone (None when none is
    left)."""
    reach, touch = PlacementReach(FINGER_PROBE_REACH), PlacementReach(TOUCH_REACH)

    def test(move: ProbeMove, hypotheses: Sequence, avoid: Sequence[str] = ()) -> ProbeMove | None:
        others = [f for f in fingers if f not in avoid]
        return finger_probe(move, hypotheses, reach, others, tilts, touch) if others else None

    return test


def reach_oracle(fingers: int) -> Callable | None:
    """The planner's placement reach test for an episode of ``fingers`` fingers at once (None for one)."""
    return PlacementReach() if fingers > 1 else None


__all__ = ["FINGER_PROBE_REACH", "HOLD_CLEARANCE", "PROBE_SETTINGS", "PROBE_TILTS", "REACH_CLEARANCE", "SETTINGS",
           "TIP_TABLE_CLEARANCE", "TOUCH_CLEARANCE", "TOUCH_REACH", "PlacementReach", "PlacementSettings",
           "finger_probe", "finger_probe_move", "finger_reach", "hand_solver", "pad_target", "placement_move",
           "reach_oracle"]
