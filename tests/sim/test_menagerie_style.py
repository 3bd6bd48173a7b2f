"""Menagerie-style scene test: every library object in a scene steps for 2 s under a held posture plus
random control noise, with no MuJoCo warning and a finite state."""

from __future__ import annotations

import numpy as np
import pytest

from haptic.geometry import load_library
from haptic.sim.control import Controller
from haptic.sim.physics import Simulation
from haptic.sim.scene import compose_scene, scene_object_from_polyhedron

LIBRARY = load_library()


@pytest.mark.parametrize("name", sorted(LIBRARY))
def test_object_scene_steps_without_warnings(name):
    obj = scene_object_from_polyhedron(LIBRARY[name])
    sim = Simulation(compose_scene(obj, seed=hash(name) % 1000))
    ctl = Controller(sim)
    ctl.hold_posture()
    rng = np.random.default_rng(0)
    m, d = sim.model, sim.data
    span = m.actuator_ctrlrange[:, 1] - m.actuator_ctrlrange[:, 0]
    ticks = int(2.0 / ctl.tick_period)
    for _ in range(ticks):
        ctl.update()
        d.ctrl[:] += 0.01 * span * rng.standard_normal(m.nu)  # 1 % of each actuator's range
        sim.step(ctl.gains.control_every)
    assert sim.time == pytest.approx(2.0, abs=1e-6)
    assert sim.warnings() == {}
    assert sim.state_is_finite()
    assert np.all(np.isfinite(d.sensordata))
