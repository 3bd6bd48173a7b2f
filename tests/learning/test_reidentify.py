"""Knowing a learned object again when the model it is a few millimetres from is in the library too: the tree,
which widens every data component by the learned model's bounds, keeps both; each model held to its own bounds
(the pose check and the acceptance test) tells them apart."""

import shutil

import numpy as np
import pytest

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import DEFAULT_LIBRARY, Polyhedron, model_files, save_model

# TETRA01L with its vertex 1 moved 2 mm
MOVED = Polyhedron.from_faces(
    np.array([[0.0, 0.0, 0.0], [0.101703543, -0.000799432, -0.000677384], [0.025, 0.08, 0.0], [0.035, 0.025, 0.07]]),
    [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]], name="TETRA01L_MOVED",
)  # fmt: skip
NAME = "learned_TETRA01L__v1_2mm"
"""The learned model's name as the bench names it (the library's order of names is the tree's)."""


def learned_library(root, model: Polyhedron, seed: int, name: str):
    """A copy of the shipped library with ``model`` learned into it as ``name`` (the learning episode of
    ``seed``), and the object's file."""
    lib = root / "lib"
    lib.mkdir()
    for f in model_files(DEFAULT_LIBRARY):
        shutil.copy2(f, lib / f.name)
    obj = root / f"{model.name}.json"
    save_model(model, obj)
    rec = run_episode(EpisodeSpec(model=str(obj), seed=seed, noise=1.0, learn=str(lib), learn_name=name))
    assert rec.learned["status"] == "closed"
    return lib, obj


@pytest.fixture(scope="module")
def learned(tmp_path_factory):
    """The library with the moved tetrahedron learned into it (one learning episode), and the object's file."""
    return learned_library(tmp_path_factory.mktemp("reid"), MOVED, 586626705, NAME)


@pytest.mark.parametrize("seed", [242172740, 206666331, 1039756388])
def test_the_learned_object_is_told_from_its_source(learned, seed):
    """Seeds that ran out of the episode's 40 moves with TETRA01L and the learned model both left."""
    lib, obj = learned
    rec = run_episode(EpisodeSpec(model=str(obj), seed=seed, noise=1.0, models=str(lib)))
    assert (rec.outcome, rec.recognized) == ("recognized", NAME)


def test_the_source_is_not_taken_for_the_learned_object(learned):
    lib, _ = learned
    for seed in range(1000, 1006):
        rec = run_episode(EpisodeSpec(model="TETRA01L", seed=seed, noise=1.0, models=str(lib)))
        assert rec.recognized != NAME


# WEDGE01 with an edge chamfered (4 mm legs)
CHAMFERED = Polyhedron.from_faces(
    np.array([[0.0, 0.0, 0.0], [0.0, 0.08, 0.0], [0.1, 0.08, 0.0], [0.0, 0.08, 0.06], [0.092225397, 0.0, 0.0],
              [0.0, 0.0, 0.055335238], [0.1, 0.004, 0.0], [0.0, 0.004, 0.06]]),
    [[0, 4, 5], [3, 2, 1], [1, 2, 6, 4, 0], [2, 3, 7, 6], [3, 1, 0, 5, 7], [5, 4, 6, 7]], name="WEDGE01_CHAMFERED",
)  # fmt: skip


def test_a_pose_the_data_leave_free_is_held_to_its_own_bounds_where_the_data_are(tmp_path):
    """Seed 1983564276, after three faces and an edge: the data leave the pose free along one direction, and the
    learned model's least-squares pose lay 0.5 m off along it. The pose check slides it back (from level with the
    measured points, not from where the least squares left it), and the acceptance test, which the slid pose (its
    largest residual least, not their sum) failed at 66 against 51, holds at the least-squares pose: the learned
    model's interpretation is kept, and the object recognised."""
    lib, obj = learned_library(tmp_path, CHAMFERED, 973879301, "L")
    again = run_episode(EpisodeSpec(model=str(obj), seed=1983564276, noise=1.0, models=str(lib)))
    assert (again.outcome, again.recognized) == ("recognized", "L")


