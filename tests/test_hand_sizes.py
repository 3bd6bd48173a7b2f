"""scripts/hand_sizes.py: how it sorts the episodes' ends and counts the moves, one real episode through it end to
end, and bad input as one line of error."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
import hand_sizes  # noqa: E402


def _run(*args):
    env = {**os.environ, "MUJOCO_GL": "disable"}
    return subprocess.run([sys.executable, str(ROOT / "scripts" / "hand_sizes.py"), *map(str, args)],
                          capture_output=True, text=True, cwd=ROOT, env=env)  # fmt: skip


@pytest.mark.parametrize(("record", "kind"), [
    ({"outcome": "recognized", "correct": True}, "confirmed"),
    ({"outcome": "recognized", "correct": False}, "wrong"),
    ({"outcome": "failed", "detail": "4 failed moves in a row (last: unreachable)"}, "failed"),
    ({"outcome": "ambiguous", "detail": "verification incomplete: vertices of X 2 out of the hand's reach off the "
                                        "table (a difference there cannot be measured)"}, "out of reach"),
    ({"outcome": "ambiguous", "detail": "verification incomplete: vertices of X 3 on the table with neither an edge "
                                        "rising from them nor two of their faces in reach"}, "out of reach"),
    ({"outcome": "ambiguous", "detail": "verification incomplete after 31 moves: 0 faces, 0 edges, 1 vertices of X "
                                        "not measured"}, "stalled"),
    ({"outcome": "ambiguous", "detail": "2 poses of X left that differ only where no finger reaches: no move tells "
                                        "them apart"}, "alike"),
    ({"outcome": "no-match", "detail": "verification: data component 3 (face) off the recognised pose"}, "other"),
])  # fmt: skip
def test_each_end_of_an_episode_has_its_class(record, kind):
    assert hand_sizes.outcome_class(record) == kind


def test_the_summary_counts_per_size():
    made = ["face", "index", "planner", "ok", "", "made", None]
    lost = ["face", "index", "planner", "unreachable", "met the object", "made", None]
    stop = ["face", "index", "planner", "unreachable", "the table", "table", None]
    records = [
        {"size_mm": 80, "outcome": "recognized", "correct": True, "wall_time_s": 4.0,
         "move_results": [["face", True], ["face", False], ["edge", True]], "move_reach": [made, lost, stop]},
        {"size_mm": 30, "outcome": "failed", "detail": "", "wall_time_s": 9.0,
         "move_results": [["vertex", False]], "move_reach": []},
        {"size_mm": 80, "outcome": "ambiguous", "detail": "verification incomplete after 9 moves", "wall_time_s": 2.0,
         "move_results": [["face", True]], "move_reach": [made]},
    ]  # fmt: skip
    rows = hand_sizes.summarise(records)
    assert [r["size_mm"] for r in rows] == [30, 80]
    small, large = rows
    assert small["outcomes"]["failed"] == 1 and small["moves"]["vertex"] == [0, 1]
    assert large["episodes"] == 2 and large["outcomes"]["confirmed"] == 1 and large["outcomes"]["stalled"] == 1
    assert large["moves"]["face"] == [2, 3] and large["moves"]["edge"] == [1, 1]
    assert (large["predicted_made"], large["predicted_made_failed"]) == (3, 1)  # the table's stop is not "made"
    assert large["median_wall_s"] == 3.0


def test_one_episode_end_to_end(tmp_path):
    run = _run("--sizes", "80", "--objects", "square_antiprism", "--verify", "none", "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    data = json.loads((tmp_path / "sizes.json").read_text())
    (rec,) = data["episodes"]
    assert rec["size_mm"] == 80 and rec["model"] == "square_antiprism" and rec["correct"]
    assert data["rows"][0]["outcomes"]["confirmed"] == 1
    assert (tmp_path / "sizes.png").stat().st_size > 0
    assert (tmp_path / "models_080mm" / "square_antiprism.json").exists()  # replayable with haptic explore
    assert "wrong recognitions 0" in run.stdout


@pytest.mark.parametrize("args", [("--sizes", "0,30"), ("--sizes", "30,big"), ("--objects", "no_such_solid"),
                                  ("--models", "no/such/dir")])  # fmt: skip
def test_bad_input_is_one_line_of_error(tmp_path, args):
    run = _run(*args, "--out", tmp_path / "out")
    assert run.returncode == 2
    assert len(run.stderr.strip().splitlines()) == 1 and "Traceback" not in run.stderr
    assert run.stderr.startswith("hand_sizes: ")
    assert not (tmp_path / "out" / "sizes.json").exists()
