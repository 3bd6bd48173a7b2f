"""One reach solver for the whole robot: arm and fingers, targets for one to four fingertips at once.

:class:`ReachSolver` answers "can the hand put these fingertips there, pointing so, without meeting the table,
the (hypothesised) object or itself?" with a joint configuration and the joint path to it, or a typed
:class:`ReachFailure`. It is differential inverse kinematics as a quadratic programme (mink): one frame task per
fingertip pad, an axis-alignment task per approach direction, a posture task that keeps the joints near where
they start, the joint limits and collision-avoidance limits between the hand's links and the table and object.
The QP's limits hold at every step, so the steps from the start to the solution are a collision-free path.

The solver works on a scene of its own, composed without the true object (a robot knows its table, not the
object): an executor asks it with no object or with the hypothesised model at its hypothesised pose, never with
the ground truth.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import StrEnum

import mink
import mujoco
import numpy as np

from haptic.errors import SceneError
from haptic.sim.physics import N_ARM, N_HAND
from haptic.sim.scene import (
    ARM_HOME,
    ARM_PREFIX,
    FINGER_PREFIX,
    FINGERS,
    HAND_PREFIX,
    HAND_TRACE,
    ComposedScene,
)

MM = 1000.0
"""Millimetres per metre, for messages."""


class ReachFailure(StrEnum):
    """Why a set of fingertip targets cannot be reached. A ``str``: records and messages show the value."""

    WORKSPACE = "outside the workspace"
    JOINT_LIMIT = "a joint limit"
    TABLE = "the table"
    OBJECT = "the object"
    SELF = "the hand itself"


@dataclass(frozen=True)
class FingertipTarget:
    """Where one fingertip's pad is to be, and optionally which way the finger points there."""

    finger: str
    """A name of ``haptic.sim.scene.FINGERS``."""
    point_in_world: np.ndarray
    """Target of the pad centre (3,) [m]."""
    approach_in_world: np.ndarray | None = None
    """Direction the fingertip points along (the distal link's axis from its joint to the pad) (3,), unit; None:
    any."""


@dataclass(frozen=True)
class ReachSettings:
    """Tolerances and weights of the reach solver."""

    position_tol: float = 1e-3
    """A pad counts as on its target within this distance [m]."""
    approach_tol: float = np.deg2rad(10.0)
    """A finger counts as pointing along its approach within this angle [rad]."""
    clearance: float = 0.003
    """Least distance kept between the hand's links and the table or object [m] (the target fingers' pads are
    exempt from the object: they are meant to touch it)."""
    pads_touch: bool = True
    """Whether the target fingers' pads may touch the object (targets on its surface); False: they keep the
    clearance too (targets short of it, such as a placement's lines' starts)."""
    tip_table_clearance: float | None = None
    """Least distance kept between the target fingers' fingertips (distal link and pad) and the table [m], in
    place of ``clearance`` there: a pad sent to a face near the table comes closer to it than the hand's other
    links need to. None: ``clearance`` for every link."""
    hold_clearance: float | None = None
    """With it, a step that would bring a link nearer the table or the object than its clearance less this (and
    nearer than before) is not taken either, as a step into them is not (shorter steps, then the solver stops
    there): the path keeps the clearance to within this, where the linearised limits alone let links graze the
    object [m]. None: only steps into the table or object are refused."""
    detection: float = 0.08
    """Distance below which a pair of geoms enters the collision constraints [m]: more than a step moves any
    link, so that no step jumps past a constraint not yet active."""
    dt: float = 0.02
    """Integration step of the joint velocities the QP returns [s]."""
    max_speed: float = 2.5
    """Joint speed limit of the QP [rad/s]: with ``dt``, the largest step of a joint (0.05 rad: under 4 cm at
    the fingertip, less than ``detection``)."""
    step_halvings: int = 3
    """Times a step that would enter the table or object is halved before the solver stops there."""
    max_iters: int = 200
    """Most QP steps before the solver gives up."""
    stall_iters: int = 15
    stall_progress: float = 2e-4
    """The solver stops when the pads' summed distance to their targets has shrunk by less than
    ``stall_progress`` [m] over the last ``stall_iters`` steps (a limit holds the hand)."""
    posture_cost: float = 1e-3
    """Weight of staying near the start posture (regularises the redundant joints)."""
    approach_cost: float = 0.3
    """Weight of the approach direction against the position (1)."""
    damping: float = 1e-3
    """Levenberg-Marquardt damping of the QP."""
    approach_damping: float = 1e-2
    """Levenberg-Marquardt damping of an approach task (bounds the step when the finger points against it)."""
    at_limit: float = 1e-3
    """A joint this close to a limit counts as held there [rad]."""
    reach_margin: float = 0.95
    """Targets farther from the shoulder than this fraction of the arm's and finger's stretched length are
    outside the workspace before any solving."""


