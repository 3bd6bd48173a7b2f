"""The control law's and the readout's per-tick arithmetic, done element by element on floats, equals its vector form
to the last bit: the same trajectory, tick after tick, and the same sensed contact, filtered normal and wrist reading.

The vector forms below are the law as written with numpy's vector operations (the reference); the code under test
does the same operations in the same order without numpy's per-call overhead on 3-vectors.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from conftest import BOX_CENTRE, BOX_HALF

from haptic.executor.primitives import _filtered
from haptic.geometry.se3 import unit
from haptic.sim.control import Controller, _rotation_error, _rotation_error_list
from haptic.sim.physics import N_ARM, SimulatedSensorNoise, Simulation


def _vector_rotation_error(r: np.ndarray, r_des: np.ndarray) -> np.ndarray:
    a = r_des @ r.T
    return 0.5 * np.array([a[2, 1] - a[1, 2], a[0, 2] - a[2, 0], a[1, 0] - a[0, 1]])


class _VectorController(Controller):
    """The controller with its law in numpy's vector form (the reference of the per-tick arithmetic)."""

    def _tick(self) -> None:
        m, d, g = self._m, self._d, self.gains
        mujoco.mj_fullM(m, d, self._mfull)
        m6 = self._mfull[:N_ARM, :N_ARM]
        bias = d.qfrc_bias
        if self._mode == "posture":
            e = self._arm_ref - d.qpos[:N_ARM]
            tau = m6 @ (g.posture_kp * e - g.posture_kd * d.qvel[:N_ARM])
        else:
            tau = self._vector_task_torque(m6)
        d.ctrl[:N_ARM] = tau + bias[:N_ARM]
        d.ctrl[N_ARM:] = self._hand_ref + bias[N_ARM:] / self._hand_kp

    def _vector_task_torque(self, m6: np.ndarray) -> np.ndarray:
        m, d, g = self._m, self._d, self.gains
        jacp, jacr = self._jacp, self._jacr
        mujoco.mj_jacSite(m, d, jacp, jacr, self._site)
        x = d.site_xpos[self._site]
        qvel = d.qvel
        v = jacp @ qvel
        if self._mode == "fingertip":
            a_pos = g.pos_kp * (self._x_ref - x) - g.pos_kd * v
            force = None
        else:
            a_pos, force = self._vector_hybrid_terms(x, v)
        j = self._jac_arm
        a = self._a6
        a[:3] = a_pos
        a[3:] = g.rot_kp * _vector_rotation_error(d.site_xmat[self._hand_site].reshape(3, 3), self._r_ref) - (
            g.rot_kd * (jacr @ qvel)
        )
        jjt = j @ j.T
        mujoco.mju_cholFactor(jjt, g.task_damping)
        mujoco.mju_cholSolve(self._y6, jjt, a)
        tau = m6 @ (self._y6 @ j)
        if force is not None:
            tau += j[:3].T @ force
        return tau

    def _vector_hybrid_terms(self, x: np.ndarray, v: np.ndarray):
        g, h = self.gains, self._hybrid
        t = self._d.time
        force, normal, point, count = self.sim.sense_contact(self._finger)
        h.sensed = (force, normal, point, count)
        if normal is not None and force > self._threshold:
            if h.normal is None:
                h.normal = normal
            else:
                nf = h.normal + g.normal_filter * (normal - h.normal)
                h.normal = nf / math.sqrt(float(nf @ nf))
            h.last_contact = t
        n = h.hint if h.normal is None else h.normal
        v_n = float(n @ v)
        if t - h.last_contact > g.contact_lost_after:
            d_ref = h.reference - x
            d_ref -= float(n @ d_ref) * n
            h.reference = x + d_ref
            e = g.pos_kp * d_ref - g.pos_kd * v
            return e + (g.pos_kd * (-g.approach_speed - v_n) - float(n @ e)) * n, None
        dt = self._dt
        err = h.force - force
        h.integral = min(max(h.integral + g.force_ki * err * dt, -g.force_integral_limit), g.force_integral_limit)
        f_n = max(h.force + g.force_kp * err + h.integral, 0.0)
        v_t = h.velocity - float(n @ h.velocity) * n
        lead = h.reference - x + dt * v_t
        lead -= float(n @ lead) * n
        dist = math.sqrt(float(lead @ lead))
        if dist > g.lead_cap:
            lead *= g.lead_cap / dist
        h.reference = x + lead
        e = g.pos_kp * lead + g.pos_kd * (v_t - v)
        return e - (float(n @ e) + g.normal_kd * v_n) * n, -f_n * n


def _commands(ctl: Controller, top_z: float) -> None:
    """Run one script of commands: a free move down over the box, a press that lands, slides turning on the face
    (the lead capped and not), a lift in free space and a posture hold; the state after every tick is yielded."""
    ctl.move_fingertip(np.array([BOX_CENTRE[0], 0.0, top_z + 0.012]))
    yield from _ticks(ctl, 80)
    ctl.set_hybrid(1.0, np.zeros(3), normal_hint=np.array([0.0, 0.0, 1.0]))
    yield from _ticks(ctl, 150)
    for k in range(12):
        phase = 0.5 * k
        ctl.set_hybrid(1.0, 0.03 * np.array([math.cos(phase), math.sin(phase), 0.0]))
        yield from _ticks(ctl, 8)
    ctl.set_hybrid(1.5, np.array([0.5, 0.0, 0.0]))  # a lead past its cap
    yield from _ticks(ctl, 10)
    ctl.move_fingertip(ctl.fingertip_position() + [0.0, 0.0, 0.02], "hold")
    yield from _ticks(ctl, 40)
    ctl.hold_posture()
    yield from _ticks(ctl, 20)


