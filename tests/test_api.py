"""The Python interface: ``from haptic import ...``, the command line's defaults, Python-speaking errors."""

import argparse
import json
import runpy
from dataclasses import fields
from pathlib import Path

import pytest

import haptic
from haptic.api import DEFAULT_POLICIES
from haptic.bench.runner import episode_key, key_id
from haptic.cli import build_parser, main
from haptic.episode.spec import EpisodeSpec
from haptic.errors import HapticError

EXAMPLE = Path(__file__).resolve().parents[1] / "scripts" / "api_example.py"
TIMINGS = ("wall_time_s", "decision_times_s")


def untimed(record: dict) -> dict:
    return {k: v for k, v in record.items() if k not in TIMINGS}


def test_the_interface_names_are_few_and_documented():
    from haptic import EpisodeSpec, load_library, run_episode, sweep  # noqa: F401

    for name in ("EpisodeSpec", "EpisodeRecord", "load_library", "run_episode", "sweep", "UnitsWarning"):
        assert name in haptic.__all__ and name in dir(haptic)
        assert getattr(haptic, name).__doc__, name
    with pytest.raises(AttributeError):
        haptic.no_such_name  # noqa: B018


def test_the_example_runs(capsys):
    runpy.run_path(str(EXAMPLE), run_name="__main__")
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("10 models: ")
    assert out[1].startswith("WEDGE01 seed 1: recognized WEDGE01 in 23 moves")
    assert len(out) == 2 + 4 and all(" moves" in line for line in out[2:])


def _parsed(*argv: str) -> argparse.Namespace:
    return build_parser().parse_args(list(argv))


@pytest.mark.parametrize("executor", ["geometric", "physics"])
def test_spec_defaults_are_the_command_lines(executor):
    args = _parsed("explore", "--object", "WEDGE01", "--executor", executor)
    spec = EpisodeSpec(model="WEDGE01", executor=executor)
    for name in ("seed", "policy", "noise", "max_moves", "verify", "units", "models", "skip_invalid"):
        assert getattr(args, name) == getattr(spec, name), name
    assert spec.moves == ("tracing" if executor == "physics" else "all")
    bench = _parsed("bench")
    assert bench.policy == ",".join(DEFAULT_POLICIES)
    assert (bench.seed, bench.verify, bench.max_moves, bench.executor) == (spec.seed, spec.verify, spec.max_moves,
                                                                          "geometric")  # fmt: skip


def test_python_and_command_line_give_the_same_record(tmp_path, capsys):
    out = tmp_path / "e.json"
    assert main(["explore", "--object", "WEDGE01", "--seed", "1", "--json", str(out)]) == 0
    from_cli = json.loads(out.read_text())
    from_python = haptic.run_episode(haptic.EpisodeSpec(model="WEDGE01", seed=1)).to_json()
    assert untimed(from_cli) == untimed(from_python)
    assert from_python["verify"] == "full" and from_python["move_set"] == "all" and from_python["moves"] == 23


@pytest.mark.parametrize(
    ("settings", "python_words", "cli_args", "cli_words"),
    [
        ({"verify": "fullish"}, ("verify='fullish'", "none, fast, full"), ["--verify", "fullish"],
         ("--verify", "fullish", "none")),
        ({"moves": "probing", "executor": "physics"}, ("moves='probing'", "executor='physics'", "tracing, all"),
         ["--moves", "probing", "--executor", "physics"], ("--moves probing", "--executor physics", "tracing, all")),
        ({"units": "inch"}, ("units='inch'", "mm"), ["--units", "inch"], ("--units", "inch", "mm")),
        ({"noise": 11.0}, ("noise=11.0", "0", "10"), ["--noise", "11"], ("--noise", "10")),
        ({"seed": -1}, ("seed=-1", ">= 0"), ["--seed", "-1"], ("--seed", "0")),
    ],
)  # fmt: skip
def test_errors_speak_python_in_python_and_options_on_the_command_line(
    capsys, settings, python_words, cli_args, cli_words
):
    with pytest.raises(HapticError) as err:
        EpisodeSpec(model="WEDGE01", **settings)
    assert all(w in str(err.value) for w in python_words), str(err.value)
    assert "--" not in str(err.value)
    assert main(["explore", "--object", "WEDGE01", *cli_args]) in (1, 2)
    msg = capsys.readouterr().err.strip()
    assert msg.startswith("haptic") and "error:" in msg and "\n" not in msg
    assert all(w in msg for w in cli_words), msg


def test_old_keys_read_as_the_settings_they_were_run_with():
    """Results written before verification, move sets and units were settings ran none, tracing, metres."""
    spec = EpisodeSpec(model="BOX01", seed=3, verify="none", moves="tracing")
    old = {k: v for k, v in episode_key(spec).items() if k not in ("verify", "moves", "units")}
    assert key_id(old) == key_id(episode_key(spec))
    assert key_id(old) != key_id(episode_key(EpisodeSpec(model="BOX01", seed=3)))  # today's defaults differ


def test_spec_round_trips_through_its_fields():
    from dataclasses import asdict

    for spec in (EpisodeSpec(model="BOX01"), EpisodeSpec(model="BOX01", executor="physics", units="mm")):
        assert EpisodeSpec(**asdict(spec)) == spec
    assert {f.name for f in fields(EpisodeSpec)} >= {"units", "verify", "moves"}


def test_sweep_gives_the_bench_records(tmp_path):
    out = tmp_path / "r.jsonl"
    assert main(["bench", "--episodes", "2", "--policy", "planner", "--seed", "4", "--verify", "none", "--no-plot",
                 "--out", str(out)]) == 0  # fmt: skip
    from haptic.bench.results import read_results

    from_cli = sorted((untimed(r) for r in read_results(out)), key=lambda r: key_id(r["key"]))
    from_python = haptic.sweep(episodes=2, policies=["planner"], seed=4, verify="none")
    assert sorted((untimed(r) for r in from_python), key=lambda r: key_id(r["key"])) == from_cli
    with pytest.raises(HapticError, match="policies=.*'oracle'.*valid: planner"):
        haptic.sweep(episodes=1, policies=["oracle"])
    with pytest.raises(TypeError, match="seeds"):
        haptic.sweep(episodes=1, seeds=3)


def test_load_library_warns_of_misread_units(tmp_path):
    import trimesh

    (tmp_path / "cad.stl").write_bytes(trimesh.creation.box(extents=(60, 40, 30)).export(file_type="stl"))
    with pytest.warns(haptic.UnitsWarning, match="cad.stl: 60000 mm across.*--units mm"):
        haptic.load_library(tmp_path)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert max(haptic.load_library(tmp_path, units="mm")["cad"].vertices.max(axis=0)) == pytest.approx(0.03)
