"""The false recognition of the look-alike library's learning run, replayed: LA_NOTCH_30x20 10 % taller
is LA_BOX_100x80x66 with a slot 30 mm wide and 22 mm deep across its top. The slot leaves every vertex of the box
where the box has it, and the full verification asks for the vertices only (a polyhedron is fixed by its
vertices once its faces are the model's: ``haptic.matching.acceptance.TARGETS``); its 22 moves touched the top
face near its corners only, so the data fit the box. Catching it takes measuring a face between its vertices: with
probes admitted the full verification probes the middle of every reachable face once its vertices are measured
(``haptic.planning.verify.unmeasured_middles``)."""

import pytest

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import load_library, save_model
from haptic.geometry.perturb import scale_dimension

LOOKALIKE = "assets/libraries/lookalike"


@pytest.fixture(scope="module")
def slotted_box(tmp_path_factory):
    notch = load_library(LOOKALIKE)["LA_NOTCH_30x20"]
    path = tmp_path_factory.mktemp("objects") / "LA_NOTCH_30x20__dim2_1.10.json"
    save_model(scale_dimension(notch, 2, 1.10, name="LA_NOTCH_30x20__dim2_1.10"), path)
    return path


def test_every_vertex_of_the_box_is_one_of_the_slotted_box(slotted_box):
    """Why the vertices alone cannot tell them apart: the box's 8 vertices are among the object's 16."""
    import numpy as np

    from haptic.geometry import load_model

    box = load_library(LOOKALIKE)["LA_BOX_100x80x66"]
    obj = load_model(slotted_box)
    lo_b, lo_o = box.vertices.min(axis=0), obj.vertices.min(axis=0)
    for v in box.vertices - lo_b:
        assert np.linalg.norm(obj.vertices - lo_o - v, axis=1).min() < 1e-6


def test_the_slotted_box_is_not_taken_for_the_box(slotted_box):
    """Once every vertex is measured the full verification probes each reachable face's middle: the probe at the
    top's middle falls into the slot."""
    rec = run_episode(EpisodeSpec(model=str(slotted_box), seed=1556474545, noise=1.0, models=LOOKALIKE))
    assert rec.recognized != "LA_BOX_100x80x66", rec.verified
    assert rec.outcome == "no-match", (rec.outcome, rec.verified)
