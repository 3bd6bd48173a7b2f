"""Results files: one JSON line per episode, appended whole as each episode ends.

Each line is written with a single ``write`` of the complete line followed by a flush and fsync, so an
interrupted run leaves every finished episode intact and no partial line. Reading skips nothing silently:
a malformed line is an error naming the file and line.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Iterator
from pathlib import Path

from haptic.errors import BenchError


class ResultsWriter:
    """Append episode records to a JSON-lines file (created with its parent directory when missing)."""

    def __init__(self, path: str | os.PathLike, overwrite: bool = True) -> None:
        self.path = Path(path)
        if self.path.is_dir():
            raise BenchError(f"{self.path}: is a directory; --out takes a file such as results.jsonl")
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fh = open(self.path, "w" if overwrite else "a", encoding="utf-8")  # noqa: SIM115
        except OSError as exc:
            raise BenchError(f"{self.path}: cannot write results ({exc.strerror})") from None

    def write(self, record: dict) -> None:
        line = json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n"
        self._fh.write(line)
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self) -> None:
        self._fh.close()

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
                yield json.loads(line)
            except json.JSONDecodeError as exc:
                raise BenchError(f"{p}: line {lineno} is not a JSON record ({exc.msg})") from None


def write_lines(path: str | os.PathLike, records: Iterable[dict]) -> None:
    with ResultsWriter(path) as w:
        for r in records:
            w.write(r)
