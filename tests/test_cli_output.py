"""What the command prints: a line per move, summaries that count what they say, help with defaults, one
error prefix, and units on every subcommand that reads models."""

import argparse

import pytest
import trimesh

from haptic.cli import build_parser, main
from haptic.episode_cli import GROWTH_NOTE, budget_text, move_line, summary_lines, verified_line


def _record(**over) -> dict:
    rec = {
        "model": "WEDGE01", "executor": "geometric", "policy": "planner", "seed": 1, "outcome": "recognized",
        "recognized": "WEDGE01", "correct": True, "moves": 4, "move_kinds": ["start", "face", "edge", "face", "edge"],
        "failed_moves": 0, "path_cost": 20.0, "faces": 3, "edges": 2, "vertices": 0,
        "interpretations": [76, 210, 2, 1, 1], "classes": [76, 210, 2, 1, 1], "pose_error_mm": 0.1,
        "pose_error_deg": 0.1, "wall_time_s": 1.0, "verified": None, "detail": "",
    }  # fmt: skip
    rec.update(over)
    return rec


def test_explore_prints_a_line_per_move_when_asked(capsys):
    assert main(["explore", "--object", "WEDGE01", "--seed", "1", "--verify", "none", "--progress"]) == 0
    out = capsys.readouterr().out.splitlines()
    moves = [line for line in out if line.startswith("move ")]
    assert moves[0].startswith("move  0  start   ok") and "76 interpretations" in moves[0]
    assert "cost 0.0" in moves[0]
    assert any("76 -> 210 interpretations" in m and GROWTH_NOTE in m for m in moves)
    summary = out[len(moves):]
    assert summary[0].startswith("object      WEDGE01")
    n_moves = int(next(line for line in summary if line.startswith("moves")).split()[1])
    assert len(moves) == n_moves + 1  # the start and every move, failed ones too
    assert moves[-1].endswith(f"cost {float(next(x for x in summary if x.startswith('path cost')).split()[2]):.1f}")


def test_explore_is_quiet_off_a_terminal_and_with_quiet(capsys):
    for extra in ([], ["--quiet"]):
        assert main(["explore", "--object", "WEDGE01", "--seed", "1", "--verify", "none", *extra]) == 0
        out = capsys.readouterr().out
        assert not any(line.startswith("move ") for line in out.splitlines())
        assert out.startswith("object      WEDGE01")
    assert main(["explore", "--object", "WEDGE01", "--progress", "--quiet"]) == 2  # one or the other


def test_move_line_reads():
    assert move_line(3, "edge", "ok", "", (76, 210), None, 12.34) == (
        f"move  3  edge    ok       76 -> 210 interpretations ({GROWTH_NOTE}); no pose fixed yet; cost 12.3"
    )
    assert move_line(4, "face", "ok", "", (2, 1), 1, 20.0).endswith("2 -> 1 interpretation; 1 pose class; cost 20.0")
    failed = move_line(5, "vertex", "unreachable", "no path around the table", (1, 1), 1, 25.0)
    assert "failed (no path around the table)" in failed and "->" not in failed


def test_budget_says_which_budget_and_its_value():
    moves = summary_lines(_record(outcome="budget", recognized=None, correct=False, moves=2, path_cost=30.0),
                          budget=600.0, max_moves=2)  # fmt: skip
    assert "outcome     budget: 2 moves reached the move budget of 2 (--max-moves)" in moves
    cost = _record(outcome="budget", recognized=None, correct=False, moves=1, path_cost=1620.0)
    assert budget_text(cost, 600.0, 40) == "path cost 1620.0 passed the cost budget of 600"


def test_budget_from_the_command_line(capsys):
    assert main(["explore", "--object", "WEDGE01", "--seed", "1", "--max-moves", "2", "--verify", "none"]) == 0
    out = capsys.readouterr().out
    assert "outcome     budget: 2 moves reached the move budget of 2 (--max-moves)" in out


