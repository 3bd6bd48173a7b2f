"""Physics episodes on every object of the seed library at a few random resting poses, headless: outcome,
moves, path cost, wall, CPU and simulated time, pose error and perception errors per episode, then a summary per object.

    .venv/bin/python scripts/physics_episodes.py [--poses 3] [--first-seed 1] [--objects BOX01,WEDGE01]
                                                 [--policy planner] [--moves tracing|all]
                                                 [--verify none|fast|full] [--jobs 2] [--json episodes.json]
                                                 [--probe-costs]

Pose ``k`` of an object is episode seed ``first-seed + k`` (the seed places the object and drives the planner's
random choices), so any row can be replayed with ``haptic explore --object NAME --executor physics --seed S``
(and ``--moves all`` for free-space probes too: the probes used, those that missed and those that failed are
counted per episode).
``--probe-costs`` lists every probe the planner chose with its predicted cost -- the expected one it was ranked
by, and the mean over the hypotheses that predicted the outcome it had (hit or miss) -- beside the cost the hand
reported, and sums up their differences.
After the failed moves by reason, every face, edge and vertex move is set against what the planner predicts of it
under the true interpretation of the data so far (:class:`TruthOutlook`, evaluation only): predicted made and then
failed, by reason; predicted to stop (the table, an undercut, a concave end) and stopped or went through; then every
move offered against its outcome, as before.
Copy and adapt: one episode is ``run_episode(EpisodeSpec(model=..., seed=..., executor="physics"))``.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import re
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from haptic.episode.loop import EpisodeObserver, chain_observers
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import Episode, build_episode, preload_physics
from haptic.errors import HapticError
from haptic.geometry import load_library
from haptic.geometry.io import atomic_write
from haptic.geometry.library_cache import cached_library
from haptic.planning.efficiency import class_weights
from haptic.planning.move_scores import bounded, predict_probe_moves
from haptic.planning.registry import make_policy
from haptic.planning.table import MADE, STOPS, data_table_conflict, move_outlook

SEED_OBJECTS = ("BOX01", "WEDGE01", "BOX01N", "BOX01P", "PYR01", "TETRA01L", "TETRA01R", "HEXPRISM01", "LBLOCK01",
                "FRAME01")


class ProbeCosts:
    """A policy that is ``policy`` but keeps, for each probe it chooses, the predicted costs; with :meth:`observer`,
    beside the cost the hand then reported (``rows``: one dict per probe)."""

    def __init__(self, policy) -> None:
        self.policy, self.name = policy, policy.name
        self.pending: tuple | None = None
        self.rows: list[dict] = []

    def choose(self, ctx, rng):
        decision = self.policy.choose(ctx, rng)
        self.pending = None
        if decision.move.kind == "probe":
            b = bounded(ctx)
            pred = predict_probe_moves(b, [decision.move])[0]
            self.pending = (decision.move, pred, class_weights([h.model for h in b.hypotheses]))
        return decision

    def _result(self, n, result, *rest) -> None:
        if self.pending is None or result.move is not self.pending[0]:
            return
        _, pred, w = self.pending
        self.pending = None
        hit = bool(result.ok and result.components)
        same = pred.hit == hit
        row = {"status": str(result.status), "hit": hit if result.ok else None, "actual": float(result.cost),
               "expected": float(pred.costs @ w),
               "predicted": float(pred.costs[same] @ w[same] / w[same].sum()) if same.any() else None}  # fmt: skip
        self.rows.append(row)

    def observer(self) -> EpisodeObserver:
        return EpisodeObserver(on_move=self._result, on_failed_move=self._result)


class TruthOutlook:
    """The episode's executor, but before each move it keeps what the planner predicts of the move under the true
    interpretation (:func:`truth_outlook`; evaluation: the truth is read here, never by the executor or the
    planner) in :attr:`outlook`, and the risk the deciding policy gave it (:meth:`decided`) in :attr:`risk`."""

    def __init__(self, episode: Episode) -> None:
        self.inner, self.episode = episode.executor, episode
        self.outlook: str | None = None
        self.risk: float | None = None
        self._decision = None

    def start(self):
        return self.inner.start()

    def execute(self, move):
        self.outlook = truth_outlook(self.episode, move)
        d = self._decision
        self.risk = next((float(c.risk) for c in d.candidates if c.move is move), None) if d is not None else None
        self._decision = None
        return self.inner.execute(move)

    def decided(self, n, decision) -> None:
        self._decision = decision

    def __getattr__(self, name):
        return getattr(self.inner, name)


def truth_outlook(episode: Episode, move) -> str | None:
    """What the planner's prediction (:func:`~haptic.planning.table.move_outlook`, and what the data alone say:
    :func:`~haptic.planning.table.data_table_conflict`) says of a face, edge or vertex ``move`` from the executor's
    state under the true interpretation of the data so far (:func:`~haptic.episode.evaluate.true_hypothesis`):
    "made", "edge only", "table", "undercut", "concave"; None for other moves, or where the truth cannot say (a data
    component the true model does not explain)."""
    from haptic.episode.evaluate import true_hypothesis

    ex = episode.executor
    if move.kind not in ("face", "edge", "vertex") or ex.state is None:
        return None
    comps = {c.id: c for c in ex.components}
    if data_table_conflict(move, ex.state, comps, episode.config):
        return "table"
    h = true_hypothesis(ex.components, episode.true_model, episode.world_from_model)
    return move_outlook(h, move, ex.state, comps, episode.config)[0]


def one(model: str, seed: int, policy: str, moves: str = "tracing", verify: str = "none",
        probe_costs: bool = False, models: str | None = None, fingers: int = 1) -> dict:  # fmt: skip
    """One physics episode's record as JSON (an ``error`` entry when it could not run), with the probes that
    failed (``probes_failed``) and why (``probe_failures``), and with ``probe_costs`` their predicted and
    actual costs (``probe_costs``, :class:`ProbeCosts`)."""
    failed: list[str] = []
    kinds: list[tuple[str, bool]] = []
    reasons: list[tuple[str, str]] = []
    recovered: list[tuple[str, str]] = []
    reach: list[tuple[str, str, str, str, str, str | None, float | None]] = []
    watch_truth: TruthOutlook | None = None

    def on_move(n, result, *rest) -> None:
        if n > 0 and result.move is not None:  # the start is no move
            kinds.append((result.move.kind, True))
            reach.append(move_reach(result, watch_truth))
            recovered.extend((result.move.kind, why) for why in result.info.get("recoveries", ()))

    def on_failed(n, result) -> None:
        if result.move is None:
            return
        why = result.reason or result.info.get("reason", "") or str(result.status)
        kinds.append((result.move.kind, False))
        reasons.append((result.move.kind, why))
        reach.append(move_reach(result, watch_truth))
        if result.move.kind == "probe":
            failed.append(f"{result.status}: {why}")

    watch = ProbeCosts(make_policy(policy)) if probe_costs else None
    cpu0 = time.process_time()
    try:
        spec = EpisodeSpec(model=model, seed=seed, policy=policy, executor="physics", moves=moves, verify=verify,
                           models=models, fingers=fingers)  # fmt: skip
        episode = build_episode(spec)
        watch_truth = TruthOutlook(episode)
        episode.executor = watch_truth
        mine = EpisodeObserver(on_move=on_move, on_failed_move=on_failed, on_decision=watch_truth.decided)
        obs = chain_observers(mine, watch.observer() if watch else None)
        rec = episode.run(watch, obs).to_json()
    except HapticError as exc:
        return {"model": model, "seed": seed, "outcome": "error", "correct": False, "detail": str(exc)}
    rec.update(probes_failed=len(failed), probe_failures=failed, move_results=kinds, failure_reasons=reasons,
               recoveries=recovered, move_reach=reach, cpu_time_s=round(time.process_time() - cpu0, 3))
    if watch is not None:
        rec["probe_costs"] = watch.rows
    return rec


def _f(x, fmt: str = ".1f") -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, fmt)


def _perception(r: dict) -> str:
    p = r.get("perception") or {}
    if not p:
        return "-"
    med = lambda k: p.get(k, {}).get("median")  # noqa: E731
    return (f"n {_f(med('face_normal_deg'), '.2f')}° e {_f(med('edge_direction_deg'), '.2f')}° "
            f"ep {_f(med('edge_position_mm'), '.2f')} vp {_f(med('vertex_position_mm'), '.2f')} mm "
            f"sp {p.get('spurious', '-')} mi {p.get('missed', '-')}")  # fmt: skip


def _print_probe_costs(records: list[dict]) -> None:
    """Each probe the planner chose, predicted against actual cost, then the differences' mean and range."""
    print()
    print(f"{'object':<10} {'seed':>4} {'status':<12} {'hit':<4} {'expected':>8} {'predicted':>9} {'actual':>6} "
          f"{'act−pred':>8}")  # fmt: skip
    diffs, diffs_exp = [], []
    for r in records:
        for p in r.get("probe_costs", []):
            d = None if p["predicted"] is None or p["hit"] is None else p["actual"] - p["predicted"]
            hit = "-" if p["hit"] is None else ("hit" if p["hit"] else "miss")
            print(f"{r['model']:<10} {r['seed']:>4} {p['status']:<12} {hit:<4} {p['expected']:>8.2f} "
                  f"{_f(p['predicted'], '.2f'):>9} {p['actual']:>6.2f} {_f(d, '+.2f'):>8}")  # fmt: skip
            if d is not None:
                diffs.append(d)
            if p["hit"] is not None:
                diffs_exp.append(p["actual"] - p["expected"])
    if diffs:
        a, e = np.array(diffs), np.array(diffs_exp)
        print(f"probes carried out {len(a)}: actual − predicted (for the outcome) mean {a.mean():+.2f}, "
              f"mean |·| {np.abs(a).mean():.2f}, range {a.min():+.2f} … {a.max():+.2f}; actual − expected mean "
              f"{e.mean():+.2f}, range {e.min():+.2f} … {e.max():+.2f} [units]")  # fmt: skip


