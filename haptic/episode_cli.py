"""``haptic explore``: one episode, a summary on stdout, optionally its JSON record and a rerun recording.

Function-local imports here are deliberate: a subcommand's modules load only when it runs, so that ``--help``
and a bad option answer at once, without numpy's stack, MuJoCo or rerun.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from haptic.errors import HapticError, RecordingError

if TYPE_CHECKING:
    from haptic.options import Subcommands


def add_parser(sub: Subcommands) -> None:
    from haptic.matching.acceptance import DEFAULT_VERIFY, VERIFY_MODES
    from haptic.options import noise_level, positive_int, seed_int
    from haptic.planning.moves import DEFAULT_MOVES, HAND_DEFAULT_MOVES, MOVE_SETS
    from haptic.planning.registry import POLICY_NAMES

    p = sub.add_parser(
        "explore",
        help="run one episode: explore an object by touch until it is recognised",
        description="One episode. Exit 0 when the episode ends normally, whatever its outcome.",
    )
    p.add_argument("--object", required=True, help="model name in the library, or a path to a model file")
    p.add_argument("--models", metavar="DIR", help="library directory (default: the shipped assets/models)")
    p.add_argument(
        "--skip-invalid", action="store_true", help="use the library's valid models when some files are bad"
    )
    p.add_argument("--executor", choices=("geometric", "physics"), default="geometric")
    p.add_argument("--seed", type=seed_int, default=0, help="seed of the pose, noise and policy (an integer >= 0)")
    p.add_argument("--policy", default="planner", choices=POLICY_NAMES)
    p.add_argument("--noise", type=noise_level, default=1.0, help="sensor-noise level, x the default sigma (0 to 10)")
    p.add_argument("--max-moves", type=positive_int, default=40)
    p.add_argument(
        "--verify", choices=VERIFY_MODES, default=DEFAULT_VERIFY,
        help=f"verification before recognition (default {DEFAULT_VERIFY}): none, fast (pose check; every face "
        "and edge measured) or full (also every vertex)",
    )  # fmt: skip
    p.add_argument(
        "--moves", choices=MOVE_SETS, default=None,
        help=f"admissible kinds of move (default {DEFAULT_MOVES}; {HAND_DEFAULT_MOVES} with --executor physics): "
        "tracing (face, edge, vertex moves), probing "
        "(free-space probes alone, geometric executor; a verification traces too) or all (both, one "
        "planner ranking them)",
    )  # fmt: skip
    p.add_argument("--json", metavar="OUT", help="write the episode's JSON record here")
    p.add_argument("--record", metavar="OUT.rrd", help="write a rerun recording here")
    p.add_argument("--spawn", action="store_true", help="open the rerun viewer (where one is installed)")
    p.set_defaults(run=run)


def summary_lines(rec: dict) -> list[str]:
    lines = [
        f"object      {rec['model']}  (executor {rec['executor']}, policy {rec['policy']}, seed {rec['seed']})",
        f"outcome     {rec['outcome']}" + (f": {rec['recognized']}" if rec["recognized"] else "")
        + ("  [correct]" if rec["correct"] else "  [wrong]" if rec["outcome"] == "recognized" else ""),
        f"moves       {rec['moves']} ({', '.join(rec['move_kinds'][1:]) or 'none'}"
        + (f"; {rec['failed_moves']} failed)" if rec.get("failed_moves") else ")"),
        f"path cost   {rec['path_cost']:.1f} units",
        f"data        {rec['faces']} faces, {rec['edges']} edges, {rec['vertices']} vertices",
        "interpret.  " + " -> ".join(str(c) for c in rec["interpretations"]),
    ]
    lines.append("verdict     " + verdict_line(rec))
    v = rec.get("verified")
    if v:
        line = f"verified    {v['mode']}: {v['status']}"
        if "faces" in v:
            line += (f"; measured {v['faces']}/{v['faces_reachable']} faces, {v['edges']}/{v['edges_reachable']} "
                     f"edges, {v['vertices']}/{v['vertices_reachable']} vertices (reachable)")  # fmt: skip
        if "pose_residual" in v:
            line += f"; largest residual {v['pose_residual']:.2f} x its bound ({v['pose_what']})"
        lines.append(line + f"; {v['moves']} moves, cost {v['cost']:.1f}")
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
    return lines


def verdict_line(rec: dict) -> str:
    """The outcome as the summary tables count it: correct, wrong model, right model at a wrong pose, no-match
    (right or wrong: only an object outside the library should end so), or the outcome as it is."""
    from haptic.bench.summary import outcome_class

    return outcome_class(rec)


def run(args: argparse.Namespace) -> int:
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import run_episode
    from haptic.geometry import load_library
    from haptic.geometry.io import atomic_write
    from haptic.options import check_output_file, report_skipped
    from haptic.planning.moves import default_moves

    # output paths are checked before the episode runs, so that its result cannot be lost at the end
    if args.json:
        check_output_file(args.json, "--json", "out/episode.json")
    if args.record:
        check_output_file(args.record, "--record", "out/episode.rrd", RecordingError)
    library = load_library(args.models, skip_invalid=args.skip_invalid)
    report_skipped(args.models, args.skip_invalid)
    spec = EpisodeSpec(
        model=args.object, seed=args.seed, policy=args.policy, executor=args.executor, noise=args.noise,
        models=args.models, max_moves=args.max_moves, record=args.record, skip_invalid=args.skip_invalid,
        verify=args.verify,
        moves=args.moves or default_moves(args.executor),
    )
    observer = None
    recorder = None
    if args.record or args.spawn:
        from haptic.recording import EpisodeRecorder

        recorder = EpisodeRecorder(args.record, spawn=args.spawn)
        observer = recorder.observer()
    try:
        record = run_episode(spec, library=library, observer=observer).to_json()
    finally:
        if recorder is not None:
            recorder.close()
    for line in summary_lines(record):
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
