"""scripts/verify_cost_report.py on two small records: its ratios are those of the records, and bad input is one
line of error."""

import json
import subprocess
import sys
from pathlib import Path

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode

ROOT = Path(__file__).resolve().parents[1]


def _report(*args):
    return subprocess.run([sys.executable, str(ROOT / "scripts" / "verify_cost_report.py"), *map(str, args)],
                          capture_output=True, text=True, cwd=ROOT)  # fmt: skip


def test_the_report_gives_the_records_ratios(tmp_path):
    recs = {}
    for mode in ("none", "full"):
        rs = [run_episode(EpisodeSpec(model=m, seed=s, verify=mode, moves="all")).to_json()
              for m, s in (("TETRA01R", 3), ("WEDGE01", 4))]  # fmt: skip
        recs[mode] = rs
        (tmp_path / f"{mode}.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rs))
    run = _report(tmp_path / "none.jsonl", tmp_path / "full.jsonl", "--worst", "1")
    assert run.returncode == 0, run.stderr
    row = run.stdout.splitlines()[2].split("|")
    ratio = sum(r["path_cost"] for r in recs["full"]) / sum(r["path_cost"] for r in recs["none"])
    assert row[5].strip() == f"{ratio:.2f}×"
    cost = sum(r["verified"]["cost"] for r in recs["full"])
    bound = sum(r["verified"]["tour_bound"] for r in recs["full"])
    assert row[8].strip().startswith(f"{cost / bound:.2f}×") and cost >= bound
    assert "confirmed episodes below their bound: 0 of 2" in run.stdout


def test_a_file_that_is_not_a_record_is_one_line_of_error(tmp_path):
    bad = tmp_path / "bad.jsonl"
    bad.write_text("not json\n")
    run = _report(bad, bad)
    assert run.returncode == 2 and run.stderr.startswith("error: ") and "Traceback" not in run.stderr


def test_the_report_splits_off_the_faces_middles(tmp_path):
    recs = {}
    for mode in ("none", "full"):
        rs = [run_episode(EpisodeSpec(model="BOX01", seed=s, verify=mode, moves="all")).to_json() for s in (1, 2)]
        recs[mode] = rs
        (tmp_path / f"{mode}.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rs))
    run = _report(tmp_path / "none.jsonl", tmp_path / "full.jsonl")
    assert run.returncode == 0, run.stderr
    row = run.stdout.splitlines()[2].split("|")
    full = [r["verified"] for r in recs["full"]]
    probes = sum(v.get("middles_probed", 0) for v in full) / 2
    middles = sum(v.get("middles_cost", 0.0) for v in full) / 2
    assert probes > 0 and row[11].strip() == f"{probes:.1f}, {middles:.2f}"
    rest = sum(v["cost"] - v.get("middles_cost", 0.0) for v in full) / sum(v["tour_bound"] for v in full)
    assert row[12].strip().startswith(f"{rest:.2f}×")
