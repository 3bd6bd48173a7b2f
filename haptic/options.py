"""Command-line option types and output-path checks shared by the subcommands.

Every check here runs before any work is done or any file is touched, so that bad input costs nothing and
destroys nothing. Option types raise ``argparse.ArgumentTypeError`` (the parser prints one line, exit 2);
path checks raise the caller's :class:`~haptic.errors.HapticError` subclass (one line, exit 1).
"""

from __future__ import annotations

import argparse
import math
import os
import signal
import sys
import tempfile
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Protocol

from haptic.errors import HapticError
from haptic.matching.components import NOISE_LEVELS


class Subcommands(Protocol):
    """What a subcommand's ``add_parser`` is given: the ``haptic`` command's subparsers (the object
    ``ArgumentParser.add_subparsers`` returns)."""

    def add_parser(self, name: str, **kwargs: Any) -> argparse.ArgumentParser: ...


def report_skipped(models: str | None, skipped: bool, units: str | None = None) -> None:
    """Name on stderr, one line each, the library files ``--skip-invalid`` left out, and warn of every model
    whose size suggests misread units."""
    from haptic.geometry.io import scan_library

    scan = scan_library(models, units=units)
    report_sizes(scan.size_warnings())
    if not skipped:
        return
    for msg in scan.errors.values():
        print(f"haptic: skipped invalid model file: {msg}", file=sys.stderr)


def report_sizes(warnings: Sequence[str | None]) -> None:
    """Each size warning (:func:`~haptic.geometry.io.size_warning`) as one line on stderr."""
    for text in warnings:
        if text:
            print(f"haptic: warning: {text}", file=sys.stderr)


def int_at_least(low: int):
    """An argparse type: an integer >= ``low``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"must be at least {low}, got {value}")
        return value

    parse.__name__ = f"integer >= {low}"
    return parse


seed_int = int_at_least(0)
"""A seed: any integer >= 0 (numpy seeds its generators from non-negative integers)."""
positive_int = int_at_least(1)


def noise_level(text: str) -> float:
    """An argparse type: a finite sensor-noise level within
    :data:`~haptic.matching.components.NOISE_LEVELS` (a multiple of the default σ)."""
    lo, hi = NOISE_LEVELS
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number from {lo:g} to {hi:g}, got {text!r}") from None
    if not math.isfinite(value) or not lo <= value <= hi:
        raise argparse.ArgumentTypeError(
            f"a noise level is a finite number from {lo:g} (noiseless) to {hi:g} (x the default sensor noise), "
            f"got {text!r}"
        )
    return value


def noise_levels(text: str) -> list[float]:
    """An argparse type: comma-separated noise levels, each as :func:`noise_level`."""
    parts = [p.strip() for p in text.split(",")]
    if not parts or any(not p for p in parts):
        raise argparse.ArgumentTypeError(f"expected comma-separated noise levels, got {text!r}")
    return [noise_level(p) for p in parts]


class DefaultsHelpFormatter(argparse.HelpFormatter):
    """Help that states every option's default: "(default X)" after its text, unless the text already speaks of
    its default or the option has none (a flag off, an option unset)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if (not action.option_strings or default is None or default is False or default == argparse.SUPPRESS
                or "(default" in text or text == argparse.SUPPRESS):  # fmt: skip
            return text
        if isinstance(default, list | tuple):
            default = ",".join(f"{x:g}" if isinstance(x, float) else str(x) for x in default)
        elif isinstance(default, float):
            default = f"{default:g}"
        return f"{text} (default {str(default).replace('%', '%%')})"


UNITS_HELP = (
    "units of the model files that declare none: m, cm or mm (default: the library's library.toml, else m; an OBJ "
    "'# units:' comment or a native model's units come first)"
)
"""The ``--units`` option's help, the same on every subcommand."""


def add_units_option(parser: argparse.ArgumentParser) -> None:
    """``--units mm|cm|m`` (:data:`UNITS_HELP`)."""
    from haptic.geometry.io import UNITS

    parser.add_argument("--units", choices=tuple(UNITS), default=None, help=UNITS_HELP)


