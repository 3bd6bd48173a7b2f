"""scripts/bench_optimal.py: an earlier run's rows reused (``--reuse``) are not run again."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _run(*args):
    run = subprocess.run([sys.executable, str(ROOT / "scripts" / "bench_optimal.py"), "--episodes", "2", "--moves",
                          "tracing", "--hindsight-depth", "0", "--jobs", "1", *args], capture_output=True, text=True,
                         cwd=ROOT)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    return run.stdout


def test_reused_rows_are_not_run_again(tmp_path):
    first, second = tmp_path / "a.jsonl", tmp_path / "b.jsonl"
    _run("--policies", "planner", "--json", str(first))
    out = _run("--policies", "planner,greedy", "--reuse", str(first), "--json", str(second))
    a = [json.loads(line) for line in first.read_text().splitlines()]
    b = [json.loads(line) for line in second.read_text().splitlines()]
    assert len(a) == 2 and len(b) == 4
    reused = [r for r in b if r["policy"] == "planner"]
    assert sorted(map(json.dumps, reused)) == sorted(map(json.dumps, a))  # the same rows, wall times and all
    assert {r["seed"] for r in b if r["policy"] == "greedy"} == {r["seed"] for r in a}
    assert "| greedy | 2/2 |" in out and "| planner | 2/2 |" in out
