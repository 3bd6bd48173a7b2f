"""scripts/bench_scale.py at a small size: it writes its figures, table and plot."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_bench_scale_small(tmp_path):
    args = ["--sizes", "3,5", "--episodes", "2", "--workers", "1", "--out", str(tmp_path / "o"),
            "--libraries", str(tmp_path / "libs")]  # fmt: skip
    run = subprocess.run([sys.executable, str(ROOT / "scripts" / "bench_scale.py"), *args], capture_output=True,
                         text=True, cwd=ROOT)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    data = json.loads((tmp_path / "o" / "scale.json").read_text())
    assert [r["models"] for r in data["rows"]] == [3, 5]
    for r in data["rows"]:
        assert r["episodes"] == 2 and r["correct_pct"] == 100.0 and r["wrong"] == 0
        assert r["peak_rss_mib_per_worker"] > 0 and r["arrays_s"] >= 0
    assert (tmp_path / "o" / "scale.png").stat().st_size > 0
    assert "fitted exponents" in run.stdout
