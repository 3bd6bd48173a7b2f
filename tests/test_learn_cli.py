"""``--learn DIR``: an object outside the library learned after no-match, written into a library, and known there
the next time; bad learning options answered with one line."""

import json
import shutil

import numpy as np
import pytest

from haptic.cli import main
from haptic.geometry import DEFAULT_LIBRARY, load_library, load_model, model_files, save_model, symmetry_group
from haptic.geometry.perturb import chamfer_edge


@pytest.fixture(scope="module")
def unknown(tmp_path_factory):
    """A tetrahedron of the library with its longest edge chamfered: a convex object the library does not hold."""
    tetra = load_library()["TETRA01L"]
    e = int(np.argmax(tetra.edge_lengths))
    path = tmp_path_factory.mktemp("objects") / "TETRA_CHAMFERED.json"
    save_model(chamfer_edge(tetra, e, 0.004, name="TETRA_CHAMFERED"), path)
    return path


@pytest.mark.slow
def test_explore_learns_an_unknown_object_and_knows_it_the_next_time(unknown, tmp_path, capsys):
    library = tmp_path / "library"
    library.mkdir()
    for f in model_files(DEFAULT_LIBRARY):
        shutil.copy2(f, library / f.name)
    record = tmp_path / "learn.json"
    code = main(["explore", "--object", str(unknown), "--seed", "2", "--learn", str(library), "--learn-name",
                 "CHAMFERED", "--json", str(record), "--quiet"])  # fmt: skip
    out = capsys.readouterr().out
    assert code == 0
    rec = json.loads(record.read_text())
    assert rec["outcome"] == "no-match"
    learned = rec["learned"]
    assert learned["status"] == "closed" and learned["name"] == "CHAMFERED"
    assert "learned     CHAMFERED (V 6, E 9, F 5" in out
    model = load_model(library / "CHAMFERED.json")
    truth = load_model(unknown)
    assert (model.n_vertices, model.n_edges, model.n_faces) == (truth.n_vertices, truth.n_edges, truth.n_faces)
    assert model.volume == pytest.approx(truth.volume, rel=0.02)
    assert model.learned_bounds is not None and model.learned_bounds.position > 0
    doc = json.loads((library / "CHAMFERED.json").read_text())
    prov = doc["provenance"]
    assert prov["executor"] == "geometric" and prov["episode"]["seed"] == 2 and prov["noise"] == 1
    assert prov["symmetry"] == len(symmetry_group(model))
    # the next episode, at another pose, against the library with the learned model in it
    code = main(["explore", "--object", str(unknown), "--seed", "7", "--models", str(library), "--quiet"])
    out = capsys.readouterr().out
    assert code == 0
    assert "outcome     recognized: CHAMFERED" in out


def one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


def test_learn_name_without_learn_is_refused(unknown, capsys):
    assert main(["explore", "--object", str(unknown), "--learn-name", "X"]) != 0
    assert "--learn DIR" in one_line_error(capsys)


def test_learn_into_a_file_is_refused(unknown, tmp_path, capsys):
    target = tmp_path / "file.json"
    target.write_text("{}")
    assert main(["explore", "--object", str(unknown), "--learn", str(target)]) != 0
    assert "library directory" in one_line_error(capsys)


def test_learn_name_taken_is_refused_before_the_episode(unknown, tmp_path, capsys):
    shutil.copy2(unknown, tmp_path / "TAKEN.json")
    assert main(["explore", "--object", str(unknown), "--learn", str(tmp_path), "--learn-name", "TAKEN"]) != 0
    err = one_line_error(capsys)
    assert "TAKEN" in err and "already" in err


@pytest.mark.slow
def test_bench_takes_learn(tmp_path, capsys):
    """Library objects are recognised: nothing to learn, and the records say so."""
    out = tmp_path / "bench.jsonl"
    assert main(["bench", "--episodes", "1", "--policy", "planner", "--learn", str(tmp_path / "lib"), "--out",
                 str(out), "--no-plot", "--verify", "none"]) == 0  # fmt: skip
    rec = json.loads(out.read_text().splitlines()[0])
    assert rec["learned"] is None and rec["key"]["learn"].endswith("lib")
