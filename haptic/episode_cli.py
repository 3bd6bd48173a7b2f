"""``haptic explore``: one episode, a summary on stdout, optionally its JSON record and a rerun recording.

Function-local imports here are deliberate: a subcommand's modules load only when it runs, so that ``--help``
and a bad option answer at once, without numpy's stack, MuJoCo or rerun.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from haptic.errors import HapticError, RecordingError

if TYPE_CHECKING:
    from haptic.options import Subcommands

def add_parser(sub: Subcommands) -> None:
    from haptic.episode.spec import (
        DEFAULT_EXECUTOR,
        DEFAULT_MAX_MOVES,
        DEFAULT_NOISE,
        DEFAULT_POLICY,
        DEFAULT_SEED,
        EXECUTORS,
    )
    from haptic.matching.acceptance import DEFAULT_VERIFY, VERIFY_MODES
    from haptic.options import add_fingers_option, add_units_option, noise_level, positive_int, seed_int
    from haptic.planning.moves import DEFAULT_MOVES, HAND_DEFAULT_MOVES, MOVE_SETS
    from haptic.planning.registry import POLICY_NAMES

    p = sub.add_parser(
        "explore",
        help="run one episode: explore an object by touch until it is recognised",
        description="One episode. Prints a line per move as it happens (on a terminal, or with --progress), then "
        "a summary. Exit 0 when the episode ends normally, whatever its outcome.",
    )
    p.add_argument("--object", required=True, help="model name in the library, or a path to a model file")
    p.add_argument("--models", metavar="DIR", help="library directory (default: the shipped assets/models)")
    add_units_option(p)
    p.add_argument(
        "--skip-invalid", action="store_true", help="use the library's valid models when some files are bad"
    )
    p.add_argument("--executor", choices=EXECUTORS, default=DEFAULT_EXECUTOR,
                   help="geometric: the ideal sensor with noise (fast); physics: the simulated hand in MuJoCo")
    p.add_argument("--seed", type=seed_int, default=DEFAULT_SEED,
                   help="seed of the pose, noise and policy (an integer >= 0)")
    p.add_argument("--policy", default=DEFAULT_POLICY, choices=POLICY_NAMES, help="how the next move is chosen")
    p.add_argument("--noise", type=noise_level, default=DEFAULT_NOISE,
                   help="sensor-noise level, x the default sigma (0 to 10)")
    p.add_argument("--max-moves", type=positive_int, default=DEFAULT_MAX_MOVES,
                   help="move budget: the episode ends as 'budget' after this many moves (verification moves "
                   "not counted)")
    p.add_argument(
        "--verify", choices=VERIFY_MODES, default=DEFAULT_VERIFY,
        help="verification before recognition: none, fast (pose check; every face and edge measured) or full "
        "(also every vertex)",
    )  # fmt: skip
    p.add_argument(
        "--moves", choices=MOVE_SETS, default=None,
        help=f"admissible kinds of move (default {DEFAULT_MOVES}; {HAND_DEFAULT_MOVES} with --executor physics): "
        "tracing (face, edge, vertex moves), probing "
        "(free-space probes alone, geometric executor; a verification traces too) or all (both, one "
        "planner ranking them)",
    )  # fmt: skip
    add_fingers_option(p)
    p.add_argument("--learn", metavar="DIR",
                   help="after no-match, explore on until the object's surface is closed and write its model "
                   "into the library directory DIR (its own budget, reported)")
    p.add_argument("--learn-name", metavar="NAME",
                   help="the learned model's name (default: learned_ and a digest of the episode's settings)")
    p.add_argument("--json", metavar="OUT", help="write the episode's JSON record here")
    p.add_argument("--record", metavar="OUT.rrd", help="write a rerun recording here")
    p.add_argument("--spawn", action="store_true", help="open the rerun viewer (where one is installed)")
    talk = p.add_mutually_exclusive_group()
    talk.add_argument("--progress", action="store_true",
                      help="print a line per move as it happens even when stdout is not a terminal "
                      "(default: only on a terminal)")
    talk.add_argument("--quiet", action="store_true", help="print no line per move, only the summary")
    p.set_defaults(run=run)


GROWTH_NOTE = "grows where new data fit several model features each"
"""Why an interpretation count rises: each interpretation branches into every model feature the new data fit."""


def move_line(n: int, kind: str, status: str, why: str, counts: tuple[int, int], classes: int | None,
              cost: float) -> str:  # fmt: skip
    """One move as ``explore`` prints it while the episode runs: number, kind, ok or failed and why, the
    interpretations before -> after, the pose classes, the path cost so far."""
    before, after = counts
    done = "ok" if status == "ok" else f"failed ({why or status})"
    noun = "interpretation" if after == 1 else "interpretations"
    if status != "ok" or n == 0 or before == after:
        trace = f"{after} {noun}"
    else:
        trace = f"{before} -> {after} {noun}" + (f" ({GROWTH_NOTE})" if after > before else "")
    pose = f"{classes} pose class{'es' if classes != 1 else ''}" if classes else "no pose fixed yet"
    return f"move {n:>2}  {kind:<7} {done:<8} {trace}; {pose}; cost {cost:.1f}"


class MovePrinter:
    """An observer that prints :func:`move_line` for every move as the episode runs (flushed at once)."""

    def __init__(self, out=None) -> None:
        self.out = out or sys.stdout
        self.count = 0
        self.classes: int | None = None
        self.cost = 0.0

    def observer(self):
        from haptic.episode.loop import EpisodeObserver

        return EpisodeObserver(on_move=self.on_move, on_failed_move=self.on_failed_move)

    def _print(self, line: str) -> None:
        print(line, file=self.out, flush=True)

    def on_move(self, n: int, result, count: int, rec) -> None:
        self.cost += result.cost
        self.classes = len(rec.classes) if rec is not None and rec.classes else None
        kind = "start" if n == 0 or result.move is None else result.move.kind
        self._print(move_line(n, kind, "ok", "", (self.count, count), self.classes, self.cost))
        self.count = count

    def on_failed_move(self, n: int, result) -> None:
        self.cost += result.cost
        kind = result.move.kind if result.move is not None else "start"
        self._print(move_line(n, kind, str(result.status), result.reason, (self.count, self.count), self.classes,
                              self.cost))  # fmt: skip


def placements_line(placements: list[dict]) -> str:
    """The placements of an episode: how many, how many failed, and their fingers' outcomes."""
    failed = sum(p["status"] != "ok" for p in placements)
    fingers = [f["status"] for p in placements for f in p["fingers"]]
    told = ", ".join(f"{fingers.count(k)} {k}" for k in dict.fromkeys(fingers))
    return f"{len(placements)}" + (f" ({failed} failed)" if failed else "") + f"; fingers: {told}"


