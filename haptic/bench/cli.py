"""``haptic bench``: a sweep of episodes, a results file, a summary table and a plot.

Function-local imports here are deliberate: a subcommand's modules load only when it runs, so that ``--help``
and a bad option answer at once, without numpy's stack, MuJoCo or rerun.
"""

from __future__ import annotations

import argparse
import signal
import sys
import time
from pathlib import Path

from haptic.errors import BenchError, HapticError
from haptic.options import DeferredInterrupts, Subcommands, Terminated

EXIT_SIGINT, EXIT_SIGTERM = 130, 143
"""Exit codes of a sweep ended by SIGINT (Ctrl-C) or SIGTERM: 128 + the signal's number."""


def add_parser(sub: Subcommands) -> None:
    from haptic.bench import DEFAULT_EPISODES, DEFAULT_NOISES, DEFAULT_OUT, DEFAULT_POLICIES
    from haptic.episode.spec import DEFAULT_EXECUTOR, DEFAULT_MAX_MOVES, DEFAULT_SEED, EXECUTORS
    from haptic.matching.acceptance import DEFAULT_VERIFY, VERIFY_MODES
    from haptic.options import add_fingers_option, add_units_option, noise_levels, positive_int, seed_int
    from haptic.planning.moves import DEFAULT_MOVES, HAND_DEFAULT_MOVES, MOVE_SETS
    from haptic.planning.registry import POLICY_NAMES

    p = sub.add_parser(
        "bench",
        help="run many episodes; write one JSON line per episode, a summary table and a plot",
        description="Models x random poses x noise levels x policies. Every policy runs on the same "
        "(model, pose) draws. Appends to OUT (JSON lines, one per episode as it ends, each with its episode's "
        "key) and writes, from the whole of OUT, OUT with .md (summary table) and .png (pose classes remaining "
        "vs path cost), at the end and on interrupt (exit 130 on SIGINT, 143 on SIGTERM). Prints a few columns "
        "per policy on stdout; the .md has them all.",
    )
    p.add_argument("--models", metavar="DIR", help="library directory (default: the shipped assets/models)")
    add_units_option(p)
    p.add_argument(
        "--skip-invalid", action="store_true", help="use the library's valid models when some files are bad"
    )
    p.add_argument("--executor", choices=EXECUTORS, default=DEFAULT_EXECUTOR,
                   help="geometric: the ideal sensor with noise (fast); physics: the simulated hand in MuJoCo")
    p.add_argument(
        "--policy", default=",".join(DEFAULT_POLICIES),
        help=f"comma-separated policies from {', '.join(POLICY_NAMES)} or learned:PATH (a model that "
        "scripts/train_ppo.py saved; with --moves tracing), each run on the same draws",
    )
    p.add_argument("--episodes", type=positive_int, default=DEFAULT_EPISODES, help="random (model, pose) draws")
    p.add_argument("--seed", type=seed_int, default=DEFAULT_SEED, help="seed of the sweep's draws (an integer >= 0)")
    p.add_argument(
        "--noise", type=noise_levels, default=list(DEFAULT_NOISES),
        help="comma-separated sensor-noise levels (x the sensor model's sigma, 0 to 10)",
    )
    p.add_argument(
        "--verify", choices=VERIFY_MODES, default=DEFAULT_VERIFY,
        help="verification before recognition: none, fast (pose check; every face and edge measured) or full "
        "(also every vertex)",
    )
    p.add_argument(
        "--moves", choices=MOVE_SETS, default=None,
        help=f"admissible kinds of move (default {DEFAULT_MOVES}; {HAND_DEFAULT_MOVES} with --executor physics): "
        "tracing (face, edge, vertex moves), probing "
        "(free-space probes alone, geometric executor; a verification traces too) or all (both, one "
        "planner ranking them)",
    )  # fmt: skip
    add_fingers_option(p)
    p.add_argument("--out", default=DEFAULT_OUT, help="results file (JSON lines)")
    p.add_argument("--workers", type=positive_int, default=1,
                   help="worker processes (local backend); CPUs of a Ray started here (ray backend)")
    p.add_argument("--backend", choices=("local", "ray"), default="local",
                   help="local: processes of this machine; ray: the cluster named by RAY_ADDRESS, else a Ray "
                   "started on this machine")
    p.add_argument("--max-moves", type=positive_int, default=DEFAULT_MAX_MOVES,
                   help="move budget of each episode: it ends as 'budget' after this many moves (verification "
                   "moves not counted)")
    p.add_argument("--learn", metavar="DIR",
                   help="after no-match, explore on until the object's surface is closed and write its model "
                   "into the library directory DIR (named learned_ and a digest of the episode's settings)")
    again = p.add_mutually_exclusive_group()
    again.add_argument("--resume", action="store_true",
                       help="keep OUT's episodes and run only those of the sweep not in it yet")
    again.add_argument("--force", action="store_true", help="empty an existing OUT and run the whole sweep")
    p.add_argument("--no-plot", action="store_true", help="skip the PNG plot")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    with DeferredInterrupts() as held:  # an interrupt during start-up (imports, library) ends it as in the sweep
        return _run(args, held)


