"""``--fingers``: the setting, its defaults and checks, and episodes with placements of several fingertips."""

import json

import pytest

from haptic.bench.runner import episode_key, key_id
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.errors import HapticError


def test_the_fingers_default_to_the_executor_s_and_are_checked():
    assert EpisodeSpec(model="BOX01").fingers == 1
    assert EpisodeSpec(model="BOX01", executor="physics").fingers == 1
    assert EpisodeSpec(model="BOX01", fingers=4).fingers == 4
    with pytest.raises(HapticError, match="fingers=3 is not a number of fingers; valid: 1, 2, 4"):
        EpisodeSpec(model="BOX01", fingers=3)
    assert EpisodeSpec(model="BOX01", executor="physics", fingers=2).fingers == 2


def test_a_key_written_before_the_setting_reads_as_the_index_finger_alone():
    key = episode_key(EpisodeSpec(model="BOX01", seed=2))
    old = {k: v for k, v in key.items() if k != "fingers"}
    assert key_id(old) == key_id(key)
    assert key_id(episode_key(EpisodeSpec(model="BOX01", seed=2, fingers=2))) != key_id(key)


def test_an_episode_with_four_fingers_places_them_and_records_each_finger():
    """Tracing moves, no verification (where the planner takes placements on the seed library), a few seeds: the
    planner chooses placements, each finger's outcome is recorded, and the episodes are recognised correctly."""
    placed = []
    for seed in range(1, 7):
        rec = run_episode(EpisodeSpec(model="BOX01N", seed=seed, fingers=4, moves="tracing", verify="none"))
        assert rec.correct and rec.fingers == 4
        json.dumps(rec.to_json())
        placed += rec.placements
        assert rec.move_kinds.count("placement") == sum(p["status"] == "ok" for p in rec.placements)
    assert placed, "some placement was chosen"
    for p in placed:
        assert 2 <= len(p["fingers"]) <= 4
        assert {f["status"] for f in p["fingers"]} <= {"touched", "missed", "unreachable"}
        assert [f["finger"] for f in p["fingers"]] == ["index", "middle", "ring", "thumb"][: len(p["fingers"])]


def test_one_finger_makes_no_placement():
    rec = run_episode(EpisodeSpec(model="BOX01N", seed=1, moves="tracing", verify="none"))
    assert rec.fingers == 1 and rec.placements == [] and "placement" not in rec.move_kinds
