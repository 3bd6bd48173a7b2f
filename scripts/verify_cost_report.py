"""What a verification costs, from two ``haptic bench`` records of the same draws: one with ``--verify none``, one
with a verification mode.

    .venv/bin/haptic bench --policy planner --episodes 200 --workers 1 --moves all --verify none --out none.jsonl
    .venv/bin/haptic bench --policy planner --episodes 200 --workers 1 --moves all --verify full --out full.jsonl
    .venv/bin/python scripts/verify_cost_report.py none.jsonl full.jsonl [--worst 5]

Prints one table row (markdown): episodes, verification statuses, the mean path cost of each and their ratio, and
the verification's cost (the record's ``verified.cost``) against its lower bound (``verified.tour_bound``) and the
tour planned at its start (``verified.tour_planned``), as a ratio of means with the median of the per-episode
ratios; the probes at the faces' middles and their cost (``verified.middles_probed``, ``middles_cost``), and the
cost without them against the bound; the same against the bound for the vertices alone
(``verified.tour_vertex_bound``: the bound of a confirmed verification also counts the probes the faces' middles
need) and the spanning tree's weaker bound (``verified.tour_tree_bound``) where the record has them; the confirmed
verifications that cost less than their bound (none, if it is one); then the episodes farthest above their bound,
and the models by that ratio.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter, defaultdict

import numpy as np

from haptic.errors import HapticError


def _load(path: str) -> list[dict]:
    try:
        with open(path) as f:
            return [json.loads(line) for line in f if line.strip()]
    except (OSError, json.JSONDecodeError) as exc:
        raise HapticError(f"{path}: not a haptic bench record ({exc})") from exc


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("none", help="haptic bench record with --verify none")
    ap.add_argument("verified", help="haptic bench record of the same draws with a verification mode")
    ap.add_argument("--worst", type=int, default=5, help="episodes listed farthest above their bound")
    args = ap.parse_args(argv)
    try:
        none, ver = _load(args.none), _load(args.verified)
    except HapticError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    cost0 = {(r["model"], r["seed"], r["policy"]): r["path_cost"] for r in none}
    both = [r for r in ver if (r["model"], r["seed"], r["policy"]) in cost0]
    if not both:
        print("error: the two records share no episode (model, seed and policy)", file=sys.stderr)
        return 2
    c0 = np.mean([cost0[(r["model"], r["seed"], r["policy"])] for r in both])
    c1 = np.mean([r["path_cost"] for r in both])
    v = [r for r in both if (r.get("verified") or {}).get("tour_bound")]
    cost = np.array([r["verified"]["cost"] for r in v])
    bound = np.array([r["verified"]["tour_bound"] for r in v])
    plan = np.array([r["verified"].get("tour_planned", np.nan) for r in v])
    status = Counter((r.get("verified") or {}).get("status", "-") for r in both)
    mid = np.array([r["verified"].get("middles_cost", 0.0) for r in v])
    probes = np.mean([r["verified"].get("middles_probed", 0) for r in v])
    print("| episodes | statuses | mean path cost, none | mean path cost, verified | ratio | verification's cost | "
          "its lower bound | cost / bound (median) | tour planned | cost / planned (median) | faces' middles: "
          "probes, cost | cost less the middles / bound (median) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    print(f"| {len(both)} | {', '.join(f'{k} {n}' for k, n in status.most_common())} | {c0:.2f} | {c1:.2f} | "
          f"{c1 / c0:.2f}× | {cost.mean():.2f} | {bound.mean():.2f} | {cost.mean() / bound.mean():.2f}× "
          f"({np.median(cost / bound):.2f}) | {np.nanmean(plan):.2f} | {cost.mean() / np.nanmean(plan):.2f}× "
          f"({np.nanmedian(cost / plan):.2f}) | {probes:.1f}, {mid.mean():.2f} | "
          f"{(cost - mid).mean() / bound.mean():.2f}× ({np.median((cost - mid) / bound):.2f}) |")
    for key, what in (("tour_vertex_bound", "the vertices' bound"), ("tour_tree_bound", "the spanning tree's bound")):
        other = np.array([r["verified"].get(key, np.nan) for r in v])
        t = np.isfinite(other)
        if not t.any():
            continue
        ct, mt, bt = cost[t], (cost - mid)[t], other[t]
        print(f"\n{what} ({key}, {int(t.sum())} episodes): {bt.mean():.2f}, the verification's cost "
              f"{ct.mean() / bt.mean():.2f}× it (median {np.median(ct / bt):.2f}), less the middles "
              f"{mt.mean() / bt.mean():.2f}× (median {np.median(mt / bt):.2f})")
    done = np.array([r["verified"]["status"] == "confirmed" for r in v])
    below = int(np.sum(done & (cost < bound - 1e-6)))
    print(f"\nconfirmed episodes below their bound: {below} of {int(done.sum())}")
    print(f"\nfarthest above the bound ({args.worst}):")
    for k in np.argsort(-cost / bound)[: args.worst]:
        r = v[int(k)]
        kinds = "".join(m[0] for m in r["move_kinds"][-r["verified"]["moves"]:])
        print(f"  {r['model']} seed {r['seed']}: {cost[k]:.1f} / {bound[k]:.1f} = {cost[k] / bound[k]:.2f}×, "
              f"planned {plan[k]:.1f}, {r['verified']['moves']} moves {kinds}")
    by = defaultdict(list)
    for r, c, b in zip(v, cost, bound, strict=True):
        by[r["model"]].append((c, b))
    print("\nby model (cost / bound, ratio of means):")
    for name, xs in sorted(by.items(), key=lambda kv: -sum(c for c, _ in kv[1]) / sum(b for _, b in kv[1])):
        a = np.array(xs)
        print(f"  {name}: {a[:, 0].mean() / a[:, 1].mean():.2f}× ({len(xs)} episodes, cost {a[:, 0].mean():.1f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
