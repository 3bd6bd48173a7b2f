"""Generated libraries: deterministic, valid, distinct, written and loaded back like any library."""

import numpy as np
import pytest

from haptic.cli import main
from haptic.errors import ModelError
from haptic.geometry import are_congruent, load_library
from haptic.geometry.generate import family_counts, generate_library, write_library


def test_deterministic_and_of_every_family():
    a, b = generate_library(20, seed=7), generate_library(20, seed=7)
    assert [m.name for m in a] == [m.name for m in b]
    assert all(np.array_equal(x.vertices, y.vertices) and x.faces == y.faces for x, y in zip(a, b, strict=True))
    c = generate_library(20, seed=8)
    assert any(not np.array_equal(x.vertices, y.vertices) for x, y in zip(a, c, strict=True))
    counts = family_counts(1000)
    assert sum(counts.values()) == 1000 and min(counts.values()) > 0
    assert sum(family_counts(20).values()) == 20
    assert any(not m.is_convex for m in generate_library(40, seed=0))


def test_no_two_models_congruent():
    lib = generate_library(24, seed=2)
    for i, a in enumerate(lib):
        for b in lib[i + 1 :]:
            if a.n_faces == b.n_faces and a.n_edges == b.n_edges:
                assert not are_congruent(a, b), (a.name, b.name)


def test_written_library_loads_back(tmp_path):
    out = tmp_path / "lib"
    lib = write_library(generate_library(6, seed=1), out)
    assert sorted(lib) == sorted(p.stem for p in out.iterdir()) and len(lib) == 6
    assert load_library(out).keys() == lib.keys()
    with pytest.raises(ModelError, match="not empty"):
        write_library(generate_library(2, seed=1), out)
    assert len(list(out.iterdir())) == 6  # nothing lost
    assert [p.name for p in tmp_path.iterdir()] == ["lib"]  # no temporary directory left


def test_cli_generate(tmp_path, capsys):
    assert main(["models", "generate", "--count", "5", "--seed", "3", "--out", str(tmp_path / "g")]) == 0
    assert "5 models" in capsys.readouterr().out and len(list((tmp_path / "g").iterdir())) == 5
    assert main(["models", "generate", "--count", "0", "--out", str(tmp_path / "h")]) == 1
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--count" in err and not (tmp_path / "h").exists()
