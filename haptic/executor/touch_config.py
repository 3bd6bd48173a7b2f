"""The numbers of the force-controlled primitives (:mod:`haptic.executor.primitives`): speeds, forces, timing
and the thresholds of their events, in one frozen settings object; the sensor's σ and the cones of a face's
normals the primitives share with the segmenter are :class:`~haptic.executor.segment.SegmentBounds`'."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from haptic.sim.control import ControlGains

DOWN = np.diag([-1.0, 1.0, -1.0])
"""Hand rotation ``world_from_hand`` with the fingers pointing down (the tracing posture)."""


@dataclass(frozen=True)
class TouchConfig:
    """Speeds, forces and detection thresholds of the primitives (one home for the executor's numbers)."""

    force: float = 1.0
    """Normal force target while tracing [N]."""
    face_speed: float = 0.02
    """Tracing speed across a face [m/s] (friction × speed / force ≤ 0.012 (m/s)/N, pitfall 1)."""
    edge_speed: float = 0.015
    """Ridge-following speed along an edge [m/s]."""
    roll_speed: float = 0.015
    """Speed of the pad centre while rolling over an edge [m/s]."""
    approach_speed: float = 0.02
    """Guarded-approach speed [m/s]."""
    free_speed: float = 0.20
    """Speed of free-space moves [m/s]."""
    contact_fraction: float = ControlGains.contact_fraction
    """Contact is sensed above max(contact_fraction × force, contact_sigmas × σF) [-] (the defaults: the
    hybrid controller's) ..."""
    contact_sigmas: float = ControlGains.contact_sigmas
    """... [-] (σF: :attr:`SegmentBounds.force_sigma <haptic.executor.segment.SegmentBounds.force_sigma>`)."""
    debounce: int = 3
    """Consecutive samples a detection must hold [ticks]."""
    normal_filter: float = ControlGains.normal_filter
    """Per-tick low-pass weight of a new normal sample (0..1]."""
    edge_angle: float = math.radians(10.0)
    """Edge: the filtered normal leaves the face normal by more than this [rad]."""
    loss_fraction: float = 0.3
    """Edge backup / contact loss: force below this fraction of the target ... [-]"""
    loss_time: float = 0.02
    """... for this long [s]."""
    stall_time: float = 0.3
    """Blocked: over this window [s] ..."""
    stall_fraction: float = 0.2
    """... the fingertip advanced less than this fraction of the commanded travel [-]."""
    vertex_sin: float = math.sin(math.radians(15.0))
    """Vertex: the filtered normal's component along the edge exceeds this [-]."""
    loss_lean_sin: float = math.sin(math.radians(5.0))
    """Contact lost while following a ridge is its vertex (the surface fell away) only when the filtered normal
    had leaned at least this far along the edge: the pad cannot leave the end of an edge without rolling on to
    the vertex. Lost with the normal still across the edge, the pad was lifted off it -- another part of the
    finger met the object (a frame's rim above a valley) -- and the edge goes on [-] ..."""
    loss_lean_sigmas: float = 5.0
    """... and at least this many σ of the filtered normal (:meth:`filtered_sigma`) when that is more: the lean is
    the largest over the whole ridge trace, and at noise level 4 (σn 4°, the filtered normal's 1.5° per axis) the
    noise alone took it past 5° on HEXPRISM01 at 150 mm (seed 1): a link of the finger lifted the pad off 2.5 mm
    into an edge move, and the vertex was put where the pad left the ridge, 24 mm from the edge's end (14.7 bounds;
    no-match) [-]."""
    roll_window: float = 0.001
    """A roll is over when the normal turned less than ``roll_settled`` over this much travel [m] ..."""
    roll_settled: float = math.radians(1.5)
    """... [rad] ..."""
    roll_settle_sigmas: float = 3.5
    """... or over the travel in which a roll turns by ``roll_settled`` and this many σ of the difference of two
    filtered normals more, when the sensor is noisier (:meth:`roll_settle_window`) [-]."""
    undercut_slack: float = math.radians(3.0)
    """Rolling off a face that itself leans under near the limit, the roll ends for the undercut only once the
    normal leans this much further than the face's (not on a noisy first reading) [rad]."""
    max_undercut: float = math.radians(35.0)
    """The pad reaches a surface whose normal leans at most this far back against the finger's axis (past
    perpendicular to it); beyond, the finger's phalanx meets the object first and the pad loses contact. A
    roll over a convex edge stops there (event ``"undercut"``) [rad] ..."""
    undercut_margin: float = math.radians(4.0)
    """... and the planner counts on it only this much short of the limit (:attr:`reach_undercut`): a face
    leaning under by the limit itself, at a pose known to a degree or so, may end the roll before the pad is on
    it [rad]."""
    tilt_angles: tuple[float, ...] = (math.radians(30.0), math.radians(15.0))
    """A move whose pad a link of the finger lifted off the object (the phalanx meeting the rim of a hole, a face
    leaning over the one traced) tilts the hand, the finger leaning away from that contact, by the first of these
    the arm reaches, and tries again [rad] ..."""
    tilt_min_sin: float = 0.2
    """... unless the link's contact normal is within asin of this of the finger's axis (no side to lean to) [-]."""
    table_link_cos: float = 0.95
    """A link's contact below the floor with a normal whose vertical component exceeds this is the table's [-]."""
    roll_max: float = 0.04
    """Longest pad travel while rolling over or climbing onto an edge [m]."""
    roll_loss_time: float = 0.15
    """A roll fails once contact has been lost this long [s]."""
    roll_axis_sin2: float = 0.5
    """At the start of a roll the edge's axis is ``n_a × n`` when its squared length (sin² of the turn) is at
    least this, else ``n_a ×`` the direction of travel [-] ..."""
    turned_axis_sin2: float = 1e-4
    """... and during the roll it follows ``n_a × n`` while that is longer than this (squared) [-]."""
    step_in: float = 0.0015
    """Travel onto a new face, away from the edge, after the roll settled [m]."""
    stroke: float = 0.006
    """Length of the stroke along the edge on a new face (the second leg of the L for its normal) [m]."""
    leave_edge: float = 0.003
    """A slide that starts on the edge it just met (the back leg of a stroke) counts edges only once the sensed
    normal is back on the face, or after this much travel [m]."""
    ridge_gain: float = 12.0
    """Sideways servo of ridge following: pad speed per radian of normal error, per metre of pad radius [1/s]."""
    ridge_side_speed: float = 0.012
    """Largest sideways speed of that servo [m/s]; rolling onto the ridge is given twice the time it takes at
    this speed ..."""
    ridge_acquire_slack: float = 0.6
    """... plus this [s]."""
    ridge_cone: float = math.radians(8.0)
    """The pad is on the ridge when the normal is within this of the bisector; only then does it move along [rad]."""
    ridge_min_cone: float = math.radians(2.0)
    """An edge move's ridge cone is at most half the angle from the bisector to either face's normal, and at least
    this (a few times the filtered normal's noise) [rad]."""
    ridge_acquired_ticks: int = 10
    """Ticks on the ridge after which acquiring it is done [ticks]."""
    ridge_timeout_slack: float = 3.0
    """Ridge following gives up after twice the time its distance takes, plus the acquiring time, plus this [s]."""
    stall_warmup: int = 20
    """Ticks beyond the stall window before ridge following tests for a stall [ticks]."""
    settle_time: float = 0.15
    """Shortest hold after a guarded contact before moving [s] ..."""
    settle_max: float = 0.6
    """... longest: the hold ends once the force has stayed within ``settle_band`` of the target for
    ``settle_time`` (the impact transient of the approach takes ~0.3 s to die out) [s]."""
    settle_band: float = 0.15
    """Relative force band of a settled contact [-]."""
    ramp_time: float = 0.25
    """Tangential speeds ramp up over this time at the start of a slide (a step start loses force) [s]."""
    lift: float = 0.008
    """Clearance of a repositioning move above the surface [m] ..."""
    narrow_lift: float = 0.002
    """... and of its second try when the first was blocked (a slot narrower than 2 × pad radius + lift) [m]."""
    approach_overshoot: float = 0.004
    """The guarded approach that ends a repositioning (or touches a contact again) runs this far past where the
    surface is expected [m]."""
    opposite_wall_angle: float = math.radians(60.0)
    """A repositioning that touches a normal more than this from the target face's touched the opposite wall of
    a slot [rad]."""
    min_bisector_cos: float = 0.2
    """The repositioning's waypoint is pushed out along the bisector of the two normals by the clearance
    deficit over at most 1 / this [-]."""
    lift_timeout: float = 2.0
    """Free moves off a surface along its normal: time limit [s] ..."""
    lift_tol: float = 2e-3
    """... and arrival tolerance [m]."""
    via_timeout: float = 3.0
    """Free moves to a waypoint of a repositioning or a landing: time limit [s] ..."""
    via_tol: float = 3e-3
    """... and arrival tolerance [m]."""
    target_tol: float = 1e-3
    """Arrival tolerance of a free move's last point (a move shorter than this is skipped) [m]."""
    back_off_timeout: float = 1.0
    """Time limit of a short free move backing off a contact [s]."""
    free_timeout: float = 4.0
    """Time limit of a free move [s] ..."""
    free_tol: float = 7e-4
    """... and its arrival tolerance, also of a guarded move [m]."""
    runaway: float = 0.02
    """A free move whose pad leaves the straight path to its target by more than this is stopped and held where
    it is by its joints (the arm met a joint limit and cannot keep the hand's orientation along the path: the
    task-space control would carry it on across the workspace); the move ends ``unreachable``, event
    ``runaway`` [m]. So does a guarded approach whose pad leaves its line by this, and a press in place (settling
    on a contact, holding at a vertex) whose pad leaves its point by this: the force controller pushing on into
    a contact it lost, or the arm jammed against the object and thrown off."""
    posture_tol: float = 0.02
    """A joint-space move back to the arm's home posture family ends when every arm joint is within this [rad]."""
    guarded_settle: float = 0.5
    """A guarded move waits at most this long after its command reached the end [s]."""
    timeout_factor: float = 2.0
    """A slide or an approach gives up after this times the time its distance takes ..."""
    timeout_slack: float = 2.0
    """... plus this [s]."""
    approach_end_tol: float = 1e-4
    """An approach that came this close to its full distance without contact has touched nothing [m]."""
    run_min_samples: int = 10
    """The running face normal of a slide replaces the given one after this many ticks of samples [ticks]."""
    circle_gain: float = 4.0
    """Radial servo of the vertex circle: speed per metre of radius error [1/s]."""
    circle_timeout_factor: float = 1.5
    """The vertex circle gives up after this times the time a full circle takes, plus ``timeout_slack``."""
    circle_max_sweep: float = 1.9 * math.pi
    """The vertex circle gives up after sweeping this angle [rad]."""
    pad_radius_range: tuple[float, float] = (0.005, 0.03)
    """Sensed distances of the pad centre from the contact point within this range refine the pad radius [m] ..."""
    pad_radius_gain: float = 0.02
    """... by this fraction of the difference per tick [-]."""
    stability_every: int = 20
    """The simulation's stability is checked every this many ticks [ticks]."""
    overpass: float = 0.02
    """A repositioning move whose straight legs are blocked (a non-convex solid) goes round over the top, this
    far above the higher of its start and its target [m]."""
    hand_rotation: np.ndarray = field(default_factory=lambda: DOWN.copy())
    """Hand rotation held while exploring (3, 3)."""
    link_every: int = 10
    """The hand's link positions (forward kinematics, for recordings) are sampled every this many ticks
    (0: never) [ticks]."""

    watch_every: int = 5
    """The links' contact readout is watched every this many ticks through a move (0: never): a link other than
    the pad touching the object is reported with the move (:class:`HandContact`) [ticks]."""
    wrist_force: float = 1.5
    """With the pad and every link free, the wrist's force sensor reads the hand's weight and motion (the masses of
    its bodies times their acceleration, :meth:`~haptic.sim.robot.RobotInterface.hand_inertia_force`): off it by
    0.07 N (99th percentile) and 1.03 N at most while the hand moves under force control (PYR01 at 60 and 100 mm,
    FRAME01 at 100 mm, seed 1: 3368 watched ticks), where the weight alone is 18 N off during fast approaches.
    Watched with the links' readout outside the carries between moves, a force farther than this from that reading
    is a contact of the hand, and one that neither the pad nor a link reports is counted with the move
    (``MoveResult.info["wrist"]``) [N]."""

    @property
    def reach_undercut(self) -> float:
        """The undercut the planner's reach model takes the hand to reach: ``max_undercut`` less
        ``undercut_margin`` [rad]."""
        return self.max_undercut - self.undercut_margin

    def filtered_sigma(self, normal_sigma: float) -> float:
        """σ per tangent axis of the low-passed normal (weight ``normal_filter`` per tick) of a sensor of σ
        ``normal_sigma`` per sample: ``σn √(w / (2 − w))`` [rad]."""
        w = self.normal_filter
        return normal_sigma * math.sqrt(w / (2.0 - w))

    def loss_lean(self, normal_sigma: float) -> float:
        """The lean along the edge [sin] a ridge trace's filtered normal must have reached for a lost contact to be
        its vertex: :attr:`loss_lean_sin`, or :attr:`loss_lean_sigmas` of the filtered normal's noise."""
        return max(self.loss_lean_sin, math.sin(self.loss_lean_sigmas * self.filtered_sigma(normal_sigma)))

    def roll_settle_window(self, normal_sigma: float, pad_radius: float) -> float:
        """The travel over which a roll's settle test compares the filtered normal [m]: ``roll_window``, or longer where
        the noise of the difference of two filtered normals (σn √(2 w / (2 − w)) per axis, ``w`` the
        ``normal_filter``, the two a roll's window apart nearly independent) could cancel the turn of a pad still
        rolling over the window (its length over the pad's radius): the window in which the roll turns
        ``roll_settled`` plus ``roll_settle_sigmas`` of that noise. At noise level 4 (σn 4°) the difference scatters
        by 2.1° per axis, and over the 1 mm window a pad rolling at 4.8°/mm read a turn under 1.5° often enough
        that most rolls of HEXPRISM01 at 150 mm (seed 1) settled 20-44° short of the next face; the window is then
        1.9 mm. At noise level 1 (0.5° per axis) it is ``roll_window``."""
        sigma = math.sqrt(2.0) * self.filtered_sigma(normal_sigma)
        return max(self.roll_window, pad_radius * (self.roll_settled + self.roll_settle_sigmas * sigma))

    def contact_threshold(self, force_sigma: float) -> float:
        """Sensed force above which a contact counts [N], for a force sensor of σ ``force_sigma`` [N]."""
        return max(self.contact_fraction * self.force, self.contact_sigmas * force_sigma)


__all__ = ["DOWN", "TouchConfig"]
