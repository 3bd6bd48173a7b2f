"""Bad options and output paths: one line on stderr, a non-zero exit, never "internal error", and nothing
touched: checked before any episode runs or any file is written."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from haptic.cli import main

RESULTS = '{"model": "an earlier result"}\n'


@pytest.fixture
def readonly_dir(tmp_path):
    """A directory in which no file can be created (a read-only mount when running as root)."""
    if os.geteuid() != 0:
        d = tmp_path / "ro"
        d.mkdir()
        d.chmod(0o500)
        yield d
        d.chmod(0o700)
        return
    for candidate in (Path("/sys"), Path("/proc/sys")):
        try:
            fd, tmp = tempfile.mkstemp(dir=candidate)
        except OSError:
            yield candidate
            return
        os.close(fd)
        os.unlink(tmp)
    pytest.skip("no read-only directory to write into")


@pytest.fixture
def results(tmp_path):
    """An existing results file that a bad command must leave as it is."""
    out = tmp_path / "bench" / "results.jsonl"
    out.parent.mkdir()
    out.write_text(RESULTS)
    return out


def one_line_error(capsys, code: int, expected: int, *words: str) -> str:
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert code == expected, err
    assert len(err.splitlines()) == 1, err
    assert "internal error" not in err and "Traceback" not in err
    for w in words:
        assert w in err, err
    return captured.out


def bench(out: Path, *extra: str) -> int:
    return main(["bench", "--episodes", "2", "--policy", "planner", "--no-plot", "--out", str(out), *extra])


@pytest.mark.parametrize(
    "extra, expected, words",
    [
        (["--workers", "0"], 2, ["--workers", "at least 1"]),
        (["--noise", "nan"], 2, ["--noise", "finite"]),
        (["--noise", "1,-1"], 2, ["--noise", "from 0"]),
        (["--noise", "1e3"], 2, ["--noise", "to 10"]),
        (["--max-moves", "0"], 2, ["--max-moves", "at least 1"]),
        (["--seed", "-1"], 2, ["--seed", "at least 0"]),
        (["--episodes", "0"], 2, ["--episodes"]),
        (["--models", "/nonexistent/library"], 1, ["/nonexistent/library"]),
        (["--fingers", "3"], 2, ["--fingers", "invalid choice"]),
    ],
    ids=[
        "workers-0", "noise-nan", "noise-negative", "noise-too-large", "max-moves-0", "seed-negative", "episodes-0",
        "no-library", "fingers-3",
    ],
)
def test_bench_bad_option_leaves_results_untouched(results, capsys, extra, expected, words):
    code = bench(results, "--force", *extra)
    one_line_error(capsys, code, expected, *words)
    assert results.read_text() == RESULTS


def test_bench_ray_without_ray_leaves_results_untouched(results, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray fails as where Ray is not installed
    code = bench(results, "--force", "--backend", "ray")
    one_line_error(capsys, code, 1, "--backend ray", "pip install", "--backend local")
    assert results.read_text() == RESULTS


def test_bench_refuses_an_existing_results_file(results, capsys):
    one_line_error(capsys, bench(results), 1, str(results), "--resume", "--force")
    assert results.read_text() == RESULTS


def test_bench_resume_and_force_together(results, capsys):
    one_line_error(capsys, bench(results, "--resume", "--force"), 2, "--force", "--resume")
    assert results.read_text() == RESULTS


def test_bench_out_to_a_device(capsys):
    one_line_error(capsys, bench(Path("/dev/full")), 1, "/dev/full", "not a regular file")


def test_bench_out_to_a_directory(tmp_path, capsys):
    one_line_error(capsys, bench(tmp_path), 1, "is a directory", "--out")


def test_bench_out_in_a_read_only_place(readonly_dir, capsys):
    one_line_error(capsys, bench(readonly_dir / "r" / "results.jsonl"), 1, "cannot create files", "--out")


def test_bench_out_under_a_file(results, capsys):
    one_line_error(capsys, bench(results / "results.jsonl"), 1, "not a directory")
    assert results.read_text() == RESULTS


def test_bench_summary_path_is_a_directory(tmp_path, capsys):
    (tmp_path / "results.md").mkdir()
    one_line_error(capsys, bench(tmp_path / "results.jsonl"), 1, "results.md", "is a directory")
    assert not (tmp_path / "results.jsonl").exists()


def test_bench_disk_full_mid_run_keeps_the_whole_lines(tmp_path):
    """A file-size limit makes the results file's writes fail part way (EFBIG, as a full disk gives ENOSPC):
    one line on stderr, exit 1, and the file holds only whole records."""
    import json
    import resource
    import signal

    out = tmp_path / "results.jsonl"
    limit = 3000  # bytes: about two records

    def limit_file_size():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write fails instead of killing the process
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    cmd = [sys.executable, "-m", "haptic.cli", "bench", "--episodes", "6", "--policy", "planner", "--no-plot",
           "--out", str(out)]  # fmt: skip
    r = subprocess.run(cmd, capture_output=True, text=True, preexec_fn=limit_file_size)
    err = r.stderr.strip().splitlines()
    assert r.returncode == 1, r.stderr
    assert len(err) == 1 and "cannot write results" in err[0] and "--resume" in err[0], r.stderr
    assert "internal error" not in r.stderr
    text = out.read_text()
    assert text.endswith("\n") and 0 < len(text) <= limit
    lines = text.splitlines()
    assert all(json.loads(line)["key"] for line in lines)
    assert f"the {len(lines)} episodes written before are kept" in err[0]


def test_explore_json_to_a_directory_fails_before_the_episode(tmp_path, capsys):
    out = one_line_error(capsys, main(["explore", "--object", "WEDGE01", "--json", str(tmp_path)]), 1,
                         "is a directory", "--json")  # fmt: skip
    assert "outcome" not in out  # the episode never ran


def test_explore_json_in_a_read_only_place(readonly_dir, capsys):
    out = one_line_error(capsys, main(["explore", "--object", "WEDGE01", "--json", str(readonly_dir / "e.json")]),
                         1, "cannot create files")  # fmt: skip
    assert "outcome" not in out


def test_explore_record_to_a_directory(tmp_path, capsys):
    one_line_error(capsys, main(["explore", "--object", "WEDGE01", "--record", str(tmp_path)]), 1, "--record")


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--seed", "-1"], ["--seed", "at least 0"]),
        (["--seed", "x"], ["--seed", "integer"]),
        (["--max-moves", "0"], ["--max-moves"]),
        (["--noise", "nan"], ["--noise", "finite"]),
        (["--noise", "-0.5"], ["--noise"]),
    ],
    ids=["seed-negative", "seed-text", "max-moves-0", "noise-nan", "noise-negative"],
)
def test_explore_bad_option(capsys, extra, words):
    one_line_error(capsys, main(["explore", "--object", "WEDGE01", *extra]), 2, *words)


def test_scene_export_to_a_read_only_place(readonly_dir, capsys):
    out = one_line_error(capsys, main(["scene", "--object", "WEDGE01", "--export", str(readonly_dir / "s.xml")]),
                         1, "cannot create files", "--export")  # fmt: skip
    assert "joints" not in out  # nothing composed or compiled


def test_scene_export_to_a_directory(tmp_path, capsys):
    one_line_error(capsys, main(["scene", "--object", "WEDGE01", "--export", str(tmp_path)]), 1, "is a directory")


def test_scene_negative_seed(capsys):
    one_line_error(capsys, main(["scene", "--object", "WEDGE01", "--seed", "-1"]), 2, "--seed", "at least 0")


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--moves", "probing", "--executor", "physics"], ["--moves probing", "geometric", "tracing"]),
        (["--moves", "probing", "--executor", "physics", "--policy", "optimal"], ["--moves probing", "geometric"]),
    ],
    ids=["probing-physics", "probing-physics-optimal"],
)
def test_explore_move_set_not_available_with(capsys, extra, words):
    one_line_error(capsys, main(["explore", "--object", "WEDGE01", *extra]), 1, *words)


def test_bench_move_set_not_available_with(tmp_path, capsys):
    out = tmp_path / "r.jsonl"
    one_line_error(capsys, main(["bench", "--moves", "probing", "--policy", "planner,optimal", "--executor", "physics",
                                 "--episodes", "1", "--out", str(out)]), 1, "geometric", "tracing, all")  # fmt: skip
    assert not out.exists()
