"""A resting probe on the simulated hand: with the arm and the index finger held where the last move left them, the
middle finger's joints alone close its pad along a line onto a face the hypotheses predict, press and stroke; the
face it measures lies within its bounds of the true face, and the exploring pad's state is unchanged."""

import numpy as np
import pytest

from haptic.episode.loop import EpisodeObserver
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import build_episode
from haptic.matching.components import DataFace
from haptic.planning.move_scores import Decision
from haptic.planning.registry import make_policy


class _TakeResting:
    """The planner, but a resting probe it offers is taken (the planner itself ranks them below other moves)."""

    name = "planner"

    def __init__(self) -> None:
        self.policy = make_policy("planner")

    def choose(self, ctx, rng):
        decision = self.policy.choose(ctx, rng)
        resting = [c for c in decision.candidates if getattr(c.move, "resting", False)]
        return Decision(resting[0].move, decision.candidates) if resting else decision


def _within_bounds(face: DataFace, ep) -> bool:
    poly, pose = ep.true_model, ep.world_from_model
    normals = pose.rotate(poly.face_normals)
    pts = np.atleast_2d(face.points)
    for f in range(poly.n_faces):
        if float(np.arccos(np.clip(normals[f] @ face.normal, -1.0, 1.0))) > face.normal_bound:
            continue
        p0 = pose.apply(poly.vertices[poly.faces[f][0]])
        if float(np.abs((pts - p0) @ normals[f]).mean()) <= face.position_bound:
            return True
    return False


@pytest.mark.slow
def test_the_middle_finger_measures_a_face_while_the_index_rests():
    """BOX01P at seed 3: after the landing and the first moves the planner offers resting probes by the middle
    finger (its reach test reaching two lines); taken, one touches the step's face and measures it."""
    ep = build_episode(EpisodeSpec(model="BOX01P", seed=3, executor="physics", verify="none", fingers=4))
    taken, before = [], []

    def keep(n, result, *rest) -> None:
        if getattr(result.move, "resting", False):
            taken.append((result, before[-1] if before else None))
        before.append(result.state)

    rec = ep.run(_TakeResting(), EpisodeObserver(on_move=keep, on_failed_move=keep))
    assert rec.outcome == "recognized" and rec.correct
    touched = [(r, s) for r, s in taken if r.ok and r.components]
    assert touched, [(str(r.status), r.reason) for r, _ in taken]
    result, state = touched[0]
    assert result.move.finger == "middle" and result.info["resting"]
    face = result.components[0]
    assert isinstance(face, DataFace) and _within_bounds(face, ep)
    assert result.free_space  # the closing's line up to the contact
    costs = ep.config.costs
    assert result.cost < costs.c_m + costs.c_q + costs.c_n + costs.c_s * 0.5  # no placement's fixed cost
    assert state is not None and result.state.face == state.face  # the exploring pad's state as it was
    assert np.allclose(result.state.position, state.position)
    assert rec.resting and rec.resting[0]["finger"] == "middle"
