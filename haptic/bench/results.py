"""Results files: one JSON line per episode, appended whole as each episode ends.

Each line is written with a single ``write`` of the complete line followed by an fsync, so an interrupted run
leaves every finished episode intact; a write that fails (disk full) is cut back to the last whole line.
Reading skips nothing silently: a malformed line is an error naming the file and line. Every record carries
its episode's ``key`` (:func:`haptic.bench.runner.episode_key`), by which a sweep resumes.
"""

from __future__ import annotations

import json
import os
import signal
from collections.abc import Iterator
from pathlib import Path

from haptic.errors import BenchError

_INTERRUPTS = {signal.SIGINT, signal.SIGTERM}


class ResultsWriter:
    """Append episode records to a JSON-lines file (created with its parent directory when missing)."""

    def __init__(self, path: str | os.PathLike, overwrite: bool = False) -> None:
        self.path = Path(path)
        self.written = 0
        """Records written by this writer."""
        if self.path.is_dir():
            raise BenchError(f"{self.path}: is a directory; --out takes a file such as results.jsonl")
        flags = os.O_WRONLY | os.O_CREAT | os.O_APPEND | (os.O_TRUNC if overwrite else 0)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fd = os.open(self.path, flags, 0o666)
        except OSError as exc:
            raise BenchError(f"{self.path}: cannot write results ({exc.strerror})") from None

    def write(self, record: dict) -> None:
        """Append one record as one line; on a write error the file is cut back to its whole lines."""
        data = (json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n").encode()
        size = os.fstat(self._fd).st_size
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, _INTERRUPTS)  # a line is written whole or not at all
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(self._fd, view) :]
            os.fsync(self._fd)
        except OSError as exc:
            try:
                os.ftruncate(self._fd, size)
            except OSError:
                pass
            raise BenchError(
                f"{self.path}: cannot write results ({exc.strerror}); the {self.written} episodes written before "
                "are kept (run again with --resume to finish)"
            ) from None
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        self.written += 1

    def close(self) -> None:
        os.close(self._fd)

    def __enter__(self) -> ResultsWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def read_results(path: str | os.PathLike) -> list[dict]:
    """All records of a results file."""
    return list(iter_results(path))


def iter_results(path: str | os.PathLike) -> Iterator[dict]:
    p = Path(path)
    if not p.exists():
        raise BenchError(f"{p}: no such results file")
    with open(p, encoding="utf-8") as fh:
        for lineno, line in enumerate(fh, 1):
            if not line.strip():
                continue
            try:
                record = json.loads(line)
            except json.JSONDecodeError as exc:
                raise BenchError(f"{p}: line {lineno} is not a JSON record ({exc.msg})") from None
            if not isinstance(record, dict):
                raise BenchError(f"{p}: line {lineno} is not a JSON object (a results file holds one per line)")
            yield record


def drop_partial_line(path: str | os.PathLike) -> int:
    """Cut a last line that was never finished (no newline: the run died while writing it); returns the
    bytes dropped. Whole lines are never touched."""
    p = Path(path)
    if not p.is_file():
        return 0
    with open(p, "rb+") as fh:
        data = fh.read()
        if not data or data.endswith(b"\n"):
            return 0
        keep = data.rfind(b"\n") + 1
        fh.truncate(keep)
        return len(data) - keep
