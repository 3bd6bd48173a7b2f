"""The ``haptic`` command.

Every subcommand turns a :class:`~haptic.errors.HapticError` into one line on stderr and a non-zero exit.
Function-local imports here are deliberate: a subcommand's modules load only when it runs, so that ``--help``
and a bad option answer at once, without numpy's stack, MuJoCo or rerun.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from haptic.errors import HapticError

if TYPE_CHECKING:
    from haptic.options import Subcommands

Runner = Callable[[argparse.Namespace], int]


def _add_models(sub: Subcommands) -> None:
    from haptic.options import add_units_option

    p = sub.add_parser("models", help="list, show and check polyhedral models")
    msub = p.add_subparsers(dest="models_cmd", required=True, metavar="{list,show,check,generate}")

    lp = msub.add_parser("list", help="the models of a library: V/E/F, genus, convexity, symmetry order")
    lp.add_argument("--models", metavar="DIR", help="library directory (default: the shipped assets/models)")
    add_units_option(lp)
    lp.add_argument("--json", action="store_true", help="one JSON object per line instead of a table")
    lp.set_defaults(run=_models_list)

    sp = msub.add_parser("show", help="one model in full: faces, edges, vertices, symmetry")
    sp.add_argument("name", help="a model name in the library, or a path to a model file")
    sp.add_argument("--models", metavar="DIR", help="library directory (default: the shipped assets/models)")
    add_units_option(sp)
    sp.set_defaults(run=_models_show)

    cp = msub.add_parser(
        "check",
        help="validate model files; exit 1 if any is bad",
        description="Load and validate each FILE as a library would: one line per file, 'ok' with its size and "
        "counts, or the error; a warning when a model's size suggests misread units. Exit 1 if any file is bad.",
    )
    cp.add_argument("files", nargs="+", metavar="FILE", help="model files (.json, .obj, .stl, .ply)")
    add_units_option(cp)
    cp.set_defaults(run=_models_check)

    gp = msub.add_parser(
        "generate",
        help="write a deterministic library of N models (for scale tests)",
        description="Random convex polyhedra and their mirror images, prisms and antiprisms, boxes, wedges and "
        "pyramids of close dimensions, L blocks and slotted blocks: N models drawn from SEED, written as native "
        "model files into a new directory OUT, then loaded back and validated like any library.",
    )
    gp.add_argument("--count", type=int, required=True, metavar="N", help="number of models")
    gp.add_argument("--seed", type=int, default=0, help="seed of the draw")
    gp.add_argument("--out", required=True, metavar="DIR", help="new (or empty) library directory to write")
    gp.set_defaults(run=_models_generate)


def _models_list(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from haptic.geometry.io import scan_library
    from haptic.geometry.symmetry import model_summary
    from haptic.options import report_sizes

    scan = scan_library(args.models, progress=True, units=args.units)
    report_sizes(scan.size_warnings())
    models = list(scan.models.values())
    rows = [model_summary(m) for m in tqdm(models, desc="symmetry", unit="model", disable=None, leave=False)]
    for msg in scan.errors.values():
        print(f"haptic: error: {msg}", file=sys.stderr)
    status = 1 if scan.errors else 0
    if args.json:
        for r in rows:
            print(json.dumps(r))
        return status
    if not rows:
        print(f"0 valid models; {len(scan.errors)} invalid files")
        return status
    w = max(12, *(len(r["name"]) for r in rows))
    head = f"{'name':<{w}} {'V':>3} {'E':>3} {'F':>3} {'V-E+F':>5} {'genus':>5} {'convex':>6} {'sym':>4}  size [mm]"
    print(head)
    print("-" * len(head))
    for r in rows:
        size = " x ".join(f"{x:g}" for x in r["extents_mm"])
        print(
            f"{r['name']:<{w}} {r['V']:>3} {r['E']:>3} {r['F']:>3} {r['euler']:>5} {r['genus']:>5} "
            f"{'yes' if r['convex'] else 'no':>6} {r['symmetry']:>4}  {size}"
        )
    print(f"{len(rows)} models" + (f"; {len(scan.errors)} invalid files (named on stderr)" if scan.errors else ""))
    return status


def _models_show(args: argparse.Namespace) -> int:
    import numpy as np

    from haptic.geometry import convex_decomposition, resolve_model, symmetry_group
    from haptic.geometry.io import scan_library, size_warning
    from haptic.geometry.se3 import rotation_angle
    from haptic.geometry.symmetry import model_summary
    from haptic.matching.recognition import near_symmetries
    from haptic.options import report_sizes

    lib = None
    if not os.path.exists(args.name):
        scan = scan_library(args.models, units=args.units)
        bad = [msg for path, msg in scan.errors.items() if path.stem == args.name]
        if bad:
            raise HapticError(bad[0])
        lib = scan.models
    m = resolve_model(args.name, lib, units=args.units)
    report_sizes([size_warning(m, args.units)])
    sym = symmetry_group(m)
    s = model_summary(m, symmetry=sym)
    print(f"{m.name}  ({m.source})")
    print(
        f"  V={s['V']} E={s['E']} F={s['F']}  V-E+F={s['euler']}  genus={s['genus']}  "
        f"convex={'yes' if s['convex'] else 'no'}  volume={s['volume_cm3']:g} cm^3"
    )
    print(f"  size {' x '.join(f'{x:g}' for x in s['extents_mm'])} mm; convex pieces: {len(convex_decomposition(m))}")
    angles = sorted(round(float(np.degrees(rotation_angle(t.rotation)))) for t in sym)
    print(f"  symmetry group: {len(sym)} proper rotations (angles {angles} deg)")
    near = near_symmetries(m)
    if near:
        worst = max(float(np.linalg.norm(t.apply(m.vertices)[:, None] - m.vertices[None], axis=2).min(axis=1).max())
                    for t in near)  # fmt: skip
        turns = sorted(round(float(np.degrees(rotation_angle(t.rotation)))) for t in near)
        print(
            f"  near-symmetries: {len(near)} more rotations (angles {turns} deg) map it onto itself within "
            f"{worst * 1e3:.3g} mm, beyond its file's precision ({m.tolerances.match * 1e3:.3g} mm) but not touch's: "
            "poses that differ by one are one pose class"
        )
    print("  faces  (n, d [mm], vertex loop):")
    for f, loop in enumerate(m.faces):
        n = m.face_normals[f]
        print(f"    F{f:<3} n=({n[0]:+.3f}, {n[1]:+.3f}, {n[2]:+.3f})  d={m.face_offsets[f] * 1e3:+8.2f}  {list(loop)}")
    print("  edges  (source->dest, length [mm], left/right face, convex/concave):")
    for e, (a, b) in enumerate(m.edges):
        kind = "convex" if m.edge_convexity[e] > 0 else "concave"
        print(
            f"    E{a}/{b:<4} l={m.edge_lengths[e] * 1e3:7.2f}  left F{m.edge_left_face[e]:<3} "
            f"right F{m.edge_right_face[e]:<3} {kind}"
        )
    return 0


def _models_check(args: argparse.Namespace) -> int:
    import numpy as np

    from haptic.geometry import load_model
    from haptic.geometry.io import size_warning
    from haptic.options import report_sizes

    bad = 0
    for f in args.files:
        try:
            m = load_model(f, units=args.units)
        except HapticError as exc:
            print(f"haptic: error: {exc}", file=sys.stderr)
            bad += 1
        else:
            size = " x ".join(f"{x * 1e3:.4g}" for x in np.ptp(m.vertices, axis=0))
            print(f"{f}: ok  V={m.n_vertices} E={m.n_edges} F={m.n_faces} genus={m.genus}  size {size} mm")
            report_sizes([size_warning(m, args.units)])
    return 1 if bad else 0


def _models_generate(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from haptic.geometry.generate import iter_library, write_library

    if args.count < 1:
        raise HapticError(f"--count must be at least 1, got {args.count}")
    bar = tqdm(iter_library(args.count, args.seed), total=args.count, unit="model", desc="generate", file=sys.stderr)
    library = write_library(bar, args.out)
    faces = sum(m.n_faces for m in library.values())
    edges = sum(m.n_edges for m in library.values())
    print(f"{len(library)} models ({faces} faces, {edges} edges) written to {args.out} and validated")
    return 0


def _optional_subcommands() -> list[Callable[[Subcommands], None]]:
    """Subcommands whose modules may pull in heavy dependencies are imported only when present."""
    out = []
    for module in ("haptic.sim.cli", "haptic.episode_cli", "haptic.bench.cli"):
        try:
            mod = __import__(module, fromlist=["add_parser"])
        except ModuleNotFoundError as exc:
            if exc.name and (exc.name == module or module.startswith(exc.name + ".")):
                continue
            raise
        out.append(mod.add_parser)
    return out


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line on stderr (exit 2), like every other error of the command; help that states
    every option's default (:class:`~haptic.options.DefaultsHelpFormatter`)."""

    def __init__(self, *args, **kwargs) -> None:
        from haptic.options import DefaultsHelpFormatter

        kwargs.setdefault("formatter_class", DefaultsHelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(
        prog="haptic",
        description="Recognise and localise polyhedral objects by active touch with a simulated robot hand.",
    )
    sub = ap.add_subparsers(dest="cmd", required=True)
    _add_models(sub)
    for add in _optional_subcommands():
        add(sub)
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    import signal
    import threading

    from haptic.options import DeferredInterrupts, Terminated, raise_terminated

    main_thread = threading.current_thread() is threading.main_thread()
    on_sigterm = signal.signal(signal.SIGTERM, raise_terminated) if main_thread else None
    try:
        with DeferredInterrupts():  # the subcommands' imports cannot swallow an early Ctrl-C
            ap = build_parser()
        try:
            args = ap.parse_args(argv)
        except SystemExit as exc:  # --help, or a usage error already printed as one line
            return exc.code if isinstance(exc.code, int) else 2
        return int(args.run(args) or 0)
    except HapticError as exc:
        print(f"haptic: error: {exc}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output piped into head & co.
        sys.stderr.close()
        return 0
    except KeyboardInterrupt:
        print("haptic: interrupted", file=sys.stderr)
        return 130
    except Terminated:
        print("haptic: terminated", file=sys.stderr)
        return 143
    except Exception as exc:  # a bug, not bad input: one line unless asked for the traceback
        if os.environ.get("HAPTIC_DEBUG"):
            raise
        print(
            f"haptic: internal error: {type(exc).__name__}: {exc} (set HAPTIC_DEBUG=1 for the traceback)",
            file=sys.stderr,
        )
        return 2
    finally:
        if main_thread:
            signal.signal(signal.SIGTERM, on_sigterm)


if __name__ == "__main__":
    raise SystemExit(main())