def budget_text(rec: dict, budget: float, max_moves: int) -> str:
    """Which budget a "budget" episode ran out of, and its value."""
    if rec["path_cost"] > budget:
        return f"path cost {rec['path_cost']:.1f} passed the cost budget of {budget:g}"
    v = rec.get("verified") or {}
    counted = rec["moves"] - v.get("moves", 0)
    extra = f" ({v['moves']} verification moves not counted)" if v.get("moves") else ""
    return f"{counted} moves reached the move budget of {max_moves} (--max-moves){extra}"


def verified_line(rec: dict) -> str:
    """What the verification confirmed, in words that count what they say."""
    v = rec["verified"]
    status = v["status"]
    if status == "verifying":  # the episode ended before the verification did
        return (f"{v['mode']}: not finished: the episode ended {rec['outcome']} during verification, after "
                f"{v['moves']} verification moves (cost {v['cost']:.1f})")  # fmt: skip
    if status == "not needed":
        return f"{v['mode']}: not needed (no single pose class was left to verify)"
    line = f"{v['mode']}: {status}"
    if "faces" in v:
        parts, totals = [], []
        for what in ("faces", "edges", "vertices"):
            reach = v[f"{what}_reachable"]
            got = round(v[f"{what}_fraction"] * reach)
            parts.append(f"{got}/{reach} {what}")
            totals.append(f"{v[what]}/{v.get(f'{what}_total', '?')}")
        line += f"; measured of the reachable: {', '.join(parts)} (of all the model's: {', '.join(totals)})"
    if "pose_residual" in v:
        line += f"; largest residual {v['pose_residual']:.2f} x its bound ({v['pose_what']})"
    if v.get("table_shadow_mm"):
        line += (f"; nothing measured within {v['table_shadow_mm']:.1f} mm of the table (the model taken on trust "
                 f"there, {v['vertices_shadowed']} vertices in the table's shadow)")  # fmt: skip
    elif v.get("table_band_mm"):
        line += f"; nothing measured within {v['table_band_mm']:.1f} mm of the table (the model taken on trust there)"
    return line + f"; {v['moves']} verification moves, cost {v['cost']:.1f}"


