"""The reach solver (``haptic.sim.reach``, mink's QP over arm and fingers) against the arm-only damped least
squares of ``haptic.sim.control.solve_fingertip_ik`` on the same fingertip targets over the table.

    .venv/bin/python scripts/bench_reach.py [--targets 200] [--seed 0]

Targets: pad centres drawn uniformly over the table's work region (x 0.40-0.80 m, y ±0.20 m, 15-150 mm above the
table top), for the index finger; the multi-finger rows put two or four pads 25-40 mm apart around such a point.
Per solver and kind of target it prints how many were reached, how many of those leave a link of the hand
inside the table (the arm-only solver does not look at the table; the QP keeps a clearance), the failure
reasons, and the time per query.
"""

from __future__ import annotations

import argparse
import os
import time
from collections import Counter

os.environ.setdefault("MUJOCO_GL", "disable")

import numpy as np  # noqa: E402

from haptic.sim.control import solve_fingertip_ik  # noqa: E402
from haptic.sim.physics import Simulation  # noqa: E402
from haptic.sim.reach import FingertipTarget, ReachSolver  # noqa: E402
from haptic.sim.scene import FINGERS, compose_scene  # noqa: E402

DOWN = np.array([0.0, 0.0, -1.0])


def draw_points(rng: np.random.Generator, n: int, top: float) -> np.ndarray:
    lo = np.array([0.40, -0.20, top + 0.015])
    hi = np.array([0.80, 0.20, top + 0.150])
    return lo + rng.random((n, 3)) * (hi - lo)


def row(name: str, reached: int, inside: int, n: int, reasons: Counter, ms: list[float]) -> str:
    why = ", ".join(f"{k}: {v}" for k, v in reasons.most_common()) or "-"
    return (f"| {name} | {reached}/{n} | {inside} | {np.median(ms):.1f} / {np.percentile(ms, 90):.1f} | {why} |")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--targets", type=int, default=200, help="targets per kind (default 200)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the targets (default 0)")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    scene = compose_scene(None)
    sim = Simulation(scene)
    solver = ReachSolver(scene)
    top = solver.table_top_z
    points = draw_points(rng, args.targets, top)
    print("| solver, targets | reached | of them, hand inside the table | ms median / p90 | not reached: why |")
    print("|---|---|---|---|---|")

    for name, rotation in (("arm-only DLS, index, hand pointing down", DOWN_ROTATION),
                           ("arm-only DLS, index, any hand rotation", None)):  # fmt: skip
        reached = inside = 0
        reasons: Counter = Counter()
        ms = []
        for p in points:
            t0 = time.perf_counter()
            r = solve_fingertip_ik(sim, "index", p, rotation)
            ms.append(1000 * (time.perf_counter() - t0))
            if not r.reachable:
                reasons["not reached"] += 1
                continue
            reached += 1
            q = np.concatenate([r.arm_q, sim.data.qpos[sim.hand]])
            if solver.table_clearance(q) < 0.0:
                inside += 1
        print(row(name, reached, inside, len(points), reasons, ms))

    kinds = {
        "QP, index, any direction": lambda p: [FingertipTarget("index", p)],
        "QP, index, pointing down": lambda p: [FingertipTarget("index", p, DOWN)],
        "QP, index + middle": lambda p: [FingertipTarget("index", p + [0, 0.0175, 0]),
                                         FingertipTarget("middle", p - [0, 0.0175, 0])],
        "QP, four fingers": lambda p: [FingertipTarget(f, p + off) for f, off in zip(FINGERS, FOUR, strict=True)],
    }
    for name, make in kinds.items():
        reached = inside = 0
        reasons = Counter()
        ms = []
        for p in points:
            t0 = time.perf_counter()
            r = solver.solve(make(p))
            ms.append(1000 * (time.perf_counter() - t0))
            if not r.ok:
                reasons[str(r.reason)] += 1
                continue
            reached += 1
            inside += int(solver.table_clearance(r.qpos) < 0.0)
        print(row(name, reached, inside, len(points), reasons, ms))
    return 0


DOWN_ROTATION = np.diag([-1.0, 1.0, -1.0])
"""A hand rotation with its z (along the fingers) pointing down, as the tracing moves hold it."""
FOUR = np.array([[0.0, 0.035, 0.0], [0.0, 0.0, 0.0], [0.0, -0.035, 0.0], [0.04, 0.02, 0.0]])
"""Pad offsets of the four-finger targets: three in a row 35 mm apart, the thumb opposite [m]."""


if __name__ == "__main__":
    raise SystemExit(main())