def move_reach(result, truth: TruthOutlook | None = None) -> tuple[str, str, str, str, str, str | None, float | None]:
    """A move made, as the reach it was offered with and what came of it: (kind, finger -- "index" for the exploring
    one pointing down --, whose prediction it was -- "solver" for a move with the reach solver's path, the
    planner's otherwise --, status, reason ("" when it succeeded), the planner's prediction under the true
    interpretation (:class:`TruthOutlook`; None: none), the risk the deciding policy gave it (None: no policy's
    decision))."""
    m = result.move
    finger = getattr(m, "finger", None) or ("+".join(f.finger for f in m.fingers) if m.kind == "placement"
                                             else "index")  # fmt: skip
    by = "solver" if getattr(m, "path", None) is not None else "planner"
    why = "" if result.ok else (result.reason or result.info.get("reason", "") or str(result.status))
    outlook, risk = (truth.outlook, truth.risk) if truth is not None else (None, None)
    return (m.kind, finger, by, str(result.status), why, outlook, risk)


REACH_WORDS = ("unreachable", "table", "limit", "blocked", "joint", "met the object", "out of the pad's reach",
               "out of reach", "runaway", "touched something", "carry it no further")
"""A failed move's reason that says the hand could not get or go where the move needed it (the table, a joint limit,
the object in the way of a link, a blocked stroke), rather than that it got there and sensed other than predicted,
names one of these ..."""
NOT_REACH = ("could not locate the vertex",)
"""... unless it begins with one of these (an edge move that found no vertex: what it sensed, whatever blocked it)."""


