"""The robot as an executor sees it: commands to the controller and sensor readings, nothing else.

:class:`RobotInterface` is the handle an executor gets. It has no public path to the MuJoCo model or
data, the scene, or the ground truth: its readings are :class:`~haptic.sim.physics.SensorReading`
snapshots (joint encoders, fingertip forward kinematics, touch, per-fingertip contact point / normal /
force), and its commands go to the :class:`~haptic.sim.control.Controller`. Evaluation code that needs
the object's pose asks the :class:`~haptic.sim.physics.Simulation` (``ground_truth()``), which an
executor is never given.
"""

from __future__ import annotations

import numpy as np

from haptic.sim.control import Controller, HybridStatus, IKResult, solve_fingertip_ik
from haptic.sim.physics import (
    LINK_CHAINS,
    LINK_NAMES,
    ContactSummary,
    LinkContact,
    LinkGeom,
    SensorReading,
    Simulation,
    finger_index,
)
from haptic.sim.scene import FINGERS


class RobotInterface:
    """Robot-side handle: read sensors, command the controller, advance time."""

    __slots__ = ("_ctl", "_sim")

    def __init__(self, sim: Simulation, controller: Controller | None = None) -> None:
        self._sim = sim
        self._ctl = controller or Controller(sim)

    fingers = FINGERS
    """Finger names, in the order of every per-finger array."""
    link_names = LINK_NAMES
    """Names of the rows of :meth:`link_array` and :meth:`link_poses` (the arm's and the hand's links, then the
    fingertip pads)."""
    link_chains = LINK_CHAINS
    """The hand's skeleton as polylines of :attr:`link_names` (the wrist to the palm, the palm along each
    finger)."""

    # -- sensing ----------------------------------------------------------------------------------------------
    def read(self) -> SensorReading:
        """What the robot senses now (encoders, fingertip kinematics, touch, contacts), noise applied."""
        return self._sim.read_sensors()

    def sense_contact(self, finger: str) -> ContactSummary:
        """Aggregated contact of one fingertip (total normal force, mean normal and point), noise applied."""
        return self._sim.contact_summary(self._ctl_finger_index(finger))

    def sense_contact_values(self, finger: str) -> tuple[float, np.ndarray | None, np.ndarray | None, int]:
        """:meth:`sense_contact` as a plain tuple (normal force, normal, point, count): the per-tick path."""
        return self._sim.sense_contact(finger_index(finger))

    def link_contacts(self) -> tuple[LinkContact, ...]:
        """The contacts of the robot's links other than the fingertip pads (:attr:`SensorReading.link_contacts`)
        alone, noise applied, without reading the other sensors (no noise drawn when there are none)."""
        return self._sim.link_contacts()

    def watch_links(self) -> tuple[LinkContact, ...]:
        """:meth:`link_contacts` as watched all through a move (its noise drawn apart, so that watching changes no
        other reading)."""
        return self._sim.link_contacts(watch=True)

    def watch_wrist(self) -> tuple[np.ndarray, np.ndarray]:
        """The wrist force/torque sensor's force and torque (world frame) as watched all through a move (its noise
        drawn apart, so that watching changes no other reading)."""
        return self._sim.wrist_wrench(watch=True)

    def hand_inertia_force(self) -> np.ndarray:
        """The wrist force sensor's reading of the hand touching nothing, moving as it moves now (the robot's own
        masses and the motion of its joints) [N]."""
        return self._sim.hand_inertia_force()

    def hand_weight(self) -> np.ndarray:
        """The wrist force sensor's reading of the hand touching nothing, at rest (the robot's own masses) [N]."""
        return self._sim.hand_weight()

    def link_radii(self) -> dict[str, float]:
        """Per link, the radius of its thickest collision geom [m]: the bound of a point its readout reports
        (the robot's own geometry)."""
        return self._sim.link_radii()

    @property
    def time(self) -> float:
        """Simulation time [s]."""
        return self._sim.time

    @property
    def tick_period(self) -> float:
        """Duration of one control tick [s]."""
        return self._ctl.tick_period

    # -- commanding ---------------------------------------------------------------------------------------------
    @property
    def finger(self) -> str:
        """The active finger of the task-space modes."""
        return self._ctl.finger

    def set_finger(self, finger: str) -> None:
        self._ctl.set_finger(finger)

    def set_hand_posture(self, hand_q: np.ndarray) -> None:
        self._ctl.set_hand_posture(hand_q)

    def hold_posture(self, arm_q: np.ndarray | None = None, hand_q: np.ndarray | None = None) -> None:
        self._ctl.hold_posture(arm_q, hand_q)

    def move_fingertip(self, point_in_world: np.ndarray, rotation_in_world: np.ndarray | str | None = "hold") -> None:
        self._ctl.move_fingertip(point_in_world, rotation_in_world)

    def set_hybrid(
        self,
        force: float,
        velocity_in_world: np.ndarray,
        *,
        normal_hint: np.ndarray | None = None,
        rotation_in_world: np.ndarray | str | None = "hold",
        keep_state: bool = True,
    ) -> None:
        """:meth:`~haptic.sim.control.Controller.set_hybrid` (a slide sets it every tick)."""
        self._ctl.set_hybrid(force, velocity_in_world, normal_hint=normal_hint, rotation_in_world=rotation_in_world,
                             keep_state=keep_state)  # fmt: skip

    def hybrid_status(self) -> HybridStatus | None:
        return self._ctl.hybrid_status()

    def last_contact(self) -> ContactSummary:
        """The active fingertip's contact as the controller sensed it at its last hybrid tick (noise applied);
        in the other modes, sensed now."""
        return self._ctl.last_contact()

    def last_contact_values(self) -> tuple[float, np.ndarray | None, np.ndarray | None, int]:
        """:meth:`last_contact` as a plain tuple (normal force, normal, point, count): the per-tick path."""
        return self._ctl.last_contact_values()

    def is_stable(self) -> bool:
        """False when the simulation state is not finite or MuJoCo has raised a warning (instability)."""
        return self._sim.state_is_finite() and not self._sim.warned()

    def link_array(self) -> np.ndarray:
        """World positions (len(link_names), 3) [m] of the robot's own links (elbow, wrist, palm, each
        finger's link bodies, the rest of the arm, the fingertip pads) by forward kinematics; nothing of the
        object."""
        return self._sim.link_positions()

    def link_poses(self) -> np.ndarray:
        """Poses (len(link_names), 7) of the same links: position [m] then quaternion (w, x, y, z), world frame
        (forward kinematics)."""
        return self._sim.link_poses()

    def link_geoms(self) -> tuple[LinkGeom, ...]:
        """The robot's own collision geometry per link (posed by :meth:`link_poses`) and the table top of its
        workspace: for drawing the robot as it is; nothing of the object."""
        return self._sim.link_geoms()

    def fingertip_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Active fingertip position (3,) [m] and hand rotation (3, 3), from the joint encoders."""
        return self._ctl.fingertip_position(), self._ctl.hand_rotation()

    def arm_posture(self) -> np.ndarray:
        """The arm's joint angles (6,) [rad] from its encoders, without reading the other sensors (no noise
        drawn)."""
        return self._sim.data.qpos[self._sim.arm].copy()

    def reachable(
        self, finger: str, point_in_world: np.ndarray, rotation_in_world: np.ndarray | None = None,
        arm_q0: np.ndarray | None = None,
    ) -> IKResult:  # fmt: skip
        """Whether ``finger`` can put its pad centre at ``point_in_world`` (hand held as commanded); the solver
        starts from the arm's joint angles now, or from ``arm_q0``."""
        return solve_fingertip_ik(self._sim, finger, point_in_world, rotation_in_world, arm_q0=arm_q0,
                                  hand_q=self._ctl.hand_posture())  # fmt: skip

    def step(self, ticks: int = 1) -> None:
        """Advance ``ticks`` control ticks."""
        self._ctl.step(ticks)

    def _ctl_finger_index(self, finger: str) -> int:
        return finger_index(finger)
