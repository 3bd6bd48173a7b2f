"""Units: ``--units``, a library's ``library.toml``, a file's own declaration, and the size warning.

A 60 x 40 x 30 mm CAD box written in millimetres (binary STL, PLY) loads at 60 mm when the units say so, and
otherwise loads at 60 m with a warning that names the file.
"""

import shutil

import numpy as np
import pytest
import trimesh

from haptic.errors import HapticError, ModelError
from haptic.geometry import load_library, load_model, resolve_model
from haptic.geometry.io import (
    DEFAULT_LIBRARY,
    LIBRARY_FILE,
    default_units,
    library_units,
    scan_library,
    size_warning,
)

CAD_MM = (60.0, 40.0, 30.0)
"""The box's extents in its file's numbers (millimetres)."""


def cad_box(folder, suffix: str, name: str = "cadbox"):
    """A 60 x 40 x 30 box written by trimesh in millimetre numbers, as ``suffix`` (binary STL or PLY)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}{suffix}"
    mesh = trimesh.creation.box(extents=CAD_MM)
    path.write_bytes(mesh.export(file_type=suffix[1:]))
    return path


def extents_mm(model):
    return tuple(np.round(np.ptp(model.vertices, axis=0) * 1e3, 6))


@pytest.mark.parametrize("suffix", [".stl", ".ply"])
def test_millimetre_mesh_loads_at_its_size_with_units(tmp_path, suffix):
    path = cad_box(tmp_path, suffix)
    if suffix == ".stl":
        assert path.read_bytes()[:5] != b"solid"  # binary STL
    assert sorted(extents_mm(load_model(path, units="mm"))) == sorted(CAD_MM)
    assert sorted(extents_mm(load_model(path, units="cm"))) == sorted(10 * x for x in CAD_MM)
    assert sorted(extents_mm(load_model(path))) == sorted(1000 * x for x in CAD_MM)  # metres: the default


@pytest.mark.parametrize("suffix", [".stl", ".ply"])
def test_size_warning_names_the_file_and_the_units(tmp_path, suffix):
    path = cad_box(tmp_path, suffix)
    text = size_warning(load_model(path))
    assert text is not None and text.startswith(str(path)) and "60000 mm across" in text
    assert "--units mm" in text
    assert size_warning(load_model(path, units="mm")) is None


def test_size_warning_for_a_model_too_small(tmp_path):
    path = cad_box(tmp_path, ".stl")
    (tmp_path / LIBRARY_FILE).write_text('units = "mm"\n')
    metres = tmp_path / "m"
    metres.mkdir()
    tiny = metres / "tiny.stl"
    tiny.write_bytes(trimesh.creation.box(extents=(0.06, 0.04, 0.03)).export(file_type="stl"))
    text = size_warning(load_model(tiny, units="mm"), "mm")
    assert text is not None and "0.06 mm across" in text and "smaller" in text and "--units m" in text
    assert size_warning(load_model(path)) is None  # library.toml read: 60 mm


def test_library_toml_declares_the_units_of_every_format(tmp_path):
    lib = tmp_path / "cad"
    cad_box(lib, ".stl", "boxstl")
    cad_box(lib, ".ply", "boxply")
    (lib / "boxobj.obj").write_text(trimesh.creation.box(extents=CAD_MM).export(file_type="obj"))
    (lib / LIBRARY_FILE).write_text('# the CAD export\nunits = "mm"\n')
    assert library_units(lib) == "mm" and default_units(lib) == "mm" and default_units(lib, "cm") == "cm"
    library = load_library(lib)
    assert set(library) == {"boxstl", "boxply", "boxobj"}
    for model in library.values():
        assert sorted(extents_mm(model)) == sorted(CAD_MM), model.name
    assert not scan_library(lib).size_warnings()
    # --units comes before library.toml
    for model in load_library(lib, units="cm").values():
        assert sorted(extents_mm(model)) == sorted(10 * x for x in CAD_MM)


def test_a_files_own_units_come_first(tmp_path):
    lib = tmp_path / "mixed"
    lib.mkdir()
    (lib / LIBRARY_FILE).write_text('units = "mm"\n')
    obj = trimesh.creation.box(extents=(6.0, 4.0, 3.0)).export(file_type="obj")
    (lib / "declared.obj").write_text("# units: cm\n" + obj)
    shutil.copy(DEFAULT_LIBRARY / "WEDGE01.json", lib)  # native: "units": "m"
    shipped = load_library()["WEDGE01"]
    for units in (None, "mm", "cm", "m"):
        library = load_library(lib, units=units)
        assert sorted(extents_mm(library["declared"])) == sorted(CAD_MM), units
        assert np.allclose(library["WEDGE01"].vertices, shipped.vertices), units


def test_native_model_without_units_follows_the_library(tmp_path):
    import json

    lib = tmp_path / "native"
    lib.mkdir()
    doc = json.loads((DEFAULT_LIBRARY / "WEDGE01.json").read_text())
    doc.pop("units")
    doc["vertices"] = (np.asarray(doc["vertices"]) * 1000).tolist()
    (lib / "wedge_mm.json").write_text(json.dumps(doc))
    assert size_warning(load_model(lib / "wedge_mm.json")) is not None
    (lib / LIBRARY_FILE).write_text('units = "mm"\n')
    model = load_model(lib / "wedge_mm.json")
    assert np.allclose(model.vertices, load_library()["WEDGE01"].vertices)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ('units = "inch"\n', ("'inch'", "'m', 'cm', 'mm'")),
        ("units = 3\n", ("3", "'mm'")),
        ('units = "mm\n', ("not valid TOML", 'units = "mm"')),
    ],
)
def test_bad_library_toml_is_refused_by_name(tmp_path, text, words):
    cad_box(tmp_path, ".stl")
    (tmp_path / LIBRARY_FILE).write_text(text)
    for load in (lambda: load_library(tmp_path), lambda: load_model(tmp_path / "cadbox.stl")):
        with pytest.raises(ModelError) as err:
            load()
        msg = str(err.value)
        assert str(tmp_path / LIBRARY_FILE) in msg and "\n" not in msg
        assert all(w in msg for w in words), msg


def test_unknown_units_argument_is_refused():
    with pytest.raises(HapticError, match="units='inch'.*valid: m, cm, mm"):
        load_library(units="inch")


def test_a_file_outside_the_library_is_read_in_the_given_units(tmp_path):
    path = cad_box(tmp_path, ".ply")
    assert sorted(extents_mm(resolve_model(str(path), load_library(), units="mm"))) == sorted(CAD_MM)


def test_changing_library_toml_loads_the_library_again(tmp_path):
    from haptic.geometry.library_cache import cached_library

    cad_box(tmp_path, ".stl")
    assert max(extents_mm(cached_library(tmp_path)["cadbox"])) == 60000
    (tmp_path / LIBRARY_FILE).write_text('units = "mm"\n')
    assert max(extents_mm(cached_library(tmp_path)["cadbox"])) == 60
    assert max(extents_mm(cached_library(tmp_path, units="cm")["cadbox"])) == 600
