"""The physics executor knows the table (a workspace prior): moves that would put the pad on it fail at once."""

from __future__ import annotations

import math

import numpy as np

from haptic.executor.physics import PhysicsExecutor
from haptic.geometry import load_library
from haptic.sim import RobotInterface, SimulatedSensorNoise, Simulation, compose_scene, random_object_pose
from haptic.sim.scene import TABLE_TOP_Z, scene_object_from_polyhedron


def _executor() -> PhysicsExecutor:
    obj = scene_object_from_polyhedron(load_library()["BOX01"])
    pose = random_object_pose(obj, np.random.default_rng(3))
    sim = Simulation(compose_scene(obj, pose), noise=SimulatedSensorNoise.from_notes(), seed=3)
    return PhysicsExecutor(RobotInterface(sim), rng=np.random.default_rng(3))


def test_vertex_circle_is_limited_by_the_table():
    ex = _executor()
    n = np.array([1.0, 0.0, 0.0])  # a vertical face
    up = np.array([0.0, 0.0, 1.0])  # the edge runs up from the vertex
    w = np.array([0.0, 1.0, 0.0])  # into the face, horizontally

    def sweep(height: float) -> float:
        vtx = np.array([0.5, 0.0, TABLE_TOP_Z + height])
        return ex.workspace.circle_sweep_off_table(vtx, n, -up, w)

    assert sweep(0.0) == 0.0  # a vertex on the table: not even the circle's start is reachable
    assert sweep(0.06) == 2 * math.pi  # a top vertex: the whole circle is clear
    part = sweep(0.018)  # low: the circle may start but must stop before it dips to the table
    assert 0.0 < part < math.pi
    # a horizontal face at table-vertex height is still clear (the pad rests on it from above)
    assert ex.workspace.pad_clearance(np.array([0.5, 0.0, TABLE_TOP_Z + 0.005]), up) > 0.004
    assert ex.workspace.pad_clearance(np.array([0.5, 0.0, TABLE_TOP_Z + 0.005]), n) < 0.0
