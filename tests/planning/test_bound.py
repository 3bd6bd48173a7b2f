"""The bound on the hypotheses a policy scores against."""

import pytest

from haptic.geometry import load_library
from haptic.planning.bound import reduce_hypotheses
from haptic.planning.hypothesis import Hypothesis

LIB = load_library()


def _hyps(per_model: dict[str, int]) -> list[Hypothesis]:
    out = []
    for name, n in per_model.items():
        out += [Hypothesis(name, LIB[name], None, {}, {}, {}, leaves=(i,)) for i in range(n)]
    return out


def test_no_reduction_within_the_bound():
    h = _hyps({"BOX01": 3, "WEDGE01": 2})
    assert reduce_hypotheses(h, 5) == h and reduce_hypotheses(h, None) == h


def test_models_taken_in_turns():
    h = _hyps({"BOX01": 10, "WEDGE01": 1, "PYR01": 3})
    kept = reduce_hypotheses(h, 6)
    names = [k.model for k in kept]
    assert len(kept) == 6 and set(names) == {"BOX01", "WEDGE01", "PYR01"}
    assert names.count("BOX01") == 3 and names.count("PYR01") == 2  # turns: B W P, B P, B
    assert [k.leaves for k in kept if k.model == "BOX01"] == [(0,), (1,), (2,)]
    assert kept == [x for x in h if x in kept]  # original order kept


def test_more_models_than_the_bound_keeps_one_class_of_evenly_spaced_models():
    h = _hyps({name: 2 for name in sorted(LIB)})
    kept = reduce_hypotheses(h, 4)
    assert len(kept) == 4 and len({k.model for k in kept}) == 4
    assert kept[0].model == sorted(LIB)[0] and kept[-1].model == sorted(LIB)[-1]
    with pytest.raises(ValueError):
        reduce_hypotheses(h, 0)