def add_fingers_option(parser: argparse.ArgumentParser) -> None:
    """``--fingers 1|2|4``: fingers at once (:data:`~haptic.planning.moves.FINGER_COUNTS`)."""
    from haptic.planning.moves import DEFAULT_FINGERS, FINGER_COUNTS, HAND_DEFAULT_FINGERS

    parser.add_argument(
        "--fingers", type=int, choices=FINGER_COUNTS, default=None,
        help=f"fingers the hand may use at once (default {DEFAULT_FINGERS}; {HAND_DEFAULT_FINGERS} with --executor "
        "physics): 1, the index finger alone; 2 or 4, placements of up to that many fingertips closing on "
        "different faces in one approach join the moves, ranked by the same planner (on the simulated hand, only "
        "placements its reach solver reaches with the hypothesised object in place). The default is 1: with the "
        "default move set the planner takes no placement (a probe tells as much for less); with --moves tracing "
        "they save about 6%% of the path cost on the geometric executor, and on the hand none is chosen (a "
        "tracing move eliminates more per unit cost) (README, 'Several fingers at once')",
    )  # fmt: skip


def check_output_file(path: str | os.PathLike, option: str, example: str, error=HapticError) -> Path:
    """Check that ``path`` can be written as a regular file, without changing anything there.

    Valid: an existing regular file that can be opened for writing, or a missing file whose nearest existing
    ancestor is a directory in which a file can be created (missing directories are made at write time).
    Raises ``error`` naming ``option``, the path and what would be valid.
    """
    p = Path(path)
    hint = f"{option} takes a file such as {example}"
    if p.exists() or p.is_symlink():
        if p.is_dir():
            raise error(f"{p}: is a directory; {hint}")
        if not p.is_file():
            raise error(f"{p}: not a regular file; {hint}")
        try:
            with open(p, "a"):  # append mode: neither truncates nor changes the file
                pass
        except OSError as exc:
            raise error(f"{p}: cannot write ({exc.strerror}); {hint} in a writable place") from None
        return p
    check_output_dir(p.parent, option, hint, error)
    return p


def check_output_dir(path: str | os.PathLike, option: str, hint: str, error=HapticError) -> Path:
    """Check that files can be created in directory ``path`` (made later when missing) by creating and
    removing a temporary file in it, or in its nearest existing ancestor. ``hint`` says what is valid."""
    p = Path(path)
    probe = p
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if not probe.is_dir():
        raise error(f"{p}: {probe} is not a directory; {hint}")
    try:
        fd, tmp = tempfile.mkstemp(prefix=".haptic-probe-", dir=probe)
    except OSError as exc:
        raise error(f"{p}: cannot create files in {probe} ({exc.strerror}); {hint} in a writable place") from None
    os.close(fd)
    os.unlink(tmp)
    return p


class DeferredInterrupts:
    """Note SIGINT and SIGTERM instead of acting on them until :meth:`release` (or the end of the ``with``
    block), where the first one noted is raised again for the handlers that were in place before.

    Some libraries catch ``BaseException`` around optional imports, and Ray's compiled calls turn an exception
    raised by a handler into a SystemError: a signal arriving there is taken at a point of our choosing
    instead. Handlers can only be set in the main thread; elsewhere this does nothing.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self) -> None:
        self.noted: list[int] = []
        """Signals received while deferred, in order."""
        self.handlers: dict = {}
        """The handlers in place before, restored by :meth:`release`."""

    def __enter__(self) -> DeferredInterrupts:
        if threading.current_thread() is threading.main_thread():
            self.handlers = {sig: signal.signal(sig, self._note) for sig in self.SIGNALS}
        return self

    def _note(self, signum, frame) -> None:
        self.noted.append(signum)

    def release(self) -> None:
        """Restore the handlers; a signal noted meanwhile is raised again now (KeyboardInterrupt, ...)."""
        handlers, self.handlers = self.handlers, {}
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
        if handlers and self.noted:
            signal.raise_signal(self.noted[0])

    def __exit__(self, *exc) -> None:
        self.release()


class Terminated(BaseException):
    """SIGTERM, raised in the main thread as KeyboardInterrupt is for SIGINT (see :func:`raise_terminated`)."""


def raise_terminated(signum, frame) -> None:
    """A SIGTERM handler: raise :class:`Terminated`, so that ``finally`` blocks run and the command exits 143."""
    raise Terminated()
