"""Models from any file: every corpus solid in every encoding imports with the V/E/F and symmetry order of its
formula, and so does any rigid motion of it rounded to 3–6 decimals in millimetres."""

import numpy as np
import pytest

from haptic.geometry import load_library, load_model, symmetry_group
from haptic.geometry.corpus import ENCODINGS, corpus_solids, obj_text
from haptic.geometry.io import text_quantum
from haptic.geometry.se3 import random_rotation
from haptic.geometry.tolerances import Tolerances, decimal_quantum


@pytest.mark.parametrize("encoding", ENCODINGS)
def test_every_corpus_file_imports_as_its_formula_says(corpus, encoding):
    manifest, dirs = corpus
    lib = load_library(dirs[encoding])
    wrong = []
    for s in manifest["solids"]:
        m = lib[s["name"]]
        got = (m.n_vertices, m.n_edges, m.n_faces, len(symmetry_group(m)))
        if got != (s["V"], s["E"], s["F"], s["symmetry"]):
            wrong.append((s["name"], got))
    assert not wrong, wrong
    assert len(lib) == len(manifest["solids"]) == 58


def test_corpus_families_and_precision(corpus):
    manifest, dirs = corpus
    assert {s["family"] for s in manifest["solids"]} == {
        "platonic", "prism", "antiprism", "bipyramid", "trapezohedron", "hull", "cad",
    }  # fmt: skip
    cube = {enc: load_model(next(d.glob("platonic_cube.*"))) for enc, d in dirs.items()}
    assert cube["obj6"].precision == pytest.approx(0.5e-6)
    assert cube["objmm3"].precision == pytest.approx(0.5e-6)  # 3 decimals of a millimetre
    assert 0 < cube["stl"].precision < 1e-8  # float32 at 5 cm


@pytest.mark.parametrize("decimals", [3, 4, 5, 6])
def test_rounded_rigid_motions_keep_counts_and_symmetry(tmp_path, decimals):
    """Property: a random rigid motion, then rounding to k decimals in millimetres, keeps V/E/F and the order of
    the rotation group, for every corpus solid."""
    rng = np.random.default_rng(100 + decimals)
    wrong = []
    for spec, poly in corpus_solids():
        v = poly.vertices @ random_rotation(rng).T + rng.uniform(-0.2, 0.2, size=3)
        path = tmp_path / f"{spec.name}.obj"
        path.write_text(obj_text(spec.name, v, poly.faces, decimals, units="mm"))
        m = load_model(path)
        got = (m.n_vertices, m.n_edges, m.n_faces, len(symmetry_group(m)))
        if got != (spec.V, spec.E, spec.F, spec.symmetry):
            wrong.append((spec.name, got))
    assert not wrong, wrong


def test_mirror_images_are_still_told_apart(corpus):
    _, dirs = corpus
    from haptic.geometry import are_congruent

    hull = load_model(dirs["obj6"] / "hull_03.obj")
    assert not are_congruent(hull, hull.mirrored())
    assert are_congruent(hull, load_model(dirs["stl"] / "hull_03.stl"))  # same solid, other encoding


def test_text_quantum_reads_the_written_precision():
    assert text_quantum(["0.052360", "-0.017321", "0.050000"]) == decimal_quantum(6)
    assert text_quantum(["52.360", "-17.321"]) == decimal_quantum(3)
    assert text_quantum(["5.23599e-02", "1.23457e-05"]) == decimal_quantum(7)  # the coarser of full-length ones
    assert text_quantum(["0", "1", "0.5", "0.25"]) == 0.0  # integers and round values are exact
    assert text_quantum(["0.0523598775598", "0.1"]) == decimal_quantum(13)


def test_tolerances_follow_size_and_precision():
    exact = Tolerances.for_model(0.05)
    assert exact == Tolerances()  # exact data of ordinary size: the floor
    rounded = Tolerances.for_model(0.05, decimal_quantum(6))
    assert rounded.planar > exact.planar and rounded.match > exact.match
    big = Tolerances.for_model(100.0)
    assert big.match == pytest.approx(1e-3) and big.merge > exact.merge