def reach_failure(reason: str) -> bool:
    """Whether a failed move failed for the hand's reach (:data:`REACH_WORDS`, :data:`NOT_REACH`; the status does
    not tell: "unreachable" also ends a stroke that found no face)."""
    return not reason.startswith(NOT_REACH) and any(w in reason for w in REACH_WORDS)


def print_reach(records: list[dict]) -> None:
    """The planner's prediction under the true interpretation against the outcome (:func:`print_outlook`); then
    every move offered against its outcome: the share that failed, the share that failed for the hand's reach
    (:func:`reach_failure`), those by reason; and the moves by another finger or a turned wrist."""
    rows = [tuple(x) for r in records for x in r.get("move_reach", [])]
    if not rows:
        return
    print_outlook(rows)
    failed = [x for x in rows if x[3] != "ok"]
    reach = [x for x in failed if reach_failure(x[4])]
    n = len(rows)
    print(f"moves offered {n} (the planner's risk under its hypotheses aside): failed {len(failed)} "
          f"({100 * len(failed) / n:.1f} %), of them for the hand's reach {len(reach)} "
          f"({100 * len(reach) / n:.1f} % of the moves)")  # fmt: skip
    why = Counter((k, reason_class(w)) for k, _, _, _, w, *_ in reach)
    for (k, w), c in why.most_common():
        print(f"  {c:>4}  {k:<6} {w}")
    solver = [x for x in rows if x[2] == "solver"]
    if solver:
        bad = [x for x in solver if x[3] != "ok"]
        fingers = Counter(x[1] for x in solver)
        print(f"moves on the reach solver's path {len(solver)} ({', '.join(f'{k} {v}' for k, v in fingers.items())})"
              f": failed {len(bad)}" + "".join(f"; {x[1]} {x[0]}: {reason_class(x[4])}" for x in bad))  # fmt: skip


