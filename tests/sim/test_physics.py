"""The simulation owner and the robot-side readout: contact sensing, noise, and no peeking."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest
from conftest import BOX_CENTRE, BOX_HALF, box_parts, box_pose, l_shape_parts

from haptic.errors import SceneError
from haptic.sim.control import Controller
from haptic.sim.physics import FingertipContact, LinkContact, SensorReading, SimulatedSensorNoise, Simulation
from haptic.sim.robot import RobotInterface
from haptic.sim.scene import FINGERS, compose_scene, scene_object_from_parts

TOP_Z = BOX_CENTRE[2] + BOX_HALF[2]


def _press_index_on_top(sim: Simulation, force: float = 1.0) -> Controller:
    ctl = Controller(sim)
    ctl.move_fingertip(np.array([BOX_CENTRE[0], BOX_CENTRE[1], TOP_Z + 0.015]))
    ctl.step(int(0.5 / ctl.tick_period))
    ctl.set_hybrid(force, np.zeros(3), normal_hint=np.array([0.0, 0.0, 1.0]))
    ctl.step(int(1.0 / ctl.tick_period))
    return ctl


def test_ids_are_resolved_and_home_is_loaded(box_scene):
    sim = Simulation(box_scene)
    assert len(sim.tip_site) == len(sim.pad_geom) == len(sim.touch_adr) == 4
    r = sim.read_sensors()
    assert r.arm_q.shape == (6,) and r.hand_q.shape == (16,)
    assert r.fingertip_in_world.shape == (4, 3)
    assert np.all(r.touch == 0) and all(len(c) == 0 for c in r.contacts)


def test_contact_readout_on_a_top_face(box_scene):
    sim = Simulation(box_scene)
    _press_index_on_top(sim, 1.0)
    r = sim.read_sensors()
    (c,) = r.contacts[FINGERS.index("index")]
    assert isinstance(c, FingertipContact)
    np.testing.assert_allclose(c.normal_in_world, [0, 0, 1], atol=1e-6)  # out of the face
    assert c.force_in_world[2] > 0  # the face pushes the fingertip up
    assert c.normal_force == pytest.approx(1.0, abs=0.1)
    assert c.point_in_world[2] == pytest.approx(TOP_Z, abs=5e-4)
    assert r.touch[0] == pytest.approx(c.normal_force, rel=0.05)
    assert np.all(r.touch[1:] == 0)


def test_sensor_noise_is_seeded(box_scene):
    def reading(seed):
        sim = Simulation(box_scene, noise=SimulatedSensorNoise.from_notes(), seed=seed)
        _press_index_on_top(sim)
        return sim.read_sensors()

    a, b, c = reading(1), reading(1), reading(2)
    np.testing.assert_array_equal(a.contacts[0][0].normal_in_world, b.contacts[0][0].normal_in_world)
    assert not np.array_equal(a.contacts[0][0].normal_in_world, c.contacts[0][0].normal_in_world)
    angle = np.degrees(np.arccos(np.clip(a.contacts[0][0].normal_in_world[2], -1, 1)))
    assert 0 < angle < 5


def test_unknown_finger_names_the_valid_ones(box_scene):
    with pytest.raises(SceneError, match="index, middle, ring, thumb"):
        Controller(Simulation(box_scene), finger="pinky")


# -- no peeking ------------------------------------------------------------------------------------------------
ROBOT_FIELDS = {"time", "arm_q", "arm_qd", "hand_q", "hand_qd", "fingertip_in_world", "touch", "contacts",
                "wrist_force", "wrist_torque", "link_contacts"}  # fmt: skip


def test_sensor_reading_holds_robot_quantities_only():
    assert {f.name for f in dataclasses.fields(SensorReading)} == ROBOT_FIELDS
    assert {f.name for f in dataclasses.fields(FingertipContact)} == {
        "point_in_world",
        "normal_in_world",
        "force_in_world",
        "normal_force",
    }
    assert {f.name for f in dataclasses.fields(LinkContact)} == {"link", "point_in_world", "normal_in_world",
                                                               "normal_force"}  # fmt: skip


def test_robot_interface_has_no_path_to_the_object(box_scene):
    sim = Simulation(box_scene)
    robot = RobotInterface(sim)
    assert not hasattr(robot, "__dict__")  # slots only: nothing can be hung on it
    public = [n for n in dir(robot) if not n.startswith("_")]
    for name in public:
        assert not any(w in name.lower() for w in ("object", "truth", "scene", "model", "data", "sim", "physics"))
        value = getattr(robot, name)
        assert not isinstance(value, mujoco.MjModel | mujoco.MjData | Simulation)
    reading = robot.read()
    for f in dataclasses.fields(reading):
        v = getattr(reading, f.name)
        assert isinstance(v, float | np.ndarray | tuple)


def test_readings_do_not_depend_on_where_the_object_is():
    """Without contact, nothing the robot reads changes when the object moves: it cannot sense its pose."""
    obj = scene_object_from_parts("box", box_parts())
    readings = []
    for dx in (0.0, 0.05):
        sim = Simulation(compose_scene(obj, box_pose(BOX_CENTRE + [dx, -0.03, 0.0])))
        robot = RobotInterface(sim)
        robot.hold_posture()
        robot.step(50)
        readings.append(robot.read())
    a, b = readings
    for f in dataclasses.fields(SensorReading):
        va, vb = getattr(a, f.name), getattr(b, f.name)
        if isinstance(va, np.ndarray):
            np.testing.assert_array_equal(va, vb)
        else:
            assert va == vb
    gt = [Simulation(compose_scene(obj, box_pose(BOX_CENTRE + [dx, 0, 0]))).ground_truth() for dx in (0, 0.05)]
    assert gt[1].world_from_object[0, 3] - gt[0].world_from_object[0, 3] == pytest.approx(0.05)


def test_the_wrist_sensor_weighs_the_hand_and_feels_the_fingertip_press(box_scene):
    # at rest in free space the flange holds the hand's weight; pressing the index pad down on the box with
    # 1 N the flange's upward force drops by about that much (the box carries it)
    sim = Simulation(box_scene)
    ctl = Controller(sim)
    ctl.hold_posture()
    ctl.step(int(0.5 / ctl.tick_period))
    hand = [b for b in range(sim.model.nbody) if sim.model.body(b).name.startswith("arm/hand/")]
    weight = float(sim.model.body_mass[hand].sum()) * 9.81
    r = sim.read_sensors()
    assert np.allclose(r.wrist_force, [0.0, 0.0, weight], atol=0.02 * weight)
    assert r.link_contacts == ()
    _press_index_on_top(sim, force=1.0)
    pressed = sim.read_sensors()
    assert pressed.touch[0] > 0.5
    assert weight - pressed.wrist_force[2] == pytest.approx(pressed.touch[0], abs=0.3)
    # the pad's contact is the pad's, not a link's
    assert pressed.link_contacts == ()


def test_a_link_pushed_into_the_table_is_sensed_by_that_link(box_scene):
    from haptic.sim.control import solve_fingertip_ik
    from haptic.sim.scene import TABLE_TOP_Z

    sim = Simulation(box_scene, noise=SimulatedSensorNoise.from_notes(), seed=2)
    target = np.array([0.55, 0.25, TABLE_TOP_Z + 0.012 - 0.03])  # the index pad's centre 3 cm into the table
    ik = solve_fingertip_ik(sim, "index", target)
    assert ik.reachable
    sim.reset(arm_q=ik.arm_q)
    r = sim.read_sensors()
    links = {c.link for c in r.link_contacts}
    assert links and links <= {"index_proximal", "index_medial", "index_distal"}
    for c in r.link_contacts:
        assert abs(c.point_in_world[2] - TABLE_TOP_Z) < 0.01
    assert len(r.contacts[0]) >= 1  # and the pad's own contact stays the pad's


def test_the_contact_views_read_what_the_contacts_hold():
    """The views of the contact buffer kept per number of contacts read, tick after tick, what MuJoCo's contact
    structs hold then: their geoms, constraint addresses, frames and points. Lowered onto an L's slab and slid
    into the corner under its block, the pad's contacts come and go and number none, one and two."""
    pose = box_pose(np.array([0.56, 0.0, BOX_CENTRE[2] - BOX_HALF[2]]))
    sim = Simulation(compose_scene(scene_object_from_parts("L", l_shape_parts()), pose))
    ctl = Controller(sim)
    top = pose[2, 3] + 0.03  # the slab's top
    ctl.move_fingertip(np.array([0.53, 0.0, top + 0.01]))
    ctl.step(60)
    ctl.set_hybrid(1.0, np.array([0.03, 0.0, 0.0]), normal_hint=np.array([0.0, 0.0, 1.0]))
    counts = set()
    for _ in range(400):
        ctl.step(1)
        d = sim.data
        counts.add(d.ncon)
        geoms, efc, frames, points = sim._contacts()
        assert geoms == [d.contact[i].geom.tolist() for i in range(d.ncon)]
        for i in range(d.ncon):
            c = d.contact[i]
            assert efc[i] == c.efc_address
            assert np.array_equal(frames[i], c.frame.reshape(3, 3)) and np.array_equal(points[i], c.pos)
    assert {0, 1, 2} <= counts, counts
