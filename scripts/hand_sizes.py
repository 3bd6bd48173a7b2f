"""What the simulated hand explores by object size: one library scaled to several sizes, every model at a few random
resting poses on the hand, and per size how the episodes ended, how often each kind of move succeeded and how often
a move the planner predicted made (under the true interpretation) failed; a table, a JSON file and a plot.

    .venv/bin/python scripts/hand_sizes.py [--models assets/libraries/polyhedra] [--sizes 30,45,60,80,100,150]
                                           [--poses 1] [--first-seed 1] [--verify full] [--jobs 2]
                                           [--out out/hand_sizes]

Each model is scaled so that its largest extent is the size (:func:`~haptic.geometry.perturb.scaled_to`) and written
to ``OUT/models_<size>mm`` (kept: any row replays with ``haptic explore --executor physics --models
OUT/models_<size>mm --object NAME --seed S``); the episodes are those of ``scripts/physics_episodes.py`` (the same
records, the default options but ``--verify``). An episode ends as one of:

- *confirmed*: recognised correctly and the verification confirmed it (a wrong recognition is counted apart);
- *out of reach*: the verification measured everything it could and names vertices no finger reaches, or resting on
  the table where nothing in reach places them -- the hand's geometry, a 12 mm pad beside a table, not a failed move;
- *stalled*: the verification stopped with features it counts in reach unmeasured (its moves went round without
  getting there, or failed);
- *alike*: two pose classes left that differ only where no finger reaches;
- *failed*: the episode ended on failed moves (or found no face to start from).

``OUT/sizes.json`` holds every record with its size; ``OUT/sizes.png`` plots the outcomes and the move success by
size.
"""

from __future__ import annotations

import argparse
import gc
import json
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import physics_episodes  # noqa: E402

from haptic.episode.worlds import preload_physics  # noqa: E402
from haptic.errors import HapticError  # noqa: E402
from haptic.geometry import load_library  # noqa: E402
from haptic.geometry.io import atomic_write, save_model  # noqa: E402
from haptic.geometry.perturb import scaled_to  # noqa: E402
from haptic.planning.table import MADE  # noqa: E402

OUTCOMES = ("confirmed", "out of reach", "stalled", "alike", "failed", "wrong", "other")
"""How an episode ended, in the order the table and the plot give them."""
KINDS = ("face", "edge", "vertex", "probe")
"""The kinds of move whose success is counted."""


def outcome_class(record: dict) -> str:
    """One of :data:`OUTCOMES` for an episode record (``physics_episodes.one``'s)."""
    outcome, detail = record.get("outcome", ""), record.get("detail") or ""
    if outcome == "recognized":
        return "confirmed" if record.get("correct") else "wrong"
    if outcome == "failed" or outcome == "error":
        return "failed"
    if outcome == "ambiguous":
        if "out of the hand's reach" in detail or "on the table with neither" in detail:
            return "out of reach"
        if detail.startswith("verification incomplete"):
            return "stalled"
        if "no move tells them apart" in detail:
            return "alike"
    return "other"


def summarise(records: list[dict]) -> list[dict]:
    """Per size (``record["size_mm"]``), ascending: episodes, outcomes (counts of :data:`OUTCOMES`), moves made and
    tried by kind, the face, edge and vertex moves predicted made under the true interpretation and of them those that
    failed, and the median wall time of an episode [s]."""
    out = []
    for size in sorted({r["size_mm"] for r in records}):
        rs = [r for r in records if r["size_mm"] == size]
        kinds = Counter((k, bool(ok)) for r in rs for k, ok in r.get("move_results", ()))
        made = [row for r in rs for row in r.get("move_reach", ()) if len(row) > 5 and row[5] == MADE]
        walls = [r["wall_time_s"] for r in rs if r.get("wall_time_s") is not None]
        out.append({
            "size_mm": size,
            "episodes": len(rs),
            "outcomes": {c: sum(outcome_class(r) == c for r in rs) for c in OUTCOMES},
            "moves": {k: [kinds[(k, True)], kinds[(k, True)] + kinds[(k, False)]] for k in KINDS},
            "predicted_made": len(made),
            "predicted_made_failed": sum(row[3] != "ok" for row in made),
            "median_wall_s": float(np.median(walls)) if walls else None,
        })  # fmt: skip
    return out


def _pct(a: int, b: int) -> str:
    return f"{100 * a / b:.0f} %" if b else "-"


def print_table(rows: list[dict]) -> None:
    """The summary, a row per size."""
    head = " ".join(f"{c:>12}" for c in OUTCOMES[:5])
    print(f"{'size mm':>7} {'episodes':>8} {head} {'wrong':>5} {'face':>6} {'edge':>6} {'vertex':>6} {'probe':>6} "
          f"{'pred. made failed':>17} {'median s':>8}")  # fmt: skip
    for row in rows:
        o, m = row["outcomes"], row["moves"]
        print(f"{row['size_mm']:>7g} {row['episodes']:>8} " + " ".join(f"{o[c]:>12}" for c in OUTCOMES[:5])
              + f" {o['wrong']:>5} " + " ".join(f"{_pct(*m[k]):>6}" for k in KINDS)
              + f" {_pct(row['predicted_made_failed'], row['predicted_made']):>17}"
              + f" {row['median_wall_s'] if row['median_wall_s'] is None else round(row['median_wall_s'], 1):>8}")


COLOURS = {"confirmed": "#2e7d32", "out of reach": "#9e9e9e", "stalled": "#f9a825", "alike": "#90caf9",
           "failed": "#c62828", "wrong": "#000000", "other": "#ce93d8"}  # fmt: skip