def print_outlook(rows: list[tuple]) -> None:
    """Face, edge and vertex moves by what the planner predicts of them under the true interpretation
    (:class:`TruthOutlook`) against what the hand then did: predicted made (or ending at its edge) and failed, by
    reason, and of them for the hand's reach; predicted to stop (the table, an undercut, a concave end) and stopped
    or went through; the truth could not say."""
    traced = [x for x in rows if len(x) > 5 and x[0] in ("face", "edge", "vertex")]
    if not traced:
        return
    made = [x for x in traced if x[5] is not None and x[5] not in STOPS]
    stops = [x for x in traced if x[5] in STOPS]
    unsaid = [x for x in traced if x[5] is None]
    bad = [x for x in made if x[3] != "ok"]
    reach = [x for x in bad if reach_failure(x[4])]
    n = max(1, len(made))
    print()
    print(f"moves predicted made under the true interpretation {len(made)} (of {len(traced)} face, edge, vertex moves;"
          f" {sum(x[5] != MADE for x in made)} ending at their edge): failed {len(bad)} ({100 * len(bad) / n:.1f} %), "
          f"for the hand's reach {len(reach)} ({100 * len(reach) / n:.1f} %)")  # fmt: skip
    for (k, w), c in Counter((x[0], reason_class(x[4])) for x in bad).most_common():
        print(f"  {c:>4}  {k:<6} {'reach ' if reach_failure(w) else '      '}{w}")
    went = [x for x in stops if x[3] == "ok"]
    kinds = Counter(x[5] for x in stops)
    print(f"moves predicted to stop {len(stops)} ({', '.join(f'{k} {v}' for k, v in kinds.most_common())}): stopped "
          f"{len(stops) - len(went)}, went through {len(went)}")  # fmt: skip
    for (k, o, w), c in Counter((x[0], x[5], reason_class(x[4]) or "ok") for x in stops).most_common():
        print(f"  {c:>4}  {k:<6} {o:<8} {w}")
    print(f"moves the truth could not predict {len(unsaid)}: failed {sum(x[3] != 'ok' for x in unsaid)}")


def reason_class(reason: str) -> str:
    """A failure's reason without its figures, so that like failures count together."""
    return re.sub(r"-?\d+(\.\d+)?", "#", reason).split("; no edge from the roll")[0]


