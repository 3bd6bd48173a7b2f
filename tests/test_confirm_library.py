"""scripts/confirm_library.py: every model of a library explored as itself; its summary counts what the records
say, and a bad library is one line of error."""

import json
import subprocess
import sys
from pathlib import Path

from haptic.geometry import load_library, save_model

ROOT = Path(__file__).resolve().parents[1]


def _run(*args):
    return subprocess.run([sys.executable, str(ROOT / "scripts" / "confirm_library.py"), *map(str, args)],
                          capture_output=True, text=True, cwd=ROOT)  # fmt: skip


def test_every_model_is_explored_once_and_counted(tmp_path):
    lib = load_library()
    for name in ("TETRA01L", "WEDGE01"):
        save_model(lib[name], tmp_path / "lib" / f"{name}.json")
    out = tmp_path / "out.jsonl"
    run = _run("--models", tmp_path / "lib", "--out", out)
    assert run.returncode == 0, run.stderr
    recs = [json.loads(line) for line in out.read_text().splitlines()]
    assert sorted(r["model"] for r in recs) == ["TETRA01L", "WEDGE01"]
    good = sum(r["outcome"] == "recognized" and r["correct"] for r in recs)
    assert f"episodes: 2; confirmed and correct: {good} ({50.0 * good:.1f} %)" in run.stdout
    statuses = [r["verified"]["status"] for r in recs]
    assert f"confirmed {statuses.count('confirmed')}" in run.stdout
    assert out.with_suffix(".md").read_text().split("\n\n", 1)[1] == run.stdout.split("\n\n", 1)[1].rstrip("\n") + "\n"


def test_a_bad_library_is_one_line_of_error(tmp_path):
    run = _run("--models", tmp_path / "nothing here", "--out", tmp_path / "o.jsonl")
    assert run.returncode == 1 and run.stderr.startswith("error: ") and "Traceback" not in run.stderr
