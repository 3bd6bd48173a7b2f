"""The one owner of the MuJoCo simulation, and the robot-side sensor readout.

:class:`Simulation` holds the ``MjModel`` / ``MjData`` and resolves every id once, at construction.
What a robot senses -- joint encoders, forward kinematics of the fingertips, fingertip touch force and the
per-fingertip contact readout (point, normal, force vector via ``mj_contactForce``) -- is returned as plain
frozen records (:class:`SensorReading`, :class:`FingertipContact`) that hold numbers only, never a handle
to the model or data, so nothing read through them can reveal the object's pose or geometry. Ground truth
(the object and its pose) is a separate method, :meth:`Simulation.ground_truth`, for evaluation code.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from haptic.errors import SceneError
from haptic.matching.components import NoiseModel
from haptic.sim.scene import (
    ARM_HOME,
    ARM_JOINTS,
    ARM_PREFIX,
    FINGER_PREFIX,
    FINGERS,
    HAND_JOINTS,
    HAND_PREFIX,
    HAND_TRACE,
    ComposedScene,
    SceneObject,
)

N_ARM = len(ARM_JOINTS)
N_HAND = len(HAND_JOINTS)

WARNINGS = {name: int(w) for name, w in mujoco.mjtWarning.__members__.items() if name != "mjNWARNING"}
"""MuJoCo warning kinds by name (``mjWARN_*``) -> index into ``data.warning``."""


PATCH = 0.003
"""Pad contacts closer than this to one another are one patch of contact [m]."""


def merge_patches(points: np.ndarray, normals: np.ndarray, forces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The sensed point and normal of several pad contacts: each patch (contacts within :data:`PATCH` of one
    another) sensed as its strongest contact, the patches averaged by force (see
    :meth:`Simulation.sense_contact`)."""
    n = len(points)
    keep = [i for i in range(n)
            if not any(j != i and (forces[j], -j) > (forces[i], -i) and np.linalg.norm(points[j] - points[i]) < PATCH
                       for j in range(n))]  # fmt: skip
    fk = forces[keep]
    w = fk / fk.sum() if fk.sum() > 0 else np.full(len(keep), 1.0 / len(keep))
    normal = w @ normals[keep]
    return w @ points[keep], normal / math.sqrt(float(normal @ normal))


WRIST_TORQUE_LEVER = 0.1
"""The wrist sensor's torque noise is its force noise at this lever arm, about the distance from the wrist to the
fingertips [m]."""


@dataclass(frozen=True)
class SimulatedSensorNoise:
    """Zero-mean Gaussian noise of the simulated sensors, per sample (all zero: ideal sensors): the per-sample
    part of :class:`~haptic.matching.components.NoiseModel` at its level (:meth:`from_model`). The matcher and
    planner work with the bounds of segmented components instead (the model's fitted part)."""

    force_std: float = 0.0
    """σF: touch / contact normal force [N]."""
    normal_std: float = 0.0
    """σn: contact normal direction, per tangent axis [rad]."""
    point_std: float = 0.0
    """σp: contact point, per axis [m]."""
    joint_std: float = 0.0
    """Joint encoder [rad]."""
    torque_std: float = 0.0
    """The wrist sensor's torque, per axis [N m] (its force per axis: ``force_std``)."""

    @property
    def any(self) -> bool:
        """True when some sensor is noisy."""
        return self.force_std > 0 or self.normal_std > 0 or self.point_std > 0 or self.joint_std > 0

    @classmethod
    def from_model(cls, model: NoiseModel) -> SimulatedSensorNoise:
        """The per-sample noise of ``model`` at its level (the wrist torque's: its force's at
        :data:`WRIST_TORQUE_LEVER`)."""
        k = model.level
        return cls(model.force_std * k, model.normal_std * k, model.point_std * k, model.joint_std * k,
                   model.force_std * k * WRIST_TORQUE_LEVER)  # fmt: skip

    @classmethod
    def from_notes(cls) -> SimulatedSensorNoise:
        """The levels of docs/physics-notes.md (σF 0.02 N, σn 1°, σp 0.2 mm): :meth:`from_model` at level 1."""
        return cls.from_model(NoiseModel())


