"""Scoring an episode's outcome against the truth (evaluation only: the loop never reads what is here)."""

from __future__ import annotations

import numpy as np

from haptic.episode.spec import EpisodeSpec
from haptic.geometry import SE3, Polyhedron, library_twin
from haptic.matching.pose import pose_error
from haptic.matching.recognition import NO_MATCH, RECOGNIZED, Recognition, model_symmetries

CORRECT_POSE_MM, CORRECT_POSE_DEG = 5.0, 5.0
"""A recognition is correct when the model is right and the pose within these of the truth."""


def score_outcome(
    spec: EpisodeSpec,
    library: dict[str, Polyhedron],
    true_model: Polyhedron,
    world_from_model: SE3,
    outcome: str,
    rec: Recognition | None,
) -> tuple[float | None, float | None, bool]:
    """Whether the episode's outcome is right, and the recognised pose's error: ``(mm, deg, correct)``. A
    recognition is correct when the model is the object (by name, or for a file by congruence with a library
    model) at a pose within :data:`CORRECT_POSE_MM` and :data:`CORRECT_POSE_DEG`; a no-match when the object is
    in no library model. Evaluation only: it reads the true model and pose."""
    recognized = rec.model if rec is not None and outcome == RECOGNIZED else None
    err_mm = err_deg = None
    in_library = spec.model in library
    # the library model the object is (evaluation only): by name, or for a file by congruence with one
    twin = (spec.model, SE3.identity()) if in_library else library_twin(true_model, library)
    correct = False
    if outcome == RECOGNIZED and rec.world_from_model is not None:
        if twin is not None and recognized == twin[0]:
            # the library model's pose in the world: the object's pose after the map of the model onto it
            model = library[twin[0]]
            truth = world_from_model @ twin[1]
            err_m, err_rad = pose_error(rec.world_from_model, truth, model, model_symmetries(model))
            err_mm, err_deg = err_m * 1e3, float(np.degrees(err_rad))
            correct = err_mm < CORRECT_POSE_MM and err_deg < CORRECT_POSE_DEG
    elif outcome == NO_MATCH:
        correct = twin is None
    return err_mm, err_deg, bool(correct)
