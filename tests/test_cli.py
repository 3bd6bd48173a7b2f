"""The command line: output for good input, one line and a non-zero exit for bad input."""

import subprocess
import sys

import pytest

from haptic.cli import main


def test_models_list(capsys):
    assert main(["models", "list"]) == 0
    out = capsys.readouterr().out
    assert "BOX01N" in out and "FRAME01" in out and "10 models" in out
    row = next(line for line in out.splitlines() if line.startswith("BOX01 "))
    assert row.split()[1:8] == ["8", "12", "6", "2", "0", "yes", "4"]


def test_models_list_json(capsys):
    import json

    assert main(["models", "list", "--json"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert {r["name"]: r["genus"] for r in rows}["FRAME01"] == 1


def test_models_show(capsys):
    assert main(["models", "show", "BOX01N"]) == 0
    out = capsys.readouterr().out
    assert out.count("concave") == 2 + 1  # two concave edges plus the header line
    assert "symmetry group: 2" in out


def test_models_show_unknown_name_lists_valid_names(capsys):
    assert main(["models", "show", "NOPE"]) == 1
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "NOPE" in err and "BOX01" in err


def test_models_check_good_and_bad(tmp_path, capsys):
    good = tmp_path / "good.obj"
    good.write_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"
    )
    bad = tmp_path / "open.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n")
    assert main(["models", "check", str(good)]) == 0
    capsys.readouterr()
    assert main(["models", "check", str(good), str(bad), str(tmp_path / "missing.stl")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "open.obj" in err[0] and "missing.stl" in err[1]


def test_library_option_with_a_bad_directory(tmp_path, capsys):
    assert main(["models", "list", "--models", str(tmp_path / "nowhere")]) == 1
    assert "no such model library" in capsys.readouterr().err


@pytest.mark.parametrize("args", [["models", "check", "/nonexistent/x.obj"], ["models", "show", "BAD"]])
def test_console_script_prints_no_traceback(args):
    r = subprocess.run([sys.executable, "-m", "haptic.cli", *args], capture_output=True, text=True)
    assert r.returncode == 1
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1
