"""The MuJoCo side of the testbed: scene composition, the simulation owner, sensors and controllers.

Only this package (and later ``haptic.executor``) imports mujoco / dm_control.
"""

import os

os.environ.setdefault("MUJOCO_GL", "disable")  # headless by default; set egl/osmesa yourself to render

from haptic.sim.control import ControlGains, Controller, HybridStatus, IKResult, solve_fingertip_ik  # noqa: E402
from haptic.sim.physics import (  # noqa: E402
    ContactSummary,
    FingertipContact,
    GroundTruth,
    LinkContact,
    LinkGeom,
    SensorReading,
    SimulatedSensorNoise,
    Simulation,
)
from haptic.sim.robot import RobotInterface  # noqa: E402
from haptic.sim.scene import (  # noqa: E402
    FINGERS,
    ComposedScene,
    SceneObject,
    compose_scene,
    export_scene,
    load_object,
    random_object_pose,
    scene_object_from_parts,
    scene_object_from_polyhedron,
)

__all__ = [
    "FINGERS",
    "ComposedScene",
    "ContactSummary",
    "ControlGains",
    "Controller",
    "FingertipContact",
    "GroundTruth",
    "HybridStatus",
    "IKResult",
    "LinkContact",
    "LinkGeom",
    "RobotInterface",
    "SceneObject",
    "SimulatedSensorNoise",
    "SensorReading",
    "Simulation",
    "compose_scene",
    "export_scene",
    "load_object",
    "random_object_pose",
    "scene_object_from_parts",
    "scene_object_from_polyhedron",
    "solve_fingertip_ik",
]
