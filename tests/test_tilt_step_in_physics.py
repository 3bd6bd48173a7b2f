"""On the hand, a link of the finger that met the edge above a face leaning under, the pad resting just below that
edge: the hand tilts away and the pad touches the face again a little farther in, where tilted it lands on the face
rather than on the edge's rim (``PhysicsSettings.tilt_step_in``)."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_a_trace_under_an_overhang_tilts_away_and_steps_in_rather_than_failing(tmp_path):
    # the truncated tetrahedron of assets/libraries/polyhedra at 80 mm, seed 1: a trace across a face leaning under
    # met the edge above it with the distal link; tilted 30° and 15° away, the pad touched the rim of that edge, not
    # the face, and the move failed ("trace across the face: the finger's index_distal met the object"). Tilted away
    # 6 mm farther in, the pad is on the face and the trace goes on.
    from haptic.episode.loop import EpisodeObserver
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import run_episode
    from haptic.geometry.io import load_library, save_model
    from haptic.geometry.perturb import scaled_to

    library = load_library(ROOT / "assets" / "libraries" / "polyhedra")
    models = tmp_path / "models_080mm"
    models.mkdir()
    for name in library:
        save_model(scaled_to(library[name], 0.08), models / f"{name}.json")
    moves = []
    obs = EpisodeObserver(on_move=lambda i, res, *a: moves.append(res), on_failed_move=lambda i, res: moves.append(res))
    rec = run_episode(EpisodeSpec(model="truncated_tetrahedron", seed=1, executor="physics", verify="full",
                                  models=str(models)), observer=obs)  # fmt: skip
    recoveries = [why for r in moves for why in r.info.get("recoveries", ())]
    assert any("farther in from it" in why for why in recoveries), recoveries
    assert not [r.reason for r in moves if not r.ok and "met the object" in (r.reason or "")]
    assert rec.outcome == "recognized" and rec.correct and rec.verified["status"] == "confirmed", rec.detail