# TETRA01R with its vertex 1 moved 2 mm
MOVED_R = Polyhedron.from_faces(
    np.array([[0.0, 0.0, 0.0], [-0.101703543, -0.000799432, -0.000677384], [-0.025, 0.08, 0.0], [-0.035, 0.025, 0.07]]),
    [[1, 2, 0], [3, 1, 0], [3, 2, 1], [3, 0, 2]], name="TETRA01R_MOVED",
)  # fmt: skip
NAME_R = "learned_TETRA01R__v1_2mm"


@pytest.fixture(scope="module")
def learned_r(tmp_path_factory):
    """The library with the moved mirrored tetrahedron learned into it (the bench's learning episode)."""
    return learned_library(tmp_path_factory.mktemp("reid_r"), MOVED_R, 1858836761, NAME_R)


def test_two_models_within_their_bounds_are_told_apart_by_how_well_each_fits(learned_r):
    """Seed 73510191 ran out of the episode's 40 moves with TETRA01R and the learned model both left from the
    second move on: TETRA01R passed its own pose check (largest residual 1.33 of its bounds) and acceptance test
    (255.7 against 268.7), the pose fitted to the data spreading the 2 mm over the whole. At the same bounds for
    both, its statistic is far the larger (127.9 against 100.9 after 40 moves): the data are far less likely under
    it, and it is dropped."""
    lib, obj = learned_r
    rec = run_episode(EpisodeSpec(model=str(obj), seed=73510191, noise=1.0, models=str(lib)))
    assert (rec.outcome, rec.recognized) == ("recognized", NAME_R)


def test_the_source_fits_better_than_the_learned_model_near_it(learned_r):
    lib, _ = learned_r
    for seed in range(2000, 2006):
        rec = run_episode(EpisodeSpec(model="TETRA01R", seed=seed, noise=1.0, models=str(lib)))
        assert rec.recognized != NAME_R


# FRAME01 with its vertex 2 moved 2 mm
FRAME_MOVED = Polyhedron.from_faces(
    np.array([[-0.06, -0.06, 0.0], [0.06, -0.06, 0.0], [0.060692031, 0.060692031, -0.001744187], [-0.06, 0.06, 0.0],
              [-0.06, -0.06, 0.03], [0.06, -0.06, 0.03], [0.06, 0.06, 0.03], [-0.06, 0.06, 0.03],
              [-0.03, -0.03, 0.007], [0.03, -0.03, 0.007], [0.03, 0.03, 0.007], [-0.03, 0.03, 0.007],
              [-0.03, -0.03, 0.023], [0.03, -0.03, 0.023], [0.03, 0.03, 0.023], [-0.03, 0.03, 0.023]]),
    [[0, 1, 5, 4], [9, 8, 12, 13], [4, 5, 13, 12], [1, 0, 8, 9], [1, 2, 6], [1, 6, 5], [10, 9, 13, 14], [5, 6, 14, 13],
     [10, 2, 1], [1, 9, 10], [6, 2, 3], [3, 7, 6], [11, 10, 14, 15], [6, 7, 15, 14], [3, 2, 10], [3, 10, 11],
     [3, 0, 4, 7], [8, 11, 15, 12], [7, 4, 12, 15], [0, 3, 11, 8]],
    name="FRAME01_MOVED",
)  # fmt: skip
NAME_F = "learned_FRAME01__v2_2mm"


