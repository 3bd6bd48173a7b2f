"""The arm and hand MJCF assets load on their own and carry what the issue asks for."""

from __future__ import annotations

import mujoco
import numpy as np

from haptic.sim.scene import ARM_XML, HAND_XML


def test_arm_alone_has_six_joints_motors_and_a_flange():
    m = mujoco.MjModel.from_xml_path(str(ARM_XML))
    assert m.njnt == 6 and m.nu == 6
    assert all(m.actuator_trntype[i] == mujoco.mjtTrn.mjTRN_JOINT for i in range(6))
    assert np.all(m.actuator_biastype == mujoco.mjtBias.mjBIAS_NONE)  # torque motors
    assert np.all(m.dof_damping > 0) and np.all(m.dof_armature > 0)
    assert np.all(m.jnt_limited == 1)
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "flange") >= 0


def test_hand_alone_has_four_fingers_of_four_joints_and_touch_sites():
    m = mujoco.MjModel.from_xml_path(str(HAND_XML))
    assert m.njnt == 16 and m.nu == 16
    kinds = [m.sensor_type[i] for i in range(m.nsensor)]
    assert kinds.count(mujoco.mjtSensor.mjSENS_TOUCH) == 4
    assert kinds.count(mujoco.mjtSensor.mjSENS_JOINTPOS) == 16
    assert kinds.count(mujoco.mjtSensor.mjSENS_JOINTVEL) == 16
    for p in ("ff", "mf", "rf", "th"):
        pad = m.geom(f"{p}_pad")
        site = m.site(f"{p}_tip")
        assert pad.type[0] == mujoco.mjtGeom.mjGEOM_SPHERE
        assert site.size[0] > pad.size[0]  # the touch site encloses the pad
        np.testing.assert_allclose(pad.solref, [0.01, 1.0])
        np.testing.assert_allclose(pad.solimp[:3], [0.6, 0.95, 0.0015])
        assert pad.condim[0] == 3 and pad.priority[0] > 0


def test_hand_has_visual_and_collision_classes():
    m = mujoco.MjModel.from_xml_path(str(HAND_XML))
    visual = [i for i in range(m.ngeom) if m.geom_contype[i] == 0 and m.geom_conaffinity[i] == 0]
    collision = [i for i in range(m.ngeom) if m.geom_contype[i] or m.geom_conaffinity[i]]
    assert visual and collision
    assert {int(m.geom_group[i]) for i in visual} == {2}
    assert {int(m.geom_group[i]) for i in collision} == {3}
