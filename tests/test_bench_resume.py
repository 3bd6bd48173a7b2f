"""Results that accumulate: keyed records, --resume, --force, the summary from the whole file, interrupts."""

from __future__ import annotations

import dataclasses
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from haptic.bench.results import read_results
from haptic.bench.runner import episode_key, key_id
from haptic.cli import main
from haptic.episode.loop import EpisodeRecord
from haptic.episode.spec import EpisodeSpec

TIMINGS = ("wall_time_s", "decision_times_s")


def bench(out, *extra, episodes=3):
    """A sweep without verification: what resuming keeps and runs does not depend on it, and it takes a tenth."""
    args = ["bench", "--episodes", str(episodes), "--policy", "planner,random", "--seed", "4", "--verify", "none",
            "--no-plot", "--out", str(out), *extra]  # fmt: skip
    return main(args)


def untimed(records):
    return sorted(({k: v for k, v in r.items() if k not in TIMINGS} for r in records), key=lambda r: key_id(r["key"]))


def test_records_keep_their_fields_and_add_the_key(tmp_path):
    out = tmp_path / "r.jsonl"
    assert bench(out, episodes=1) == 0
    for rec in read_results(out):
        assert {f.name for f in dataclasses.fields(EpisodeRecord)} | {"library", "key"} == set(rec)
        key = rec["key"]
        assert key["library"] == "seed" and key["model"] == rec["model"] and key["seed"] == rec["seed"]
        assert (key["policy"], key["executor"], key["noise"], key["max_moves"]) == (
            rec["policy"], rec["executor"], rec["noise"], 40)


def test_key_holds_every_setting_that_changes_results():
    spec = EpisodeSpec(model="BOX01", seed=3, record="somewhere.rrd")
    key = episode_key(spec)
    assert "record" not in key and "models" not in key and key["library"] == "seed"
    assert key_id(key) != key_id(episode_key(dataclasses.replace(spec, max_moves=12)))
    assert key_id(key) != key_id(episode_key(dataclasses.replace(spec, noise=0.5)))
    assert key_id(key) == key_id(episode_key(dataclasses.replace(spec, record=None)))
    # a key written before a setting existed reads as that setting's default
    older = {k: v for k, v in key.items() if k != "budget"}
    assert key_id(older) == key_id(key)


def test_resume_runs_only_the_missing_episodes(tmp_path, capsys):
    full, cut = tmp_path / "full.jsonl", tmp_path / "cut.jsonl"
    assert bench(full) == 0
    lines = full.read_text().splitlines(keepends=True)
    cut.write_text("".join(lines[:2]) + lines[2][:40])  # two whole records and one cut short
    capsys.readouterr()
    assert bench(cut, "--resume") == 0
    captured = capsys.readouterr()
    assert f"resume: 2 of 6 episodes already in {cut}; running 4" in captured.out
    assert "unfinished last line" in captured.err
    assert untimed(read_results(cut)) == untimed(read_results(full))
    table = cut.with_suffix(".md").read_text()
    assert "| seed | geometric | 1.0 | none | all | planner | 3 |" in table  # the summary is of the whole file
    assert bench(cut, "--resume") == 0  # nothing left to do
    assert "running 0" in capsys.readouterr().out
    assert len(read_results(cut)) == 6


def test_resume_with_other_settings_runs_them_beside(tmp_path, capsys):
    out = tmp_path / "r.jsonl"
    assert bench(out, episodes=1) == 0
    assert bench(out, "--resume", "--max-moves", "12", episodes=1) == 0
    assert "running 2" in capsys.readouterr().out
    records = read_results(out)
    assert sorted(r["key"]["max_moves"] for r in records) == [12, 12, 40, 40]


def test_force_starts_over(tmp_path):
    out = tmp_path / "r.jsonl"
    assert bench(out) == 0
    assert bench(out, "--force", episodes=1) == 0
    assert len(read_results(out)) == 2


def test_records_without_a_key_are_not_resumed(tmp_path, capsys):
    out = tmp_path / "r.jsonl"
    out.write_text('{"model": "BOX01", "seed": 1}\n')
    assert bench(out, "--resume") == 1
    err = capsys.readouterr().err
    assert "no episode key" in err and "--force" in err
    assert out.read_text() == '{"model": "BOX01", "seed": 1}\n'


def test_sigterm_keeps_finished_lines_and_writes_the_summary(tmp_path):
    """SIGTERM to the main process: exit 143, every finished line kept, the summary of the whole file written,
    and no worker left."""
    out = tmp_path / "r.jsonl"
    cmd = [sys.executable, "-m", "haptic.cli", "bench", "--episodes", "40", "--policy", "planner", "--workers", "2",
           "--no-plot", "--out", str(out)]  # fmt: skip
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while (not out.exists() or out.stat().st_size == 0) and time.monotonic() < deadline:
        time.sleep(0.1)
    os.kill(proc.pid, signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert "interrupted" in err and "--resume" in err and "Traceback" not in err
    records = read_results(out)
    assert 1 <= len(records) < 40
    table = out.with_suffix(".md").read_text()
    assert f"| seed | geometric | 1.0 | full | all | planner | {len(records)} |" in table
    time.sleep(0.5)
    assert not _live_in_group(proc.pid)


def _live_in_group(pgid: int) -> list[int]:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    try:
        from fault_injection import live_in_group
    finally:
        sys.path.pop(0)
    return live_in_group(pgid)


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="finds the workers in /proc")
def test_an_episode_whose_worker_dies_is_run_again(tmp_path):
    """SIGKILL of a local worker: its episodes go to a new worker; each episode is written once."""
    out = tmp_path / "r.jsonl"
    cmd = [sys.executable, "-m", "haptic.cli", "bench", "--episodes", "6", "--policy", "planner", "--workers", "2",
           "--moves", "tracing", "--no-plot", "--out", str(out)]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while (not out.exists() or out.stat().st_size == 0) and time.monotonic() < deadline:
        time.sleep(0.05)
    workers = [int(pid) for pid in Path(f"/proc/{proc.pid}/task/{proc.pid}/children").read_text().split()]
    os.kill(workers[0], signal.SIGKILL)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    records = read_results(out)
    assert len(records) == 6 and len({key_id(r["key"]) for r in records}) == 6