@dataclass(frozen=True)
class Reach:
    """The reach solver's answer."""

    ok: bool
    """Every target within ``position_tol`` (and ``approach_tol``), every limit kept."""
    qpos: np.ndarray
    """The joint configuration reached (arm then hand) [rad]; the closest found when not ``ok``."""
    path: np.ndarray
    """Joint configurations from the start to ``qpos`` (K, n) [rad], each step within the limits."""
    position_error: np.ndarray
    """Per target, distance of the pad centre from its target [m]."""
    approach_error: np.ndarray
    """Per target, angle between the finger and its approach [rad] (0 without one)."""
    reason: ReachFailure | None = None
    """Why not, when not ``ok``."""
    detail: str = ""
    """The reason in words (which target, how far, which limit)."""
    iterations: int = 0
    """QP steps taken."""
    clearance: dict[str, float] = field(default_factory=dict)
    """Least distance of the hand from the table and from the object [m] at ``qpos`` (keys "table", "object")."""


def _finger_axis(finger: str) -> np.ndarray:
    """The distal link's axis towards its pad, in the pad site's frame (the thumb's links run along y)."""
    return np.array([0.0, 1.0, 0.0]) if finger == "thumb" else np.array([0.0, 0.0, 1.0])


class ReachSolver:
    """Reach targets for any subset of the fingertips on the robot of a composed scene (see the module)."""

    def __init__(self, scene: ComposedScene, settings: ReachSettings | None = None) -> None:
        self.settings = settings or ReachSettings()
        self.model: mujoco.MjModel = scene.compile()
        m = self.model
        n = N_ARM + N_HAND
        if m.nq != n:
            raise SceneError(
                f"reach solver: expected a scene whose only joints are the robot's {n} hinges, got nq={m.nq}"
            )
        self.configuration = mink.Configuration(m)
        self._site = {f: f"{HAND_PREFIX}{FINGER_PREFIX[f]}_tip" for f in FINGERS}
        self._pad = {f: f"{HAND_PREFIX}{FINGER_PREFIX[f]}_pad" for f in FINGERS}
        for name in (*self._site.values(),):
            if mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name) < 0:
                raise SceneError(f"reach solver: site {name!r} not found in the scene's hand")
        arm_base = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{ARM_PREFIX}link1")
        if arm_base < 0:
            raise SceneError(f"reach solver: body {ARM_PREFIX}link1 not found; is the arm attached?")
        self._hand_geoms = [g for g in mink.get_subtree_geom_ids(m, arm_base)
                            if m.geom_contype[g] or m.geom_conaffinity[g]]  # fmt: skip
        """The robot's colliding geoms from the first moving link on: the arm's links and the hand's."""
        self._table_geoms = [self._geom("table_top")]
        obj_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "object")
        self._object_geoms = mink.get_body_geom_ids(m, obj_body) if obj_body >= 0 else []
        joints = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)]
        self._velocity = mink.VelocityLimit(m, {j: self.settings.max_speed for j in joints})
        self._limit_cache: dict[frozenset[str], list[mink.Limit]] = {}
        self._shoulder = self._arm_base()
        self._stretch = self._stretched_length()

    def site_name(self, finger: str) -> str:
        """The MuJoCo name of ``finger``'s pad-centre site."""
        return self._site[finger]

    @property
    def table_top_z(self) -> float:
        """Height of the table top [m]."""
        d = self.configuration.data
        g = self._table_geoms[0]
        return float(d.geom_xpos[g][2] + self.model.geom_size[g][2])

    def table_clearance(self, qpos: np.ndarray) -> float:
        """Least distance of the hand's links from the table at joint configuration ``qpos`` [m] (negative:
        inside it)."""
        self.configuration.update(np.asarray(qpos, dtype=float))
        return self._distance(self._hand_geoms, self._table_geoms)

    def object_clearance(self, qpos: np.ndarray, fingers: Sequence[str] = ()) -> float:
        """Least distance of the hand's links from the object at joint configuration ``qpos`` [m] (negative: inside
        it), the ``fingers``' pads left out where they may touch it (``pads_touch``); 1 m in a scene without one."""
        self.configuration.update(np.asarray(qpos, dtype=float))
        pads = self._exempt(fingers)
        return self._distance([g for g in self._hand_geoms if g not in pads], self._object_geoms)

    # -- construction helpers --------------------------------------------------------------------------------
    def _geom(self, name: str) -> int:
        g = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, name)
        if g < 0:
            raise SceneError(f"reach solver: geom {name!r} not found in the scene")
        return g

    def _arm_base(self) -> np.ndarray:
        d = mujoco.MjData(self.model)
        mujoco.mj_kinematics(self.model, d)
        b = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"{ARM_PREFIX}link2")
        return d.xpos[b].copy()

    def _stretched_length(self) -> float:
        """Upper bound of the distance from the shoulder to any pad: the sum of the body offsets along the chain
        from the shoulder's link to the farthest pad site."""
        m = self.model
        best = 0.0
        b0 = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{ARM_PREFIX}link2")
        for f in FINGERS:
            s = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, self._site[f])
            total = float(np.linalg.norm(m.site_pos[s]))
            b = int(m.site_bodyid[s])
            while b != b0 and b > 0:
                total += float(np.linalg.norm(m.body_pos[b]))
                b = int(m.body_parentid[b])
            best = max(best, total)
        return best

    # -- solving ---------------------------------------------------------------------------------------------
    def solve(
        self,
        targets: Sequence[FingertipTarget],
        start: np.ndarray | None = None,
    ) -> Reach:
        """A configuration putting each target's pad at its point (pointing along its approach), from ``start``
        (arm then hand joints [rad]; default the home posture with the hand in its tracing posture), or the
        reason it cannot."""
        s = self.settings
        if not targets:
            raise SceneError("reach solver: no fingertip targets; give one to four, one per finger")
        fingers = [t.finger for t in targets]
        for f in fingers:
            if f not in FINGERS:
                raise SceneError(f"reach solver: unknown finger {f!r}; valid fingers: {', '.join(FINGERS)}")
        if len(set(fingers)) != len(fingers):
            raise SceneError(f"reach solver: a finger has two targets ({', '.join(fingers)}); one target a finger")
        q0 = np.concatenate([ARM_HOME, HAND_TRACE]) if start is None else np.asarray(start, dtype=float).copy()
        lo, hi = self.model.jnt_range[:, 0], self.model.jnt_range[:, 1]
        q0 = np.clip(q0, lo, hi)
        points = [np.asarray(t.point_in_world, dtype=float) for t in targets]
        far = [i for i, p in enumerate(points) if np.linalg.norm(p - self._shoulder) > s.reach_margin * self._stretch]
        if far:
            i = far[0]
            dist = float(np.linalg.norm(points[i] - self._shoulder))
            return self._answer(q0, q0[None], targets, ReachFailure.WORKSPACE, 0,
                                f"{fingers[i]} target {dist * MM:.0f} mm from the shoulder, more than the arm's "
                                f"reach ({s.reach_margin * self._stretch * MM:.0f} mm)")  # fmt: skip

        cfg = self.configuration
        cfg.update(q0)
        tasks: list[mink.Task] = []
        for t, p in zip(targets, points, strict=True):
            task = mink.FrameTask(self._site[t.finger], "site", position_cost=1.0, orientation_cost=0.0)
            task.set_target(mink.SE3.from_translation(p))
            tasks.append(task)
            if t.approach_in_world is not None:
                a = np.asarray(t.approach_in_world, dtype=float)
                align = mink.AxisAlignTask(self._site[t.finger], "site", axis=_finger_axis(t.finger),
                                           cost=s.approach_cost, lm_damping=s.approach_damping)  # fmt: skip
                align.set_target(a / np.linalg.norm(a))
                tasks.append(align)
        posture = mink.PostureTask(self.model, cost=s.posture_cost)
        posture.set_target(q0)
        tasks.append(posture)
        limits = self._limits(fingers)

        path = [q0.copy()]
        progress: list[float] = []
        steps = 0
        pads = self._exempt(fingers)
        rest = [g for g in self._hand_geoms if g not in pads]
        sets = self._table_sets(fingers)
        clear, margin = self._clearance(rest), self._margins(rest, sets)
        blocked: ReachFailure | None = None
        dt = s.dt
        while steps < s.max_iters:
            steps += 1
            vel = mink.solve_ik(cfg, tasks, dt, solver="daqp", damping=s.damping, limits=limits)
            cfg.integrate_inplace(vel, dt)
            now = self._clearance(rest)
            near = self._margins(rest, sets)
            into = now < 0.0 and now < clear
            grazing = s.hold_clearance is not None and min(near) < -s.hold_clearance and min(near) < min(margin)
            if into or grazing:  # the linearised limits let a step through: not taken; shorter steps
                if into:
                    table = self._distance(self._hand_geoms, self._table_geoms)
                    blocked = ReachFailure.TABLE if table <= now else ReachFailure.OBJECT
                else:
                    blocked = ReachFailure.TABLE if near[0] <= near[1] else ReachFailure.OBJECT
                cfg.update(path[-1])
                if dt < s.dt / 2**s.step_halvings:
                    break
                dt /= 2
                continue
            clear, margin = now, near
            path.append(cfg.q.copy())
            pos_err, app_err = self._errors(targets)
            if np.all(pos_err < s.position_tol) and np.all(app_err < s.approach_tol):
                break
            progress.append(float(pos_err.sum()))
            if len(progress) > s.stall_iters and progress[-s.stall_iters - 1] - progress[-1] < s.stall_progress:
                break  # stalled: a limit holds it
        q = cfg.q.copy()
        reason, detail = self._why(targets, q, blocked)
        return self._answer(q, np.array(path), targets, reason, steps, detail)

    def _limits(self, fingers: Sequence[str]) -> list[mink.Limit]:
        key = frozenset(fingers)
        if key not in self._limit_cache:
            self._limit_cache[key] = self._make_limits(fingers)
        return self._limit_cache[key]

    def _make_limits(self, fingers: Sequence[str]) -> list[mink.Limit]:
        s = self.settings
        limits: list[mink.Limit] = [mink.ConfigurationLimit(self.model), self._velocity]
        pads = self._exempt(fingers)
        body, tips = self._table_sets(fingers)
        pairs = [(body, self._table_geoms)]
        if self._object_geoms:
            pairs.append(([g for g in self._hand_geoms if g not in pads], self._object_geoms))
        limits.append(mink.CollisionAvoidanceLimit(self.model, pairs, minimum_distance_from_collisions=s.clearance,
                                                   collision_detection_distance=s.detection))  # fmt: skip
        if tips:
            limits.append(mink.CollisionAvoidanceLimit(self.model, [(tips, self._table_geoms)],
                                                       minimum_distance_from_collisions=s.tip_table_clearance,
                                                       collision_detection_distance=s.detection))  # fmt: skip
        return limits

    def _table_sets(self, fingers: Sequence[str]) -> tuple[list[int], list[int]]:
        """The hand's geoms that keep ``clearance`` from the table, and those of the ``fingers``' fingertips that
        keep ``tip_table_clearance`` (none without it)."""
        if self.settings.tip_table_clearance is None:
            return list(self._hand_geoms), []
        tips = [g for g in self._hand_geoms if self._tip_of(g) in fingers]
        return [g for g in self._hand_geoms if g not in tips], tips

    def _margins(self, rest: Sequence[int], sets: tuple[list[int], list[int]]) -> tuple[float, float]:
        """How far beyond its clearance the hand is from the table and ``rest`` from the object at the current
        configuration [m] (negative: nearer than the clearance); only with ``hold_clearance`` (else zeros)."""
        s = self.settings
        if s.hold_clearance is None:
            return 0.0, 0.0
        body, tips = sets
        table = self._distance(body, self._table_geoms) - s.clearance
        if tips:
            table = min(table, self._distance(tips, self._table_geoms) - s.tip_table_clearance)
        obj = self._distance(rest, self._object_geoms) - s.clearance if self._object_geoms else 1.0
        return table, obj

    def _tip_of(self, g: int) -> str | None:
        """The finger whose fingertip (distal link, its pad included) geom ``g`` belongs to, or None."""
        m = self.model
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g])) or ""
        return next((f for f in FINGERS if name == f"{HAND_PREFIX}{FINGER_PREFIX[f]}_distal"), None)

    def table_margin(self, fingers: Sequence[str] = ()) -> float:
        """Least distance at the current configuration of the hand's links from the table beyond what each must
        keep (``clearance``, or ``tip_table_clearance`` for the ``fingers``' fingertips) [m]: negative where a
        link is nearer than it may be."""
        s = self.settings
        body, tips = self._table_sets(fingers)
        margin = self._distance(body, self._table_geoms) - s.clearance
        if tips:
            margin = min(margin, self._distance(tips, self._table_geoms) - s.tip_table_clearance)
        return margin

    def _exempt(self, fingers: Sequence[str]) -> set[int]:
        """The pads of ``fingers`` that may touch the object (none unless ``settings.pads_touch``)."""
        return {self._geom(self._pad[f]) for f in fingers} if self.settings.pads_touch else set()

    def _errors(self, targets: Sequence[FingertipTarget]) -> tuple[np.ndarray, np.ndarray]:
        d = self.configuration.data
        pos, app = [], []
        for t in targets:
            sid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, self._site[t.finger])
            pos.append(float(np.linalg.norm(d.site_xpos[sid] - np.asarray(t.point_in_world, dtype=float))))
            if t.approach_in_world is None:
                app.append(0.0)
                continue
            axis = d.site_xmat[sid].reshape(3, 3) @ _finger_axis(t.finger)
            a = np.asarray(t.approach_in_world, dtype=float)
            c = float(np.clip(axis @ a / np.linalg.norm(a), -1.0, 1.0))
            app.append(float(np.arccos(c)))
        return np.array(pos), np.array(app)

    def _distance(self, geoms_a: Sequence[int], geoms_b: Sequence[int]) -> float:
        """Least signed distance between two sets of geoms at the current configuration [m] (capped at 1 m)."""
        m, d = self.model, self.configuration.data
        best = 1.0
        fromto = np.zeros(6)
        for a in geoms_a:
            for b in geoms_b:
                best = min(best, mujoco.mj_geomDistance(m, d, a, b, 1.0, fromto))
        return best

    def _clearance(self, rest: Sequence[int]) -> float:
        """Least distance at the current configuration of the robot from the table and of its links other than
        the target pads from the object [m]."""
        table = self._distance(self._hand_geoms, self._table_geoms)
        return min(table, self._distance(rest, self._object_geoms)) if self._object_geoms else table

    def _why(
        self, targets: Sequence[FingertipTarget], q: np.ndarray, blocked: ReachFailure | None = None
    ) -> tuple[ReachFailure | None, str]:
        """The failure at configuration ``q`` (already in ``self.configuration``), None when every target holds;
        ``blocked``: what stopped the last step."""
        s = self.settings
        pos_err, app_err = self._errors(targets)
        pads = self._exempt([x.finger for x in targets])
        rest = [g for g in self._hand_geoms if g not in pads]
        table = self._distance(self._hand_geoms, self._table_geoms)
        on_object = self._distance(rest, self._object_geoms) if self._object_geoms else 1.0
        if np.all(pos_err < s.position_tol) and np.all(app_err < s.approach_tol):
            if table < 0.0:
                return ReachFailure.TABLE, f"the hand would touch the table ({-table * MM:.2f} mm into it)"
            if on_object < 0.0:
                return ReachFailure.OBJECT, f"the hand would touch the object ({-on_object * MM:.2f} mm into it)"
            return None, ""
        worst = int(np.argmax(pos_err / s.position_tol + app_err / s.approach_tol))
        t = targets[worst]
        miss = f"{t.finger} {pos_err[worst] * MM:.1f} mm from its target, {np.rad2deg(app_err[worst]):.0f}° off"
        if blocked is not None:
            return blocked, f"{miss}: the next step would enter {blocked}"
        if self.table_margin([x.finger for x in targets]) < s.position_tol:
            return ReachFailure.TABLE, f"{miss}: the hand is held off the table"
        if on_object < s.clearance + s.position_tol:
            return ReachFailure.OBJECT, f"{miss}: the hand is held off the object"
        lo, hi = self.model.jnt_range[:, 0], self.model.jnt_range[:, 1]
        at = np.flatnonzero((q - lo < s.at_limit) | (hi - q < s.at_limit))
        if len(at):
            names = [mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_JOINT, int(j)) for j in at]
            return ReachFailure.JOINT_LIMIT, f"{miss}: at the limit of {', '.join(n.split('/')[-1] for n in names)}"
        if len(targets) > 1:
            return ReachFailure.SELF, f"{miss}: the fingers' targets pull the hand apart"
        return ReachFailure.WORKSPACE, f"{miss}: outside the workspace"

    def _answer(self, q, path, targets, reason, iterations, detail) -> Reach:
        cfg = self.configuration
        cfg.update(q)
        pos_err, app_err = self._errors(targets)
        clearance = {"table": self._distance(self._hand_geoms, self._table_geoms)}
        if self._object_geoms:
            clearance["object"] = self._distance(self._hand_geoms, self._object_geoms)
        return Reach(ok=reason is None, qpos=q, path=path, position_error=pos_err, approach_error=app_err,
                     reason=reason, detail=detail, iterations=iterations, clearance=clearance)  # fmt: skip


__all__ = ["FingertipTarget", "Reach", "ReachFailure", "ReachSettings", "ReachSolver"]