def test_a_learned_edge_between_two_fitted_planes_is_bounded_by_both(tmp_path):
    """Seed 1347453898 ended no-match after 23 moves: the tree's face-edge angle test of a face of the learned
    frame's fold (0.56° off) and an edge where two fitted planes meet square (0.65° off), against a data edge at its
    bound (0.9°), turned the angle by 2.60°, beyond the data's and the learned model's declared bounds in quadrature
    (2.54°). An edge where two planes meet is turned by each plane's tilt: its bound is √2 normal bounds."""
    lib, obj = learned_library(tmp_path, FRAME_MOVED, 74845286, NAME_F)
    rec = run_episode(EpisodeSpec(model=str(obj), seed=1347453898, noise=1.0, models=str(lib)))
    assert (rec.outcome, rec.recognized) == ("recognized", NAME_F)


# PYR01 with its vertex 2 (a corner of the base) moved 2 mm
PYR_MOVED = Polyhedron.from_faces(
    np.array([[-0.05, -0.04, 0.0], [0.05, -0.04, 0.0], [0.051364781, 0.041456204, 0.000129776], [-0.05, 0.04, 0.0],
              [0.0, 0.0, 0.07]]),
    [[3, 2, 1], [3, 1, 0], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]], name="PYR01_MOVED",
)  # fmt: skip
NAME_P = "learned_PYR01__v2_2mm"


def test_two_poses_of_one_learned_model_are_each_held_to_its_bounds(tmp_path):
    """Seed 246192045 ran out of the episode's 40 moves with two poses of the learned pyramid left, a half turn
    apart (the pyramid it was learned from is symmetric under it): the tree, its angle tests widened by the learned
    model's bounds, kept both, and the own-bounds tests were made only with two models left. The pose half a turn
    off fails its acceptance test (434 against 287)."""
    lib, obj = learned_library(tmp_path, PYR_MOVED, 74845286, NAME_P)
    rec = run_episode(EpisodeSpec(model=str(obj), seed=246192045, noise=1.0, models=str(lib)))
    assert (rec.outcome, rec.recognized) == ("recognized", NAME_P)


# BOX01P with its vertex 0 moved 4 mm (into the box, along its diagonal)
BOX_MOVED = Polyhedron.from_faces(
    np.array([[-0.002309401, -0.002309401, -0.002309401], [0.1, 0.0, 0.0], [0.1, 0.0, 0.06], [0.065, 0.0, 0.06],
              [0.065, 0.0, 0.08], [0.035, 0.0, 0.08], [0.035, 0.0, 0.06], [0.0, 0.0, 0.06], [0.0, 0.08, 0.0],
              [0.1, 0.08, 0.0], [0.1, 0.08, 0.06], [0.065, 0.08, 0.06], [0.065, 0.08, 0.08], [0.035, 0.08, 0.08],
              [0.035, 0.08, 0.06], [0.0, 0.08, 0.06]]),
    [[7, 0, 1], [1, 2, 3, 4, 5, 6, 7], [15, 14, 13, 12, 11, 10, 9, 8], [1, 0, 8], [8, 9, 1], [9, 10, 2, 1],
     [10, 11, 3, 2], [11, 12, 4, 3], [12, 13, 5, 4], [13, 14, 6, 5], [14, 15, 7, 6], [8, 0, 7], [15, 8, 7]],
    name="BOX01P_MOVED",
)  # fmt: skip
NAME_B = "learned_BOX01P__v0_4mm"


def test_look_alikes_are_told_apart_where_they_disagree(tmp_path):
    """Seed 1546661490 ran out of the episode's 40 moves with BOX01P (two poses a half turn apart) and the learned
    model left from the 5th move, each within its own bounds: every move's predicted outcomes were alike in all of
    them, and the look-ahead went round four moves predicted to eliminate what they never did. The moved corner,
    never measured, is the one vertex where the models disagree by more than their bounds; the planner heads for it
    and the learned model is recognised."""
    lib, obj = learned_library(tmp_path, BOX_MOVED, 1618157078, NAME_B)
    rec = run_episode(EpisodeSpec(model=str(obj), seed=1546661490, noise=1.0, models=str(lib)))
    assert (rec.outcome, rec.recognized) == ("recognized", NAME_B)
