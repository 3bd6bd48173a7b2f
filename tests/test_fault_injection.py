"""scripts/fault_injection.py at a small size: sweeps killed at random moments lose and duplicate nothing."""

import os
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "fault_injection.py"


def test_killed_sweeps_resume_with_nothing_lost_or_duplicated(tmp_path):
    # three runs: the first three of the seeded order of (signal, target) cases
    cmd = [sys.executable, str(SCRIPT), "--runs", "3", "--episodes", "3", "--seed", "5", "--dir", str(tmp_path)]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env={**os.environ, "MUJOCO_GL": "disable"})
    assert r.returncode == 0, r.stdout + r.stderr
    assert "0 lost, 0 duplicated, 0 differing from the uninterrupted run, 0 processes left over; 0 bad runs" in r.stdout
    rows = [line for line in r.stdout.splitlines() if line.startswith("| ") and line[2].isdigit()]
    assert len(rows) == 3