def print_moves(records: list[dict]) -> None:
    """Move success by kind, then the failed moves by reason (most frequent first)."""
    kinds = Counter((k, ok) for r in records for k, ok in r.get("move_results", []))
    print()
    print("moves by kind: " + ", ".join(
        f"{k} {kinds[(k, True)]}/{kinds[(k, True)] + kinds[(k, False)]} "
        f"({100 * kinds[(k, True)] / max(1, kinds[(k, True)] + kinds[(k, False)]):.0f} %)"
        for k in ("face", "edge", "vertex", "probe") if kinds[(k, True)] + kinds[(k, False)]))  # fmt: skip
    why = Counter((k, reason_class(w)) for r in records for k, w in r.get("failure_reasons", []))
    print(f"failed moves by reason ({sum(why.values())}):")
    for (k, w), n in why.most_common():
        print(f"  {n:>4}  {k:<6} {w}")
    rec = Counter((k, reason_class(w)) for r in records for k, w in r.get("recoveries", []))
    print(f"moves that recovered instead of failing ({sum(rec.values())}):")
    for (k, w), n in rec.most_common():
        print(f"  {n:>4}  {k:<6} {w}")


def _mean(records: list[dict], key: str) -> float | None:
    v = [r[key] for r in records if r.get(key) is not None]
    return float(np.mean(v)) if v else None


