"""``haptic scene``: compose a scene with an object on the table and export it as a standalone MJCF.

Function-local imports here are deliberate: a subcommand's modules load only when it runs, so that ``--help``
and a bad option answer at once, without numpy's stack, MuJoCo or rerun.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

import numpy as np

from haptic.errors import SceneError

if TYPE_CHECKING:
    from haptic.options import Subcommands


def add_parser(subparsers: Subcommands) -> argparse.ArgumentParser:
    """Register the ``scene`` subcommand on ``subparsers``; returns its parser."""
    from haptic.options import add_units_option, seed_int

    p = subparsers.add_parser(
        "scene",
        help="compose the robot + table + object scene and export it as MJCF",
        description="Compose arm + hand + table with a library object resting on the table at a random pose drawn "
        "from --seed, print that pose, and export a standalone MJCF (mesh files beside it) that plain mujoco loads.",
    )
    p.add_argument("--object", required=True, help="model name in the library, or a model file path")
    p.add_argument("--models", default=None, metavar="DIR", help="library directory (default: assets/models)")
    add_units_option(p)
    p.add_argument("--seed", type=seed_int, default=0, help="seed of the object's random pose (an integer >= 0)")
    p.add_argument("--export", default=None, metavar="DIR/scene.xml",
                   help="write the scene here (default: compose and check it, write nothing)")
    p.set_defaults(run=run)
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``haptic scene``; returns the exit code (a :class:`~haptic.errors.HapticError` is for the caller:
    ``haptic``'s main prints it as one line, exit 1)."""
    from haptic.options import check_output_file
    from haptic.sim.scene import compose_scene, export_scene, load_object

    if args.export:  # checked before the scene is composed
        check_output_file(args.export, "--export", "out/scene/scene.xml", SceneError)
    obj = load_object(args.object, args.models, units=args.units)
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
    return 0
