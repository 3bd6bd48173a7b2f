"""Benchmark: raw ``mj_step`` steps/s vs controller-in-the-loop steps/s on the same scene, and their ratio.

Steps per CPU second of this process (``time.process_time``): on a machine shared with other work the figures
stay those of the code, not of the load.

The scene is the tracing case: the index fingertip pressing 1 N on the top face of a box and sliding at
2 cm/s (a 1 cm-radius circle, so it stays on the face) under the hybrid controller. Both figures start
from the same saved state; the raw figure holds the last control (no controller), stepping in chunks of
``control_every`` like the controller does.

    .venv/bin/python scripts/bench_sim.py [--seconds 4] [--control-every 4] [--repeats 3]

Last, the control law alone (``Controller.update``: one tick's law, no physics step) on the saved state, in each
mode: µs of CPU a tick, the best of the repeats.
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from haptic.sim.control import ControlGains, Controller
from haptic.sim.physics import SimulatedSensorNoise, Simulation
from haptic.sim.scene import TABLE_TOP_Z, compose_scene, scene_object_from_parts


def _box_scene():
    half = np.array([0.05, 0.04, 0.03])
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    world_from_object = np.eye(4)
    world_from_object[:3, 3] = [0.56, 0.0, TABLE_TOP_Z + half[2]]
    return compose_scene(scene_object_from_parts("box", [corners]), world_from_object), TABLE_TOP_Z + 2 * half[2]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=4.0, help="simulated seconds per measurement")
    ap.add_argument("--control-every", type=int, default=ControlGains().control_every)
    ap.add_argument("--repeats", type=int, default=3, help="best of this many runs")
    args = ap.parse_args(argv)

    scene, top_z = _box_scene()
    sim = Simulation(scene, noise=SimulatedSensorNoise.from_notes(), seed=0)
    ctl = Controller(sim, "index", ControlGains(control_every=args.control_every))
    ctl.move_fingertip(np.array([0.56, 0.0, top_z + 0.015]))
    ctl.step(int(0.5 / ctl.tick_period))
    ctl.set_hybrid(1.0, np.zeros(3), normal_hint=np.array([0.0, 0.0, 1.0]))
    ctl.step(int(0.8 / ctl.tick_period))
    if not ctl.hybrid_status().in_contact:
        print("setup failed: no contact")
        return 1

    m, d = sim.model, sim.data
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    state = np.zeros(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, state, spec)
    every = args.control_every
    ticks = int(args.seconds / ctl.tick_period)
    steps = ticks * every

    raw, ctrl = [], []
    for _ in range(args.repeats):
        mujoco.mj_setState(m, d, state, spec)
        t0 = time.process_time()
        for _ in range(ticks):
            mujoco.mj_step(m, d, nstep=every)
        raw.append(steps / (time.process_time() - t0))

        mujoco.mj_setState(m, d, state, spec)
        mujoco.mj_forward(m, d)
        forces = []
        t0 = time.process_time()
        for k in range(ticks // 10):
            phase = 2.0 * k * 10 * ctl.tick_period  # 2 rad/s: a 1 cm-radius circle at 2 cm/s
            ctl.set_hybrid(1.0, 0.02 * np.array([np.cos(phase), np.sin(phase), 0.0]))
            ctl.step(10)
            forces.append(ctl.last_contact().normal_force)
        ctrl.append(10 * (ticks // 10) * every / (time.process_time() - t0))

    top = ctl.fingertip_position()
    modes = {
        "posture": lambda: ctl.hold_posture(),
        "fingertip (pose)": lambda: ctl.move_fingertip(top + [0.0, 0.0, 0.005], "hold"),
        "hybrid (pressing, sliding)": lambda: ctl.set_hybrid(1.0, np.array([0.02, 0.0, 0.0]),
                                                             normal_hint=np.array([0.0, 0.0, 1.0])),
    }  # fmt: skip
    law = {}
    for name, command in modes.items():
        calls, best = 2000, np.inf
        for _ in range(args.repeats):
            mujoco.mj_setState(m, d, state, spec)
            mujoco.mj_forward(m, d)
            command()
            t0 = time.process_time()
            for _ in range(calls):
                ctl.update()
            best = min(best, (time.process_time() - t0) / calls)
        law[name] = best

    r, c = max(raw), max(ctrl)
    print(
        f"scene: {m.nbody} bodies, {m.nv} dofs, {m.ngeom} geoms; dt {m.opt.timestep * 1e3:g} ms; "
        f"control every {every} steps ({1 / ctl.tick_period:.0f} Hz)"
    )
    print(f"raw mj_step:            {r:10.0f} steps/s (CPU)")
    print(f"controller in the loop: {c:10.0f} steps/s (CPU)  (hybrid 1 N, sliding 2 cm/s, sensor noise on)")
    print(f"ratio:                  {c / r:10.2f}  (goal >= 0.5)")
    print(f"sensed normal force while sliding: {np.mean(forces):.3f} +- {np.std(forces):.3f} N")
    print(f"warnings: {sim.warnings() or 'none'}")
    print("the control law alone on the saved state (Controller.update, CPU):")
    for name, t in law.items():
        print(f"  {name:<28} {1e6 * t:6.1f} us a tick")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
