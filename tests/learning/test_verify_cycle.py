"""A verification that goes back and forth: re-identifying a learned object, the verification's tour, priced with
probes that no line reaches from where the sensor is, or estimated from where a face move ends, kept face moves
over one edge the cheapest; each measured nothing, and the verification stalled (`ambiguous`). Priced by
tracing when no probe is offered, and without the ways already travelled for nothing, it goes on to the vertex
it lacks."""

import pytest

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import load_library
from haptic.geometry.perturb import scale_dimension
from tests.learning.test_reidentify import learned_library


@pytest.mark.parametrize(("base", "axis", "factor", "learn_seed", "seed"), [
    ("BOX01P", 0, 1.05, 184123696, 2036727714),   # round three faces at a corner, the vertex missing 10 cm away
    ("FRAME01", 1, 0.97, 1016164991, 345201683),  # across one edge and back, beside a vertex missing
])  # fmt: skip
def test_a_verification_that_went_back_and_forth_goes_on_to_what_it_lacks(base, axis, factor, learn_seed, seed,
                                                                          tmp_path):
    """The bench's learning and re-identification episodes (seeds) that ended `ambiguous`."""
    poly = scale_dimension(load_library()[base], axis, factor, name=f"{base}__dim{axis}_{factor:.2f}")
    lib, obj = learned_library(tmp_path, poly, learn_seed, f"learned_{poly.name}")
    rec = run_episode(EpisodeSpec(model=str(obj), seed=seed, noise=1.0, models=str(lib)))
    assert rec.recognized == f"learned_{poly.name}", (rec.outcome, rec.detail)

