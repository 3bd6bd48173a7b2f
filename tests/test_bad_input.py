"""Bad model input found by trying the tool as a new user would: each gives one line on stderr and exit 1,
never a traceback; libraries load what they can."""

import json
import shutil
import subprocess
import sys

import pytest

from haptic.cli import main

TETRA = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\n"

# a cube (triangulated) with its corner (1, 1, 0)... pushed from the top through the bottom face
PUSHED_THROUGH = """v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0.5 0.5 -0.5
f 4 3 2
f 4 2 1
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
"""


def _one_line_error(capsys, args) -> str:
    rc = main(args)
    err = capsys.readouterr().err.strip()
    assert rc == 1, err
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err and "internal error" not in err, err
    return err


def _check(tmp_path, capsys, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    err = _one_line_error(capsys, ["models", "check", str(path)])
    assert name in err
    return err


def test_self_intersecting_surface_names_two_faces_that_cross(tmp_path, capsys):
    err = _check(tmp_path, capsys, "pushed.obj", PUSHED_THROUGH)
    assert "intersects itself" in err and "faces 0" in err and "cross" in err


def _l_block_with_a_crossed_face() -> str:
    """An L block (the library's LBLOCK01, in metres) with corner 0 moved 4 mm outward and cut off its three faces
    as triangles: the bottom's triangle (1, 0, 5) spans the L's notch, so the rest of the bottom, (5, 4, 3, 2, 1),
    crosses itself (its edge 1-5 runs through edge 4-3; 2-6 and 5-4 in the file's numbering), while every two
    faces meet only along edges."""
    xy = [(0, 0), (100, 0), (100, 35), (35, 35), (35, 80), (0, 80)]
    v = [(x / 1e3, y / 1e3, 0.0) for x, y in xy] + [(x / 1e3, y / 1e3, 0.05) for x, y in xy]
    v[0] = (-0.004 / 3**0.5,) * 3
    faces = [(1, 0, 5), (5, 4, 3, 2, 1), (6, 0, 1), (1, 7, 6), (5, 0, 6), (5, 6, 11), (6, 7, 8, 9, 10, 11),
             (1, 2, 8, 7), (2, 3, 9, 8), (3, 4, 10, 9), (4, 5, 11, 10)]
    return "".join(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in v) + "".join(
        "f " + " ".join(str(i + 1) for i in f) + "\n" for f in faces)


def test_a_face_whose_loop_crosses_itself_is_named(tmp_path, capsys):
    err = _check(tmp_path, capsys, "crossed.obj", _l_block_with_a_crossed_face())
    assert "face 1" in err and "crosses itself" in err and "2-6" in err and "5-4" in err, err  # the file's numbers


def test_obj_vertex_with_two_coordinates_names_the_line(tmp_path, capsys):
    err = _check(tmp_path, capsys, "short.obj", TETRA + "v 0 0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n")
    assert "line 5" in err and "needs x y z" in err


def test_json_face_index_that_is_not_an_integer(tmp_path, capsys):
    doc = {
        "vertices": [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]],
        "faces": [[0.5, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
    }
    err = _check(tmp_path, capsys, "half.json", json.dumps(doc))
    assert "0.5" in err and "not an integer" in err


def test_messages_name_the_files_own_vertex_numbers(tmp_path, capsys):
    # vertex 1 is unused and 6 repeats 2, so the solid's own numbering differs from the file's
    text = "v 5 5 5\n" + TETRA + "v 0 0 0\nf 6 4 3\nf 2 3 5\nf 3 4 5\n"  # the face 4 2 5 is missing
    err = _check(tmp_path, capsys, "open.obj", text)
    assert "open" in err
    edge = err.split("edge ")[1].split()[0]
    assert {int(x) for x in edge.split("-")} <= {2, 4, 5}, err  # an edge of the missing face, in file numbers


def test_obj_zero_length_edge_is_called_that(tmp_path, capsys):
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 1 1 0\nv 0 0 1\nf 1 2 3 4\nf 1 5 2\nf 2 5 3\nf 3 5 4\nf 4 5 1\n"
    err = _check(tmp_path, capsys, "zero.obj", text)
    assert "zero-length edge" in err and "vertices 3 and 4" in err and "line 6" in err
    assert "self-intersecting" not in err


def test_obj_face_naming_a_missing_vertex_names_the_line(tmp_path, capsys):
    err = _check(tmp_path, capsys, "far.obj", TETRA + "f 1 3 2\nf 1 2 9\nf 2 3 4\nf 3 1 4\n")
    assert "line 6" in err and "1..4" in err


@pytest.fixture
def mixed_library(tmp_path, corpus):
    """Three good corpus models and two bad files."""
    _, dirs = corpus
    lib = tmp_path / "lib"
    lib.mkdir()
    for name in ("prism_05", "platonic_cube", "hull_02"):
        shutil.copy(dirs["obj6"] / f"{name}.obj", lib)
    (lib / "short.obj").write_text(TETRA + "v 0 0\n")
    (lib / "pushed.obj").write_text(PUSHED_THROUGH)
    return lib


def test_models_list_lists_the_valid_and_names_every_bad_file(mixed_library, capsys):
    assert main(["models", "list", "--models", str(mixed_library)]) == 1
    out, err = capsys.readouterr()
    assert "prism_05" in out and "platonic_cube" in out and "3 models" in out
    lines = err.strip().splitlines()
    assert len(lines) == 2 and "pushed.obj" in lines[0] and "short.obj" in lines[1]


@pytest.mark.parametrize("command", ["explore", "bench"])
def test_explore_and_bench_refuse_a_library_with_bad_files_naming_all(mixed_library, tmp_path, capsys, command):
    args = ["--models", str(mixed_library), "--seed", "1"]
    args += (
        ["--object", "prism_05"] if command == "explore" else ["--episodes", "2", "--out", str(tmp_path / "r.jsonl")]
    )
    err = _one_line_error(capsys, [command, *args])
    assert "2 of 5 model files are invalid" in err and "pushed.obj" in err and "short.obj" in err
    assert "--skip-invalid" in err
    assert not (tmp_path / "r.jsonl").exists()


def test_skip_invalid_uses_the_valid_models(mixed_library, tmp_path, capsys):
    out_file = tmp_path / "r.jsonl"
    args = ["--models", str(mixed_library), "--seed", "3", "--skip-invalid", "--policy", "planner", "--verify", "none"]
    assert main(["bench", *args, "--episodes", "3", "--out", str(out_file), "--no-plot"]) == 0
    out, err = capsys.readouterr()
    assert err.count("skipped invalid model file") == 2
    records = [json.loads(line) for line in out_file.read_text().splitlines()]
    assert len(records) == 3 and all(r["correct"] for r in records)
    assert main(["explore", "--object", "hull_02", *args]) == 0
    assert "[correct]" in capsys.readouterr().out


@pytest.mark.parametrize("encoding", ["obj6", "stl"])
def test_explore_a_library_models_own_file_is_scored_by_congruence(corpus, capsys, encoding):
    _, dirs = corpus
    path = next(dirs[encoding].glob("antiprism_05.*"))
    assert main(["explore", "--object", str(path), "--models", str(dirs["obj6"]), "--seed", "2"]) == 0
    out = capsys.readouterr().out
    assert "recognized: antiprism_05  [correct]" in out


def test_models_list_and_show_on_a_large_mesh(tmp_path, capsys):
    import trimesh

    path = tmp_path / "ball.stl"
    trimesh.creation.icosphere(subdivisions=3, radius=0.05).export(path)  # 1280 triangles
    assert main(["models", "list", "--models", str(tmp_path)]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("ball "))
    assert row.split()[1:4] == ["642", "1920", "1280"] and row.split()[7] == "60"
    assert main(["models", "show", str(path)]) == 0
    assert "symmetry group: 60 proper rotations" in capsys.readouterr().out


def test_console_prints_no_traceback_for_bad_files(tmp_path):
    bad = tmp_path / "short.obj"
    bad.write_text(TETRA + "v 0 0\n")
    half = tmp_path / "half.json"
    half.write_text(json.dumps({"vertices": [[0, 0, 0]] * 4, "faces": [[0.5, 1, 2]] * 4}))
    r = subprocess.run(
        [sys.executable, "-m", "haptic.cli", "models", "check", str(bad), str(half)], capture_output=True, text=True
    )
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert len(lines) == 2 and "short.obj" in lines[0] and "half.json" in lines[1]  # one line per bad file
