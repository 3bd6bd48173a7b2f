"""On the hand, a verification move across the other face of the edge the pad is on (``FaceMove.face``): the
features still to measure may lie on neither the current face nor any face a move across it reaches."""

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_a_small_steps_top_corner_is_reached_across_the_other_face_of_the_edge_below_it(tmp_path):
    # part_small_step of scripts/make_parts.py (30 mm long, its L-shaped top 20 mm above the table), seed 2: the pad
    # went round the edges of the side faces below the top's far corner, no move across a side face reaching it,
    # until the stall rule ended the verification (24 moves, "1 vertices ... not measured"). Across the top, the
    # other face of those edges, a move reaches the edge beside that corner and an edge move measures it; what is left
    # is out of every finger's reach, and the verification says so.
    from haptic.episode.loop import EpisodeObserver
    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import run_episode

    sys.path.insert(0, str(ROOT / "scripts"))
    import make_parts

    assert make_parts.main([str(tmp_path / "parts")]) == 0
    moves = []
    obs = EpisodeObserver(on_move=lambda i, res, *a: moves.append(res), on_failed_move=lambda i, res: moves.append(res))
    rec = run_episode(EpisodeSpec(model="part_small_step", seed=2, executor="physics", verify="full",
                                  models=str(tmp_path / "parts")), observer=obs)  # fmt: skip
    across = [r for r in moves if r.move.kind == "face" and r.move.face is not None]
    assert any(r.ok for r in across), [r.reason for r in across]
    assert rec.outcome == "ambiguous" and rec.verified["status"] == "incomplete" and "of part_small_step" in rec.detail
    assert "not measured" not in rec.detail and "out of the hand's reach" in rec.detail, rec.detail
    assert rec.moves <= 16
