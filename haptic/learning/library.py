"""A learned model written into a library: the project's native model file, with where it came from.

The file is an ordinary native model (:func:`haptic.geometry.io.load_model` reads it like any other) with one
more key, ``provenance``: the episode it was learned in (its key), the executor, the noise level, the data's
error bounds and how the learning went. Coordinates are written with the decimals of the model's precision,
so that the file is read back at the precision it was validated at. Writes are atomic.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import asdict
from pathlib import Path

from haptic.errors import ModelError
from haptic.geometry.io import FORMAT_VERSION, NATIVE_SUFFIX, atomic_write
from haptic.geometry.polyhedron import Polyhedron
from haptic.geometry.symmetry import symmetry_group
from haptic.learning.reconstruct import LearnBounds, decimals_for

LEARNED_PREFIX = "learned_"
"""Names of learned models not named by the user: this and a digest of the episode's key."""
PROVENANCE_EXCLUDED = ("record", "learn", "learn_name")
"""Fields of an episode spec that do not define the data a model was learned from."""


def episode_provenance(spec) -> dict:
    """What defines the episode a model is learned in (the fields of its spec but where its outputs go)."""
    return {k: v for k, v in asdict(spec).items() if k not in PROVENANCE_EXCLUDED}


def learned_name(spec) -> str:
    """``learned_`` and 8 hex digits of the episode's key: the same episode learns the same name."""
    text = json.dumps(episode_provenance(spec), sort_keys=True, default=str)
    return LEARNED_PREFIX + hashlib.sha1(text.encode()).hexdigest()[:8]


def check_learn_target(directory: str | os.PathLike, name: str | None) -> Path:
    """The library directory learned models go into, checked before an episode runs: a directory or a path where
    one can be made; with a user's ``name``, one no model file of the directory has yet."""
    d = Path(directory)
    if d.exists() and not d.is_dir():
        raise ModelError(f"{d}: --learn takes a library directory, and this is a file")
    if name is not None:
        if not name or any(ch in name for ch in "/\\") or name.startswith("."):
            raise ModelError(f"--learn-name {name!r} is not a model name: a file stem without '/' or a leading '.'")
        taken = [p for p in d.glob(f"{name}.*")] if d.is_dir() else []
        if taken:
            raise ModelError(f"{taken[0]}: a model named {name!r} is already in {d}; choose another --learn-name "
                             "or remove the file")  # fmt: skip
    return d


def model_text(poly: Polyhedron, provenance: dict) -> str:
    """The native JSON of ``poly`` with ``provenance``, coordinates written at the model's precision."""
    decimals = decimals_for(poly.precision) if poly.precision > 0 else 9
    verts = ",\n    ".join("[" + ", ".join(f"{float(x):.{decimals}f}" for x in p) + "]" for p in poly.vertices)
    faces = ",\n    ".join(json.dumps(list(f)) for f in poly.faces)
    prov = json.dumps(_short(provenance), indent=2, sort_keys=True, default=str).replace("\n", "\n  ")
    return (
        f'{{\n  "format": "haptic-polyhedron",\n  "version": {FORMAT_VERSION},\n  "name": {json.dumps(poly.name)},\n'
        f'  "units": "m",\n  "vertices": [\n    {verts}\n  ],\n  "faces": [\n    {faces}\n  ],\n'
        f'  "provenance": {prov}\n}}\n'
    )


PROVENANCE_DIGITS = 3
"""Significant digits of the provenance's numbers: fewer than any coordinate's, for a native file's precision is
read from its longest-written numbers (:func:`haptic.geometry.io.text_quantum`)."""


def _short(x):
    """``x`` with every float rounded to :data:`PROVENANCE_DIGITS` significant digits (a whole number written as
an integer: ``163.0`` would count four)."""
    if isinstance(x, dict):
        return {k: _short(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_short(v) for v in x]
    if isinstance(x, float):
        v = float(f"{x:.{PROVENANCE_DIGITS}g}")
        return int(v) if v.is_integer() else v
    return x


def write_learned(poly: Polyhedron, directory: str | os.PathLike, spec, bounds: LearnBounds, learned: dict) -> Path:
    """Write ``poly`` as ``directory/<name>.json`` (atomically) with its provenance: the episode ``spec``, the
    data's error ``bounds``, the learning's record ``learned`` and the model's symmetry group's order."""
    path = Path(directory) / f"{poly.name}{NATIVE_SUFFIX}"
    provenance = {
        "learned_from": "touch",
        "episode": episode_provenance(spec),
        "executor": spec.executor,
        "noise": spec.noise,
        "bounds": bounds.to_json(),
        "precision_m": poly.precision,
        "symmetry": len(symmetry_group(poly)),
        "learning": {k: v for k, v in learned.items() if k != "path"},
    }
    atomic_write(path, model_text(poly, provenance))
    return path
