"""``haptic bench``: results file, summary, plot; one-line errors."""

import json

from haptic.bench.results import read_results
from haptic.cli import main


def test_bench_writes_results_summary_and_plot(tmp_path, capsys):
    out = tmp_path / "r" / "results.jsonl"
    # without verification (test_bench_is_deterministic runs the defaults): the files are what is checked here
    args = ["bench", "--episodes", "3", "--policy", "planner,random", "--seed", "2", "--verify", "none"]
    assert main([*args, "--out", str(out)]) == 0
    records = read_results(out)
    assert len(records) == 6
    assert {r["policy"] for r in records} == {"planner", "random"}
    # both policies ran on the same (model, seed) draws
    draws = {p: sorted((r["model"], r["seed"]) for r in records if r["policy"] == p) for p in ("planner", "random")}
    assert draws["planner"] == draws["random"]
    assert out.with_suffix(".md").read_text().startswith("| library |")
    assert out.with_suffix(".png").read_bytes()[:4] == b"\x89PNG"
    printed = capsys.readouterr().out
    assert any(line.split()[:2] == ["planner", "3"] for line in printed.splitlines()) and "episodes/min" in printed
    assert "| planner |" in out.with_suffix(".md").read_text()
    json.dumps(records)


def test_bench_is_deterministic(tmp_path):
    a, b = tmp_path / "a.jsonl", tmp_path / "b.jsonl"
    for p in (a, b):
        args = ["bench", "--episodes", "2", "--policy", "planner", "--seed", "5", "--out", str(p), "--no-plot"]
        assert main(args) == 0
    strip = [{k: v for k, v in r.items() if k not in ("wall_time_s", "decision_times_s")} for r in read_results(a)]
    again = [{k: v for k, v in r.items() if k not in ("wall_time_s", "decision_times_s")} for r in read_results(b)]
    assert strip == again


def test_bench_errors_are_one_line(tmp_path, capsys):
    assert main(["bench", "--episodes", "1", "--policy", "planner,oracle", "--out", str(tmp_path / "x.jsonl")]) == 1
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "oracle" in err and "planner" in err
    assert main(["bench", "--episodes", "1", "--out", str(tmp_path)]) == 1
    assert "is a directory" in capsys.readouterr().err
    assert main(["bench", "--episodes", "0"]) == 2  # a usage error, checked by the parser
    assert "--episodes" in capsys.readouterr().err


def test_bench_physics_executor_on_a_small_library(tmp_path, capsys):
    """``--executor physics`` end to end on a two-model library: the MuJoCo hand runs every episode (to recognition:
    verification on the hand is tested in test_episode_physics)."""
    import shutil

    from haptic.geometry.io import DEFAULT_LIBRARY

    lib = tmp_path / "small"
    lib.mkdir()
    for name in ("PYR01", "WEDGE01"):
        shutil.copy(DEFAULT_LIBRARY / f"{name}.json", lib)
    out = tmp_path / "p" / "results.jsonl"
    args = ["bench", "--executor", "physics", "--models", str(lib), "--episodes", "2", "--policy", "planner",
            "--seed", "1", "--verify", "none", "--no-plot", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    records = read_results(out)
    assert len(records) == 2
    assert all(r["executor"] == "physics" and r["library"] == "small" for r in records)
    assert all(r["model"] in ("PYR01", "WEDGE01") and r["sim_time_s"] > 1.0 for r in records)
    assert all(r["outcome"] in ("recognized", "ambiguous", "no-match", "budget", "failed") for r in records)
    assert any(r["outcome"] == "recognized" for r in records)
    printed = capsys.readouterr().out
    assert any(line.split()[:2] == ["planner", "2"] for line in printed.splitlines()) and "episodes/min" in printed
    assert "| small | physics | 1.0 | none | planner | 2 |" in out.with_suffix(".md").read_text()