def print_placements(records: list[dict]) -> None:
    """Placements of several fingertips: how many, their share of the moves, how many succeeded, and each
    finger's outcome (a failed finger's reason)."""
    placed = [p for r in records for p in r.get("placements", ())]
    if not any(r.get("fingers", 1) > 1 for r in records):
        return
    moves = sum(len(r.get("move_results", ())) for r in records)
    ok = sum(p["status"] == "ok" for p in placed)
    asked = sum((r.get("placement_reach") or {}).get("asked", 0) for r in records)
    reached = sum((r.get("placement_reach") or {}).get("reached", 0) for r in records)
    why = Counter()
    for r in records:
        why.update((r.get("placement_reach") or {}).get("reasons", {}))
    print(f"the planner's reach test: {asked} placements asked about, {reached} reached"
          + (f"; why not: {', '.join(f'{k} {v}' for k, v in why.most_common())}" if why else ""))
    print(f"placements {len(placed)} ({100 * len(placed) / max(1, moves):.1f} % of {moves} moves), {ok} succeeded")
    for p in placed:
        if p["status"] != "ok":
            print(f"  failed: {p['status']}: {p.get('reason', '')}")
    fingers = Counter((f["status"], reason_class(f.get("reason", ""))) for p in placed for f in p["fingers"])
    for (status, why), n in fingers.most_common():
        print(f"  {n:>4}  finger {status}" + (f": {why}" if why else ""))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=3, help="random resting poses (episodes) per object")
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--objects", default=None,
                    help="comma-separated model names (default: the seed objects, or every model of --models)")
    ap.add_argument("--models", default=None, metavar="DIR", help="library directory (default: the shipped one)")
    ap.add_argument("--policy", default="planner")
    ap.add_argument("--moves", default="tracing", choices=("tracing", "all"), help="admissible kinds of move")
    ap.add_argument("--probe-costs", action="store_true",
                    help="list each probe the planner chose: predicted against actual cost")
    ap.add_argument("--verify", default="none", choices=("none", "fast", "full"),
                    help="verification before recognition (default none: the matcher's verdict)")
    ap.add_argument("--fingers", type=int, default=1, choices=(1, 2, 4),
                    help="fingers the hand may use at once (placements of several fingertips with 2 or 4)")
    ap.add_argument("--jobs", type=int, default=1, help="episodes run in parallel (processes)")
    ap.add_argument("--json", default=None, help="write every episode record here")
    args = ap.parse_args(argv)

    if args.objects:
        objects = [o for o in args.objects.split(",") if o]
    elif args.models:
        try:
            objects = sorted(load_library(args.models))
        except HapticError as exc:
            ap.error(str(exc))
    else:
        objects = list(SEED_OBJECTS)
    jobs = [(o, args.first_seed + k, args.policy, args.moves, args.verify, args.probe_costs, args.models,
             args.fingers) for o in objects for k in range(args.poses)]
    t0 = time.perf_counter()
    preload_physics((cached_library(args.models)[o] for o in objects), jobs=args.jobs)  # the workers fork with it done
    # what is loaded now lives as long as the process: out of the collector's reach, a full collection in an episode
    # no longer traverses the modules' hundred thousand objects (nor touches a forked worker's copy of them)
    gc.freeze()
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            records = list(pool.map(one, *zip(*jobs, strict=True)))
    else:
        records = [one(*j) for j in jobs]

    width = max(10, *(len(o) for o in objects))
    print(f"{'object':<{width}} {'seed':>4} {'outcome':<10} {'ok':<3} {'moves':>5} {'fail':>4} {'probes':>6} "
          f"{'cost':>6} {'wall s':>6} {'sim s':>6} {'err mm':>6} {'err °':>5}  perception (medians)")  # fmt: skip
    for r in records:
        probes = f"{r.get('probes', 0)}/{r.get('probe_misses', 0)}/{r.get('probes_failed', 0)}"
        print(f"{r['model']:<{width}} {r['seed']:>4} {r['outcome']:<10} {'yes' if r['correct'] else 'no':<3} "
              f"{r.get('moves', 0):>5} {r.get('failed_moves', 0):>4} {probes:>6} {_f(r.get('path_cost')):>6} "
              f"{_f(r.get('wall_time_s')):>6} {_f(r.get('sim_time_s')):>6} {_f(r.get('pose_error_mm'), '.2f'):>6} "
              f"{_f(r.get('pose_error_deg'), '.2f'):>5}  {_perception(r)}")  # fmt: skip
        if r["outcome"] not in ("recognized",) and r.get("detail"):
            print(f"{'':<16}{r['detail']}")

    print()
    print(f"{'object':<{width}} {'correct':>7} {'wrong':>5} {'moves':>6} {'cost':>6} {'wall s':>6} {'sim s':>6} "
          f"{'err mm':>6}  (medians over the correctly recognised episodes; probes: used/missed/failed)")  # fmt: skip
    wrong_total = 0
    for o in objects:
        rs = [r for r in records if r["model"] == o]
        good = [r for r in rs if r["correct"]]
        wrong = [r for r in rs if r["outcome"] == "recognized" and not r["correct"]]
        wrong_total += len(wrong)

        def med(k: str, good=good) -> float | None:
            v = [r[k] for r in good if r.get(k) is not None]
            return float(np.median(v)) if v else None

        print(f"{o:<{width}} {len(good):>3}/{len(rs):<3} {len(wrong):>5} {_f(med('moves')):>6} "
              f"{_f(med('path_cost')):>6} {_f(med('wall_time_s')):>6} {_f(med('sim_time_s')):>6} "
              f"{_f(med('pose_error_mm'), '.2f'):>6}")  # fmt: skip
    good = [r for r in records if r["correct"]]
    walls = [r["wall_time_s"] for r in good]
    print()
    outcomes = Counter(r["outcome"] for r in records)
    print(f"correct {len(good)}/{len(records)}, wrong recognitions {wrong_total}; outcomes: "
          f"{', '.join(f'{k} {v}' for k, v in sorted(outcomes.items()))}; median wall time to recognition "
          f"{_f(float(np.median(walls)) if walls else None)} s; total {time.perf_counter() - t0:.0f} s")  # fmt: skip
    print(f"mean over all episodes: path cost {_f(_mean(records, 'path_cost'), '.2f')}, moves "
          f"{_f(_mean(records, 'moves'), '.2f')}, wall time {_f(_mean(records, 'wall_time_s'), '.2f')} s, CPU time "
          f"{_f(_mean(records, 'cpu_time_s'), '.2f')} s (the episode's process's, its start not included), simulated "
          f"{_f(_mean(records, 'sim_time_s'), '.1f')} s; over the correct: path cost "
          f"{_f(_mean(good, 'path_cost'), '.2f')}, moves {_f(_mean(good, 'moves'), '.2f')}")
    print_moves(records)
    print_reach(records)
    print_placements(records)
    if args.probe_costs:
        _print_probe_costs(records)
    if args.json:
        atomic_write(args.json, json.dumps(records, indent=1))
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
