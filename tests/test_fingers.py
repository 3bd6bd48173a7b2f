"""``--fingers``: the setting, its defaults and checks, and episodes with placements of several fingertips."""

import pytest

from haptic.bench.runner import episode_key, key_id
from haptic.episode.spec import EpisodeSpec
from haptic.errors import HapticError


def test_the_fingers_default_to_the_executor_s_and_are_checked():
    assert EpisodeSpec(model="BOX01").fingers == 1
    assert EpisodeSpec(model="BOX01", executor="physics").fingers == 1
    assert EpisodeSpec(model="BOX01", fingers=4).fingers == 4
    with pytest.raises(HapticError, match="fingers=3 is not a number of fingers; valid: 1, 2, 4"):
        EpisodeSpec(model="BOX01", fingers=3)
    with pytest.raises(HapticError, match="geometric executor only"):
        EpisodeSpec(model="BOX01", executor="physics", fingers=2)


def test_a_key_written_before_the_setting_reads_as_the_index_finger_alone():
    key = episode_key(EpisodeSpec(model="BOX01", seed=2))
    old = {k: v for k, v in key.items() if k != "fingers"}
    assert key_id(old) == key_id(key)
    assert key_id(episode_key(EpisodeSpec(model="BOX01", seed=2, fingers=2))) != key_id(key)