@dataclass(frozen=True)
class FingertipContact:
    """One contact of a fingertip pad with anything, as the fingertip senses it (world frame)."""

    point_in_world: np.ndarray
    """Contact point (3,) [m]."""
    normal_in_world: np.ndarray
    """Unit normal (3,) of the touched surface, pointing out of it towards the fingertip."""
    force_in_world: np.ndarray
    """Force (3,) exerted on the fingertip by the touched surface [N] (normal + friction)."""
    normal_force: float
    """Component of the force along the normal [N] (>= 0 while pressing)."""


@dataclass(frozen=True)
class LinkContact:
    """A contact of a robot link other than a fingertip pad with anything (the object, the table), as the
    link's contact readout senses it (world frame): where the hand touches what it did not mean to."""

    link: str
    """The link's name (one of :data:`LINK_NAMES`)."""
    point_in_world: np.ndarray
    """Contact point (3,) [m]."""
    normal_in_world: np.ndarray
    """Unit normal (3,) of the touched surface, pointing out of it towards the link."""
    normal_force: float
    """Force along the normal [N]."""


@dataclass(frozen=True)
class SensorReading:
    """A snapshot of what the robot senses. Per-finger arrays follow ``FINGERS`` order."""

    time: float
    """Simulation time of the reading [s]."""
    arm_q: np.ndarray
    """Arm joint angles (6,) [rad] (encoders)."""
    arm_qd: np.ndarray
    """Arm joint velocities (6,) [rad/s]."""
    hand_q: np.ndarray
    """Hand joint angles (16,) [rad] (encoders), ``HAND_JOINTS`` order."""
    hand_qd: np.ndarray
    """Hand joint velocities (16,) [rad/s]."""
    fingertip_in_world: np.ndarray
    """Fingertip pad centres (4, 3) [m], forward kinematics of the encoders."""
    touch: np.ndarray
    """Touch sensor per fingertip (4,) [N]: sum of normal forces inside the tip site."""
    contacts: tuple[tuple[FingertipContact, ...], ...]
    """Per fingertip, its pad's contacts (possibly none)."""
    wrist_force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """The wrist force/torque sensor's force (3,) [N], world frame: what the flange exerts on the hand (the
    hand's weight and every contact of the hand, pads and links)."""
    wrist_torque: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """... its torque (3,) [N m] about the wrist site (the hand's origin at the flange), world frame."""
    link_contacts: tuple[LinkContact, ...] = ()
    """Contacts of the robot's links other than the fingertip pads (the palm, the finger links, the arm)."""

    def finger(self, name: str) -> int:
        """Index of finger ``name`` in the per-finger arrays."""
        return finger_index(name)


@dataclass(frozen=True)
class ContactSummary:
    """The aggregated contact of one fingertip, as the controller uses it (sensed, with noise)."""

    normal_force: float
    """Sum of pad normal forces [N] (0 without contact)."""
    normal_in_world: np.ndarray | None
    """Force-weighted mean unit normal (3,) out of the touched surface, or None without contact."""
    point_in_world: np.ndarray | None
    """Force-weighted mean contact point (3,) [m], or None without contact."""
    count: int
    """Number of pad contacts."""


_NO_CONTACT = ContactSummary(0.0, None, None, 0)


@dataclass(frozen=True)
class GroundTruth:
    """What the simulator knows and the robot does not. For evaluation code only."""

    object: SceneObject | None
    """The object (name and convex pieces in its own frame)."""
    world_from_object: np.ndarray
    """Object pose (4, 4) [m]."""


HAND_LINK_PARTS = ("base", "proximal", "medial", "distal")
"""The link bodies of each finger, from the palm out."""


def hand_link_bodies() -> tuple[tuple[str, str], ...]:
    """(link name, MuJoCo body name) of the robot links :meth:`Simulation.link_positions` reports (robot
    bodies only): the elbow and the wrist of the arm (the forearm between them), the palm, each finger's link
    bodies, then the rest of the arm's bodies that carry collision geometry (the base on the stand, the
    waist, the shoulder, the wrist's pitch link)."""
    out = [("elbow", ARM_PREFIX + "link3"), ("wrist", ARM_PREFIX + "link6"), ("palm", HAND_PREFIX + "palm")]
    for f in FINGERS:
        out.extend((f"{f}_{part}", f"{HAND_PREFIX}{FINGER_PREFIX[f]}_{part}") for part in HAND_LINK_PARTS)
    out.extend((("base", ARM_PREFIX + "base"), ("waist", ARM_PREFIX + "link1"), ("shoulder", ARM_PREFIX + "link2"),
                ("wrist_pitch", ARM_PREFIX + "link5")))  # fmt: skip
    return tuple(out)


