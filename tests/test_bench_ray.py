"""The Ray backend: a local Ray with 2 CPUs gives the local backend's records, resumes, and leaves nothing.

Skipped where Ray is not installed (``pip install -e '.[ray]'``), unless HAPTIC_REQUIRE_RAY=1 (as in CI), where
a missing Ray fails.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

import pytest

from haptic.bench.results import read_results
from haptic.bench.runner import key_id, ray_available
from haptic.cli import main

if not ray_available():
    if os.environ.get("HAPTIC_REQUIRE_RAY") == "1":
        pytest.fail("HAPTIC_REQUIRE_RAY=1 but Ray is not installed: pip install -e '.[ray]'", pytrace=False)
    pytest.skip("Ray is not installed (pip install -e '.[ray]')", allow_module_level=True)

TIMINGS = ("wall_time_s", "decision_times_s")


def untimed(records):
    return sorted(({k: v for k, v in r.items() if k not in TIMINGS} for r in records), key=lambda r: key_id(r["key"]))


def processes_with_env(entry: bytes) -> list[int]:
    """Processes whose environment holds ``entry`` (Ray's daemons and workers inherit the driver's)."""
    pids = []
    for p in Path("/proc").iterdir():
        if not p.name.isdigit() or int(p.name) == os.getpid():
            continue
        try:
            env = (p / "environ").read_bytes().split(b"\0")
            state = (p / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if entry in env and state != "Z":
            pids.append(int(p.name))
    return pids


@contextmanager
def private_ray():
    """The environment of a bench that starts its own Ray in a fresh RAY_TMPDIR; on leaving, every process of that
    Ray must be gone within 20 s (those left are killed, and the test fails)."""
    ray_tmp = tempfile.mkdtemp(prefix="hr", dir="/tmp")  # short: Ray's socket paths must fit 107 bytes
    entry = f"RAY_TMPDIR={ray_tmp}".encode()
    env = {**os.environ, "RAY_TMPDIR": ray_tmp, "MUJOCO_GL": "disable"}
    env.pop("RAY_ADDRESS", None)
    try:
        yield env
        deadline = time.monotonic() + 20
        while (left := processes_with_env(entry)) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not left, f"Ray processes left: {left}"
    finally:
        for pid in processes_with_env(entry):
            os.kill(pid, 9)
        shutil.rmtree(ray_tmp, ignore_errors=True)


@pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="needs /proc to find Ray's processes")
def test_ray_resumes_a_local_sweep_with_the_same_records_and_leaves_no_process(tmp_path):
    local, mixed = tmp_path / "local.jsonl", tmp_path / "mixed.jsonl"
    # without verification: the records the two backends must agree on are the same, in a tenth of the time
    args = ["bench", "--episodes", "3", "--policy", "planner,random", "--seed", "6", "--verify", "none", "--no-plot"]
    assert main([*args, "--workers", "2", "--out", str(local)]) == 0
    lines = local.read_text().splitlines(keepends=True)
    mixed.write_text("".join(lines[:2]))  # the local backend did two; Ray resumes the other four

    cmd = [sys.executable, "-m", "haptic.cli", *args, "--backend", "ray", "--workers", "2", "--resume",
           "--out", str(mixed)]  # fmt: skip
    with private_ray() as env:
        r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        assert "running 4" in r.stdout
        assert untimed(read_results(mixed)) == untimed(read_results(local))


@pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="needs /proc to find Ray's processes")
def test_sigterm_during_a_ray_sweep_keeps_the_lines_and_stops_ray(tmp_path):
    import signal

    out = tmp_path / "r.jsonl"
    cmd = [sys.executable, "-m", "haptic.cli", "bench", "--backend", "ray", "--workers", "2", "--episodes", "30",
           "--policy", "planner", "--no-plot", "--out", str(out)]  # fmt: skip
    with private_ray() as env:
        proc = subprocess.Popen(cmd, env=env, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)  # fmt: skip
        deadline = time.monotonic() + 240
        while (not out.exists() or out.stat().st_size == 0) and time.monotonic() < deadline:
            time.sleep(0.1)
        os.killpg(proc.pid, signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 143, err
        assert "internal error" not in err and "--resume" in err
        records = read_results(out)
        assert 1 <= len(records) < 30 and len({key_id(r["key"]) for r in records}) == len(records)
        assert f"| planner | {len(records)} |" in out.with_suffix(".md").read_text()
