"""What defines one episode: :class:`EpisodeSpec` (with the library's files, everything its result depends on).

The defaults here are the command line's: ``haptic explore`` and ``haptic bench`` read them for their options, so
that ``EpisodeSpec(model="WEDGE01", seed=1)`` is the episode ``haptic explore --object WEDGE01 --seed 1`` runs.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from haptic.errors import HapticError
from haptic.geometry.io import UNITS
from haptic.matching.acceptance import DEFAULT_VERIFY, VERIFY_MODES
from haptic.matching.components import NOISE_LEVELS
from haptic.planning.moves import FINGER_COUNTS, MOVE_SETS, default_fingers, default_moves

EXECUTORS = ("geometric", "physics")
"""The executors an episode runs on: the ideal sensor with noise, the simulated hand."""
LENGTH_UNITS = tuple(UNITS)
"""Units a library's files may be read in (``units``; :data:`haptic.geometry.io.UNITS`)."""
DEFAULT_EXECUTOR = "geometric"
DEFAULT_POLICY = "planner"
DEFAULT_SEED = 0
DEFAULT_NOISE = 1.0
"""Sensor-noise level: x the default sensor model's σ."""
DEFAULT_BUDGET = 600.0
"""Path-cost budget [units]."""
DEFAULT_MAX_MOVES = 40
"""Move budget (verification moves not counted)."""

LEGACY_DEFAULTS = {"verify": "none", "moves": "tracing", "units": "m", "fingers": 1}
"""What an episode written before a setting existed (or before its default changed) was run with: verification
none, tracing moves, files read in metres, the index finger alone. Bench keys missing a setting read as these
(:func:`~haptic.bench.runner.key_id`)."""


def episode_pairs(
    pairs: str | None, objects: str | None, seeds: str, names: Callable[[], list[str]]
) -> list[tuple[str, int]]:
    """The (model, seed) episodes an evaluation script's ``--pairs OBJECT:SEED,...``, or else its ``--objects A,B``
    (default: every model, ``names()``) and ``--seeds 1,2``, name; a :class:`~haptic.errors.HapticError` naming
    the item that is neither."""
    try:
        if pairs:
            out = []
            for item in pairs.split(","):
                model, _, seed = item.partition(":")
                out.append((model, int(seed)))
            return out
        listed = objects.split(",") if objects else names()
        return [(m, int(s)) for m in listed for s in seeds.split(",")]
    except ValueError:
        raise HapticError(f"--pairs {pairs!r} / --seeds {seeds!r}: give OBJECT:SEED,... and SEED,... with whole "
                          f"seeds, e.g. --pairs BOX01N:1,FRAME01:3 or --seeds 1,2") from None


def python_option(name: str, value) -> str:
    """How Python spells a setting in messages: ``verify='fullish'``."""
    return f"{name}={value!r}"


def cli_option(name: str, value) -> str:
    """How the command line spells a setting in messages: ``--verify fullish``."""
    return {"model": "--object"}.get(name, "--" + name.replace("_", "-")) + f" {value}"


def check_settings(values: Mapping, spell: Callable[[str, object], str] = python_option) -> None:
    """Refuse settings no episode can run with, by a :class:`~haptic.errors.HapticError` naming the setting as
    ``spell`` writes it (:func:`python_option` or :func:`cli_option`) and what would be valid. ``values``: any of
    the fields of :class:`EpisodeSpec`."""
    for check in (_check_choices, _check_moves, _check_fingers, _check_counts, _check_noise, _check_budget):
        why = check(values, spell)
        if why is not None:
            name, text = why
            raise HapticError(f"{spell(name, values[name])} {text}")


def _check_choices(values: Mapping, spell: Callable[[str, object], str]) -> tuple[str, str] | None:
    choices = (
        ("executor", EXECUTORS, "an executor"),
        ("verify", VERIFY_MODES, "a verification mode"),
        ("units", (None, *LENGTH_UNITS), "a length unit (None: the library's library.toml, else metres)"),
    )
    for name, valid, what in choices:
        if name in values and values[name] not in valid:
            return name, f"is not {what}; valid: {', '.join(str(v) for v in valid)}"
    return None


def _check_moves(values: Mapping, spell: Callable[[str, object], str]) -> tuple[str, str] | None:
    moves = values.get("moves")
    if moves is None:
        return None
    if moves not in MOVE_SETS:
        return "moves", f"is not a move set; valid: {', '.join(MOVE_SETS)}"
    executor = values.get("executor", DEFAULT_EXECUTOR)
    if moves == "probing" and executor != "geometric":
        return "moves", (f"is not available: probes alone run on the geometric executor only; valid with "
                         f"{spell('executor', executor)}: tracing, all")  # fmt: skip
    return None