LINK_NAMES: tuple[str, ...] = tuple(n for n, _ in hand_link_bodies()) + tuple(f"{f}_tip" for f in FINGERS)
"""Names of the rows of :meth:`Simulation.link_positions`: the link bodies' origins, then each fingertip's pad
centre."""

LINK_CHAINS: tuple[tuple[str, ...], ...] = (("elbow", "wrist", "palm"),) + tuple(
    ("palm", *(f"{f}_{part}" for part in HAND_LINK_PARTS), f"{f}_tip") for f in FINGERS
)
"""The hand's skeleton as polylines of :data:`LINK_NAMES`: the forearm (elbow to wrist) on to the palm, and the
palm out along each finger to its pad."""


GEOM_KINDS = {
    int(mujoco.mjtGeom.mjGEOM_SPHERE): "sphere",
    int(mujoco.mjtGeom.mjGEOM_CAPSULE): "capsule",
    int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder",
    int(mujoco.mjtGeom.mjGEOM_BOX): "box",
    int(mujoco.mjtGeom.mjGEOM_ELLIPSOID): "ellipsoid",
    int(mujoco.mjtGeom.mjGEOM_MESH): "mesh",
}
"""The MuJoCo geom types :class:`LinkGeom` describes, by name."""


@dataclass(frozen=True)
class LinkGeom:
    """One collision geom of the robot, in the frame of the link it moves with, or a fixed piece of the
    workspace (the table top) in the world frame: what a recording draws of the robot as it is."""

    link: str | None
    """Name in :data:`LINK_NAMES` of the link it moves with; None: fixed in the world."""
    name: str
    """MuJoCo geom name (may be empty)."""
    kind: str
    """``sphere``, ``capsule``, ``cylinder``, ``box``, ``ellipsoid`` or ``mesh``."""
    size: tuple[float, float, float]
    """MuJoCo ``geom_size``: radius (sphere); radius, half-length along z (capsule, cylinder); half-sizes
    (box, ellipsoid) [m]."""
    pose: np.ndarray
    """Position (3,) [m] and quaternion (w, x, y, z) of the geom in the link frame (world frame when ``link``
    is None), as (7,)."""
    rgba: tuple[float, float, float, float]
    """Colour in [0, 1]: the geom's own when opaque (the pads), else the link's visual paint."""
    vertices: np.ndarray | None = None
    """Mesh vertices (n, 3) in the geom frame [m] (meshes only)."""
    triangles: np.ndarray | None = None
    """Mesh triangles (m, 3), indices into ``vertices`` (meshes only)."""


def finger_index(name: str) -> int:
    """Index of a finger name in ``FINGERS``; :class:`SceneError` lists the valid names."""
    try:
        return FINGERS.index(name)
    except ValueError:
        raise SceneError(f"unknown finger {name!r}; valid fingers: {', '.join(FINGERS)}") from None