def test_verification_counts_what_it_says():
    v = {"mode": "full", "status": "confirmed", "moves": 6, "cost": 30.0, "faces": 7, "edges": 9, "vertices": 6,
         "faces_reachable": 6, "edges_reachable": 9, "vertices_reachable": 6, "faces_total": 8, "edges_total": 12,
         "vertices_total": 6, "faces_fraction": 1.0, "edges_fraction": 0.7778, "vertices_fraction": 1.0}  # fmt: skip
    line = verified_line(_record(verified=v))
    assert "7/6" not in line
    assert "measured of the reachable: 6/6 faces, 7/9 edges, 6/6 vertices" in line
    assert "(of all the model's: 7/8, 9/12, 6/6)" in line and "6 verification moves" in line



def test_the_verified_line_says_how_far_the_model_is_taken_on_trust_beside_the_table():
    v = {"mode": "full", "status": "confirmed", "moves": 6, "cost": 30.0, "table_band_mm": 16.0}
    assert "nothing measured within 16.0 mm of the table (the model taken on trust there)" in verified_line(
        _record(verified=v))
    line = verified_line(_record(verified={**v, "table_shadow_mm": 26.3, "vertices_shadowed": 6, "shadowed": [1]}))
    assert "nothing measured within 26.3 mm of the table" in line and "6 vertices in the table's shadow" in line
    assert "16.0 mm" not in line

def test_a_failed_episode_does_not_pretend_to_verify():
    v = {"mode": "full", "status": "verifying", "moves": 4, "cost": 0.0}
    line = verified_line(_record(outcome="failed", recognized=None, correct=False, verified=v))
    assert line.startswith("full: not finished: the episode ended failed during verification")
    assert "verifying" not in line


def test_the_interpretation_trace_is_explained_when_it_grows():
    grows = next(x for x in summary_lines(_record()) if x.startswith("interpret."))
    assert "76 -> 210" in grows and GROWTH_NOTE in grows
    narrows = next(x for x in summary_lines(_record(interpretations=[76, 12, 1])) if x.startswith("interpret."))
    assert GROWTH_NOTE not in narrows


def test_bench_prints_a_compact_summary_and_keeps_the_table(tmp_path, capsys):
    out = tmp_path / "r.jsonl"
    assert main(["bench", "--episodes", "2", "--policy", "planner,random", "--verify", "none", "--no-plot",
                 "--out", str(out)]) == 0  # fmt: skip
    printed = capsys.readouterr().out.splitlines()
    head = next(i for i, line in enumerate(printed) if line.startswith("policy"))
    assert printed[head].split() == ["policy", "episodes", "correct", "wrong", "other", "mean", "cost", "mean",
                                     "moves"]  # fmt: skip
    assert printed[head + 1].split()[:2] == ["planner", "2"] and printed[head + 2].split()[:2] == ["random", "2"]
    assert max(len(line) for line in printed[head:head + 3]) <= 80  # fits a terminal
    assert not any(line.startswith("|") for line in printed)
    table = out.with_suffix(".md").read_text()
    assert table.startswith("| library |") and "decide ms" in table and "| planner |" in table


def _options(parser: argparse.ArgumentParser, path=()):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _options(sub, (*path, name))
        elif action.dest != "help":
            yield path, parser, action


def test_help_describes_every_option_and_states_its_default():
    seen = 0
    for path, parser, action in _options(build_parser()):
        where = f"haptic {' '.join(path)} {action.option_strings or action.dest}"
        assert action.help, where
        text = parser.formatter_class(prog="haptic")._get_help_string(action)
        if action.option_strings and action.default not in (None, False):
            assert "(default" in text, where
        seen += 1
    assert seen > 40
    for option in ("--executor", "--policy", "--noise", "--max-moves", "--seed", "--verify", "--moves"):
        action = next(a for p, _, a in _options(build_parser()) if p == ("explore",) and option in a.option_strings)
        assert action.help