def _check_fingers(values: Mapping, spell: Callable[[str, object], str]) -> tuple[str, str] | None:
    fingers = values.get("fingers")
    if fingers is None:
        return None
    if isinstance(fingers, bool) or fingers not in FINGER_COUNTS:
        return "fingers", f"is not a number of fingers; valid: {', '.join(map(str, FINGER_COUNTS))}"
    return None


def _check_counts(values: Mapping, spell: Callable[[str, object], str]) -> tuple[str, str] | None:
    for name, low in (("seed", 0), ("max_moves", 1)):
        v = values.get(name, low)
        if isinstance(v, bool) or not isinstance(v, numbers.Integral) or v < low:
            return name, f"is not valid: an integer >= {low}"
    return None


def _check_noise(values: Mapping, spell: Callable[[str, object], str]) -> tuple[str, str] | None:
    if "noise" not in values:
        return None
    lo, hi = NOISE_LEVELS
    try:
        noise = float(values["noise"])
    except (TypeError, ValueError):
        noise = math.nan
    if not math.isfinite(noise) or not lo <= noise <= hi:
        return "noise", (f"is out of range: a noise level is a finite number from {lo:g} (noiseless) to {hi:g} "
                         "(x the default sensor noise)")  # fmt: skip
    return None


def _check_budget(values: Mapping, spell: Callable[[str, object], str]) -> tuple[str, str] | None:
    budget = values.get("budget", 1.0)
    if not (isinstance(budget, int | float) and budget > 0):
        return "budget", "is not valid: a path-cost budget is a number > 0"
    return None


@dataclass(frozen=True)
class EpisodeSpec:
    """Everything that determines one episode (with the library's files). The defaults are the command line's.

    >>> EpisodeSpec(model="WEDGE01", seed=1).moves  # the geometric executor's default move set
    'all'
    """

    model: str
    """True model: a name in the library, or a path to a model file."""
    seed: int = DEFAULT_SEED
    """Seed of the episode's generator: the pose, the start, the noise and the policy's random choices."""
    policy: str = DEFAULT_POLICY
    """Policy name (:data:`haptic.planning.registry.POLICY_NAMES`; checked when the episode runs)."""
    executor: str = DEFAULT_EXECUTOR
    """"geometric" (ideal sensor with noise) or "physics" (MuJoCo hand)."""
    noise: float = DEFAULT_NOISE
    """Sensor-noise level: multiplies every σ of the default noise model (0 = noiseless)."""
    models: str | None = None
    """Library directory (None: the shipped library)."""
    budget: float = DEFAULT_BUDGET
    """Cost budget: the episode ends as "budget" once its path cost passes this [units]."""
    max_moves: int = DEFAULT_MAX_MOVES
    """Move budget: the episode ends as "budget" after this many moves (verification moves not counted)."""
    record: str | None = None
    """Path of a rerun recording to write (None: none)."""
    skip_invalid: bool = False
    """Use the library's valid models when some of its files are bad (else refuse the library)."""
    verify: str = DEFAULT_VERIFY
    """Verification before recognition: "none", "fast" or "full" (:mod:`haptic.matching.acceptance`). A record
    written before the field existed was run with "none" (:data:`LEGACY_DEFAULTS`)."""
    moves: str | None = None
    """Admissible kinds of move: "tracing" (face, edge, vertex moves), "probing" (free-space probes alone,
    geometric executor) or "all" (both, ranked by one planner; every policy plans them). None: the executor's
    default (:func:`haptic.planning.moves.default_moves`: all on the geometric executor, tracing on the simulated
    hand), filled in at construction. A record written before the field existed was run with "tracing"."""
    units: str | None = None
    """Units of the library's model files that declare none ("mm", "cm" or "m"; None: the library's
    ``library.toml``, else metres). A file's own declaration comes first."""
    fingers: int | None = None
    """Fingers the hand may use at once (``FINGER_COUNTS``): 1, the index finger alone; 2 or 4, placements of up
    to that many fingertips join the moves (:mod:`haptic.planning.placements`). None: the executor's default
    (:func:`haptic.planning.moves.default_fingers`), filled in at construction. A record written before the field
    existed was run with 1."""
    learn: str | None = None
    """Library directory a model learned after ``no-match`` is written into (``--learn DIR``: the episode explores
    on until the object's surface is closed, :mod:`haptic.episode.learning`); None: no learning."""
    learn_name: str | None = None
    """The learned model's name (None: ``learned_`` and a digest of the episode's key)."""

    def __post_init__(self) -> None:
        check_settings({k: getattr(self, k) for k in self.__dataclass_fields__})
        if self.moves is None:
            object.__setattr__(self, "moves", default_moves(self.executor))
        if self.fingers is None:
            object.__setattr__(self, "fingers", default_fingers(self.executor))