class Simulation:
    """The one owner of the MuJoCo model and data of a composed scene.

    Ids, addresses and slices are resolved once here; everything else uses them.
    """

    def __init__(
        self,
        scene: ComposedScene,
        *,
        noise: SimulatedSensorNoise | None = None,
        seed: int = 0,
    ) -> None:
        self._scene = scene
        self.model: mujoco.MjModel = scene.compile()
        self.data: mujoco.MjData = mujoco.MjData(self.model)
        self.noise = noise or SimulatedSensorNoise()
        self._noisy = self.noise.any  # asked every tick (the noise is fixed)
        self._seed = seed
        self._rng = np.random.default_rng(seed)
        m = self.model

        def jid(name: str) -> int:
            i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
            if i < 0:
                raise SceneError(f"scene: joint {name!r} not found; is the robot attached (arm at 'arm_mount')?")
            return i

        arm_j = [jid(ARM_PREFIX + n) for n in ARM_JOINTS]
        hand_j = [jid(HAND_PREFIX + n) for n in HAND_JOINTS]
        qadr = np.array([m.jnt_qposadr[j] for j in arm_j + hand_j])
        dadr = np.array([m.jnt_dofadr[j] for j in arm_j + hand_j])
        n = N_ARM + N_HAND
        if not (np.array_equal(qadr, np.arange(n)) and np.array_equal(dadr, np.arange(n))) or m.nv != n:
            raise SceneError(
                f"scene: expected the robot's {n} hinge joints to be the first and only dofs (arm then hand), "
                f"got qpos addresses {qadr.tolist()} with nv={m.nv}; the object must be static"
            )
        self.arm = slice(0, N_ARM)
        """Slice of the arm joints in qpos / qvel / ctrl."""
        self.hand = slice(N_ARM, N_ARM + N_HAND)
        """Slice of the hand joints in qpos / qvel / ctrl."""
        act_j = m.actuator_trnid[:, 0]
        if m.nu != n or not np.array_equal(act_j, np.array(arm_j + hand_j)):
            raise SceneError(f"scene: expected {n} actuators, one per robot joint in order; got {m.nu}")
        self.hand_kp = m.actuator_gainprm[self.hand, 0].copy()
        """Position-servo stiffness of the hand motors [N m/rad]."""

        def oid(kind: mujoco.mjtObj, name: str) -> int:
            i = mujoco.mj_name2id(m, kind, name)
            if i < 0:
                raise SceneError(f"scene: {kind.name[6:].lower()} {name!r} not found in the hand")
            return i

        pre = [HAND_PREFIX + FINGER_PREFIX[f] for f in FINGERS]
        self.tip_site = np.array([oid(mujoco.mjtObj.mjOBJ_SITE, p + "_tip") for p in pre])
        self._tip_site_list: list[int] = self.tip_site.tolist()
        self.pad_geom = np.array([oid(mujoco.mjtObj.mjOBJ_GEOM, p + "_pad") for p in pre])
        touch = [oid(mujoco.mjtObj.mjOBJ_SENSOR, p + "_touch") for p in pre]
        self.touch_adr = np.array([m.sensor_adr[s] for s in touch])
        self.flange_site = oid(mujoco.mjtObj.mjOBJ_SITE, ARM_PREFIX + "flange")
        self.link_body = np.array([oid(mujoco.mjtObj.mjOBJ_BODY, b) for _, b in hand_link_bodies()])
        """Body ids of the robot links of :data:`LINK_NAMES` (robot bodies only, never the object)."""
        self._link_geoms: tuple[LinkGeom, ...] | None = None
        self._geom_finger = np.full(m.ngeom, -1, dtype=int)
        self._geom_finger[self.pad_geom] = np.arange(len(FINGERS))
        self._geom_finger_list: list[int] = self._geom_finger.tolist()
        self._geom_link = self._robot_geom_links()
        """Per geom: the index in :data:`LINK_NAMES` of the robot link it belongs to (-1: a pad, the object,
        the table)."""
        self._geom_link_list: list[int] = self._geom_link.tolist()
        ft = [oid(mujoco.mjtObj.mjOBJ_SENSOR, HAND_PREFIX + n) for n in ("wrist_force", "wrist_torque")]
        self.wrist_adr = np.concatenate([m.sensor_adr[s] + np.arange(3) for s in ft])
        self.wrist_site = oid(mujoco.mjtObj.mjOBJ_SITE, HAND_PREFIX + "wrist_ft")
        root = int(m.site_bodyid[self.wrist_site])
        below = [b for b in range(m.nbody) if b == root or self._descends(b, root)]
        self._hand_bodies = tuple(below)  # the bodies whose weight and motion the wrist's sensor carries
        self._hand_masses = tuple((b, float(m.body_mass[b])) for b in below)
        self._acc6 = np.zeros(6)
        self.home_key = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home")
        self._force6 = np.zeros(6)
        self._force3 = self._force6[:3]  # a view: the contact force's normal and tangential parts
        self._contact_views: dict[int, tuple[np.ndarray, np.ndarray, list[np.ndarray], list[np.ndarray]]] = {}
        self._scratch: mujoco.MjData | None = None
        self.reset()

    def _descends(self, body: int, root: int) -> bool:
        """Whether ``body`` hangs below ``root`` in the kinematic tree."""
        parent = self.model.body_parentid
        while body != 0:
            body = int(parent[body])
            if body == root:
                return True
        return False

    # -- state ---------------------------------------------------------------------------------------------
    def reset(self, arm_q: np.ndarray | None = None, hand_q: np.ndarray | None = None) -> None:
        """Reset to the ``home`` keyframe (or the given postures [rad]) at rest; re-seed the sensor noise."""
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        d.qpos[self.arm] = ARM_HOME if arm_q is None else arm_q
        d.qpos[self.hand] = HAND_TRACE if hand_q is None else hand_q
        d.ctrl[self.hand] = d.qpos[self.hand]
        self._rng = np.random.default_rng(self._seed)
        # the added senses draw their noise apart, so that the fingertip's readings are those of the same seed
        self._senses_rng = np.random.default_rng([self._seed, 1])
        # the links' readout watched through a move draws apart again: watching leaves every other reading as it was
        self._watch_rng = np.random.default_rng([self._seed, 2])
        # and the wrist's watched through a move apart from those
        self._wrist_rng = np.random.default_rng([self._seed, 3])
        mujoco.mj_forward(m, d)

    def _robot_geom_links(self) -> np.ndarray:
        """Per geom, the :data:`LINK_NAMES` index of the robot link body it hangs from (its own body or the
        nearest ancestor among them); -1 for the fingertip pads and every geom not of the robot."""
        m = self.model
        link_of = {int(b): i for i, b in enumerate(self.link_body)}
        out = np.full(m.ngeom, -1, dtype=int)
        for g in range(m.ngeom):
            b = int(m.geom_bodyid[g])
            while b > 0 and b not in link_of:
                b = int(m.body_parentid[b])
            if b in link_of and g not in set(self.pad_geom.tolist()) and m.geom_contype[g] | m.geom_conaffinity[g]:
                out[g] = link_of[b]
        return out

    def scratch_data(self) -> mujoco.MjData:
        """A second ``MjData`` of the model, for what must not touch the simulation (the fingertip IK's kinematics):
        made once; each user sets the joint positions it works at (the kinematics depend on nothing else)."""
        if self._scratch is None:
            self._scratch = mujoco.MjData(self.model)
        return self._scratch

    def step(self, n: int = 1) -> None:
        """Advance ``n`` physics steps with the current controls (``mj_step`` with ``nstep``)."""
        mujoco.mj_step(self.model, self.data, nstep=n)

    @property
    def time(self) -> float:
        """Simulation time [s]."""
        return float(self.data.time)

    @property
    def timestep(self) -> float:
        """Physics time step [s]."""
        return float(self.model.opt.timestep)

    def warnings(self) -> dict[str, int]:
        """MuJoCo warning counters that are non-zero, by name."""
        w = self.data.warning
        return {name: int(w[i].number) for name, i in WARNINGS.items() if w[i].number}

    def warned(self) -> bool:
        """Whether some MuJoCo warning counter is non-zero (:meth:`warnings` without naming them)."""
        return bool(self.data.warning.number.any())

    def state_is_finite(self) -> bool:
        d = self.data
        return bool(np.isfinite(d.qpos).all() and np.isfinite(d.qvel).all() and np.isfinite(d.qacc).all())

    def ground_truth(self) -> GroundTruth:
        """The object and its pose -- for evaluation only; never hand this to an executor."""
        return GroundTruth(object=self._scene.object, world_from_object=self._scene.world_from_object.copy())

    # -- robot-side readout -----------------------------------------------------------------------------------
    def _noisy_normal(self, n: np.ndarray) -> np.ndarray:
        s = self.noise.normal_std
        if s <= 0:
            return n
        out = n + s * self._rng.standard_normal(3)
        out -= np.dot(out - n, n) * n  # perturb in the tangent plane only
        return out / np.linalg.norm(out)

    def _contacts(self) -> tuple[list[list[int]], np.ndarray, list[np.ndarray], list[np.ndarray]]:
        """The contacts now: their geom pairs (a list), constraint addresses (ncon,), frames (each (3, 3), the normal
        first) and points (each (3,)). The arrays are views of the data's contact buffer, made once per number of
        contacts: MuJoCo puts every step's contacts at the start of the data's arena, and making the views is most
        of reading a contact (about 2 µs each, where reading their values is a tenth of that)."""
        n = self.data.ncon
        views = self._contact_views.get(n)
        if views is None:
            con = self.data.contact
            views = self._contact_views[n] = (con.geom, con.efc_address, [f.reshape(3, 3) for f in con.frame],
                                              list(con.pos))  # fmt: skip
        geom, efc, frames, points = views
        return geom.tolist(), efc, frames, points

    def _pad_contacts(self, finger: int | None):
        """Raw (finger, point, normal-out-of-surface, force-on-pad) for pad contacts, ideal sensing."""
        d = self.data
        out = []
        if d.ncon == 0:
            return out
        owner = self._geom_finger_list
        geoms, efc, frames, points = self._contacts()
        for i, (g1, g2) in enumerate(geoms):
            k1, k2 = owner[g1], owner[g2]
            if finger is None:
                if k1 < 0 and k2 < 0:
                    continue
            elif k1 != finger and k2 != finger:
                continue
            if efc[i] < 0:  # excluded or inactive contact
                continue
            mujoco.mj_contactForce(self.model, d, i, self._force6)
            frame = frames[i]
            f = self._force3.dot(frame)  # force of geom1 on geom2, world frame
            if k1 >= 0 and (finger is None or k1 == finger):
                # the pad is geom1: flip into "on the pad, out of the touched surface" (normal: geom1 -> geom2)
                out.append((k1, points[i].copy(), -frame[0], -f))
            else:
                out.append((k2, points[i].copy(), frame[0].copy(), f))
        return out

    def contact_summary(self, finger: int) -> ContactSummary:
        """Aggregated sensed contact of one fingertip (noise applied): total normal force, force-weighted
        mean normal and point over the contact patches (see :meth:`sense_contact`)."""
        return ContactSummary(*self.sense_contact(finger))

    def sense_contact(self, finger: int) -> tuple[float, np.ndarray | None, np.ndarray | None, int]:
        """:meth:`contact_summary` as a plain tuple (the controller's fast path).

        Contacts within :data:`PATCH` of one another are one patch of the pad on the surface, sensed as the
        patch's strongest contact: a non-convex object is simulated as convex pieces, and a pad pressing a
        face next to the seam of two coplanar pieces also touches the neighbour's edge there, at a normal
        tilted by several degrees, which a real surface does not have. Separate patches (the pad in a
        corner, on two faces at once) are averaged, weighted by force."""
        raw = self._pad_contacts(finger)
        if not raw:
            return 0.0, None, None, 0
        if len(raw) == 1:
            _, point, normal, f = raw[0]
            total = max(float(f.dot(normal)), 0.0)
        else:
            fn = np.array([max(float(f @ n), 0.0) for _, _, n, f in raw])
            total = float(fn.sum())
            point, normal = merge_patches(np.array([p for _, p, _, _ in raw]), np.array([n for _, _, n, _ in raw]), fn)
        nz = self.noise
        if self._noisy:  # element by element on floats, the dot products by numpy: the vector form's arithmetic
            z0, z1, z2, z3, z4, z5, z6 = self._rng.standard_normal(7).tolist()
            total += nz.force_std * z0
            if nz.point_std > 0:
                s = nz.point_std
                p0, p1, p2 = point.tolist()
                point = np.array([p0 + s * z1, p1 + s * z2, p2 + s * z3])
            if nz.normal_std > 0:
                s = nz.normal_std
                e0, e1, e2 = s * z4, s * z5, s * z6
                c = float(np.array([e0, e1, e2]).dot(normal))
                n0, n1, n2 = normal.tolist()
                m0, m1, m2 = n0 + (e0 - c * n0), n1 + (e1 - c * n1), n2 + (e2 - c * n2)  # in the tangent plane
                normal = np.array([m0, m1, m2])
                size = math.sqrt(float(normal.dot(normal)))
                normal = np.array([m0 / size, m1 / size, m2 / size])  # normal / size, element by element
        return total, normal, point, len(raw)

    def wrist_wrench(self, watch: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """The wrist force/torque sensor (MuJoCo ``force`` and ``torque`` sensors at the hand's ``wrist_ft``
        site): force (3,) [N] and torque (3,) [N m] in the world frame, noise applied. ``watch``: the sensor
        watched all through a move, its noise drawn apart from the other senses'."""
        raw = self.data.sensordata[self.wrist_adr]
        rot = self.data.site_xmat[self.wrist_site].reshape(3, 3)
        force, torque = rot @ raw[:3], rot @ raw[3:]
        nz = self.noise
        rng = self._wrist_rng if watch else self._senses_rng
        if nz.force_std > 0:
            force = force + nz.force_std * rng.standard_normal(3)
        if nz.torque_std > 0:
            torque = torque + nz.torque_std * rng.standard_normal(3)
        return force, torque

    def hand_inertia_force(self) -> np.ndarray:
        """What the wrist's force sensor reads of the hand touching nothing, moving as it moves now (3,) [N], world
        frame: the mass of each of the hand's bodies below the sensor times its acceleration with gravity's offset
        (the robot's own model and the motion of its joints; at rest :meth:`hand_weight`). Carried between moves the
        arm swings the hand by up to 17 N off its weight."""
        m, d = self.model, self.data
        acc, body = self._acc6, mujoco.mjtObj.mjOBJ_BODY
        f0 = f1 = f2 = 0.0  # summed body by body on floats: the arithmetic of the vector sum, without its overhead
        for b, mass in self._hand_masses:
            mujoco.mj_objectAcceleration(m, d, body, b, acc, 0)
            _, _, _, a0, a1, a2 = acc.tolist()
            f0, f1, f2 = f0 + mass * a0, f1 + mass * a1, f2 + mass * a2
        return np.array([f0, f1, f2])

    def hand_weight(self) -> np.ndarray:
        """What the wrist's force sensor reads of the hand at rest touching nothing (3,) [N], world frame: the
        weight of the hand below the sensor, from the robot's own model (the masses of its bodies)."""
        m = self.model
        body = int(m.site_bodyid[self.wrist_site])
        return -float(m.body_subtreemass[body]) * np.asarray(m.opt.gravity, dtype=float)

    def link_contacts(self, watch: bool = False) -> tuple[LinkContact, ...]:
        """Contacts of the robot's links other than the fingertip pads with anything not of the robot (the
        object, the table), noise applied as to a pad's contacts: each link's contact readout. ``watch``: the
        readout taken all through a move, its noise drawn apart from the other senses'."""
        d, nz = self.data, self.noise
        rng = self._watch_rng if watch else self._senses_rng
        if d.ncon == 0:
            return ()
        owner = self._geom_link_list
        out = []
        geoms, efc, frames, points = self._contacts()
        for i, (g1, g2) in enumerate(geoms):
            k1, k2 = owner[g1], owner[g2]
            if (k1 < 0) == (k2 < 0):  # neither a link, or link against link
                continue
            if efc[i] < 0:
                continue
            mujoco.mj_contactForce(self.model, d, i, self._force6)
            normal = frames[i][0].copy()  # geom1 -> geom2
            link = k1 if k1 >= 0 else k2
            if k1 >= 0:
                normal = -normal  # out of the touched surface, towards the link
            point = points[i].copy()
            if nz.point_std > 0:
                point = point + nz.point_std * rng.standard_normal(3)
            out.append(LinkContact(LINK_NAMES[link], point, normal, float(self._force6[0])))
        return tuple(out)

    def link_radii(self) -> dict[str, float]:
        """Per link of :data:`LINK_NAMES` with collision geometry (the pads apart), the radius of its thickest
        geom [m] (a sphere's, capsule's or cylinder's radius, a box's least half-size): how far from where its
        readout puts a contact the touched point may lie (a link's skin is not the pad's)."""
        m = self.model
        out: dict[str, float] = {}
        for g, k in enumerate(self._geom_link_list):
            if k < 0:
                continue
            size = m.geom_size[g]
            kind = GEOM_KINDS.get(int(m.geom_type[g]))
            r = float(min(size)) if kind in ("box", "ellipsoid", "mesh") else float(size[0])
            out[LINK_NAMES[k]] = max(out.get(LINK_NAMES[k], 0.0), r)
        return out

    def touch(self) -> np.ndarray:
        """Touch force per fingertip (4,) [N], noise applied (clipped at 0)."""
        t = self.data.sensordata[self.touch_adr].copy()
        if self.noise.force_std > 0:
            t = np.maximum(t + self.noise.force_std * self._rng.standard_normal(len(t)), 0.0)
        return t

    def fingertip_positions(self) -> np.ndarray:
        """Fingertip pad centres (4, 3) in the world [m] (forward kinematics)."""
        return self.data.site_xpos[self.tip_site].copy()

    def link_positions(self) -> np.ndarray:
        """Origins of the robot's links then the fingertip pad centres (len(LINK_NAMES), 3) in the world [m]
        (forward kinematics of the robot's own bodies; the rows follow :data:`LINK_NAMES`)."""
        d = self.data
        return np.concatenate((d.xpos[self.link_body], d.site_xpos[self.tip_site]))

    def link_poses(self) -> np.ndarray:
        """Poses of the rows of :meth:`link_positions`: position [m] then quaternion (w, x, y, z) of each link
        body's frame (the pad sites' frames for the fingertips), (len(LINK_NAMES), 7), world frame (forward
        kinematics of the robot's own bodies)."""
        d = self.data
        nb = len(self.link_body)
        out = np.empty((nb + len(self.tip_site), 7))
        out[:nb, :3] = d.xpos[self.link_body]
        out[:nb, 3:] = d.xquat[self.link_body]
        out[nb:, :3] = d.site_xpos[self.tip_site]
        xmat = d.site_xmat
        for k, s in enumerate(self._tip_site_list):
            mujoco.mju_mat2Quat(out[nb + k, 3:], xmat[s])
        return out

    def link_geoms(self) -> tuple[LinkGeom, ...]:
        """The robot's collision geometry, each geom in its link's frame (links of :data:`LINK_NAMES`, posed by
        :meth:`link_poses`), and the table top, fixed in the world: the robot and its workspace, never the
        object. Built once."""
        if self._link_geoms is None:
            self._link_geoms = self._make_link_geoms()
        return self._link_geoms

    def _make_link_geoms(self) -> tuple[LinkGeom, ...]:
        m, d = self.model, self.data
        out: list[LinkGeom] = []
        for name, b in zip(LINK_NAMES, self.link_body, strict=False):
            geoms = range(m.body_geomadr[b], m.body_geomadr[b] + m.body_geomnum[b])
            paint = next((tuple(m.geom_rgba[g]) for g in geoms if not (m.geom_contype[g] or m.geom_conaffinity[g])),
                         None)  # fmt: skip
            for g in geoms:
                kind = GEOM_KINDS.get(int(m.geom_type[g]))
                if kind is None or not (m.geom_contype[g] or m.geom_conaffinity[g]):
                    continue
                rgba = tuple(float(x) for x in m.geom_rgba[g])
                if rgba[3] < 1.0:
                    rgba = tuple(float(x) for x in paint[:3]) + (1.0,) if paint is not None else rgba[:3] + (1.0,)
                out.append(LinkGeom(name, m.geom(g).name, kind, tuple(float(x) for x in m.geom_size[g]),
                                    np.r_[m.geom_pos[g], m.geom_quat[g]], rgba, *self._mesh_of(g)))  # fmt: skip
        table = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "table_top")
        if table >= 0:
            quat = np.empty(4)
            mujoco.mju_mat2Quat(quat, d.geom_xmat[table])
            out.append(LinkGeom(None, "table_top", GEOM_KINDS[int(m.geom_type[table])],
                                tuple(float(x) for x in m.geom_size[table]), np.r_[d.geom_xpos[table], quat],
                                tuple(float(x) for x in m.geom_rgba[table])))  # fmt: skip
        return tuple(out)

    def _mesh_of(self, g: int) -> tuple[np.ndarray | None, np.ndarray | None]:
        m = self.model
        if int(m.geom_type[g]) != int(mujoco.mjtGeom.mjGEOM_MESH):
            return None, None
        k = m.geom_dataid[g]
        v0, nv, f0, nf = m.mesh_vertadr[k], m.mesh_vertnum[k], m.mesh_faceadr[k], m.mesh_facenum[k]
        return m.mesh_vert[v0 : v0 + nv].astype(float), m.mesh_face[f0 : f0 + nf].astype(int)

    def read_sensors(self) -> SensorReading:
        """Everything the robot senses now, as a plain snapshot (noise applied)."""
        d, nz = self.data, self.noise
        q = d.qpos[: N_ARM + N_HAND].copy()
        if nz.joint_std > 0:
            q += nz.joint_std * self._rng.standard_normal(len(q))
        per: list[list[FingertipContact]] = [[] for _ in FINGERS]
        for k, p, n, f in self._pad_contacts(None):
            fn = float(np.dot(f, n))
            if nz.force_std > 0:
                f = f + nz.force_std * self._rng.standard_normal() * n
                fn = float(np.dot(f, n))
            if nz.point_std > 0:
                p = p + nz.point_std * self._rng.standard_normal(3)
            per[k].append(FingertipContact(p, self._noisy_normal(n), f, fn))
        wrench = self.wrist_wrench()
        return SensorReading(
            time=float(d.time),
            arm_q=q[self.arm],
            arm_qd=d.qvel[self.arm].copy(),
            hand_q=q[self.hand],
            hand_qd=d.qvel[self.hand].copy(),
            fingertip_in_world=self.fingertip_positions(),
            touch=self.touch(),
            contacts=tuple(tuple(c) for c in per),
            wrist_force=wrench[0],
            wrist_torque=wrench[1],
            link_contacts=self.link_contacts(),
        )