def _ticks(ctl: Controller, n: int):
    for _ in range(n):
        ctl.step(1)
        d = ctl.sim.data
        yield d.qpos.copy(), d.qvel.copy(), d.ctrl.copy()


@pytest.mark.parametrize("noise", [None, SimulatedSensorNoise.from_notes()], ids=["ideal", "noisy"])
def test_the_law_on_floats_runs_the_vector_forms_trajectory_to_the_last_bit(box_scene, noise):
    top_z = float(BOX_CENTRE[2] + BOX_HALF[2])
    runs = []
    for kind in (Controller, _VectorController):
        sim = Simulation(box_scene, noise=noise, seed=3)
        runs.append(list(_commands(kind(sim, "index"), top_z)))
    assert len(runs[0]) == len(runs[1])
    for k, (a, b) in enumerate(zip(*runs, strict=True)):
        for x, y in zip(a, b, strict=True):
            assert np.array_equal(x, y), f"tick {k}: the state or the controls differ from the vector form's"


def test_the_rotation_error_on_floats_is_the_vector_forms():
    rng = np.random.default_rng(5)
    for _ in range(2000):
        r, _ = np.linalg.qr(rng.standard_normal((3, 3)))
        r_des, _ = np.linalg.qr(rng.standard_normal((3, 3)))
        want = _vector_rotation_error(r, r_des)
        assert _rotation_error_list(r, r_des) == want.tolist()
        assert np.array_equal(_rotation_error(r, r_des), want)


def test_the_filtered_normal_on_floats_is_the_vector_forms():
    rng = np.random.default_rng(6)
    for _ in range(2000):
        a, b = unit(rng.standard_normal(3)), unit(rng.standard_normal(3))
        w = float(rng.uniform(0.05, 1.0))
        assert np.array_equal(_filtered(a, b, w), unit(a + w * (b - a)))


def _vector_sense(sim: Simulation, finger: int):
    """:meth:`Simulation.sense_contact` of one pad contact, its noise in the vector form."""
    raw = sim._pad_contacts(finger)
    _, point, normal, f = raw[0]
    total = max(float(f @ normal), 0.0)
    nz = sim.noise
    z = sim._rng.standard_normal(7)
    total += nz.force_std * float(z[0])
    point = point + nz.point_std * z[1:4]
    pert = nz.normal_std * z[4:7]
    normal = normal + (pert - (pert @ normal) * normal)
    normal /= math.sqrt(float(normal @ normal))
    return total, normal, point, len(raw)


def test_the_noisy_contact_reading_on_floats_is_the_vector_forms(box_scene):
    sim = Simulation(box_scene, noise=SimulatedSensorNoise.from_notes(), seed=4)
    ctl = Controller(sim, "index")
    top_z = float(BOX_CENTRE[2] + BOX_HALF[2])
    ticks = _commands(ctl, top_z)
    checked = 0
    for _ in range(300):
        next(ticks)
        if len(sim._pad_contacts(0)) != 1:
            continue
        state = sim._rng.bit_generator.state
        got = sim.sense_contact(0)
        sim._rng.bit_generator.state = state
        want = _vector_sense(sim, 0)
        assert got[0] == want[0] and got[3] == want[3]
        assert np.array_equal(got[1], want[1]) and np.array_equal(got[2], want[2])
        checked += 1
    assert checked > 100


def test_the_hands_inertia_force_on_floats_is_the_vector_sum(box_scene):
    sim = Simulation(box_scene, seed=0)
    ctl = Controller(sim, "index")
    ctl.move_fingertip(ctl.fingertip_position() + [0.03, 0.02, 0.05])
    m, d = sim.model, sim.data
    for _ in range(30):
        ctl.step(1)
        want = np.zeros(3)
        acc = np.zeros(6)
        for b in sim._hand_bodies:
            mujoco.mj_objectAcceleration(m, d, mujoco.mjtObj.mjOBJ_BODY, b, acc, 0)
            want += m.body_mass[b] * acc[3:]
        assert np.array_equal(sim.hand_inertia_force(), want)


def test_a_rotation_argument_changed_in_place_is_checked_again(box_scene):
    """The check of a fingertip target's rotation is skipped only for the very numbers that passed it last."""
    from haptic.errors import SceneError

    sim = Simulation(box_scene, seed=0)
    ctl = Controller(sim, "index")
    target = ctl.fingertip_position()
    rot = ctl.hand_rotation()
    ctl.move_fingertip(target, rot)
    ctl.move_fingertip(target, rot)  # the same numbers: accepted again
    rot[0, 0] += 0.5  # the same array, no longer a rotation
    with pytest.raises(SceneError):
        ctl.move_fingertip(target, rot)
    with pytest.raises(SceneError):
        ctl.set_hybrid(1.0, np.zeros(3), rotation_in_world=rot)
    rot[0, 0] -= 0.5
    ctl.move_fingertip(target, rot)
    assert np.array_equal(ctl._r_ref, rot) and ctl._r_ref is not rot
