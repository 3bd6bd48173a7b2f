"""Controllers: gravity-compensated holds, operational-space fingertip control, hybrid force/motion,
reachability."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from conftest import BOX_CENTRE, BOX_HALF

from haptic.sim.control import ControlGains, Controller, solve_fingertip_ik
from haptic.sim.physics import SimulatedSensorNoise, Simulation
from haptic.sim.scene import HAND_TRACE

TOP_Z = BOX_CENTRE[2] + BOX_HALF[2]
DOWN = np.diag([-1.0, 1.0, -1.0])  # hand pointing down, palm facing the robot


def _true_index_force(sim: Simulation) -> float:
    return sum(float(f @ n) for _, _, n, f in sim._pad_contacts(0))


def test_posture_hold_keeps_the_fingertip_still(box_scene):
    sim = Simulation(box_scene)
    ctl = Controller(sim)
    ctl.hold_posture()
    x0 = sim.fingertip_positions()
    ctl.step(int(2.0 / ctl.tick_period))
    assert np.abs(sim.fingertip_positions() - x0).max() < 1e-3
    np.testing.assert_allclose(sim.data.qpos[sim.hand], HAND_TRACE, atol=0.02)


def test_without_gravity_compensation_the_arm_sags(box_scene):
    """The hold above is not vacuous: the same PD without the bias torques lets the fingertip drop."""
    sim = Simulation(box_scene)
    ctl = Controller(sim)
    ctl.hold_posture()
    x0 = sim.fingertip_positions()[0]
    for _ in range(int(1.0 / ctl.tick_period)):
        ctl.update()
        sim.data.ctrl[sim.arm] -= sim.data.qfrc_bias[sim.arm]
        sim.step(ctl.gains.control_every)
    assert x0[2] - sim.fingertip_positions()[0][2] > 5e-3


@pytest.mark.parametrize("rotation", ["hold", None], ids=["pose", "position-only"])
def test_fingertip_holds_a_target_within_1mm(box_scene, rotation):
    sim = Simulation(box_scene)
    ctl = Controller(sim, "index")
    target = sim.fingertip_positions()[0] + np.array([0.03, -0.04, -0.05])
    ctl.move_fingertip(target, rotation)
    ctl.step(int(1.0 / ctl.tick_period))
    errors = []
    for _ in range(int(1.0 / ctl.tick_period)):
        ctl.step(1)
        errors.append(np.linalg.norm(sim.fingertip_positions()[0] - target))
    assert max(errors) < 1e-3


def test_other_finger_can_be_the_active_one(box_scene):
    sim = Simulation(box_scene)
    ctl = Controller(sim, "middle")
    target = sim.fingertip_positions()[1] + np.array([0.0, 0.02, -0.02])
    ctl.move_fingertip(target)
    ctl.step(int(1.5 / ctl.tick_period))
    assert np.linalg.norm(sim.fingertip_positions()[1] - target) < 1e-3


def _slide(sim: Simulation, velocity, seconds=1.5, settle=0.3):
    ctl = Controller(sim)
    ctl.move_fingertip(np.array([BOX_CENTRE[0] - 0.015, BOX_CENTRE[1] - 0.015, TOP_Z + 0.015]))
    ctl.step(int(0.5 / ctl.tick_period))
    ctl.set_hybrid(1.0, np.zeros(3), normal_hint=np.array([0.0, 0.0, 1.0]))
    ctl.step(int(1.0 / ctl.tick_period))
    assert ctl.hybrid_status().in_contact
    start = sim.fingertip_positions()[0]
    ctl.set_hybrid(1.0, np.asarray(velocity, float))
    ctl.step(int(settle / ctl.tick_period))
    forces = []
    for _ in range(int(seconds / ctl.tick_period)):
        ctl.step(1)
        forces.append(_true_index_force(sim))
    travel = sim.fingertip_positions()[0] - start
    return np.array(forces), travel, ctl


@pytest.mark.parametrize("noise", [None, SimulatedSensorNoise.from_notes()], ids=["ideal", "noisy"])
@pytest.mark.parametrize("direction", [(1.0, 0.0), (0.0, 1.0)], ids=["x", "y"])
def test_hybrid_holds_1N_while_sliding_at_2cm_per_s(box_scene, noise, direction):
    sim = Simulation(box_scene, noise=noise, seed=3)
    v = 0.02 * np.array([*direction, 0.0])
    forces, travel, ctl = _slide(sim, v)
    assert forces.min() > 0  # never lost contact
    assert forces.mean() == pytest.approx(1.0, abs=0.05)
    assert forces.std() < 0.1
    assert travel @ v / 0.02 == pytest.approx(0.02 * 1.8, rel=0.1)  # moved at 2 cm/s
    assert abs(travel[2]) < 1e-3
    assert sim.warnings() == {}
    np.testing.assert_allclose(ctl.hybrid_status().normal_in_world, [0, 0, 1], atol=0.03)


def test_hybrid_at_a_lower_control_rate_still_regulates(box_scene):
    sim = Simulation(box_scene)
    ctl = Controller(sim, gains=ControlGains(control_every=8))
    ctl.move_fingertip(np.array([BOX_CENTRE[0], BOX_CENTRE[1], TOP_Z + 0.015]))
    ctl.step(int(0.5 / ctl.tick_period))
    ctl.set_hybrid(1.0, np.array([0.02, 0.0, 0.0]), normal_hint=np.array([0.0, 0.0, 1.0]))
    ctl.step(int(1.2 / ctl.tick_period))
    forces = []
    for _ in range(int(1.0 / ctl.tick_period)):
        ctl.step(1)
        forces.append(_true_index_force(sim))
    assert np.mean(forces) == pytest.approx(1.0, abs=0.05) and np.std(forces) < 0.1


def test_reachability(box_scene):
    sim = Simulation(box_scene)
    target = np.array([0.6, 0.05, TOP_Z + 0.01])
    res = solve_fingertip_ik(sim, "index", target, DOWN)
    assert res.reachable and res.position_error < 1e-4
    q_before = sim.data.qpos.copy()
    assert not solve_fingertip_ik(sim, "index", np.array([1.8, 0.0, 0.5]), DOWN).reachable
    np.testing.assert_array_equal(sim.data.qpos, q_before)  # the query does not touch the simulation
    # the controller reaches what the check calls reachable
    ctl = Controller(sim)
    ctl.move_fingertip(target, DOWN)
    ctl.step(int(2.0 / ctl.tick_period))
    assert np.linalg.norm(sim.fingertip_positions()[0] - target) < 1e-3


def test_stepping_computes_the_sensors_of_each_ticks_last_step_alone(box_scene):
    """Sensors skipped in a tick's first physics steps: the same state and the same sensor readings as stepping
    with every sensor computed in every step."""
    runs = []
    for every_step in (False, True):
        sim = Simulation(box_scene, noise=SimulatedSensorNoise.from_notes(), seed=0)
        flags = sim.model.opt.disableflags
        ctl = Controller(sim)
        ctl.move_fingertip(np.array([0.56, 0.0, TOP_Z + 0.01]))
        ctl.step(60)
        ctl.set_hybrid(1.0, np.array([0.01, 0.0, 0.0]), normal_hint=np.array([0.0, 0.0, 1.0]))
        for _ in range(120):
            if every_step:
                ctl.update()
                sim.step(ctl.gains.control_every)
            else:
                ctl.step(1)
        assert sim.model.opt.disableflags == flags  # the sensors' flag restored
        runs.append((sim.data.qpos.copy(), sim.data.sensordata.copy(), sim.touch()))
    assert runs[0][1].any()  # the wrist and the pad sense the press
    for a, b in zip(*runs, strict=True):
        assert np.array_equal(a, b)


def test_island_discovery_off_gives_the_same_steps(box_scene):
    """The scene leaves MuJoCo's island discovery off (the robot is one kinematic tree, the object static: one
    island): pressing and sliding on the box, every tick's state, contacts and sensors are those with it on."""
    island = int(mujoco.mjtDisableBit.mjDSBL_ISLAND)
    runs = []
    for discover in (False, True):
        sim = Simulation(box_scene, noise=SimulatedSensorNoise.from_notes(), seed=0)
        assert sim.model.opt.disableflags & island
        if discover:
            sim.model.opt.disableflags &= ~island
        ctl = Controller(sim)
        ctl.move_fingertip(np.array([0.56, 0.0, TOP_Z + 0.01]))
        ctl.step(60)
        ctl.set_hybrid(1.0, np.array([0.01, 0.0, 0.0]), normal_hint=np.array([0.0, 0.0, 1.0]))
        ticks = []
        for _ in range(150):
            ctl.step(1)
            d = sim.data
            ticks.append(np.concatenate([d.qpos, d.qvel, d.qacc, d.sensordata, [d.ncon, d.nefc]]))
        runs.append(np.array(ticks))
    assert runs[0][:, -2].max() > 0  # the pad touches the box
    assert np.array_equal(runs[0], runs[1])