def summary_lines(rec: dict, budget: float | None = None, max_moves: int | None = None) -> list[str]:
    """The summary ``explore`` prints after an episode. ``budget`` and ``max_moves`` (default: the record's key,
    else :class:`~haptic.episode.spec.EpisodeSpec`'s defaults) say which budget a "budget" episode ran out of."""
    from haptic.episode.spec import DEFAULT_BUDGET, DEFAULT_MAX_MOVES

    key = rec.get("key") or {}
    budget = budget if budget is not None else key.get("budget", DEFAULT_BUDGET)
    max_moves = max_moves if max_moves is not None else key.get("max_moves", DEFAULT_MAX_MOVES)
    outcome = f"outcome     {rec['outcome']}"
    if rec["recognized"]:
        outcome += f": {rec['recognized']}"
    if rec["outcome"] == "budget":
        outcome += f": {budget_text(rec, budget, max_moves)}"
    outcome += "  [correct]" if rec["correct"] else "  [wrong]" if rec["outcome"] == "recognized" else ""
    counts = rec["interpretations"]
    trace = " -> ".join(str(c) for c in counts)
    if any(b > a for a, b in zip(counts, counts[1:], strict=False)):
        trace += f"  ({GROWTH_NOTE})"
    lines = [
        f"object      {rec['model']}  (executor {rec['executor']}, policy {rec['policy']}, seed {rec['seed']})",
        outcome,
        f"moves       {rec['moves']} ({', '.join(rec['move_kinds'][1:]) or 'none'}"
        + (f"; {rec['failed_moves']} failed)" if rec.get("failed_moves") else ")"),
        f"path cost   {rec['path_cost']:.1f} units",
        f"data        {rec['faces']} faces, {rec['edges']} edges, {rec['vertices']} vertices",
        "interpret.  " + trace,
    ]
    if rec.get("classes") and rec["classes"] != counts:
        lines.append("pose cl.    " + " -> ".join(str(c) for c in rec["classes"])
                     + "  (pose classes; the interpretation count where no pose is fixed yet)")  # fmt: skip
    if rec.get("placements"):
        lines.append("placements  " + placements_line(rec["placements"]))
    lines.append("verdict     " + verdict_line(rec))
    if rec.get("verified"):
        lines.append("verified    " + verified_line(rec))
    if rec["pose_error_mm"] is not None:
        lines.append(f"pose error  {rec['pose_error_mm']:.3f} mm, {rec['pose_error_deg']:.3f} deg")
    time_line = f"wall time   {rec['wall_time_s']:.2f} s"
    if rec.get("sim_time_s") is not None:
        time_line += f"; simulated {rec['sim_time_s']:.2f} s"
    lines.append(time_line)
    if rec.get("perception"):
        p = rec["perception"]
        lines.append(
            "perception  " + ", ".join(f"{k} {v:.3g}" for k, v in p.items() if isinstance(v, int | float))
        )
    if rec.get("detail"):
        lines.append(f"detail      {rec['detail']}")
    if rec.get("learned"):
        lines.append("learned     " + learned_line(rec["learned"]))
    return lines