def test_help_shows_the_defaults(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["bench", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for shown in ("(default geometric)", "(default planner,random)", "(default 1)", "(default out/bench/results.jsonl)",
                  "(default 40)", "(default full)"):  # fmt: skip
        assert shown in text, shown


def test_scene_help_says_what_it_does(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["scene", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "given" not in text and "random pose drawn from --seed" in text


def test_errors_have_one_prefix(tmp_path, capsys):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\n")
    assert main(["models", "check", str(bad)]) == 1
    assert capsys.readouterr().err.startswith(f"haptic: error: {bad}")
    assert main(["models", "list", "--models", str(tmp_path)]) == 1
    assert capsys.readouterr().err.startswith(f"haptic: error: {bad}")
    assert main(["scene", "--object", "NOSUCH"]) == 1
    assert capsys.readouterr().err.startswith("haptic: error: cannot load object 'NOSUCH'")


def _cad_library(tmp_path, suffix=".stl"):
    lib = tmp_path / "cad"
    lib.mkdir()
    (lib / f"cadbox{suffix}").write_bytes(trimesh.creation.box(extents=(60, 40, 30)).export(file_type=suffix[1:]))
    return lib


@pytest.mark.parametrize("suffix", [".stl", ".ply"])
def test_models_read_in_millimetres_with_units(tmp_path, capsys, suffix):
    lib = _cad_library(tmp_path, suffix)
    path = lib / f"cadbox{suffix}"
    assert main(["models", "list", "--models", str(lib)]) == 0
    captured = capsys.readouterr()
    assert "60000 x 40000 x 30000" in captured.out
    assert f"haptic: warning: {path}: 60000 mm across" in captured.err and "--units mm" in captured.err
    assert main(["models", "list", "--models", str(lib), "--units", "mm"]) == 0
    captured = capsys.readouterr()
    assert "60 x 40 x 30" in captured.out and not captured.err
    assert main(["models", "check", str(path)]) == 0
    captured = capsys.readouterr()
    assert "size 6e+04 x 4e+04 x 3e+04 mm" in captured.out and f"{path}: 60000 mm across" in captured.err
    assert main(["models", "check", "--units", "mm", str(path)]) == 0
    captured = capsys.readouterr()
    assert f"{path}: ok" in captured.out and "size 60 x 40 x 30 mm" in captured.out and not captured.err
    assert main(["models", "show", "cadbox", "--models", str(lib), "--units", "mm"]) == 0
    assert "size 60 x 40 x 30 mm" in capsys.readouterr().out


@pytest.mark.parametrize("how", ["--units", "library.toml"])
@pytest.mark.parametrize("suffix", [".stl", ".ply"])
def test_a_millimetre_box_is_recognised(tmp_path, capsys, how, suffix):
    lib = _cad_library(tmp_path, suffix)
    import shutil

    from haptic.geometry.io import DEFAULT_LIBRARY

    for name in ("BOX01", "WEDGE01"):  # native models declare metres: they stay as they are
        shutil.copy(DEFAULT_LIBRARY / f"{name}.json", lib)
    extra = ["--units", "mm"] if how == "--units" else []
    if how == "library.toml":
        (lib / "library.toml").write_text('units = "mm"\n')
    assert main(["explore", "--object", "cadbox", "--models", str(lib), "--seed", "2", *extra]) == 0
    captured = capsys.readouterr()
    assert "outcome     recognized: cadbox  [correct]" in captured.out and "warning" not in captured.err


def test_explore_warns_of_misread_units(tmp_path, capsys):
    lib = _cad_library(tmp_path)
    import shutil

    from haptic.geometry.io import DEFAULT_LIBRARY

    shutil.copy(DEFAULT_LIBRARY / "BOX01.json", lib)
    assert main(["explore", "--object", "BOX01", "--models", str(lib), "--verify", "none"]) == 0
    err = capsys.readouterr().err
    assert f"haptic: warning: {lib / 'cadbox.stl'}: 60000 mm across" in err and "--units mm" in err


def test_bench_keys_carry_the_units(tmp_path, capsys):
    lib = _cad_library(tmp_path)
    out = tmp_path / "r.jsonl"
    base = ["bench", "--models", str(lib), "--episodes", "1", "--policy", "planner", "--verify", "none",
            "--no-plot", "--out", str(out)]  # fmt: skip
    assert main([*base, "--units", "mm"]) == 0
    (lib / "library.toml").write_text('units = "mm"\n')
    assert main([*base, "--resume"]) == 0  # the same units by another way: the same episodes
    assert "running 0" in capsys.readouterr().out
    assert main([*base, "--resume", "--units", "cm"]) == 0  # other units: other episodes, beside
    assert "running 1" in capsys.readouterr().out
    from haptic.bench.results import read_results

    assert sorted(r["key"]["units"] for r in read_results(out)) == ["cm", "mm"]
