"""Near-symmetries: rotations that map a model onto itself within touch's resolution but not within its file's
precision count as symmetries for recognition, so that a solid written from inexact coordinates is recognised."""

from __future__ import annotations

import numpy as np
import pytest

import haptic
from haptic.geometry import symmetry_group
from haptic.geometry.io import load_model
from haptic.matching.recognition import NEAR_SYMMETRY, model_symmetries, near_symmetries


def _prism_obj(path, x_mm: float, y_mm: float, z_mm: float = 30.0):
    """A box of ``x × y × z`` mm written as a 3-decimal millimetre OBJ (its precision 0.0005 mm)."""
    corners = [(sx * x_mm / 2, sy * y_mm / 2, sz * z_mm / 2) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    faces = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    lines = ["# units: mm", *(f"v {x:.3f} {y:.3f} {z:.3f}" for x, y, z in corners)]
    lines += [f"f {' '.join(map(str, f))}" for f in faces]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(
    ("y_mm", "exact", "near"),
    [
        (40.0, 8, 0),  # a square prism: every rotation exact
        (40.01, 4, 4),  # 5 µm off square: the four turns about the square's axis and diagonals are near
        (40.6, 4, 4),  # 0.42 mm off at every vertex: within NEAR_SYMMETRY, still near
        (41.0, 4, 0),  # 0.71 mm off at every vertex: a different solid to touch
    ],
)
def test_near_symmetries_are_the_rotations_within_touchs_resolution_not_the_files(tmp_path, y_mm, exact, near):
    m = load_model(_prism_obj(tmp_path / "p.obj", 40.0, y_mm))
    assert len(symmetry_group(m)) == exact
    found = near_symmetries(m)
    # every vertex carried within NEAR_SYMMETRY of a vertex, some farther than the file's precision
    for t in found:
        d = np.linalg.norm(t.apply(m.vertices)[:, None] - m.vertices[None], axis=2).min(axis=1)
        assert d.max() <= NEAR_SYMMETRY + 1e-12 and d.max() > m.tolerances.match
    assert len(found) == near
    assert len(model_symmetries(m)) == len(symmetry_group(m)) + len(found)


def test_a_nearly_square_prism_is_recognised_and_confirmed_not_explored_to_the_budget(tmp_path):
    """Two poses 90° apart place this prism within 5 µm of each other: no touch separates them. Taken as
    distinct pose classes, the planner spends the episode trying to (the move budget); as one, the prism is
    recognised, its pose right, and the verification confirms it."""
    lib = tmp_path / "lib"
    lib.mkdir()
    _prism_obj(lib / "NEARSQUARE.obj", 40.0, 40.01)
    _prism_obj(lib / "FLAT.obj", 60.0, 40.0, 12.0)
    for seed in (1, 2):
        r = haptic.run_episode(haptic.EpisodeSpec(model="NEARSQUARE", models=str(lib), seed=seed)).to_json()
        assert r["outcome"] == "recognized" and r["correct"], (seed, r["outcome"])
        assert r["verified"]["status"] == "confirmed"
