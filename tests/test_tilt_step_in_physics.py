"""On the hand, a link of the finger that met the object where the pad rests on a face leaning under: the hand tilts
away and, where tilted the pad lands on the rim of an edge rather than on the face, touches the face again a little
farther in (``PhysicsSettings.tilt_step_in``): away from the link's contact, then on along the slide."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def polyhedra_80mm(tmp_path_factory):
    from haptic.geometry.io import load_library, save_model
    from haptic.geometry.perturb import scaled_to

    library = load_library(ROOT / "assets" / "libraries" / "polyhedra")
    models = tmp_path_factory.mktemp("models_080mm")
    for name in library:
        save_model(scaled_to(library[name], 0.08), models / f"{name}.json")
    return models


@pytest.mark.slow
@pytest.mark.parametrize(("model", "recovered"), [
    # a trace across a face leaning under met the ridge above it with the distal link; tilted 30° and 15° away, the
    # pad touched the rim of that ridge, not the face, and the move failed ("trace across the face: the finger's
    # index_distal met the object"); tilted away 6 mm farther in from the link's contact, the pad is on the face
    ("truncated_tetrahedron", "farther in from it"),
    # the same on a lateral face of the prism leaning under, the link's contact beside the slide: tilted, farther in
    # from it, the pad touched the next lateral face's rim (twice the move failed so); 6 mm on along the slide it is
    # on the face
    ("elongated_pentagonal_bipyramid", "on along the slide"),
])  # fmt: skip
def test_a_trace_under_an_overhang_tilts_away_and_steps_in_rather_than_failing(polyhedra_80mm, model, recovered):
    from haptic.episode.loop import EpisodeObserver
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import run_episode

    moves = []
    obs = EpisodeObserver(on_move=lambda i, res, *a: moves.append(res), on_failed_move=lambda i, res: moves.append(res))
    rec = run_episode(EpisodeSpec(model=model, seed=1, executor="physics", verify="full", models=str(polyhedra_80mm)),
                      observer=obs)  # fmt: skip
    recoveries = [why for r in moves for why in r.info.get("recoveries", ())]
    assert any(recovered in why for why in recoveries), recoveries
    met = [r.reason for r in moves if not r.ok and r.reason.startswith("trace across the face") and "met" in r.reason]
    assert not met
    assert rec.outcome == "recognized" and rec.correct and rec.verified["status"] == "confirmed", rec.detail
