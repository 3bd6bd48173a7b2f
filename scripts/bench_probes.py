"""Benchmark of free-space probes at the planner's decision points, geometric executor (not a timed test).

For random objects and poses, tracing moves at random until the matcher holds two or more pose classes; then
at that decision point: the probe candidates and their predictions (:mod:`haptic.planning.probe_lines`,
:mod:`haptic.planning.probe_prediction`), the most
efficient probe against the most efficient tracing move (the planner's own scoring), and the best probe
carried out at the true object, its data matched (:mod:`haptic.matching.free_space`). Prints per trial and in sum:
pose classes the true class's prediction says the probe eliminates against those the matcher then
eliminated, whether the true class survived, and the time to generate and predict the candidates.

    .venv/bin/python scripts/bench_probes.py [--trials 40] [--seed 0] [--noise 1.0] [--models DIR] [--c-p 2.0]
        [--c-s 20.0]

``--c-p``, ``--c-s``: the probe's cost constants (:class:`~haptic.planning.moves.CostModel`); the tracing moves
keep their defaults.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from haptic.episode.loop import hypotheses_from
from haptic.executor.geometric import GeometricExecutor
from haptic.geometry import SE3, load_library
from haptic.matching.components import SensorNoise
from haptic.matching.free_space import apply_probes
from haptic.matching.library import LibraryArrays
from haptic.matching.recognition import PoseTolerance, equivalent_by_symmetry, recognize
from haptic.matching.tree import InterpretationTree
from haptic.planning.config import PlannerConfig
from haptic.planning.efficiency import class_weights
from haptic.planning.moves import CostModel
from haptic.planning.policies import Context, PlannerPolicy
from haptic.planning.probe_lines import candidate_probes
from haptic.planning.probe_prediction import predict_probes


def _true_class(classes, name, truth, tol) -> int | None:
    for k, c in enumerate(classes):
        if c.name == name and equivalent_by_symmetry(truth, c.world_from_model, c.model, tol):
            return k
    return None


def trial(lib, arrays, rng, noise, costs: CostModel | None = None, max_moves: int = 12) -> dict | None:
    """One decision point; None when the walk recognised the object (or found no pose) first."""
    names = sorted(lib)
    name = names[int(rng.integers(len(names)))]
    truth = SE3.random(rng, 0.1)
    ex = GeometricExecutor(lib[name], truth, noise, rng)
    tree = InterpretationTree(arrays)
    components = {}
    for c in ex.start().components:
        tree.add(c)
        components[c.id] = c
    rec = recognize(tree, max_interpretations=400)
    for _ in range(max_moves):
        if len(rec.classes) >= 2 and rec.status == "exploring":
            break
        options = ex.admissible_moves(rng, n_directions=1)
        res = ex.execute(options[int(rng.integers(len(options)))])
        if res.ok:
            for c in res.components:
                tree.add(c)
                components[c.id] = c
            rec = recognize(tree, max_interpretations=400)
    if len(rec.classes) < 2 or rec.status != "exploring":
        return None
    tol = PoseTolerance.from_data(tree.data)
    k_true = _true_class(rec.classes, name, truth, tol)
    hyps = hypotheses_from(tree, rec)
    weights = class_weights([h.model for h in hyps])
    t0 = time.perf_counter()
    moves = candidate_probes(hyps)
    preds = predict_probes(hyps, moves, ex.state.position, components, noise, costs)
    scores = [p.score(weights) for p in preds]
    t_probe = time.perf_counter() - t0
    t0 = time.perf_counter()
    decision = PlannerPolicy().choose(Context(hyps, ex.state, components, noise, PlannerConfig(), tree=tree), rng)
    t_trace = time.perf_counter() - t0
    best_trace = max((c.score for c in decision.candidates), default=0.0)
    i = int(np.argmax([s[0] for s in scores]))
    pred = preds[i]
    predicted = int(pred.eliminates()[k_true].sum()) if k_true is not None else None
    res = ex.execute(pred.move)
    hits = []
    for c in res.components:
        tree.add(c)
        hits.append(c.id)
    t0 = time.perf_counter()
    apply_probes(tree, res.free_space, hits)
    t_match = time.perf_counter() - t0
    after = recognize(tree, max_interpretations=400)
    alive = after.classes or ()
    survived = after.status != "no-match" and (
        not alive or _true_class(alive, name, truth, PoseTolerance.from_data(tree.data)) is not None
    )
    return {
        "model": name, "classes": len(rec.classes), "candidates": len(moves), "probe_eff": scores[i][0],
        "trace_eff": best_trace, "hit": bool(res.components), "predicted": predicted,
        "eliminated": len(rec.classes) - len(alive) if alive else None, "true_survived": survived,
        "t_probe": t_probe, "t_trace": t_trace, "t_match": t_match, "leaves": tree.count,
    }  # fmt: skip


def run(trials: int = 40, seed: int = 0, noise: float = 1.0, models: str | None = None, quiet: bool = False,
        costs: CostModel | None = None):
    lib = load_library(models) if models else load_library()
    arrays = LibraryArrays.build(lib)
    rng = np.random.default_rng(seed)
    rows = []
    attempts = 0
    while len(rows) < trials and attempts < 10 * trials:
        attempts += 1
        r = trial(lib, arrays, rng, SensorNoise().scaled(noise), costs)
        if r is None:
            continue
        rows.append(r)
        if not quiet:
            print(f"{r['model']:>12} classes {r['classes']:3d} cands {r['candidates']:3d} "
                  f"eff probe {r['probe_eff']:.3f} trace {r['trace_eff']:.3f} hit {r['hit']!s:5} "
                  f"elim predicted {r['predicted']} actual {r['eliminated']} true kept {r['true_survived']} "
                  f"t {r['t_probe']:.3f}s/{r['t_trace']:.3f}s/{r['t_match']:.3f}s")  # fmt: skip
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--noise", type=float, default=1.0)
    ap.add_argument("--models", default=None)
    ap.add_argument("--c-p", type=float, default=CostModel.c_p, help="cost per probe [units]")
    ap.add_argument("--c-s", type=float, default=CostModel.c_s, help="cost per metre of free space [units/m]")
    a = ap.parse_args()
    rows = run(a.trials, a.seed, a.noise, a.models, costs=CostModel(c_p=a.c_p, c_s=a.c_s))
    if not rows:
        print("no decision point reached")
        return
    pe = np.array([r["probe_eff"] for r in rows])
    te = np.array([r["trace_eff"] for r in rows])
    both = [r for r in rows if r["predicted"] is not None and r["eliminated"] is not None]
    med_classes = np.median([r["classes"] for r in rows])
    med_cands = np.median([r["candidates"] for r in rows])
    print(f"\n{len(rows)} decision points (seed {a.seed}, noise {a.noise}, c_p {a.c_p:g}, c_s {a.c_s:g}); classes "
          f"at decision: median {med_classes:.0f}; candidates: median {med_cands:.0f}")
    print(f"true class survived the probe: {sum(r['true_survived'] for r in rows)}/{len(rows)}")
    print(f"best probe hit: {sum(r['hit'] for r in rows)}/{len(rows)}")
    print(f"efficiency, best probe vs best tracing move: median {np.median(pe):.3f} vs {np.median(te):.3f}; "
          f"probe higher at {int((pe > te).sum())}/{len(rows)}")
    if both:
        p = np.array([r["predicted"] for r in both])
        q = np.array([r["eliminated"] for r in both])
        print(f"classes eliminated (under the true class's prediction vs matcher): mean {p.mean():.2f} vs "
              f"{q.mean():.2f}; equal at {int((p == q).sum())}/{len(both)}")
    t_probe, t_trace = np.median([r["t_probe"] for r in rows]), np.median([r["t_trace"] for r in rows])
    t_match = np.median([r["t_match"] for r in rows])
    print(f"time to generate and predict the probe candidates: median {t_probe:.3f} s; to score the tracing "
          f"moves: median {t_trace:.3f} s; to match the probe's data (apply_probes): median {t_match:.3f} s, "
          f"max {max(r['t_match'] for r in rows):.3f} s (shared machine)")


if __name__ == "__main__":
    main()