def learned_line(learned: dict) -> str:
    """How learning the object went: the model and its file, or why there is none; the learning's own cost."""
    cost = f"{learned['moves']} learning moves, cost {learned['path_cost']:.1f}"
    if "name" in learned:
        where = f" -> {learned['path']}" if "path" in learned else ""
        return (f"{learned['name']} (V {learned['V']}, E {learned['E']}, F {learned['F']}, "
                f"{learned['volume_cm3']:.2f} cm^3){where}; {cost}")  # fmt: skip
    detail = f" ({learned['detail']})" if learned.get("detail") else ""
    return f"no model: {learned['status']}{detail}; {cost}"


def verdict_line(rec: dict) -> str:
    """The outcome as the summary tables count it: correct, wrong model, right model at a wrong pose, no-match
    (right or wrong: only an object outside the library should end so), or the outcome as it is."""
    from haptic.bench.summary import outcome_class

    return outcome_class(rec)


def run(args: argparse.Namespace) -> int:
    from haptic.episode.spec import EpisodeSpec, check_settings, cli_option
    from haptic.episode.worlds import run_episode
    from haptic.geometry import load_library, load_model, resolve_model
    from haptic.geometry.io import atomic_write, size_warning
    from haptic.options import check_output_file, report_sizes, report_skipped

    # output paths are checked before the episode runs, so that its result cannot be lost at the end
    if args.json:
        check_output_file(args.json, "--json", "out/episode.json")
    if args.record:
        check_output_file(args.record, "--record", "out/episode.rrd", RecordingError)
    if args.learn_name is not None and args.learn is None:
        raise HapticError("--learn-name names a learned model: give --learn DIR too")
    if args.learn is not None:
        from haptic.learning.library import check_learn_target

        check_learn_target(args.learn, args.learn_name)
    settings = dict(
        model=args.object, seed=args.seed, policy=args.policy, executor=args.executor, noise=args.noise,
        models=args.models, max_moves=args.max_moves, record=args.record, skip_invalid=args.skip_invalid,
        verify=args.verify, moves=args.moves, units=args.units, learn=args.learn, learn_name=args.learn_name,
        fingers=args.fingers,
    )  # fmt: skip
    check_settings(settings, cli_option)
    spec = EpisodeSpec(**settings)
    library = load_library(args.models, skip_invalid=args.skip_invalid, units=args.units)
    report_skipped(args.models, args.skip_invalid, args.units)
    if args.object not in library:  # a model file outside the library
        report_sizes([size_warning(resolve_model(args.object, library, units=args.units), args.units)])
    observers = []
    if args.progress or (not args.quiet and sys.stdout.isatty()):
        observers.append(MovePrinter().observer())
    recorder = None
    if args.record or args.spawn:
        from haptic.recording import EpisodeRecorder

        recorder = EpisodeRecorder(args.record, spawn=args.spawn)
        observers.append(recorder.observer())
    try:
        from haptic.episode.loop import chain_observers

        observer = chain_observers(*observers) if observers else None
        record = run_episode(spec, library=library, observer=observer).to_json()
        learned = record.get("learned") or {}
        if recorder is not None and learned.get("path"):
            recorder.log_learned(load_model(learned["path"]), record["moves"])
    finally:
        if recorder is not None:
            recorder.close()
    for line in summary_lines(record, spec.budget, spec.max_moves):
        print(line)
    if args.json:
        try:
            atomic_write(Path(args.json), json.dumps(record, indent=2) + "\n")
        except OSError as exc:
            raise HapticError(f"{args.json}: cannot write the episode's record ({exc.strerror})") from None
        print(f"json        {args.json}")
    if args.record:
        print(f"recording   {args.record}  (open with: rerun {args.record})")
    return 0
