"""Where a physics episode's CPU goes: the episodes of ``scripts/physics_episodes.py`` run in this process, the CPU time
(``time.process_time``) of each part summed over them, with the simulated time and the control ticks.

    .venv/bin/python scripts/episode_cpu.py [--objects BOX01,WEDGE01] [--seed 1] [--verify none|fast|full]

The parts: ``mj_step`` (the physics steps of every control tick), the control law (``Controller._tick``: the
operational-space torque, the hybrid terms, the fingertip's contact sensing), the rest of each tick (the tick loop
and the primitives' bookkeeping: the trace's rows, the links' and the wrist's watch), building the episode (scene
composition, the model's compilation, the convex pieces of a non-convex model), the truth scored for the records
(the perception scores and the true interpretation ``physics_episodes.py`` computes before every move; evaluation
only), and the rest (planner, matcher, segmenter, landing search, ...). Each part is timed by wrapping its
functions, which adds about a microsecond a call: compare runs of this script with each other, not with
``physics_episodes.py``'s ``cpu_time_s``.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import defaultdict
from pathlib import Path

import haptic
from haptic.episode import evaluate
from haptic.executor import primitives
from haptic.sim import control, physics, scene

# the episode runner of the checkout ``haptic`` is imported from (another commit's, with PYTHONPATH set to it)
sys.path.insert(0, str(Path(haptic.__file__).resolve().parents[1] / "scripts"))
import physics_episodes  # noqa: E402

SPENT: dict[str, float] = defaultdict(float)
CALLS: dict[str, int] = defaultdict(int)


def _timed(owner, name: str, part: str) -> None:
    """Replace ``owner.name`` by a wrapper adding its CPU time to ``SPENT[part]`` (outermost calls only)."""
    fn = getattr(owner, name)
    depth = [0]

    def wrapper(*args, **kwargs):
        depth[0] += 1
        t0 = time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            depth[0] -= 1
            if depth[0] == 0:
                SPENT[part] += time.process_time() - t0
                CALLS[part] += 1

    setattr(owner, name, wrapper)


def _timed_mj_step() -> None:
    """Time the controller's ``mj_step`` calls (the module's reference to MuJoCo, not MuJoCo itself)."""
    mj = control.mujoco
    step = mj.mj_step

    class _MuJoCo:
        def __getattr__(self, name):
            return getattr(mj, name)

        @staticmethod
        def mj_step(m, d, nstep=1):
            t0 = time.process_time()
            step(m, d, nstep=nstep)
            SPENT["mj_step"] += time.process_time() - t0
            CALLS["mj_step"] += nstep

    control.mujoco = _MuJoCo()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--objects", default=",".join(physics_episodes.SEED_OBJECTS))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--verify", default="none", choices=("none", "fast", "full"))
    args = ap.parse_args(argv)

    _timed_mj_step()
    _timed(control.Controller, "_tick", "control law")
    _timed(primitives.Toucher, "tick", "ticks")
    _timed(scene, "compose_scene", "building the episode")
    _timed(scene, "scene_object_from_polyhedron", "building the episode")
    _timed(physics.Simulation, "__init__", "building the episode")
    if hasattr(evaluate, "true_hypothesis"):
        _timed(evaluate, "true_hypothesis", "truth for the records")
    _timed(evaluate, "score_components", "truth for the records")
    _timed(physics_episodes, "one", "episodes")
    import haptic.sim

    haptic.sim.compose_scene = scene.compose_scene

    sim_time = 0.0
    for name in [o for o in args.objects.split(",") if o]:
        rec = physics_episodes.one(name, args.seed, "planner", verify=args.verify)
        sim_time += rec.get("sim_time_s", 0.0)
        print(f"{name:<12} {rec['outcome']:<10} moves {rec.get('moves', 0):>3}  "
              f"simulated {rec.get('sim_time_s', 0):6.1f} s")
    total, ticks = SPENT["episodes"], CALLS["control law"]
    parts = {
        "mj_step": SPENT["mj_step"],
        "control law": SPENT["control law"],
        "rest of the ticks": SPENT["ticks"] - SPENT["mj_step"] - SPENT["control law"],
        "building the episode": SPENT["building the episode"],
        "truth for the records": SPENT["truth for the records"],
    }
    parts["the rest"] = total - sum(parts.values())
    print(f"\n{CALLS['episodes']} episodes, {sim_time:.1f} simulated s, {ticks} control ticks, "
          f"{CALLS['mj_step']} steps; CPU {total:.2f} s ({sim_time / total:.1f} simulated s per CPU s)")
    for k, v in parts.items():
        in_ticks = k in ("mj_step", "control law", "rest of the ticks")
        per = f"{1e6 * v / ticks:6.1f} us a tick" if ticks and in_ticks else ""
        print(f"  {k:<22} {v:7.2f} s  {100 * v / total:5.1f} %  {per}")
    if CALLS["mj_step"]:
        print(f"  mj_step: {1e6 * SPENT['mj_step'] / CALLS['mj_step']:.1f} us a step")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
