"""The parts library of ``scripts/make_parts.py``: STL files a CAD tool would export, read back as the models drawn."""

import sys
from pathlib import Path

import numpy as np
import pytest

from haptic.geometry import load_library

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
import make_parts  # noqa: E402


def test_the_parts_read_back_as_their_outlines_extruded(tmp_path):
    assert make_parts.main([str(tmp_path / "parts")]) == 0
    lib = load_library(tmp_path / "parts")
    assert sorted(lib) == sorted(make_parts.PARTS)
    # V, E, F of an outline of n corners extruded: 2n, 3n, n + 2; convex where the outline is
    for name, (outline, depth, _) in make_parts.PARTS.items():
        m, n = lib[name], len(outline)
        assert (m.n_vertices, m.n_edges, m.n_faces) == (2 * n, 3 * n, n + 2), name
        xy = np.asarray(outline, float)
        size = sorted([*(xy.max(axis=0) - xy.min(axis=0)), depth])
        assert np.allclose(sorted(1000 * (m.vertices.max(axis=0) - m.vertices.min(axis=0))), size, atol=1e-6), name
    assert lib["part_box_60x40x30"].is_convex and lib["part_hexprism"].is_convex
    assert not any(lib[p].is_convex for p in ("part_lbracket", "part_tblock", "part_uchannel", "part_small_step"))


def test_a_directory_with_files_is_left_alone(tmp_path):
    (tmp_path / "keep.txt").write_text("mine")
    assert make_parts.main([str(tmp_path)]) == 1
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_an_outline_drawn_clockwise_is_refused():
    with pytest.raises(ValueError, match="counter-clockwise"):
        make_parts.ear_clip(np.array([[0, 0], [0, 1], [1, 1], [1, 0]], float))