def plot(rows: list[dict], path: Path, title: str) -> None:
    """Outcomes (stacked, share of the episodes) and move success by kind against size, into ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sizes = [r["size_mm"] for r in rows]
    x = np.arange(len(rows))
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.4), gridspec_kw={"wspace": 0.45})
    bottom = np.zeros(len(rows))
    for c in OUTCOMES:
        share = np.array([r["outcomes"][c] / max(r["episodes"], 1) for r in rows])
        if share.any():
            a.bar(x, share, bottom=bottom, color=COLOURS[c], label=c, width=0.7)
            bottom += share
    a.set_xticks(x, [f"{r['size_mm']:g}\n({r['episodes']})" for r in rows])
    a.set_xlabel("object size (largest extent) [mm] (episodes)")
    a.set_ylabel("share of episodes")
    a.set_ylim(0, 1)
    a.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    a.set_title("how the episodes ended")
    for k, style in zip(KINDS, ("o-", "s-", "^-", "d--"), strict=True):
        rate = [100 * r["moves"][k][0] / r["moves"][k][1] if r["moves"][k][1] else np.nan for r in rows]
        if not np.all(np.isnan(rate)):
            b.plot(sizes, rate, style, label=f"{k} moves made")
    failed = [100 * r["predicted_made_failed"] / r["predicted_made"] if r["predicted_made"] else np.nan for r in rows]
    b.plot(sizes, [100 - f for f in failed], "k:", label="predicted made, made")
    b.axhline(95, color="0.6", lw=0.8)
    b.set_xlabel("object size (largest extent) [mm]")
    b.set_ylabel("%")
    low = float(np.nanmin([np.nanmin(line.get_ydata()) for line in b.get_lines()]))
    b.set_ylim(min(80.0, 5 * np.floor((low - 1) / 5)), 100.5)
    b.legend(fontsize=8, loc="lower right")
    b.set_title("moves")
    fig.suptitle(title, fontsize=10)
    fig.subplots_adjust(left=0.06, right=0.98, bottom=0.16, top=0.86)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    tmp.replace(path)


def parse_sizes(text: str) -> list[float]:
    """Sizes in mm from ``"30,45,60"``; a clear error for anything but positive numbers."""
    try:
        sizes = [float(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise HapticError(f"--sizes {text!r}: give sizes in mm, comma-separated, e.g. 30,60,150") from None
    if not sizes or any(not np.isfinite(s) or s <= 0 for s in sizes):
        raise HapticError(f"--sizes {text!r}: every size must be a number of mm above 0, e.g. 30,60,150")
    return sizes


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", default="assets/libraries/polyhedra", metavar="DIR", help="library to scale")
    ap.add_argument("--sizes", default="30,45,60,80,100,150", help="largest extents, mm, comma-separated")
    ap.add_argument("--poses", type=int, default=1, help="random resting poses (episodes) per model and size")
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--objects", default=None, help="comma-separated model names (default: every model)")
    ap.add_argument("--verify", default="full", choices=("none", "fast", "full"),
                    help="verification (default full, as haptic explore)")
    ap.add_argument("--jobs", type=int, default=1, help="episodes run in parallel (processes)")
    ap.add_argument("--out", default="out/hand_sizes", metavar="DIR", help="where the libraries, JSON and plot go")
    args = ap.parse_args(argv)
    try:
        sizes = parse_sizes(args.sizes)
        if args.poses < 1 or args.jobs < 1:
            raise HapticError("--poses and --jobs must be at least 1")
        library = load_library(args.models)
        names = sorted(library) if not args.objects else [o for o in args.objects.split(",") if o]
        unknown = [n for n in names if n not in library]
        if unknown:
            raise HapticError(f"--objects: {', '.join(unknown)} not in {args.models} (it has "
                              f"{', '.join(sorted(library))})")
        out = Path(args.out)
        dirs, scaled = {}, []
        for size in sizes:
            d = out / f"models_{size:03g}mm"
            for n in names:
                scaled.append(scaled_to(library[n], size / 1000.0))
                save_model(scaled[-1], d / f"{n}.json")
            dirs[size] = str(d)
    except HapticError as exc:
        print(f"hand_sizes: {exc}", file=sys.stderr)
        return 2

    from tqdm import tqdm

    jobs = [(n, args.first_seed + k, "planner", "tracing", args.verify, False, dirs[size], 1, size)
            for size in sizes for n in names for k in range(args.poses)]  # fmt: skip
    t0 = time.perf_counter()
    preload_physics(scaled, jobs=args.jobs)  # the workers fork with it done (as physics_episodes.py)
    gc.freeze()
    bar = tqdm(total=len(jobs), unit="episode", file=sys.stderr)
    done: dict[int, dict] = {}
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            futures = {pool.submit(physics_episodes.one, *j[:-1]): k for k, j in enumerate(jobs)}
            for f in as_completed(futures):
                done[futures[f]] = f.result()
                bar.update()
    else:
        for k, j in enumerate(jobs):
            done[k] = physics_episodes.one(*j[:-1])
            bar.update()
    bar.close()
    records = [{**done[k], "size_mm": j[-1]} for k, j in enumerate(jobs)]
    rows = summarise(records)
    print_table(rows)
    wrong = sum(r["outcomes"]["wrong"] for r in rows)
    print(f"{len(records)} episodes in {time.perf_counter() - t0:.0f} s; wrong recognitions {wrong}; --verify "
          f"{args.verify}, {args.poses} pose(s) from seed {args.first_seed}, {args.models}")  # fmt: skip
    atomic_write(out / "sizes.json", json.dumps({"rows": rows, "episodes": records}, indent=1))
    plot(rows, out / "sizes.png", f"{Path(args.models).name} on the hand, --verify {args.verify}, "
         f"{args.poses} pose(s) per model and size")  # fmt: skip
    print(f"wrote {out / 'sizes.json'} and {out / 'sizes.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
