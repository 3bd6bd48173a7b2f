"""Force-controlled exploration primitives on the simulated hand (seed §3.1).

Each primitive is a small state machine run one control tick at a time through a
:class:`~haptic.sim.robot.RobotInterface` -- the only handle it has: commands to the controller, the joint
encoders' forward kinematics, and the fingertip's sensed contact (force, normal, point, noise applied). It
ends with an *event* (why it stopped: ``"contact"``, ``"convex-edge"``, ``"concave-edge"``, ``"vertex"``,
``"done"``; ``"table"`` when a slide would take the pad onto the table) or a failure status
(``"no-contact"``, ``"unreachable"``, ``"timeout"``, ``"unstable"``), and returns the contact trace it
recorded (time, fingertip pose, contact point, normal, force, phase) and the distance the fingertip travelled.

Every number of the primitives is a field of :class:`TouchConfig` (motion, forces, timing, event detection)
or, where the segmenter shares it (the sensor's σ, the cones of a face's normals), of
:class:`~haptic.executor.segment.SegmentBounds`.

Detection follows ``docs/physics-notes.md``: contact when the sensed force exceeds max(0.1 F, 5 σF) for 3 samples
with a valid normal (pitfall 5); an edge when the filtered normal leaves the running face normal by more
than 10° for 3 samples (convex when it tilts towards the direction of travel -- the surface falls away --,
concave when it tilts against it -- the finger is blocked) or, as a backup, when the force stays below
0.3 F for 20 ms (the surface fell away) or progress stalls (blocked); a vertex while following an edge when
the filtered normal gains a component along the edge above sin 15°, or contact is lost once the normal leaned
along the edge (pitfall 8; lost before, the pad was lifted off the edge, and the move fails). Contact lost on a face,
in a roll or round a vertex while a link of the hand other than the pad touches the object is event ``"hand"``
(``unreachable``): that link lifted the pad off, and no edge is there.
Ridge following presses along the sensed normal and servos sideways to keep it on the bisector of the two
face normals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from haptic.executor.segment import SegmentBounds
from haptic.executor.touch_config import TouchConfig
from haptic.geometry.se3 import angle, cross, finite3, perpendicular, unit
from haptic.matching.batch_poses import exp_so3
from haptic.matching.trace import PHASES, ContactTrace, empty_trace
from haptic.sim.robot import RobotInterface
from haptic.sim.scene import PAD_RADIUS

SERVO_LAG = 0.13
"""The position servo trails a moving command by about this much time [s] (measured: 15 mm at 0.15 m/s)."""
OPPOSED = 1e-6
"""Two unit normals whose sum is shorter than this (squared) are opposed: they have no bisector [-]."""
AT_CENTRE = 1e-6
"""A contact this close to the vertex circle's centre has no radial direction [m]."""
STOPS = ("table", "hand")
"""Events that end a leg of a stroke without failing the stroke (the table ahead, a finger link on the object)."""
FAILURES = ("no-contact", "unreachable", "timeout", "unstable")
"""Failure statuses of a primitive (the move statuses of :class:`~haptic.planning.moves.MoveResult`)."""
_FREE = PHASES.index("free")
_NAN3 = (math.nan, math.nan, math.nan)
"""A trace row's point and normal without a valid contact."""


def _filtered(normal: np.ndarray, sample: np.ndarray, weight: float) -> np.ndarray:
    """``unit(normal + weight * (sample - normal))``, the low-pass of a unit normal, element by element on floats
    (the vector form's arithmetic without numpy's per-call overhead; the norm's dot product by numpy)."""
    a0, a1, a2 = normal.tolist()
    b0, b1, b2 = sample.tolist()
    f0, f1, f2 = a0 + weight * (b0 - a0), a1 + weight * (b1 - a1), a2 + weight * (b2 - a2)
    v = np.array([f0, f1, f2])
    n = math.sqrt(float(v.dot(v)))
    return np.array([f0 / n, f1 / n, f2 / n]) if n > 0 else v  # unit(v), element by element


def roll_settled(hist: list[tuple[float, np.ndarray]], travelled: float, normal: np.ndarray, window: float,
                 settled: float) -> bool:  # fmt: skip
    """Whether a roll is over: the filtered ``normal`` turned less than ``settled`` [rad] from the last one of ``hist``
    (the roll's (travel, filtered normal) so far) at least ``window`` [m] of travel before ``travelled``
    (:meth:`~haptic.executor.touch_config.TouchConfig.roll_settle_window`)."""
    for s, nn in reversed(hist):
        if s <= travelled - window:
            return angle(nn, normal) < settled
    return False


ROLL_ON_FACE = 0.004
"""A roll over a convex edge whose sensed normal has not yet turned past the edge angle from the face it left after
this much travel [m] slides on that face (event ``"face"``): the slide's contact weakened with no edge there, or was
lost at an edge's end before the normal turned, and the roll, heading back against the travel, came onto the face
again."""


def _wrist_watch() -> dict:
    """The counts of :meth:`Toucher.take_wrist` before any watch."""
    return {"watched": 0, "links": 0, "links_felt": 0, "unexplained": 0, "free_max": 0.0}


@dataclass(frozen=True, eq=False)
class PrimitiveResult:
    """How a primitive ended, what it recorded and how far it went."""

    status: str
    """``"ok"`` or a failure in :data:`FAILURES`."""
    event: str
    """Why it stopped: ``"contact"``, ``"convex-edge"``, ``"concave-edge"``, ``"vertex"``, ``"done"``,
    ``"blocked"``, ``"lost"``, ``"limit"`` (a failure's detail)."""
    trace: ContactTrace
    """The samples recorded."""
    distance: float
    """Path length of the pad centre [m]."""
    info: dict = field(default_factory=dict)
    """Primitive-specific results (estimated normals, directions)."""

    @property
    def ok(self) -> bool:
        return self.status == "ok"


@dataclass(frozen=True)
class HandContact:
    """A contact of a link of the hand other than the exploring pad (another finger, a phalanx, the palm) with the
    object, as the link's contact readout senses it (world frame)."""

    time: float
    """Simulation time [s]."""
    link: str
    """The link's name."""
    point_in_world: np.ndarray
    """Contact point (3,) [m]."""
    normal_in_world: np.ndarray
    """Unit normal (3,) out of the touched surface, towards the link."""
    normal_force: float
    """Force along the normal [N]."""