def _check_learned(policies: list[str], args: argparse.Namespace) -> None:
    """A ``learned:PATH`` policy: its model file loads, and it acts on tracing moves (``--moves tracing``)."""
    from haptic.planning.moves import default_moves
    from haptic.planning.registry import is_learned

    if not any(map(is_learned, policies)):
        return
    from haptic.env.learned import learned_path, load_model

    for name in filter(is_learned, policies):
        load_model(learned_path(name))
        moves = args.moves or default_moves(args.executor)
        if moves != "tracing":
            raise BenchError(f"--policy {name} chooses among tracing moves; add --moves tracing (not {moves}) so "
                             "that every policy plays the same moves")  # fmt: skip


def _run(args: argparse.Namespace, held: DeferredInterrupts) -> int:
    from haptic.bench.results import ResultsWriter, drop_partial_line, iter_results
    from haptic.bench.runner import episode_key, key_id, plan_sweep, ray_available
    from haptic.episode.spec import check_settings, cli_option
    from haptic.geometry import load_library
    from haptic.options import check_output_file, report_skipped
    from haptic.planning.registry import POLICY_NAMES, is_learned

    # Everything is checked before any episode runs or any file is touched.
    policies = [p.strip() for p in args.policy.split(",") if p.strip()]
    bad = [p for p in policies if p not in POLICY_NAMES and not is_learned(p)]
    if bad or not policies:
        raise BenchError(f"unknown policy {', '.join(bad) or '(none)'}; valid: {', '.join(POLICY_NAMES)}, "
                         "learned:PATH")  # fmt: skip
    _check_learned(policies, args)
    if args.backend == "ray" and not ray_available():
        raise BenchError("--backend ray needs Ray: pip install -e '.[ray]' (or use --backend local)")
    out = check_output_file(args.out, "--out", "out/bench/results.jsonl", BenchError)
    summaries = [out.with_suffix(".md")] + ([] if args.no_plot else [out.with_suffix(".png")])
    for path in summaries:
        check_output_file(path, "--out (its summary beside it)", "out/bench/results.jsonl", BenchError)
    common = dict(
        executor=args.executor, models=args.models, max_moves=args.max_moves, skip_invalid=args.skip_invalid,
        verify=args.verify, moves=args.moves, units=args.units, fingers=args.fingers,
    )  # fmt: skip
    check_settings(common, cli_option)
    if args.learn is not None:
        from haptic.learning.library import check_learn_target

        common["learn"] = str(check_learn_target(args.learn, None).resolve())
    library = load_library(args.models, skip_invalid=args.skip_invalid, units=args.units)
    report_skipped(args.models, args.skip_invalid, args.units)
    specs = plan_sweep(sorted(library), args.episodes, args.seed, policies, args.noise, **common)
    has_results = out.is_file() and out.stat().st_size > 0
    if has_results and not (args.resume or args.force):
        raise BenchError(
            f"{out}: already holds results; --resume runs only the episodes of this sweep not in it yet, "
            "--force starts it over"
        )
    done: set[str] = set()
    if has_results and args.resume:
        if drop_partial_line(out):
            print(f"{out}: dropped an unfinished last line", file=sys.stderr)
        for n, rec in enumerate(iter_results(out), 1):
            if "key" not in rec:
                raise BenchError(f"{out}: record {n} has no episode key (written before results were keyed); "
                                 "--force starts the file over")
            done.add(key_id(rec["key"]))
    todo = [s for s in specs if key_id(episode_key(s)) not in done]
    if args.resume:
        print(f"resume: {len(specs) - len(todo)} of {len(specs)} episodes already in {out}; running {len(todo)}")
    for path in (out.with_suffix(".md"), out.with_suffix(".png")):
        path.unlink(missing_ok=True)  # a summary never describes other results than the file's

    # the handlers taken over after the sweep; SIGTERM raises Terminated (haptic.cli.main sets that up)
    previous = {sig: held.handlers.get(sig, signal.getsignal(sig)) for sig in (signal.SIGINT, signal.SIGTERM)}
    code, failure = 0, None
    t0 = time.perf_counter()
    try:
        with ResultsWriter(out, overwrite=args.force) as writer:
            try:
                held.release()  # an interrupt held over start-up takes effect here
                _sweep(todo, args, writer)
            except KeyboardInterrupt:
                code = EXIT_SIGINT
            except Terminated:
                code = EXIT_SIGTERM
            except Exception as exc:  # reported once the summary of what was kept is written
                failure = exc
            finally:
                signal.signal(signal.SIGINT, signal.SIG_IGN)  # the summary is written whatever comes next
                signal.signal(signal.SIGTERM, signal.SIG_IGN)
        wall = time.perf_counter() - t0
        if failure is not None:
            try:
                _write_summary(out, args.no_plot, quiet=True)
            except (OSError, HapticError):
                pass  # the results file is what counts; --resume writes the summary again
            raise failure
        _write_summary(out, args.no_plot)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if code:
        print(f"haptic: interrupted after {writer.written} episodes of {len(todo)}; every finished one is in {out} "
              "(run again with --resume to finish)", file=sys.stderr)
        return code
    rate = f" ({60 * writer.written / wall:.0f} episodes/min)" if writer.written and wall > 0 else ""
    print(f"{writer.written} episodes in {wall:.1f} s{rate}; results: {out}")
    return 0


