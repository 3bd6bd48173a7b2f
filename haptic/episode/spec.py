"""What defines one episode: :class:`EpisodeSpec` (with the library's files, everything its result depends on)."""

from __future__ import annotations

from dataclasses import dataclass

from haptic.errors import HapticError
from haptic.planning.moves import MOVE_SETS


@dataclass(frozen=True)
class EpisodeSpec:
    """Everything that determines one episode (with the library's files)."""

    model: str
    """True model: a name in the library, or a path to a model file."""
    seed: int
    """Seed of the episode's generator: the pose, the start, the noise and the policy's random choices."""
    policy: str = "planner"
    """Policy name."""
    executor: str = "geometric"
    """"geometric" (ideal sensor with noise) or "physics" (MuJoCo hand)."""
    noise: float = 1.0
    """Sensor-noise level: multiplies every σ of the default noise model (0 = noiseless)."""
    models: str | None = None
    """Library directory (None: the shipped library)."""
    budget: float = 600.0
    """Cost budget: the episode ends as "budget" once its path cost passes this [units]."""
    max_moves: int = 40
    """Move budget: the episode ends as "budget" after this many moves."""
    record: str | None = None
    """Path of a rerun recording to write (None: none)."""
    skip_invalid: bool = False
    """Use the library's valid models when some of its files are bad (else refuse the library)."""
    verify: str = "none"
    """Verification before recognition: "none", "fast" or "full" (:mod:`haptic.matching.acceptance`)."""
    moves: str = "tracing"
    """Admissible kinds of move: "tracing" (face, edge, vertex moves), "probing" (free-space probes alone,
    geometric executor) or "all" (both, ranked by one planner; every policy plans them). The command line's
    default is ``haptic.planning.moves.DEFAULT_MOVES``; this one is what a record written before the field
    existed was run with."""

    def __post_init__(self) -> None:
        if self.moves == "tracing":  # the tracing moves run everywhere
            return
        if self.moves not in MOVE_SETS:
            raise HapticError(f"unknown --moves {self.moves!r}; valid: {', '.join(MOVE_SETS)}")
        if self.moves == "probing" and self.executor != "geometric":
            raise HapticError(
                f"--moves probing: probes alone run on the geometric executor only; "
                f"valid with --executor {self.executor}: tracing, all"
            )
