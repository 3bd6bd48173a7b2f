"""``haptic scene``: compose a scene with an object on the table and export it as a standalone MJCF.

Function-local imports here are deliberate: a subcommand's modules load only when it runs, so that ``--help``
and a bad option answer at once, without numpy's stack, MuJoCo or rerun.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

import numpy as np

from haptic.errors import HapticError, SceneError

if TYPE_CHECKING:
    from haptic.options import Subcommands


def add_parser(subparsers: Subcommands) -> argparse.ArgumentParser:
    """Register the ``scene`` subcommand on ``subparsers``; returns its parser."""
    from haptic.options import seed_int

    p = subparsers.add_parser(
        "scene",
        help="compose the robot + table + object scene and export it as MJCF",
        description="Compose arm + hand + table with a library object at a seeded random (or given) pose, "
        "and export a standalone MJCF (mesh files beside it) that plain mujoco loads.",
    )
    p.add_argument("--object", required=True, help="model name in the library, or a model file path")
    p.add_argument("--models", default=None, help="library directory (default: assets/models)")
    p.add_argument("--seed", type=seed_int, default=0, help="seed of the object's random pose (an integer >= 0)")
    p.add_argument("--export", default=None, metavar="DIR/scene.xml", help="write the scene here")
    p.set_defaults(run=run)
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``haptic scene``; returns the exit code (errors: one line on stderr, exit 1)."""
    from haptic.options import check_output_file
    from haptic.sim.scene import compose_scene, export_scene, load_object

    try:
        if args.export:  # checked before the scene is composed
            check_output_file(args.export, "--export", "out/scene/scene.xml", SceneError)
        obj = load_object(args.object, args.models)
        scene = compose_scene(obj, seed=args.seed)
        model = scene.compile()
        t = scene.world_from_object
        print(f"object {obj.name}: {len(obj.parts)} convex part(s); seed {args.seed}")
        print(f"world_from_object translation [m]: {np.array2string(t[:3, 3], precision=4)}")
        print(f"world_from_object rotation:\n{np.array2string(t[:3, :3], precision=4)}")
        print(f"model: {model.njnt} joints, {model.nu} actuators, {model.nsensor} sensors")
        if args.export:
            path = export_scene(scene, args.export)
            print(f"wrote {path}")
    except HapticError as exc:
        print(f"haptic scene: error: {exc}", file=sys.stderr)
        return 1
    return 0


def main(argv: list[str] | None = None) -> int:
    """Stand-alone entry point (``python -m haptic.sim.cli scene ...``)."""
    ap = argparse.ArgumentParser(prog="haptic")
    add_parser(ap.add_subparsers(dest="command", required=True))
    args = ap.parse_args(argv)
    return args.run(args)


if __name__ == "__main__":
    raise SystemExit(main())