def _sweep(specs, args: argparse.Namespace, writer) -> None:
    """Run ``specs`` and append each record as it ends."""
    from contextlib import closing

    from tqdm import tqdm

    from haptic.bench.runner import run_sweep

    with tqdm(total=len(specs), unit="ep", desc="bench", disable=None, file=sys.stderr) as bar:
        with closing(run_sweep(specs, workers=args.workers, backend=args.backend)) as records:
            for rec in records:
                writer.write(rec)
                bar.update(1)


def _write_summary(out: Path, no_plot: bool, quiet: bool = False) -> None:
    """The summary table and the plot, from every record of ``out``, each written atomically."""
    from haptic.bench.results import read_results
    from haptic.bench.summary import compact_table, markdown_table, plot_interpretations_vs_cost, summary_rows
    from haptic.geometry.io import atomic_write

    records = read_results(out) if out.exists() else []
    probing = any(r.get("move_set", "tracing") != "tracing" for r in records)  # a column only where it tells
    placing = any(r.get("fingers", 1) != 1 for r in records)
    keys = ("library", "executor", "noise", "verify", *(("move_set",) if probing else ()),
            *(("fingers",) if placing else ()), "policy")  # fmt: skip
    rows = summary_rows(records, keys)
    atomic_write(out.with_suffix(".md"), markdown_table(rows))
    if not quiet:
        print(compact_table(rows), end="")
        print(f"table: {out.with_suffix('.md')} (every column)")
    if not no_plot and records:
        libraries = sorted({str(r.get("library")) for r in records})
        png = plot_interpretations_vs_cost(records, out.with_suffix(".png"), title=f"{', '.join(libraries)} library")
        if not quiet:
            print(f"plot: {png}")
