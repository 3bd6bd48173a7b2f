"""Controllers of the arm + hand: posture hold, operational-space fingertip control, hybrid force/motion.

All modes are gravity compensated (``qfrc_bias``) and run at a lower rate than the physics: one control
tick computes the arm torques and hand servo targets, then ``mj_step`` advances ``control_every`` physics
steps with them (zero-order hold). The hand's motors are position servos; the controller holds the finger
postures and adds their gravity/bias torque as a target offset (``tau / kp``).

Modes (one active finger, a parameter; the index by default):

- ``posture``: computed-torque joint PD about a held arm posture;
- ``fingertip``: operational-space control (Khatib 1987) of the fingertip position, and orientation unless
  asked not to, through the six arm joints (position-only leaves a joint-posture task in the null space);
- ``hybrid``: regulates the normal force along the SENSED contact normal (feed-forward + PI on the force
  error + normal damping) while moving tangentially; the tangential reference is re-anchored on the
  tangent plane through the tip every tick and its lead is capped, and tangential motion stops after
  contact has been lost for a while (docs/physics-notes.md, pitfalls 3-5). Before the first contact it approaches
  along ``-normal_hint`` at ``approach_speed``.

Only robot-side quantities enter the control law: joint state, the robot's own dynamics and kinematics,
and the fingertip contact readout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from haptic.errors import SceneError
from haptic.geometry.se3 import finite3
from haptic.sim.physics import N_ARM, ContactSummary, Simulation, finger_index
from haptic.sim.scene import ARM_HOME, FINGERS, ROTATION_ATOL, ZERO_VECTOR

_SENSORS_OFF = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
"""The option flag that skips the sensors in a physics step (:meth:`Controller.step`)."""


@dataclass(frozen=True)
class ControlGains:
    """Gains and rates of :class:`Controller` and of the fingertip IK (one home for the controller's numbers)."""

    control_every: int = 5
    """Physics steps per control tick (1 ms steps: 5 -> a 200 Hz control law)."""
    posture_kp: float = 100.0
    """Joint posture stiffness per unit inertia [1/s^2] (computed-torque PD)."""
    posture_kd: float = 20.0
    """Joint posture damping per unit inertia [1/s]."""
    pos_kp: float = 400.0
    """Operational-space position stiffness per unit task mass [1/s^2]."""
    pos_kd: float = 40.0
    """Operational-space position damping per unit task mass [1/s]."""
    rot_kp: float = 300.0
    """Orientation stiffness per unit task inertia [1/s^2]."""
    rot_kd: float = 35.0
    """Orientation damping per unit task inertia [1/s]."""
    force_kp: float = 1.5
    """Proportional gain on the normal-force error [N/N]."""
    force_ki: float = 20.0
    """Integral gain on the normal-force error [1/s]."""
    force_integral_limit: float = 2.0
    """Bound on the integral term [N]."""
    normal_kd: float = 20.0
    """Damping along the normal in hybrid mode, per unit task mass [1/s]."""
    approach_speed: float = 0.01
    """Speed along -normal_hint before the first contact in hybrid mode [m/s]."""
    lead_cap: float = 0.002
    """Largest lead of the tangential reference ahead of the tip [m]."""
    contact_lost_after: float = 0.03
    """Time without contact after which tangential motion stops [s]."""
    contact_fraction: float = 0.1
    """Contact is sensed above max(contact_fraction * force target, contact_sigmas * sigma_F,
    min_contact_force) ..."""
    contact_sigmas: float = 5.0
    """... [-] (sigma_F: the simulated force sensor's noise) ..."""
    min_contact_force: float = 0.02
    """... [N]."""
    task_damping: float = 1e-8
    """Added to the diagonal of the task-space inverse inertia before it is factored (damped least squares:
    exact away from singularities) [-]."""
    ik_damping: float = 1e-4
    """Fingertip IK: damping of its least-squares steps [-] ..."""
    ik_max_step: float = 0.2
    """... the largest joint step per iteration [rad] ..."""
    ik_rotation_weight: float = 0.1
    """... and, choosing the best of its starts when none reaches the target, the weight of the orientation
    error against the position error [m/rad]."""
    normal_filter: float = 0.25
    """Per-tick low-pass weight of a new normal sample (0..1]."""


@dataclass(frozen=True)
class IKResult:
    """Result of a fingertip inverse-kinematics query."""

    reachable: bool
    """True when the target is met within tolerance inside the joint limits."""
    arm_q: np.ndarray
    """Best arm posture found (6,) [rad]."""
    position_error: float
    """Remaining fingertip position error [m]."""
    rotation_error: float
    """Remaining orientation error [rad] (0 when no orientation was asked)."""


@dataclass(frozen=True)
class HybridStatus:
    """What the hybrid controller currently believes (all robot-side)."""

    in_contact: bool
    """Contact sensed within the last ``contact_lost_after``."""
    normal_force: float
    """Last sensed normal force [N]."""
    normal_in_world: np.ndarray | None
    """Filtered sensed normal (3,), out of the touched surface; None before the first contact."""
    reference_in_world: np.ndarray
    """Tangential reference point (3,) [m]."""


def _rotation_error(r: np.ndarray, r_des: np.ndarray) -> np.ndarray:
    """Small-angle orientation error (3,) [rad] taking r to r_des, world frame: ½ Σ_i r_i × r_des_i."""
    return np.array(_rotation_error_list(r, r_des))


def _rotation_error_list(r: np.ndarray, r_des: np.ndarray) -> list[float]:
    """:func:`_rotation_error` as a list of floats (the control law's per-tick path): the same product and the same
    differences, without numpy's per-call overhead on its three entries."""
    a = r_des.dot(r.T).ravel().tolist()
    return [0.5 * (a[7] - a[5]), 0.5 * (a[2] - a[6]), 0.5 * (a[3] - a[1])]


def solve_fingertip_ik(
    sim: Simulation,
    finger: str,
    point_in_world: np.ndarray,
    rotation_in_world: np.ndarray | None = None,
    *,
    arm_q0: np.ndarray | None = None,
    hand_q: np.ndarray | None = None,
    position_tol: float = 1e-4,
    rotation_tol: float = 1e-3,
    max_iters: int = 300,
    gains: ControlGains | None = None,
) -> IKResult:
    """Arm posture putting ``finger``'s pad centre at ``point_in_world`` [m] (and the hand frame -- the
    flange site, z along the fingers -- at ``rotation_in_world`` (3, 3) if given), hand held at ``hand_q``;
    joint limits respected. This is the reachability check of a fingertip target.

    Damped least squares (``gains``: its damping, step and weights) on a scratch copy of the state; the
    simulation itself is not touched.
    """
    g = gains or ControlGains()
    k = finger_index(finger)
    m = sim.model
    d = sim.scratch_data()
    d.qpos[:] = sim.data.qpos
    if hand_q is not None:
        d.qpos[sim.hand] = hand_q
    target = np.asarray(point_in_world, dtype=float)
    site = int(sim.tip_site[k])
    hand_site = int(sim.flange_site)
    lo, hi = m.jnt_range[:N_ARM, 0], m.jnt_range[:N_ARM, 1]
    jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    starts = [sim.data.qpos[sim.arm].copy() if arm_q0 is None else np.asarray(arm_q0, dtype=float)]

    starts.append(ARM_HOME.copy())
    best: IKResult | None = None
    for q0 in starts:
        q = np.clip(q0, lo, hi)
        for _ in range(max_iters):
            d.qpos[sim.arm] = q
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            e_p = target - d.site_xpos[site]
            if rotation_in_world is None:
                e = e_p
                e_r = 0.0
            else:
                rv = _rotation_error(d.site_xmat[hand_site].reshape(3, 3), rotation_in_world)
                e = np.concatenate([e_p, rv])
                e_r = float(np.linalg.norm(rv))
            if np.linalg.norm(e_p) < position_tol and e_r < rotation_tol:
                break
            mujoco.mj_jacSite(m, d, jacp, jacr, site)
            j = jacp[:, sim.arm] if rotation_in_world is None else np.vstack([jacp[:, sim.arm], jacr[:, sim.arm]])
            dq = j.T @ np.linalg.solve(j @ j.T + g.ik_damping * np.eye(len(e)), e)
            n = np.linalg.norm(dq)
            if n > g.ik_max_step:
                dq *= g.ik_max_step / n
            q = np.clip(q + dq, lo, hi)
        d.qpos[sim.arm] = q
        mujoco.mj_kinematics(m, d)
        e_p = float(np.linalg.norm(target - d.site_xpos[site]))
        e_r = 0.0
        if rotation_in_world is not None:
            e_r = float(np.linalg.norm(_rotation_error(d.site_xmat[hand_site].reshape(3, 3), rotation_in_world)))
        res = IKResult(e_p < position_tol and e_r < rotation_tol, q.copy(), e_p, e_r)
        if res.reachable:
            return res
        w = g.ik_rotation_weight
        if best is None or e_p + w * e_r < best.position_error + w * best.rotation_error:
            best = res
    assert best is not None
    return best


@dataclass
class _Hybrid:
    force: float
    velocity: np.ndarray
    normal: np.ndarray | None
    hint: np.ndarray
    reference: np.ndarray
    integral: float = 0.0
    last_contact: float = -np.inf
    sensed: tuple = (0.0, None, None, 0)


class Controller:
    """Gravity-compensated controller of the arm and hand of a :class:`Simulation`.

    Set a mode (``hold_posture``, ``move_fingertip``, ``set_hybrid``), then ``step(ticks)``: every tick
    computes the law once and advances ``gains.control_every`` physics steps.
    """

    def __init__(self, sim: Simulation, finger: str = "index", gains: ControlGains | None = None) -> None:
        self.sim = sim
        self.gains = gains or ControlGains()
        if self.gains.control_every < 1:
            raise SceneError(f"ControlGains.control_every must be >= 1, got {self.gains.control_every}")
        m = sim.model
        self._jac = np.zeros((6, m.nv))
        self._jacp, self._jacr = self._jac[:3], self._jac[3:]
        self._jac_arm = self._jac[:, :N_ARM]
        self._jac_arm_pos_t = self._jac_arm[:3].T  # a view: the arm's position Jacobian transposed (3 of 6 rows)
        self._mfull = np.zeros((m.nv, m.nv))
        self._hand_lo = m.actuator_ctrlrange[sim.hand, 0].copy()
        self._hand_kp = sim.hand_kp
        self._eye3 = np.eye(3)
        self._rotation_tol = ROTATION_ATOL + 1e-5 * self._eye3  # np.allclose's atol + rtol |I| (rtol 1e-5)
        self._rotation_passed = b""  # the bytes of the last rotation argument that passed the check
        self._hand_site = int(sim.flange_site)
        self._m, self._d = sim.model, sim.data
        self._opt = sim.model.opt  # the model's options (a view: the physics steps toggle the sensors in it)
        self._a6 = np.zeros(6)
        self._y6 = np.zeros(6)
        self._jjt = np.zeros((6, 6))
        d = sim.data
        # views into the simulation's state (MjData keeps its buffers): the tick reads and writes them without
        # looking the arrays up again
        self._m6 = self._mfull[:N_ARM, :N_ARM]
        self._qpos_arm, self._qvel, self._qvel_arm = d.qpos[:N_ARM], d.qvel, d.qvel[:N_ARM]
        self._bias_arm, self._bias_hand = d.qfrc_bias[:N_ARM], d.qfrc_bias[N_ARM:]
        self._ctrl_arm, self._ctrl_hand = d.ctrl[:N_ARM], d.ctrl[N_ARM:]
        self._hand_servo = np.zeros(self._hand_kp.size)
        self._hand_xmat = d.site_xmat[self._hand_site].reshape(3, 3)
        self._dt = self.gains.control_every * sim.timestep
        self._threshold = 0.0
        self._threshold_of = math.nan  # the force target the contact threshold was worked out for
        self._finger = 0
        self.set_finger(finger)
        self._mode = "posture"
        self._arm_ref = sim.data.qpos[sim.arm].copy()
        self._hand_ref = sim.data.qpos[sim.hand].copy()
        self._x_ref = np.zeros(3)
        self._x_ref_list = [0.0, 0.0, 0.0]
        self._r_ref: np.ndarray | None = None
        self._hybrid: _Hybrid | None = None

    # -- configuration ----------------------------------------------------------------------------------------
    @property
    def finger(self) -> str:
        """The active finger (the one whose fingertip the task-space modes control)."""
        return FINGERS[self._finger]

    def set_finger(self, finger: str) -> None:
        self._finger = finger_index(finger)
        self._site = int(self.sim.tip_site[self._finger])
        self._tip_xpos = self._d.site_xpos[self._site]  # a view: the active fingertip's position as simulated

    @property
    def mode(self) -> str:
        """``posture``, ``fingertip`` or ``hybrid``."""
        return self._mode

    @property
    def tick_period(self) -> float:
        """Control period [s]."""
        return self.gains.control_every * self.sim.timestep

    def set_hand_posture(self, hand_q: np.ndarray) -> None:
        """Hold the hand at ``hand_q`` (16,) [rad] (``HAND_JOINTS`` order), in every mode."""
        q = np.asarray(hand_q, dtype=float)
        if q.shape != (self._hand_lo.size,):
            raise SceneError(f"hand posture: expected shape ({self._hand_lo.size},), got {q.shape}")
        self._hand_ref = q.copy()

    def hand_posture(self) -> np.ndarray:
        """The held hand posture (16,) [rad]."""
        return self._hand_ref.copy()

    def hold_posture(self, arm_q: np.ndarray | None = None, hand_q: np.ndarray | None = None) -> None:
        """Hold the arm at ``arm_q`` (6,) [rad] (default: where it is) and the hand at ``hand_q``."""
        self._mode = "posture"
        self._arm_ref = self.sim.data.qpos[self.sim.arm].copy() if arm_q is None else np.asarray(arm_q, float)
        if hand_q is not None:
            self.set_hand_posture(hand_q)
        self._hybrid = None

    def fingertip_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Active fingertip site position (3,) [m] and rotation (3, 3) in the world (forward kinematics)."""
        d = self.sim.data
        return d.site_xpos[self._site].copy(), d.site_xmat[self._site].reshape(3, 3).copy()

    def fingertip_position(self) -> np.ndarray:
        """Active fingertip site position (3,) [m] in the world (forward kinematics)."""
        return self._tip_xpos.copy()

    def hand_rotation(self) -> np.ndarray:
        """Rotation (3, 3) ``world_from_hand`` of the hand frame (the flange site, z along the fingers)."""
        return self._hand_xmat.copy()

    def move_fingertip(self, point_in_world: np.ndarray, rotation_in_world: np.ndarray | str | None = "hold") -> None:
        """Servo the active fingertip to ``point_in_world`` [m].

        ``rotation_in_world``: a (3, 3) rotation ``world_from_hand`` of the hand frame (the flange site, z
        along the fingers), ``"hold"`` (its rotation now), or None (position only; the arm posture now
        is kept in the null space). The hand, not the fingertip, is oriented: the finger servos are
        compliant and the arm cannot orient a link beyond them.
        """
        x = np.asarray(point_in_world, dtype=float)
        if x.shape != (3,) or not finite3(x):
            raise SceneError(f"fingertip target: expected a finite (3,) point, got {x!r}")
        self._mode = "fingertip"
        self._x_ref = x.copy()
        self._x_ref_list = x.tolist()
        self._r_ref = self._rotation_arg(rotation_in_world)
        self._arm_ref = self._qpos_arm.copy()
        self._hybrid = None

    def set_hybrid(
        self,
        force: float,
        velocity_in_world: np.ndarray,
        *,
        normal_hint: np.ndarray | None = None,
        rotation_in_world: np.ndarray | str | None = "hold",
        keep_state: bool = True,
    ) -> None:
        """Press with ``force`` [N] along the sensed normal while moving at ``velocity_in_world`` [m/s]
        (its component in the sensed tangent plane is used).

        ``normal_hint``: the expected outward normal, used until a contact normal is sensed (default: the
        last sensed normal, else +z). With ``keep_state`` a running hybrid mode keeps its force integral,
        normal estimate and reference (use it to change the velocity or force mid-stroke).
        """
        v = np.asarray(velocity_in_world, dtype=float)
        if v.shape != (3,) or not finite3(v) or not math.isfinite(force) or force <= 0:
            raise SceneError(f"hybrid target: need force > 0 [N] and a finite (3,) velocity, got {force}, {v!r}")
        prev = self._hybrid if (keep_state and self._mode == "hybrid") else None
        if prev is not None and normal_hint is None:  # a running press, its hint kept (the fast path of a slide)
            prev.force, prev.velocity = float(force), v.copy()
            self._threshold = self._contact_threshold(force)
            return
        hint = np.array([0.0, 0.0, 1.0]) if normal_hint is None else np.asarray(normal_hint, dtype=float)
        size = np.linalg.norm(hint)
        if size < ZERO_VECTOR:
            raise SceneError("hybrid target: normal_hint must be a non-zero vector")
        hint = hint / size
        if prev is not None:
            prev.force, prev.velocity = float(force), v.copy()
            self._threshold = self._contact_threshold(force)
            prev.hint = hint
            return
        x, _ = self.fingertip_pose()
        self._mode = "hybrid"
        self._threshold = self._contact_threshold(force)
        self._r_ref = self._rotation_arg(rotation_in_world)
        self._hybrid = _Hybrid(force=float(force), velocity=v.copy(), normal=None, hint=hint, reference=x)

    def _contact_threshold(self, force: float) -> float:
        """The sensed force above which the hybrid mode counts a contact, for a target ``force`` [N] (worked out again
        only for another force: a slide sets the same one every tick)."""
        if force != self._threshold_of:
            g = self.gains
            self._threshold_of = force
            self._threshold_value = max(g.contact_fraction * float(force), g.contact_sigmas * self.sim.noise.force_std,
                                        g.min_contact_force)  # fmt: skip
        return self._threshold_value

    def hybrid_status(self) -> HybridStatus | None:
        """State of the hybrid mode, or None in another mode."""
        h = self._hybrid
        if h is None:
            return None
        in_contact = self.sim.data.time - h.last_contact <= self.gains.contact_lost_after
        n = None if h.normal is None else h.normal.copy()
        return HybridStatus(in_contact, h.sensed[0], n, h.reference.copy())

    def last_contact(self) -> ContactSummary:
        """The active fingertip's contact as sensed at the last hybrid tick (or now, in other modes)."""
        return ContactSummary(*self.last_contact_values())

    def last_contact_values(self) -> tuple[float, np.ndarray | None, np.ndarray | None, int]:
        """:meth:`last_contact` as a plain tuple (normal force, normal, point, count): the per-tick path."""
        if self._hybrid is not None:
            return self._hybrid.sensed
        return self.sim.sense_contact(self._finger)

    def _rotation_arg(self, rot: np.ndarray | str | None) -> np.ndarray | None:
        if rot is None:
            return None
        if isinstance(rot, str):
            if rot != "hold":
                raise SceneError(f"rotation_in_world: expected a (3, 3) rotation, 'hold' or None, got {rot!r}")
            return self.hand_rotation()
        r = np.asarray(rot, dtype=float)
        if r.shape != (3, 3):
            raise SceneError(f"rotation_in_world: expected a (3, 3) rotation matrix, got {r!r}")
        # np.allclose(rᵀr, I, atol=ROTATION_ATOL) entry by entry, without its overhead, and only for a rotation
        # other than the last one that passed (a free move asks every tick with the same one)
        key = r.tobytes()
        if key != self._rotation_passed:
            if not bool((np.abs(r.T @ r - self._eye3) <= self._rotation_tol).all()):
                raise SceneError(f"rotation_in_world: expected a (3, 3) rotation matrix, got {r!r}")
            self._rotation_passed = key
        return r.copy()

    # -- running -----------------------------------------------------------------------------------------------
    def step(self, ticks: int = 1) -> None:
        """Run ``ticks`` control ticks (each ``gains.control_every`` physics steps).

        The sensors are computed in each tick's last physics step alone: nothing reads them in between, and
        they do not act on the dynamics (the same trajectory and readings, at less cost per step)."""
        m, d, n = self._m, self._d, self.gains.control_every
        tick, step = self._tick, mujoco.mj_step
        opt = self._opt
        flags = opt.disableflags
        quiet = flags | _SENSORS_OFF
        try:
            for _ in range(ticks):
                tick()
                if n > 1:
                    opt.disableflags = quiet
                    step(m, d, n - 1)
                    opt.disableflags = flags
                step(m, d)
        finally:
            opt.disableflags = flags

    def update(self) -> None:
        """Compute the controls for the current state into ``data.ctrl`` without stepping (one tick's law)."""
        self._tick()

    def _tick(self) -> None:
        g = self.gains
        mujoco.mj_fullM(self._m, self._d, self._mfull)
        m6 = self._m6
        if self._mode == "posture":
            e = self._arm_ref - self._qpos_arm
            tau = m6.dot(g.posture_kp * e - g.posture_kd * self._qvel_arm)
        else:
            tau = self._task_torque(m6)
        # MuJoCo clamps ctrl to the actuators' ctrlrange (torque limits, joint ranges) itself
        np.add(tau, self._bias_arm, out=self._ctrl_arm)
        np.divide(self._bias_hand, self._hand_kp, out=self._hand_servo)
        np.add(self._hand_ref, self._hand_servo, out=self._ctrl_hand)

    def _task_torque(self, m6: np.ndarray) -> np.ndarray:
        """Operational-space torque (6,) of the fingertip / hybrid task (bias not included).

        With orientation the task is square: tau = M J^-1 a + J^T f (damped inverse near singularities),
        which equals J^T (Lambda a + f) with Lambda = J^-T M J^-1. Position-only: tau = J^T (Lambda a + f)
        plus a joint-posture task in the dynamically consistent null space.

        The per-tick arithmetic on 3-vectors is done on floats, element by element, and every product of
        vectors and matrices by numpy's own (BLAS) routines: the same operations in the same order as the
        vector form, so the same torques to the last bit (``tests/sim/test_control_law.py``).
        """
        g = self.gains
        jacp, jacr = self._jacp, self._jacr
        mujoco.mj_jacSite(self._m, self._d, jacp, jacr, self._site)  # views into self._jac (6, nv)
        x = self._tip_xpos
        qvel = self._qvel
        v = jacp.dot(qvel)
        if self._mode == "fingertip":
            kp, kd = g.pos_kp, g.pos_kd
            x0, x1, x2 = x.tolist()
            r0, r1, r2 = self._x_ref_list
            v0, v1, v2 = v.tolist()
            a_pos = [kp * (r0 - x0) - kd * v0, kp * (r1 - x1) - kd * v1, kp * (r2 - x2) - kd * v2]
            force = None
        else:
            a_pos, force = self._hybrid_terms(x, v)
        if self._r_ref is not None:
            j = self._jac_arm
            a = self._a6
            e0, e1, e2 = _rotation_error_list(self._hand_xmat, self._r_ref)
            w0, w1, w2 = jacr.dot(qvel).tolist()
            kp, kd = g.rot_kp, g.rot_kd
            a[:] = [*a_pos, kp * e0 - kd * w0, kp * e1 - kd * w1, kp * e2 - kd * w2]
            jjt = self._jjt
            j.dot(j.T, out=jjt)
            mujoco.mju_cholFactor(jjt, g.task_damping)  # damped least squares: exact away from singularities
            mujoco.mju_cholSolve(self._y6, jjt, a)
            tau = m6.dot(self._y6.dot(j))
            if force is not None:
                tau += self._jac_arm_pos_t @ force
            return tau
        a_pos = np.array(a_pos)
        d = self._d
        jp = jacp[:, :N_ARM]
        m6_inv = np.linalg.inv(m6)
        lam_inv = jp @ m6_inv @ jp.T
        lam_inv.flat[::4] += g.task_damping
        lam = np.linalg.inv(lam_inv)
        f = lam @ a_pos
        if force is not None:
            f += force
        tau = jp.T @ f
        jbar = m6_inv @ jp.T @ lam  # dynamically consistent generalised inverse
        e = self._arm_ref - d.qpos[:N_ARM]
        tau += (m6 @ (g.posture_kp * e - g.posture_kd * qvel[:N_ARM])) @ (np.eye(N_ARM) - jbar @ jp)
        return tau

    def _hybrid_terms(self, x: np.ndarray, v: np.ndarray) -> tuple[list[float], np.ndarray | None]:
        """Task acceleration (3,) and the normal force to add (3,) or None, of the hybrid law.

        Element-wise arithmetic on floats, the dot products by numpy (see :meth:`_task_torque`)."""
        g, h = self.gains, self._hybrid
        t = self._d.time
        sensed = self.sim.sense_contact(self._finger)
        h.sensed = sensed
        force, normal = sensed[0], sensed[1]
        n = h.normal
        if normal is not None and force > self._threshold:
            if n is None:
                n = h.normal = normal
            else:
                k = g.normal_filter
                p0, p1, p2 = n.tolist()
                q0, q1, q2 = normal.tolist()
                f0, f1, f2 = p0 + k * (q0 - p0), p1 + k * (q1 - p1), p2 + k * (q2 - p2)
                nf = np.array([f0, f1, f2])
                size = math.sqrt(float(nf.dot(nf)))
                n = h.normal = np.array([f0 / size, f1 / size, f2 / size])  # nf / size, element by element
            h.last_contact = t
        if n is None:
            n = h.hint
        n0, n1, n2 = n.tolist()
        x0, x1, x2 = x.tolist()
        v0, v1, v2 = v.tolist()
        v_n = float(n.dot(v))
        kp, kd = g.pos_kp, g.pos_kd
        if t - h.last_contact > g.contact_lost_after:
            # approach (or re-acquire) along -n at approach_speed, hold the tangential position
            d_ref = h.reference - x
            s = float(n.dot(d_ref))
            d0, d1, d2 = d_ref.tolist()
            d0, d1, d2 = d0 - s * n0, d1 - s * n1, d2 - s * n2
            h.reference = np.array([x0 + d0, x1 + d1, x2 + d2])
            e0, e1, e2 = kp * d0 - kd * v0, kp * d1 - kd * v1, kp * d2 - kd * v2
            c = kd * (-g.approach_speed - v_n) - float(n.dot(np.array([e0, e1, e2])))
            return [e0 + c * n0, e1 + c * n1, e2 + c * n2], None
        dt = self._dt
        err = h.force - force
        h.integral = min(max(h.integral + g.force_ki * err * dt, -g.force_integral_limit), g.force_integral_limit)
        f_n = max(h.force + g.force_kp * err + h.integral, 0.0)
        u = h.velocity
        s = float(n.dot(u))
        u0, u1, u2 = u.tolist()
        t0, t1, t2 = u0 - s * n0, u1 - s * n1, u2 - s * n2  # the velocity in the tangent plane
        r0, r1, r2 = h.reference.tolist()
        l0, l1, l2 = r0 - x0 + dt * t0, r1 - x1 + dt * t1, r2 - x2 + dt * t2
        s = float(n.dot(np.array([l0, l1, l2])))
        l0, l1, l2 = l0 - s * n0, l1 - s * n1, l2 - s * n2  # re-anchor on the tangent plane through the tip
        lead = np.array([l0, l1, l2])
        dist = math.sqrt(float(lead.dot(lead)))
        if dist > g.lead_cap:
            k = g.lead_cap / dist  # cap the lead of the reference
            l0, l1, l2 = l0 * k, l1 * k, l2 * k
        h.reference = np.array([x0 + l0, x1 + l1, x2 + l2])
        e0, e1, e2 = kp * l0 + kd * (t0 - v0), kp * l1 + kd * (t1 - v1), kp * l2 + kd * (t2 - v2)
        c = float(n.dot(np.array([e0, e1, e2]))) + g.normal_kd * v_n
        return [e0 - c * n0, e1 - c * n1, e2 - c * n2], np.array([-f_n * n0, -f_n * n1, -f_n * n2])