class Toucher:
    """Runs the primitives with one finger of the robot and records everything it senses.

    The toucher keeps the filtered normal, the contact debouncer and the path length across primitives; each
    primitive returns the trace rows it recorded. ``bounds``: the sensor's σ and the cones of a face's normals
    it shares with the segmenter.
    """

    def __init__(self, robot: RobotInterface, config: TouchConfig | None = None, finger: str = "index",
                 bounds: SegmentBounds | None = None) -> None:  # fmt: skip
        if not isinstance(robot, RobotInterface):
            raise TypeError(f"Toucher needs a RobotInterface (the robot-side handle), got {type(robot).__name__}")
        self.robot = robot
        self.config = config or TouchConfig()
        self.bounds = bounds or SegmentBounds()
        self.finger = finger
        robot.set_finger(finger)
        self.dt = robot.tick_period
        self.threshold = self.config.contact_threshold(self.bounds.force_sigma)
        self.normal: np.ndarray | None = None  # filtered sensed normal
        self.contact_ticks = 0  # consecutive valid-contact samples
        self.weak_ticks = 0  # consecutive samples with force below loss_fraction × force
        self.hybrid = False
        self.pad_radius = PAD_RADIUS  # refined from the sensed contact (|tip − contact point|)
        self.pad_model_radius = PAD_RADIUS  # the pad's radius in the hand's model (what a contact on one patch reads)
        self._rows: list[tuple] = []
        self._ticks = 0
        self._links: list[tuple[float, np.ndarray]] = []  # (time, link positions) samples
        self._hand: list[HandContact] = []  # the links' contacts with the object watched since the last take
        self._wrist = _wrist_watch()  # the wrist's force watched since the last take
        tip, rot = robot.fingertip_pose()
        self.tip = tip
        self.rotation = rot
        self.hand_rotation = np.array(self.config.hand_rotation, dtype=float)
        """The hand's rotation ``world_from_hand`` every command holds (3, 3): the config's tracing posture, or
        that posture tilted away from where a finger link met the object (:meth:`tilt_away`)."""
        self.home_q = robot.arm_posture()
        """The arm's joint angles when the toucher was made (its posture family: a free move that ran away is
        brought back to it)."""
        self.contact: tuple[float, np.ndarray | None, np.ndarray | None] = (0.0, None, None)
        self._unhealthy = False
        self.floor_z: float | None = None
        """Lowest height [m] the pad's lowest point may reach while sliding (the table top plus a margin, a
        workspace prior set by the executor); a slide heading down stops there with event ``"table"``. None:
        no floor."""
        self.top_z: float | None = None
        """Height [m] of the highest point the pad has touched (None before any touch): a reposition held on its
        way round over the top lower than the pad resting on it, a link of the hand on the object above the height
        the way was to cross at, goes round clear of it (:meth:`_held_over_the_top`)."""

    # -- the tick ---------------------------------------------------------------------------------------------
    def tick(self, phase: str) -> None:
        """Advance one control tick, sense, record a row."""
        r, cfg = self.robot, self.config
        r.step(1)
        f, n, p, _ = r.last_contact_values() if self.hybrid else r.sense_contact_values(self.finger)
        tip, rot = r.fingertip_pose()
        self.tip, self.rotation = tip, rot
        valid = n is not None and f > self.threshold and finite3(n)
        if valid:
            self.contact_ticks += 1
            if self.normal is None or self.contact_ticks == 1:
                self.normal = n.copy()
            else:
                self.normal = _filtered(self.normal, n, cfg.normal_filter)
            off = tip - p
            d = math.sqrt(float(off.dot(off)))
            lo, hi = cfg.pad_radius_range
            if lo < d < hi:
                self.pad_radius += cfg.pad_radius_gain * (d - self.pad_radius)
            z = float(p[2])
            self.top_z = z if self.top_z is None else max(self.top_z, z)
            self.contact = (f, n, p)
        else:
            self.contact_ticks = 0
            self.contact = (f, None, None)
        self.weak_ticks = self.weak_ticks + 1 if f < cfg.loss_fraction * cfg.force else 0
        rows = self._rows
        rows.append((r.time, tip, rot, p if valid else _NAN3, n if valid else _NAN3, f, PHASES.index(phase)))
        if not (finite3(tip) and math.isfinite(f)):
            self._unhealthy = True
        elif len(rows) % cfg.stability_every == 0 and not r.is_stable():
            self._unhealthy = True
        self._ticks += 1
        every = cfg.link_every
        if every > 0 and self._ticks % every == 0:
            self._links.append((r.time, r.link_poses()))
        watch = cfg.watch_every
        if watch > 0 and self._ticks % watch == 0:
            self._watch_links()

    def _watch_links(self) -> None:
        """Book the links' contacts with anything but the table (:meth:`on_table`) above the contact threshold, and
        compare the wrist's force with what the pad and the links report (:meth:`_watch_wrist`)."""
        touching = False
        for c in self.robot.watch_links():
            if c.normal_force <= self.threshold:
                continue
            touching = True
            if not self.on_table(c):
                self._hand.append(HandContact(self.robot.time, c.link, c.point_in_world, c.normal_in_world,
                                              c.normal_force))  # fmt: skip
        if self.config.wrist_force > 0:
            self._watch_wrist(touching)

    def _watch_wrist(self, link_touching: bool) -> None:
        """With the pad free and the hand under force control (not carried between moves), the wrist's force off
        what the hand's weight and motion read (:meth:`~haptic.sim.robot.RobotInterface.hand_inertia_force`) by more
        than :attr:`~TouchConfig.wrist_force` is a contact of the hand: counted as one a link reports
        (``links_felt`` of ``links``) or as one nothing else reports (``unexplained``). The largest force off that
        reading with nothing touching is kept (``free_max``), which tells how far the threshold stands from the
        hand's own motion."""
        if self.contact[1] is not None or not self._rows or self._rows[-1][-1] == _FREE:
            return
        force, _ = self.robot.watch_wrist()
        off = float(np.linalg.norm(force - self.robot.hand_inertia_force()))
        felt = off > self.config.wrist_force
        w = self._wrist
        w["watched"] += 1
        if link_touching:
            w["links"] += 1
            w["links_felt"] += int(felt)
        else:
            w["unexplained"] += int(felt)
            w["free_max"] = max(w["free_max"], round(off, 3))

    def take_wrist(self) -> dict:
        """The wrist's watch since the last call (:meth:`_watch_wrist`): ticks ``watched`` with the pad free, of them
        those with a link's contact (``links``) and those the wrist felt (``links_felt``), ticks with a force
        nothing else reports (``unexplained``) and the largest force off the hand's weight and motion with nothing
        touching (``free_max``) [N]."""
        out, self._wrist = self._wrist, _wrist_watch()
        return out

    def take_hand(self) -> list[HandContact]:
        """The links' contacts with the object watched since the last call, in order."""
        out, self._hand = self._hand, []
        return out

    def on_table(self, c) -> bool:
        """Whether a link's contact ``c`` is with the table top: below :attr:`floor_z` with an upward normal."""
        return float(c.normal_in_world[2]) > self.config.table_link_cos and (
            self.floor_z is None or float(c.point_in_world[2]) < self.floor_z
        )

    def sample_links(self) -> None:
        """Sample the hand's link poses now (once per simulation time)."""
        t = self.robot.time
        if not self._links or self._links[-1][0] != t:
            self._links.append((t, self.robot.link_poses()))

    def take_links(self) -> tuple[np.ndarray, np.ndarray]:
        """The link samples since the last call: times (n,) [s] and poses (n, len(robot.link_names), 7),
        position [m] then quaternion (w, x, y, z), world frame."""
        samples, self._links = self._links, []
        if not samples:
            return np.zeros(0), np.zeros((0, len(self.robot.link_names), 7))
        t, p = zip(*samples, strict=True)
        return np.array(t), np.stack(p)

    @property
    def touching(self) -> bool:
        """Debounced contact with a valid normal."""
        return self.contact_ticks >= self.config.debounce

    @property
    def unhealthy(self) -> bool:
        return self._unhealthy

    def take_trace(self) -> ContactTrace:
        """The rows recorded since the last call."""
        rows, self._rows = self._rows, []
        if not rows:
            return empty_trace()
        t, tip, rot, p, n, f, ph = zip(*rows, strict=True)
        return ContactTrace(np.array(t), np.array(tip), np.array(rot), np.array(p, dtype=float),
                            np.array(n, dtype=float), np.array(f), np.array(ph, dtype=int))  # fmt: skip

    def _result(self, status: str, event: str, start_distance: float, **info) -> PrimitiveResult:
        trace = self.take_trace()
        return PrimitiveResult(status, event, trace, _path_length(trace.tip_in_world, start_distance), info)

    def _press(self, velocity: np.ndarray, hint: np.ndarray | None = None) -> None:
        cfg = self.config
        self.robot.set_hybrid(cfg.force, velocity, normal_hint=hint, rotation_in_world=self.hand_rotation)
        self.hybrid = True

    def _settle(self, phase: str = "settle") -> str | None:
        """Press in place until the force has stayed within the band for ``settle_time`` (at most
        ``settle_max``). None when settled; ``"nan"`` when the simulation became unhealthy, ``"runaway"`` when
        the pad ran off (:meth:`_ran_away`)."""
        cfg = self.config
        need = max(1, int(cfg.settle_time / self.dt))
        good = 0
        start = self.tip.copy()
        for _ in range(max(need, int(cfg.settle_max / self.dt))):
            self.tick(phase)
            if self._unhealthy:
                return "nan"
            if self._ran_away(start):
                return "runaway"
            good = good + 1 if abs(self.contact[0] - cfg.force) < cfg.settle_band * cfg.force else 0
            if good >= need:
                break
        return None

    def _ran_away(self, start: np.ndarray, along: np.ndarray | None = None) -> bool:
        """Whether the pad, pressing in place from ``start`` (or moving from it along the unit ``along``), has
        left that point (that line) by more than :attr:`TouchConfig.runaway`: the force controller pushing into
        a contact it lost, or the arm jammed against the object and thrown off; the pad is then stopped and held
        where it is by the joints."""
        off = self.tip - start
        if along is not None:
            off = off - float(off.dot(along)) * along
        if float(off.dot(off)) <= self.config.runaway**2:
            return False
        self.hybrid = False
        self.robot.hold_posture()
        self.tick("free")
        return True

    def link_touch(self):
        """The strongest sensed contact of a link of the hand other than the pads (a phalanx, the palm) with
        anything but the table top (a contact below :attr:`floor_z` with an upward normal), from the links'
        contact readout; None when there is none."""
        best = None
        for c in self.robot.link_contacts():
            if self.on_table(c) or c.normal_force <= self.threshold:
                continue
            if best is None or c.normal_force > best.normal_force:
                best = c
        return best

    def _lost(self, status: str, event: str, met=None, **info) -> PrimitiveResult:
        """Contact lost: event ``"hand"`` (``unreachable``; ``info``: ``link``, its contact's ``link_normal``) when
        a link of the hand meets the object now, or met it (``met``, the link's contact) when the contact was lost
        -- it lifted the pad off, and no edge is there --, else ``event``."""
        link = self.link_touch() or met
        if link is not None:
            return self._result("unreachable", "hand", 0.0, link=link.link, link_normal=link.normal_in_world.copy())
        return self._result(status, event, 0.0, **info)

    def tilted(self, away: np.ndarray, angle_: float) -> np.ndarray | None:
        """The hand's rotation tilted by ``angle_`` [rad] so that the finger's axis, pointing up from the pad,
        leans toward the horizontal part of ``away`` (the sensed normal of a link's contact: out of the object
        toward the link) -- the finger's links clear the object there; None when ``away`` is near vertical. The
        tilt is from the config's tracing posture (tilts do not add up)."""
        upright = np.asarray(self.config.hand_rotation, dtype=float)
        back = -(upright @ np.array([0.0, 0.0, 1.0]))
        m = np.asarray(away, dtype=float) - float(np.asarray(away, dtype=float) @ back) * back
        if float(m @ m) < self.config.tilt_min_sin**2:
            return None
        return exp_so3(angle_ * unit(cross(back, m))) @ upright

    def reaches(self, normal: np.ndarray, rotation: np.ndarray | None = None) -> bool:
        """Whether the pad can touch a face of ``normal`` with the hand at ``rotation`` (default: as held): the
        face leans back against the finger's axis at most :attr:`TouchConfig.max_undercut`."""
        rot = self.hand_rotation if rotation is None else rotation
        back = -(rot @ np.array([0.0, 0.0, 1.0]))
        return float(np.asarray(normal, dtype=float) @ back) >= -math.sin(self.config.max_undercut)

    def below_floor(self, heading: np.ndarray | None = None) -> bool:
        """The pad's lowest point is below :attr:`floor_z` (and ``heading``, when given, points down)."""
        if self.floor_z is None or (heading is not None and float(heading[2]) >= 0.0):
            return False
        return float(self.tip[2]) - self.pad_radius < self.floor_z

    def ramp(self, k: int) -> float:
        """Speed factor (0, 1] of tick ``k`` of a slide."""
        return min(1.0, (k + 1) * self.dt / self.config.ramp_time)

    # -- free space ----------------------------------------------------------------------------------------------
    def move_free(self, point: np.ndarray, timeout: float | None = None, tol: float | None = None,
                  retry: bool = True) -> PrimitiveResult:  # fmt: skip
        """Move the pad centre to ``point`` [m] in free space along a straight line (position control), within
        ``timeout`` [s] (default ``free_timeout``) to within ``tol`` [m] (default ``free_tol``). A move that runs
        away from its line (:attr:`TouchConfig.runaway`) is stopped; with ``retry`` the arm goes back to its
        home posture family above (:meth:`back_to_home_posture`) and the move is made once more from there."""
        cfg = self.config
        timeout = cfg.free_timeout if timeout is None else timeout
        tol = cfg.free_tol if tol is None else tol
        start = self.tip.copy()
        self.hybrid = False
        self.normal = None
        if not self.robot.reachable(self.finger, point, self.hand_rotation).reachable:
            return self._result("unreachable", "limit", 0.0, target=point)
        dist = float(np.linalg.norm(point - start))
        n_ticks = max(1, int(dist / cfg.free_speed / self.dt))
        path = point - start
        length2 = float(path @ path)
        for k in range(1, int(timeout / self.dt)):
            s = min(1.0, k / n_ticks)
            self.robot.move_fingertip(start + s * (point - start), self.hand_rotation)
            self.tick("free")
            if self._unhealthy:
                return self._result("unstable", "nan", 0.0)
            if s >= 1.0 and np.linalg.norm(self.tip - point) < tol:
                return self._result("ok", "done", 0.0)
            along = min(max(float((self.tip - start).dot(path)) / length2, 0.0), 1.0) if length2 > 0 else 0.0
            if float(np.linalg.norm(self.tip - start - along * path)) > cfg.runaway:
                self.robot.hold_posture()
                self.tick("free")
                if retry and self.back_to_home_posture(point):
                    return self.move_free(point, timeout, tol, retry=False)
                return self._result("unreachable", "runaway", 0.0, target=point)
        return self._result("timeout", "limit", 0.0)

    def back_to_home_posture(self, point: np.ndarray, at: np.ndarray | None = None) -> bool:
        """After a free move ran away: move the arm in joint space to the posture, of the family it started in
        (:attr:`home_q`), that puts the pad ``overpass`` above the higher of where it is and ``point`` (over where
        it is, or over ``at``); False when there is none or the arm does not get there."""
        cfg = self.config
        xy = self.tip if at is None else np.asarray(at, dtype=float)
        above = np.array([xy[0], xy[1], max(float(self.tip[2]), float(point[2])) + cfg.overpass])
        ik = self.robot.reachable(self.finger, above, self.hand_rotation, arm_q0=self.home_q)
        if not ik.reachable:
            return False
        self.robot.hold_posture(ik.arm_q)
        for _ in range(int(cfg.free_timeout / self.dt)):
            self.tick("free")
            if self._unhealthy:
                return False
            if float(np.abs(self.robot.arm_posture() - ik.arm_q).max()) < cfg.posture_tol:
                return True
        return False

    def move_guarded(
        self, point: np.ndarray, speed: float, phase: str = "free", max_lag: float = 0.004, timeout: float | None = None
    ) -> PrimitiveResult:
        """Move the pad centre to ``point`` [m] along a straight line at ``speed`` [m/s] (position control) in
        free space, stopping at the first touch anywhere on the hand's fingertips: the active pad's debounced
        contact, or any other fingertip's sensed contact force above the threshold. Event ``"done"`` (status
        ok) when it got there; ``"contact"`` (status ok; ``info``: ``finger``, ``point``, ``normal`` sensed,
        ``travel`` of the pad centre along the line [m]) at a touch; ``"blocked"`` (``unreachable``) when the pad
        lags its commanded point by more than ``max_lag`` beyond the servo's own lag (about 0.1 s of travel:
        :data:`SERVO_LAG`) -- something unsensed, a phalanx or the palm, holds the hand back; ``"limit"``
        (``unreachable``) when the arm cannot reach ``point``."""
        cfg = self.config
        target = np.asarray(point, dtype=float)
        start = self.tip.copy()
        self.hybrid = False
        self.normal = None
        self.contact_ticks = 0
        if not self.robot.reachable(self.finger, target, self.hand_rotation).reachable:
            return self._result("unreachable", "limit", 0.0, target=target)
        dist = float(np.linalg.norm(target - start))
        u = (target - start) / dist if dist > 0 else np.zeros(3)
        n_ticks = max(1, int(math.ceil(dist / speed / self.dt)))
        others = [f for f in self.robot.fingers if f != self.finger]
        settle_ticks = int(cfg.guarded_settle / self.dt)
        max_lag = max_lag + SERVO_LAG * speed
        timeout = timeout if timeout is not None else dist / speed + cfg.timeout_slack
        for k in range(1, int(timeout / self.dt)):
            s = min(1.0, k / n_ticks)
            command = start + s * (target - start)
            self.robot.move_fingertip(command, self.hand_rotation)
            self.tick(phase)
            if self._unhealthy:
                return self._result("unstable", "nan", 0.0)
            travel = float((self.tip - start).dot(u))
            if self.touching:
                self.robot.move_fingertip(self.tip.copy(), self.hand_rotation)
                return self._result("ok", "contact", 0.0, finger=self.finger, point=self.contact[2].copy(),
                                    normal=self.normal.copy(), travel=travel)  # fmt: skip
            for f in others:
                c = self.robot.sense_contact(f)
                if c.normal_force > self.threshold and c.normal_in_world is not None:
                    self.robot.move_fingertip(self.tip.copy(), self.hand_rotation)
                    return self._result("ok", "contact", 0.0, finger=f, point=c.point_in_world.copy(),
                                        normal=c.normal_in_world.copy(), travel=travel)  # fmt: skip
            if float(np.linalg.norm(self.tip - command)) > max_lag and s < 1.0:
                self.robot.move_fingertip(self.tip.copy(), self.hand_rotation)
                return self._result("unreachable", "blocked", 0.0, travel=travel)
            if s >= 1.0 and (np.linalg.norm(self.tip - target) < cfg.free_tol or k > n_ticks + settle_ticks):
                return self._result("ok", "done", 0.0, travel=travel)
        return self._result("timeout", "limit", 0.0)

    def approach(
        self,
        direction: np.ndarray,
        max_distance: float,
        timeout: float | None = None,
        speed: float | None = None,
        settle: bool = True,
    ) -> PrimitiveResult:
        """Guarded move of the pad along ``direction`` until a debounced contact, then press with the force
        target and settle. ``info["normal"]``: the settled sensed normal; ``info["point"]``: the contact point."""
        cfg = self.config
        d = unit(np.asarray(direction, dtype=float))
        self.hybrid = False
        self.normal = None
        self.contact_ticks = 0
        start = self.tip.copy()
        target = start.copy()
        speed = speed or cfg.approach_speed
        timeout = timeout or (max_distance / speed + cfg.timeout_slack)
        step = speed * self.dt
        touched = False
        for _ in range(int(timeout / self.dt)):
            if float((target - start).dot(d)) < max_distance:
                target = target + step * d
            self.robot.move_fingertip(target, self.hand_rotation)
            self.tick("approach")
            if self._unhealthy:
                return self._result("unstable", "nan", 0.0)
            if self._ran_away(start, d):
                return self._result("unreachable", "runaway", 0.0)
            if self.touching:
                touched = True
                break
            if float((self.tip - start).dot(d)) >= max_distance - cfg.approach_end_tol:
                return self._result("no-contact", "done", 0.0)
        if not touched:
            return self._result("timeout", "limit", 0.0)
        if not settle:  # a probe: stop where it touched
            self.robot.move_fingertip(self.tip.copy(), self.hand_rotation)
            return self._result("ok", "contact", 0.0, normal=self.normal.copy(), point=self.contact[2].copy())
        self._press(np.zeros(3), hint=-d)
        why = self._settle()
        if why is not None:
            return self._result("unstable" if why == "nan" else "unreachable", why, 0.0)
        if self.contact[1] is None:
            return self._result("no-contact", "lost", 0.0)
        return self._result("ok", "contact", 0.0, normal=self.normal.copy(), point=self.contact[2].copy())

    def lift_and_approach(
        self, point_on_surface: np.ndarray, normal: np.ndarray, floor_z: float | None = None
    ) -> PrimitiveResult:
        """Reposition without going through the object: lift off along the current contact normal, pass a
        waypoint that is at least the clearance outside both the current face's plane and the target face's
        plane, stop above ``point_on_surface`` along its face ``normal`` and touch it with a guarded approach.

        On a convex solid a path whose legs each stay outside one face plane by the clearance cannot meet the
        solid (each leg's ends are outside that plane). ``floor_z``: lowest height of the pad centre (the table
        plus the pad radius and a margin) [m].

        In a gap narrower than twice the pad radius plus the lift (a slot of a non-convex solid) the points a
        lift away from the walls lie inside the opposite wall: the moves there are blocked, or the approach
        touches the opposite wall (a normal facing away from ``normal``). The reposition is then tried once
        more with the lift cut to ``narrow_lift``."""
        res = self._lift_and_approach(point_on_surface, normal, floor_z, self.config.lift)
        n_t = unit(np.asarray(normal, dtype=float))
        wrong = res.ok and angle(res.info["normal"], n_t) > self.config.opposite_wall_angle
        if res.status == "timeout" or wrong:
            again = self._lift_and_approach(point_on_surface, normal, floor_z, self.config.narrow_lift)
            res = PrimitiveResult(again.status, again.event, ContactTrace.concatenate([res.trace, again.trace]),
                                  res.distance + again.distance, again.info)  # fmt: skip
        return res

    def _lift_and_approach(
        self, point_on_surface: np.ndarray, normal: np.ndarray, floor_z: float | None, lift: float
    ) -> PrimitiveResult:
        cfg = self.config
        n_t = unit(np.asarray(normal, dtype=float))
        q_t = np.asarray(point_on_surface, dtype=float)
        clear = lift + self.pad_radius
        if self.normal is not None and self.contact[2] is not None:
            n_c, q_c = self.normal.copy(), self.contact[2].copy()
        elif self.normal is not None:
            n_c, q_c = self.normal.copy(), self.tip - self.pad_radius * self.normal
        else:
            n_c, q_c = np.array([0.0, 0.0, 1.0]), self.tip - self.pad_radius * np.array([0.0, 0.0, 1.0])
        lifted = q_c + clear * n_c
        above = q_t + clear * n_t
        mid = 0.5 * (lifted + above)
        bis = n_c + n_t
        bis = unit(bis) if bis @ bis > OPPOSED else np.array([0.0, 0.0, 1.0])
        deficit = max(clear - float((mid - q_c) @ n_c), clear - float((mid - q_t) @ n_t), 0.0)
        waypoint = mid + deficit / max(float(bis @ n_c), cfg.min_bisector_cos) * bis
        points = [lifted, waypoint, above]
        if floor_z is not None:
            for w in points:
                w[2] = max(w[2], floor_z)
        pieces = []
        res = self.move_free(points[0], timeout=cfg.lift_timeout, tol=cfg.lift_tol)
        pieces.append(res)
        for w, tol in ((points[1], cfg.via_tol), (points[2], cfg.target_tol)):
            if not res.ok:
                break
            if float(np.linalg.norm(w - self.tip)) > cfg.target_tol:
                res = self.move_free(w, timeout=cfg.via_timeout, tol=tol)
                pieces.append(res)
        if res.status == "timeout":
            # blocked: the straight legs cut a corner of a non-convex solid. Go round over the top instead:
            # straight up, across above the target, down to it (objects rest on the table; nothing is above)
            crossed = self._overpass_height(above, cfg.overpass)
            res = self._over_the_top(above, cfg.overpass, pieces)
            if res.status == "timeout" and self._held_over_the_top(above, crossed):
                # still blocked, a link of the finger on the object above the pad, the way across lower than the
                # pad resting on the highest point it touched: below the object's top the links reach over it
                # (BOX01N at 150 mm on an end, seed 1: beside its slot's floor, measured with the hand tilted and
                # turned upright 57 mm below the top face, the links rested on that face's rim, and every way across
                # 20 mm above the pad was held there). Round over the top once more, the pad clear of that point
                res = self._over_the_top(above, cfg.overpass, pieces, clear_top=True)
        if res.ok:
            res = self.approach(-n_t, 2 * lift + cfg.approach_overshoot)
            pieces.append(res)
        return PrimitiveResult(res.status, res.event, ContactTrace.concatenate([p.trace for p in pieces]),
                               sum(p.distance for p in pieces), res.info)  # fmt: skip

    def _held_over_the_top(self, above: np.ndarray, crossed: float) -> bool:
        """Whether a way round over the top that is held (``above`` its target), meant to go across with the pad at
        height ``crossed`` [m], went lower than the pad resting on the highest point touched (:attr:`top_z`), and
        a link of the hand touches the object above that height now: across there the links meet the object (BOX01N
        at 150 mm, seed 1: the index finger's medial link on the top face's rim, 55 mm above the height the way was
        to cross at). A link touching the object below that height was not held by what the way goes over (the
        distal link in a slot 4-9 mm below the top of cad_slotted of the formula corpus, seed 1, 10 mm below the
        height the way was to cross at), and a way higher still would not free it."""
        if self.top_z is None or self.top_z + self.pad_radius <= crossed:
            return False
        link = self.link_touch()
        return link is not None and float(link.point_in_world[2]) > crossed

    def _overpass_height(self, above: np.ndarray, rise: float, clear_top: bool = False) -> float:
        """The pad's height [m] across a way round over the top from where it is to ``above``: ``rise`` above the
        higher of the two (with ``clear_top``, the highest of those and the pad resting on the highest point
        touched, :attr:`top_z`)."""
        top = self.top_z + self.pad_radius if clear_top and self.top_z is not None else -math.inf
        return max(float(self.tip[2]), float(above[2]), top) + rise

    def _over_the_top(self, above: np.ndarray, rise: float, pieces: list[PrimitiveResult], clear_top: bool = False
                      ) -> PrimitiveResult:  # fmt: skip
        """Free moves from the pad's position straight up to :meth:`_overpass_height`, across, and down to
        ``above``. The last result (status ``timeout`` when still blocked)."""
        cfg = self.config
        z = self._overpass_height(above, rise, clear_top)
        res = self._result("ok", "done", 0.0)
        for w, tol in ((np.array([self.tip[0], self.tip[1], z]), cfg.via_tol),
                       (np.array([above[0], above[1], z]), cfg.via_tol), (above, cfg.target_tol)):  # fmt: skip
            res = self.move_free(w, timeout=cfg.via_timeout, tol=tol)
            pieces.append(res)
            if not res.ok:
                break
        return res

    # -- on a face -------------------------------------------------------------------------------------------
    def trace_face(
        self, direction: np.ndarray, face_normal: np.ndarray, max_distance: float, phase: str = "face",
        from_edge: bool = False,
    ) -> PrimitiveResult:
        """Slide across the face of normal ``face_normal`` along ``direction`` until an edge (convex: the
        surface falls away; concave: the finger is blocked), or ``max_distance`` (event ``"done"``).
        ``from_edge``: the slide starts on the edge it just met (the pad on its ridge, the sensed normal turned
        from the face's): edges count only once the normal is back on the face, within ``leave_edge`` of travel.

        ``info``: ``face_normal`` (the running mean of the sensed normals on the face), ``direction`` (the
        in-plane travel direction), ``kind`` of the edge."""
        cfg = self.config
        n_f = unit(np.asarray(face_normal, dtype=float))
        d = np.asarray(direction, dtype=float)
        d = unit(d - (d @ n_f) * n_f)
        self._press(cfg.face_speed * d)
        start = self.tip.copy()
        over = 0
        progress: list[float] = []
        window = max(2, int(cfg.stall_time / self.dt))
        n_sum = np.zeros(3)
        n_run = n_f
        timeout = max_distance / cfg.face_speed * cfg.timeout_factor + cfg.timeout_slack
        for k in range(int(timeout / self.dt)):
            self._press(self.ramp(k) * cfg.face_speed * d)
            self.tick(phase)
            if self._unhealthy:
                return self._result("unstable", "nan", 0.0)
            travelled = float((self.tip - start).dot(d))
            progress.append(travelled)
            if self.below_floor(d):
                return self._result("unreachable", "table", 0.0, face_normal=n_run, direction=d)
            if self.weak_ticks * self.dt >= cfg.loss_time:
                return self._lost("ok", "convex-edge", face_normal=unit(n_sum) if n_sum.any() else n_run,
                                  direction=d, kind="convex", lost=True)  # fmt: skip
            n = self.normal
            if from_edge and n is not None and (angle(n, n_f) <= cfg.edge_angle or travelled > cfg.leave_edge):
                from_edge = False  # off the ridge: its rows (the pad on the edge, not the face) are not the face's
                self.take_trace()
            if n is not None and self.contact[1] is not None and not from_edge:
                a = angle(n, n_run)
                if a > cfg.edge_angle:
                    over += 1
                    if over >= cfg.debounce:
                        kind = "convex" if float((n - n_run).dot(d)) > 0 else "concave"
                        return self._result("ok", f"{kind}-edge", 0.0, face_normal=n_run, direction=d, kind=kind)
                else:
                    over = 0
                    if angle(n, n_f) < self.bounds.sample_cone:  # the face's samples, never a slow drift
                        n_sum += self.contact[1]
                        if k > cfg.run_min_samples:
                            n_run = unit(n_sum)
            if travelled >= max_distance:
                return self._result("ok", "done", 0.0, face_normal=n_run, direction=d)
            if len(progress) > window and progress[-1] - progress[-1 - window] < (
                cfg.stall_fraction * cfg.face_speed * cfg.stall_time
            ):
                return self._result("unreachable", "blocked", 0.0, face_normal=n_run, direction=d)
        return self._result("timeout", "limit", 0.0)

    def cross_edge(self, kind: str, n_a: np.ndarray, direction: np.ndarray) -> PrimitiveResult:
        """Roll over a convex edge, or climb out of a concave one, from face ``n_a`` onto the next face, until
        the sensed normal settles. ``info``: ``normal`` (the next face's normal, coarse), ``edge_direction``
        (n_a × n_b), ``away`` (the in-plane direction on the new face pointing away from the edge). A roll that
        does not settle within ``roll_max`` of travel (or the time for it) while a link of the finger touches the
        object ends with event ``"hand"`` (the link held it back: BOX01N seed 1, rolling the tilted hand onto the
        floor of its slot, the link on the slot's ceiling), else ``"limit"``; a roll over a convex edge whose normal
        has not turned from ``n_a`` after :data:`ROLL_ON_FACE` of travel, with event ``"face"``."""
        cfg = self.config
        n_a = unit(np.asarray(n_a, dtype=float))
        d = np.asarray(direction, dtype=float)
        e = unit(cross(n_a, self.normal)) if self.normal is not None else perpendicular(n_a)
        if e @ e < cfg.roll_axis_sin2:
            e = unit(cross(n_a, d))
        sign = -1.0 if kind == "convex" else 1.0
        back = -(self.hand_rotation @ np.array([0.0, 0.0, 1.0]))  # up the finger
        hist: list[tuple[float, np.ndarray]] = []
        travelled = 0.0
        last = self.tip.copy()
        lost = 0
        met = None  # a link of the finger on the object when the contact was lost
        turned = False  # the sensed normal turned past the edge angle from n_a
        window = cfg.roll_settle_window(self.bounds.normal_sigma, self.pad_radius)
        for _ in range(int(cfg.roll_max / cfg.roll_speed * 2.0 / self.dt)):
            n = self.normal if self.normal is not None else n_a
            if angle(n, n_a) > self.bounds.sample_cone:
                e_new = cross(n_a, n)
                if e_new.dot(e_new) > cfg.turned_axis_sin2:
                    e = unit(e_new)
            t = unit(cross(n, e))
            if sign * float(t.dot(n_a)) < 0:
                t = -t
            if kind == "convex" and float(t.dot(n_a)) > 0:  # never climb back onto face a
                t = unit(t - float(t.dot(n_a)) * n_a)
            self._press(cfg.roll_speed * t)
            self.tick("roll")
            if self._unhealthy:
                return self._result("unstable", "nan", 0.0)
            travelled += float(np.linalg.norm(self.tip - last))
            last = self.tip.copy()
            if self.contact[1] is None:
                lost += 1
                if lost == 1:  # a link that lifted the pad off may have left the object by the time the roll gives up
                    met = self.link_touch()
                if lost * self.dt > cfg.roll_loss_time:
                    return self._lost("no-contact", "lost", met)
                continue
            lost = 0
            hist.append((travelled, self.normal.copy()))
            turned = turned or angle(self.normal, n_a) > cfg.edge_angle
            if kind == "convex" and not turned and travelled > ROLL_ON_FACE:
                # on the face it left, the roll would slide on across it to roll_max (FRAME01 seed 2: the slide's
                # contact weakened in the middle of the top face, and the roll slid 24 mm over it)
                return self._lost("unreachable", "face", met)
            if kind == "convex" and self.below_floor():
                # rolling down round the edge the pad reached the table's clearance: it cannot go on round to the
                # next face (leaning under next to the table), and the normal it settles at is the edge's, the pad
                # resting on the edge above the table (prism_08 at 100 mm: 28° below the horizontal between a side
                # and a face leaning under at 45°, the "face" stroked there 43 bounds off)
                self._press(np.zeros(3))
                self.tick("roll")
                return self._result("unreachable", "table", 0.0)
            # leaning under past the limit, and further than face a (from a face near the limit, noise alone
            # must not end the roll)
            limit = min(-math.sin(cfg.max_undercut), float(n_a.dot(back)) - math.sin(cfg.undercut_slack))
            if kind == "convex" and float(self.normal.dot(back)) < limit:
                self._press(np.zeros(3))
                self.tick("roll")
                return self._result("unreachable", "undercut", 0.0)
            if angle(self.normal, n_a) > cfg.edge_angle:
                if roll_settled(hist, travelled, self.normal, window, cfg.roll_settled):
                    n_b = self.normal.copy()
                    away = unit(cross(n_b, e))
                    if float(away.dot(t)) < 0:
                        away = -away
                    return self._result("ok", "done", 0.0, normal=n_b, edge_direction=unit(cross(n_a, n_b)),
                                        away=away)  # fmt: skip
            if travelled > cfg.roll_max:
                return self._lost("unreachable", "limit")
        # a roll that never settled: held back by a link of the finger on the object (event "hand"), or turning on
        return self._lost("timeout", "limit")

    def stroke(self, normal: np.ndarray, away: np.ndarray, along: np.ndarray, step_in: float | None = None
               ) -> PrimitiveResult:  # fmt: skip
        """A short L on a face for its normal: ``step_in`` along ``away``, then ``stroke`` along ``along`` (the
        other way if an edge comes first). ``info["normal"]``: mean sensed normal on the face; ``info["at_table"]``:
        the step in (``step_in`` not given) was stopped by the table, and the pad did not leave the edge;
        ``info["link"]``, ``info["link_normal"]``: the link of the finger that lifted the pad off in the last leg it
        did, and its contact's normal (None when none did). A step in
        held back fails the stroke; ``info["held"]`` then names the link of the finger touching the object, if one
        does (:meth:`_held_by_link`).

        A leg heading down that would bring the pad onto the table (event ``"table"``: a face leaning under,
        next to the table), or one whose pad a link of the finger lifted off (``"hand"``), ends there without
        failing the stroke: the step in is skipped, the stroke turns back the other way; the rows recorded still
        tell the face (the caller's fit judges whether they are enough)."""
        cfg = self.config
        n_f = unit(np.asarray(normal, dtype=float))
        # out of a concave corner the force is shared by both faces: press on the new one alone before sliding
        self._press(np.zeros(3), hint=n_f)
        why = self._settle("settle")
        if why is not None:
            return self._result("unstable" if why == "nan" else "unreachable", why, 0.0)
        self.take_trace()  # rows in place, not of the stroke
        pieces = [self.trace_face(away, n_f, cfg.step_in if step_in is None else step_in, phase="stroke")]
        if not pieces[-1].ok and pieces[-1].event not in STOPS:
            # a step in held back ("blocked") fails the stroke: the pad may still rest on the ridge, its normal
            # partway round, and legs along the edge from there ride the ridge (antiprism_04 of the formula corpus at
            # 150 mm, seed 1: the step held back after 1.1 mm, the legs measured a "face" 15 bounds off, no-match);
            # elsewhere the legs from a step so held measured the face within its bound (BOX01N seed 1, in a slot),
            # and their rows alone do not tell the two apart
            return self._held_by_link(pieces[-1])
        pieces.append(self.trace_face(along, n_f, cfg.stroke, phase="stroke"))
        if (pieces[-1].ok and pieces[-1].event != "done") or pieces[-1].event in STOPS:
            back = self.trace_face(-along, n_f, cfg.stroke * 2.0, phase="stroke", from_edge=True)
            pieces.append(back)
        # the first leg starts where the roll settled, next to the edge and maybe a corner, the pad still touching
        # their rims: it measures the face only when asked for its width (step_in given) or when the others
        # hold too few rows. A leg that a link of the finger stopped is not the face's either when the others hold
        # enough: over its last millimetres the link pressing on the object lifts and tilts the pad (bipyramid_08 at
        # 150 mm: such a leg's rows 1.3° off the face on average, its start 2-4°, and the face 1.7 bounds off)
        clean = [p for p in pieces if p.event != "hand"] or pieces
        if len(clean) < len(pieces) and sum(int(p.trace.in_contact.sum()) for p in clean) < self.bounds.min_face_rows:
            clean = pieces
        rest = ContactTrace.concatenate([p.trace for p in clean if p is not pieces[0]])
        narrow = step_in is None and int(rest.in_contact.sum()) >= self.bounds.min_face_rows
        rim = step_in is None and self._stepped_onto_rim(pieces[0])
        # the step in off the edge just rolled over stopped by the table: the pad stays where the roll settled, which
        # the table too may have stopped short of the face (the legs along the edge then ride its ridge)
        at_table = step_in is None and pieces[0].event == "table"
        trace = rest if narrow else ContactTrace.concatenate([p.trace for p in clean])
        ok_rows = trace.in_contact & (trace.phase == PHASES.index("stroke"))
        n_mean = dominant_normal(trace.normal_in_world[ok_rows], n_f, self.bounds.face_cone / 2.0, cfg.edge_angle)
        failed = [p for p in pieces if not p.ok and p.event not in STOPS]
        status = failed[-1].status if failed else "ok"
        event = failed[-1].event if failed else "done"
        # both legs along the edge met another edge: the next face is narrow along it there
        blocked = len(pieces) == 3 and all(p.ok and p.event not in ("done", *STOPS) for p in pieces[1:])
        # the last leg whose pad a link of the finger lifted off: which link, and its contact's normal (the way the
        # hand would tilt to clear it)
        held = next((p.info for p in reversed(pieces) if p.event == "hand"), {})
        return PrimitiveResult(status, event, trace, sum(p.distance for p in pieces),
                               {"normal": n_mean, "rim": rim, "blocked": blocked, "at_table": at_table,
                                "link": held.get("link"), "link_normal": held.get("link_normal")})  # fmt: skip

    def _held_by_link(self, step: PrimitiveResult) -> PrimitiveResult:
        """A stroke's step in that stalled (``"blocked"``), with ``info["held"]``: the link of the finger that touches
        the object now (None when none does). The pad stepped in under an overhang, its links meeting the object above
        it (BOX01N seed 1 on an end, its slot sideways: the pad rolled onto the slot's floor, 30 mm under its ceiling,
        and the medial link met the ceiling's edge a millimetre in), or onto a face leaning under, the links meeting
        the face it left."""
        if step.event != "blocked":
            return step
        link = self.link_touch()
        return replace(step, info={**step.info, "held": None if link is None else link.link})

    def _stepped_onto_rim(self, step: PrimitiveResult) -> bool:
        """Whether a stroke's first leg, off the edge just rolled over, met another edge or turned its sensed
        normal off the face, by more than :attr:`~SegmentBounds.sample_cone` (the mean of its first
        :attr:`~SegmentBounds.steady_window` rows against that of its last: 0.1-1.9° on a face, 4.5-10.6° where
        the pad had rolled onto the rim of the face's far edge, over five episodes of the seed library at
        30-150 mm). The legs along the face would then ride that rim with a steady normal turned partway round it
        (BOX01N at 30 mm: 20° off the face's, 25 times its bound)."""
        if step.event not in ("done", *STOPS):
            return True
        n = step.trace.normal_in_world[step.trace.in_contact]
        k = self.bounds.steady_window
        if len(n) < 2 * k:
            return False
        # the two means differ by the noise alone by σn √(2 / k) per axis: at noise level 4 (σn 4°) by 2.4° on
        # average, and the fixed cone alone then took most strokes on a face for a rim
        b = self.bounds
        cut = max(b.sample_cone, b.rim_sigmas * b.normal_sigma * math.sqrt(2.0 / k))
        return angle(unit(n[:k].sum(axis=0)), unit(n[-k:].sum(axis=0))) > cut

    # -- along an edge -----------------------------------------------------------------------------------------
    def follow_edge(
        self,
        along: np.ndarray,
        n_a: np.ndarray,
        n_b: np.ndarray,
        toward_a: np.ndarray,
        max_distance: float,
        acquire_only: bool = False,
        concave: bool = False,
        strict: bool = False,
    ) -> PrimitiveResult:
        """Ridge following: press along the sensed normal, servo sideways to keep it on the bisector of
        ``n_a`` and ``n_b``, move along ``along`` until a vertex (the normal gains a component along the edge
        above sin 15°, or contact is lost once it leaned along it, or progress stalls). ``toward_a``: the sideways
        direction that turns the normal towards ``n_a``. With ``acquire_only`` it stops once the normal is on
        the bisector. Contact lost before the normal leaned along the edge (:attr:`TouchConfig.loss_lean_sin`)
        is no vertex: ``no-contact``, event ``lost`` (:meth:`TouchConfig.loss_lean`: a lean beyond the noise).

        ``concave``: the edge is a valley, where the pad rests in the corner against both faces and no sideways
        motion turns the sensed normal (the force-weighted mean of the two contacts') onto the bisector: pressed
        sideways toward a face, the pad leaves the other and the normal jumps to the first's, back and forth,
        never on the bisector long enough to gather speed along the edge (BOX01N seed 2, BOX01P seed 3: upright
        valleys, the pad rocking in place until the move stalled). In a valley the pad is drawn into the corner
        instead (sideways along the tangent plane toward the bisector's inside) and rides it whenever it touches.
        ``strict``: the pad is on the ridge only when the normal lies within half the way from the bisector to
        either face's normal (:attr:`TouchConfig.ridge_min_cone` at least), not within ``ridge_cone``: beside an
        edge turning less than twice that cone, a pad resting on either face is within it (hull_07 of the formula
        corpus: a pad 3 mm in from a shallow edge "acquired" its ridge at once).

        ``info``: ``event_sign`` (+1 the surface fell away at the vertex, −1 the finger was blocked)."""
        cfg = self.config
        u = unit(np.asarray(along, dtype=float))
        n_a, n_b = unit(np.asarray(n_a, float)), unit(np.asarray(n_b, float))
        m = n_a - (n_a @ n_b) * n_b
        m = unit(m - (m @ u) * u)
        nb_p = unit(n_b - (n_b @ u) * u)
        theta = math.atan2(float(n_a @ m), float(n_a @ nb_p))
        target = 0.5 * theta
        cone = min(cfg.ridge_cone, max(cfg.ridge_min_cone, 0.5 * abs(target))) if strict else cfg.ridge_cone
        side = unit(toward_a - (toward_a @ u) * u)
        into = -unit(n_a + n_b) if concave else u  # into a valley's corner
        start = self.tip.copy()
        speed = 0.0 if acquire_only else cfg.edge_speed
        over = 0
        on_ridge = 0
        # a normal leaning back against ``along`` is a wall ahead only once the pad has been on the edge's
        # line: starting beyond the end of the edge behind it (rolling on the vertex there), the normal leans
        # back until the pad has moved onto the ridge
        on_line = False
        lean = -1.0  # the filtered normal's largest component along ``along`` on the ridge
        progress: list[float] = []
        window = max(2, int(cfg.stall_time / self.dt))
        timeout = (max_distance / cfg.edge_speed if not acquire_only else 0.0) * cfg.timeout_factor + (
            cfg.ridge_timeout_slack
        )
        err = 0.0
        # rolling onto the bisector takes pad radius × angle at the sideways speed limit; allow twice that
        n0 = self.normal if self.normal is not None else n_b
        roll_angle = abs(target - math.atan2(float(n0 @ m), float(n0 @ nb_p)))
        acquire_time = 2.0 * self.pad_radius * roll_angle / cfg.ridge_side_speed + cfg.ridge_acquire_slack
        timeout += acquire_time
        for _ in range(int(timeout / self.dt)):
            n = self.normal if self.normal is not None else n_b
            alpha = math.atan2(float(n.dot(m)), float(n.dot(nb_p)))
            err = target - alpha
            v_side = cfg.ridge_gain * self.pad_radius * err
            lim = cfg.ridge_side_speed
            v_side = max(-lim, min(lim, v_side))
            s_dir = unit(side - float(side.dot(n)) * n)
            ridge_ok = abs(err) < cone
            if concave:
                ridge_ok = self.contact[1] is not None
                v_side, s_dir = cfg.ridge_side_speed, into - float(into.dot(n)) * n
            v = v_side * s_dir + (self.ramp(on_ridge) * speed * u if (ridge_ok or on_ridge > 0) else 0.0 * u)
            self._press(v)
            self.tick("ridge")
            if self._unhealthy:
                return self._result("unstable", "nan", 0.0)
            if ridge_ok:
                on_ridge += 1
                if acquire_only and on_ridge >= cfg.ridge_acquired_ticks:
                    return self._result("ok", "done", 0.0, error=err)
            travelled = float((self.tip - start).dot(u))
            progress.append(travelled)
            if on_ridge == 0:
                if len(progress) * self.dt > acquire_time:
                    return self._result("timeout", "limit", 0.0, error=err)
                continue
            if self.weak_ticks * self.dt >= cfg.loss_time:
                if lean < cfg.loss_lean(self.bounds.normal_sigma):
                    return self._result("no-contact", "lost", 0.0, lean=lean)
                return self._result("ok", "vertex", 0.0, event_sign=1, lost=True)
            if self.normal is not None:
                c = float(self.normal.dot(u))
                if self.contact[1] is not None:
                    lean = max(lean, c)
                if abs(c) > cfg.vertex_sin and (c > 0 or on_line):
                    over += 1
                    if over >= cfg.debounce:
                        return self._result("ok", "vertex", 0.0, event_sign=1 if c > 0 else -1)
                else:
                    over = 0
                    on_line = on_line or abs(c) <= cfg.vertex_sin
            if acquire_only:
                continue
            if travelled > max_distance:
                return self._result("unreachable", "limit", 0.0)
            if len(progress) > window + cfg.stall_warmup and progress[-1] - progress[-1 - window] < (
                cfg.stall_fraction * speed * cfg.stall_time
            ):
                return self._result("ok", "vertex", 0.0, event_sign=-1, stalled=True)
        return self._result("timeout", "limit", 0.0, error=err)

    def hold(self, seconds: float, phase: str = "vertex") -> PrimitiveResult:
        """Press in place (zero tangential velocity) for ``seconds``."""
        return self._hold(seconds, phase, reading=False)

    def hold_reading(self, seconds: float, phase: str = "vertex") -> PrimitiveResult:
        """:meth:`hold`, reading the pad's contacts every tick each on its own, not merged into one point and normal
        (a pad resting on two rims at once senses the mean of the two, on neither): ``info["contacts"]``, per tick
        the tuple of the fingertip's sensed contacts."""
        return self._hold(seconds, phase, reading=True)

    def _hold(self, seconds: float, phase: str, reading: bool) -> PrimitiveResult:
        self._press(np.zeros(3))
        start = self.tip.copy()
        k = self.robot.fingers.index(self.finger) if reading else None
        seen = []
        for _ in range(max(1, int(seconds / self.dt))):
            self.tick(phase)
            if self._unhealthy:
                return self._result("unstable", "nan", 0.0)
            if self._ran_away(start):
                return self._result("unreachable", "runaway", 0.0)
            if k is not None:
                seen.append(tuple(self.robot.read().contacts[k]))
        return self._result("ok", "done", 0.0, contacts=seen) if reading else self._result("ok", "done", 0.0)

    # -- around a vertex ---------------------------------------------------------------------------------------
    def circle_vertex(
        self,
        vertex: np.ndarray,
        normal: np.ndarray,
        start_direction: np.ndarray,
        radius: float,
        max_sweep: float | None = None,
    ) -> PrimitiveResult:
        """Slide on the face of ``normal`` along a circle of ``radius`` about ``vertex``, leaving along
        ``start_direction`` (the in-plane tangent at the start), until the next edge (convex or concave).
        ``max_sweep``: the circle gives up (``unreachable``, event ``"table"``) after sweeping this angle
        [rad] (default, and at most, ``circle_max_sweep``: then it ends with ``timeout``) -- the executor sets it
        where the circle would bring the pad onto the table; the pad's reaching
        :attr:`floor_z` ends it the same way. ``info``: like :meth:`trace_face`, plus ``arc`` (the angle
        swept [rad])."""
        cfg = self.config
        full = cfg.circle_max_sweep
        max_sweep = full if max_sweep is None else max_sweep
        n_f = unit(np.asarray(normal, dtype=float))
        vtx = np.asarray(vertex, dtype=float)
        p0 = self.contact[2] if self.contact[2] is not None else self.tip - self.pad_radius * n_f
        r0 = p0 - vtx
        r0 = unit(r0 - (r0 @ n_f) * n_f)
        t0 = unit(start_direction - (start_direction @ n_f) * n_f)
        axis = unit(cross(r0, t0))  # ± n_f: the sense of the circle
        over = 0
        swept = 0.0
        prev = r0
        n_sum = np.zeros(3)
        n_run = n_f
        timeout = 2.0 * math.pi * radius / cfg.face_speed * cfg.circle_timeout_factor + cfg.timeout_slack
        progress_t: list[float] = []
        window = max(2, int(cfg.stall_time / self.dt))
        start_tip = self.tip.copy()
        path = 0.0
        for k in range(int(timeout / self.dt)):
            p = self.contact[2] if self.contact[2] is not None else self.tip - self.pad_radius * n_run
            r = p - vtx
            r = r - (r.dot(n_f)) * n_f
            rad = math.sqrt(float(r.dot(r)))
            rh = r / rad if rad > AT_CENTRE else r0
            t = unit(cross(axis, rh))
            v = cfg.face_speed * t + cfg.circle_gain * (radius - rad) * rh
            self._press(v)
            prev_tip = self.tip.copy()
            self.tick("circle")
            if self._unhealthy:
                return self._result("unstable", "nan", 0.0)
            path += float(np.linalg.norm(self.tip - prev_tip))
            progress_t.append(path)
            # signed about the circle's axis: the contact point's noise turns ``rh`` back and forth by a degree a
            # tick at the circle's radius, and unsigned turns summed that noise (trapezohedron_12 at 77 mm: a circle
            # that gave up after "sweeping" 342° had gone 137° round its vertex, short of the next edge)
            swept += math.atan2(float(axis.dot(cross(prev, rh))), float(prev.dot(rh)))
            prev = rh
            if (swept > max_sweep and max_sweep < full) or self.below_floor(t):
                return self._result("unreachable", "table", 0.0, arc=swept)
            if self.weak_ticks * self.dt >= cfg.loss_time:
                return self._lost("ok", "convex-edge", face_normal=n_run, direction=t, kind="convex", arc=swept,
                                  lost=True)  # fmt: skip
            n = self.normal
            if n is not None and self.contact[1] is not None:
                a = angle(n, n_run)
                if a > cfg.edge_angle:
                    over += 1
                    if over >= cfg.debounce:
                        kind = "convex" if float((n - n_run).dot(t)) > 0 else "concave"
                        return self._result("ok", f"{kind}-edge", 0.0, face_normal=n_run, direction=t, kind=kind,
                                            arc=swept)  # fmt: skip
                else:
                    over = 0
                    if angle(n, n_f) < self.bounds.sample_cone:  # the face's samples, never a slow drift
                        n_sum += self.contact[1]
                        if k > cfg.run_min_samples:
                            n_run = unit(n_sum)
            if swept > min(max_sweep, full):
                return self._result("timeout", "limit", 0.0, arc=swept)
            if len(progress_t) > window and path - progress_t[-1 - window] < (
                cfg.stall_fraction * cfg.face_speed * cfg.stall_time
            ):
                return self._result("unreachable", "blocked", 0.0, arc=swept)
        del start_tip
        return self._result("timeout", "limit", 0.0, arc=swept)


def dominant_normal(normals: np.ndarray, guess: np.ndarray, cone: float, within: float) -> np.ndarray:
    """The mean of the densest cluster of ``normals`` (rows within ``cone`` of each other), among those within
    ``within`` of ``guess``; ``guess`` when none is. A face's rows share one normal, while a roll's or an edge's
    spread: the cluster is the face even when ``guess`` (a roll's settled normal near a corner) is a few degrees
    off it."""
    nn = np.asarray(normals, dtype=float).reshape(-1, 3)
    nn = nn[nn @ guess > math.cos(within)]
    if not len(nn):
        return guess
    near = nn @ nn.T > math.cos(cone)
    seed = nn[int(np.argmax(near.sum(axis=1)))]
    return unit(nn[nn @ seed > math.cos(cone)].sum(axis=0))


def _path_length(points: np.ndarray, offset: float = 0.0) -> float:
    if len(points) < 2:
        return offset
    return offset + float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


__all__ = [
    "FAILURES",
    "PHASES",
    "ContactTrace",
    "PrimitiveResult",
    "Toucher",
    "angle",
    "empty_trace",
    "perpendicular",
    "roll_settled",
    "unit",
]
