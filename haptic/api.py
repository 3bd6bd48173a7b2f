"""The Python interface: the few names ``import haptic`` offers, with the command line's defaults.

>>> import haptic
>>> record = haptic.run_episode(haptic.EpisodeSpec(model="WEDGE01", seed=1))  # haptic explore --object WEDGE01 --seed 1
>>> record.outcome, record.moves  # doctest: +SKIP

Errors are :class:`~haptic.errors.HapticError` with messages that name the setting as Python spells it
(``verify='fullish' is not a verification mode; valid: none, fast, full``).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence

from haptic.bench import DEFAULT_EPISODES, DEFAULT_NOISES, DEFAULT_POLICIES
from haptic.episode.loop import EpisodeRecord
from haptic.episode.spec import DEFAULT_SEED, EpisodeSpec, check_settings
from haptic.episode.worlds import run_episode
from haptic.errors import HapticError
from haptic.geometry import io
from haptic.geometry.polyhedron import Polyhedron


class UnitsWarning(UserWarning):
    """A model's size across suggests its file's units were misread (60 000 mm across: millimetres read as
    metres)."""


def load_library(
    models: str | os.PathLike | None = None, *, units: str | None = None, skip_invalid: bool = False
) -> dict[str, Polyhedron]:
    """The models of a library directory by name (``models``; None: the shipped library), as ``haptic models
    list --models DIR`` reads them.

    ``units`` ("mm", "cm" or "m") are those of the files that declare none; None: the folder's ``library.toml``
    (``units = "mm"``), else metres. A file's own declaration (an OBJ ``# units:`` comment, a native model's
    ``units``) comes first. A :class:`UnitsWarning` names each model larger than 1 m or smaller than 5 mm across.
    ``skip_invalid``: keep the valid models of a library with bad files (else a
    :class:`~haptic.errors.ModelError` names every bad file).
    """
    check_settings({"units": units})
    library = io.load_library(models, skip_invalid=skip_invalid, units=units)
    for text in io.scan_library(models, units=units).size_warnings():
        warnings.warn(text, UnitsWarning, stacklevel=2)
    return library


def sweep(
    models: str | None = None,
    *,
    episodes: int = DEFAULT_EPISODES,
    seed: int = DEFAULT_SEED,
    policies: Sequence[str] = DEFAULT_POLICIES,
    noises: Sequence[float] = DEFAULT_NOISES,
    workers: int = 1,
    **settings,
) -> list[dict]:
    """Run what ``haptic bench`` runs and return its records (JSON dicts, each with its ``library`` and ``key``),
    in the order of the sweep: ``episodes`` random (model, pose) draws from ``seed``, each under every policy
    and noise level. ``settings``: any other field of :class:`EpisodeSpec` (``executor``, ``verify``, ``moves``,
    ``max_moves``, ``units``, ...), the same for every episode. ``workers`` > 1 runs them in that many processes.
    """
    from contextlib import closing

    from haptic.bench.runner import episode_key, key_id, plan_sweep, run_sweep
    from haptic.planning.registry import POLICY_NAMES

    bad = sorted((set(settings) - set(EpisodeSpec.__dataclass_fields__)) | ({"model", "seed", "policy", "noise"}
                                                                              & set(settings)))  # fmt: skip
    if bad:
        raise TypeError(f"sweep() got settings it does not take: {', '.join(bad)} (the sweep draws model and "
                        "seed; policies and noises are lists)")  # fmt: skip
    check_settings({"seed": seed, **settings})
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise HapticError(f"episodes={episodes!r} is not valid: an integer >= 1")
    policies, noises = [policies] if isinstance(policies, str) else list(policies), list(noises)
    unknown = [p for p in policies if p not in POLICY_NAMES]
    if unknown or not policies:
        raise HapticError(f"policies={policies!r}: unknown policy {', '.join(map(repr, unknown)) or '(none)'}; "
                          f"valid: {', '.join(POLICY_NAMES)}")  # fmt: skip
    for n in noises:
        check_settings({"noise": n})
    library = load_library(settings.get("models"), units=settings.get("units"),
                           skip_invalid=settings.get("skip_invalid", False))  # fmt: skip
    specs = plan_sweep(sorted(library), episodes, seed, policies, [float(n) for n in noises], **settings)
    with closing(run_sweep(specs, workers=workers)) as records:
        by_key = {key_id(r["key"]): r for r in records}
    return [by_key[key_id(episode_key(s))] for s in specs]


__all__ = ["EpisodeRecord", "EpisodeSpec", "UnitsWarning", "load_library", "run_episode", "sweep"]
