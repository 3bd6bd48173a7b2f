"""The move sources of the episode loop (haptic/episode/sources.py): each source's rule, their order, and a source
plugged into the loop; the loop's ending conditions and bookkeeping (haptic/episode/loop.py, state.py)."""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

import haptic.episode.sources as sources
from haptic.episode.loop import (
    ENDINGS,
    MAX_FAILED_MOVES,
    Ending,
    EpisodeObserver,
    drive,
    failed_in_a_row,
    loop_steps,
    out_of_budget,
    too_many_interpretations,
    verdict,
)
from haptic.episode.sources import (
    CheaperOpening,
    DecisionPoint,
    MoveSource,
    PolicyDecisions,
    ProbeOpening,
    RandomFallback,
    TracingOpening,
    VerificationMoves,
    decision_context,
    episode_sources,
)
from haptic.episode.spec import EpisodeSpec
from haptic.episode.state import EpisodeState
from haptic.episode.worlds import build_episode
from haptic.errors import PlanningError
from haptic.geometry.library_cache import cached_library
from haptic.matching.free_space import MAX_POSED as PROBES_MAX_POSED
from haptic.matching.recognition import AMBIGUOUS, EXPLORING, NO_MATCH, RECOGNIZED
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import EdgeMove, FaceMove, MoveResult, ProbeMove, SensorState
from haptic.planning.opening_probes import LibraryExtent
from haptic.planning.policies import Decision, PlannerPolicy

LIB = cached_library(None)
FACE = FaceMove(np.array([1.0, 0.0, 0.0]))
PROBE = ProbeMove(np.zeros(3), np.array([0.0, 0.0, -1.0]), 0.3)


class Counts:
    """A tree stand-in: only its count is read."""

    def __init__(self, count: int) -> None:
        self.count = count


def view(**kw):
    """A stand-in for :class:`EpisodeState` with what a source reads: unposed, no verification, nothing failed."""
    hyps = kw.pop("hyps", [])
    out = SimpleNamespace(
        posed=bool(hyps), verifying=False, sensor=SensorState(np.zeros(3), 0), components={}, config=PlannerConfig(),
        noise=None, tree=Counts(10), failed_here=[], probed=[], verifier=None, moves=0, cost=0.0,
    )  # fmt: skip
    for k, v in kw.items():
        setattr(out, k, v)
    out.hypotheses = lambda: list(hyps)
    out.avoid = (*out.failed_here, *out.probed)
    out.probe_failed_here = any(m.kind == "probe" for m in out.failed_here)
    return out


def started(model: str = "BOX01", seed: int = 3) -> EpisodeState:
    """The state of a geometric episode after its start (one face measured)."""
    ep = build_episode(EpisodeSpec(model, seed=seed), LIB)
    state = EpisodeState.begin(ep.library, ep.noise, ep.config, None)
    state.took(ep.executor.start())
    return state


def spy(monkeypatch, name: str, answer):
    """Replace ``sources.<name>`` by a function that keeps its calls and returns ``answer``."""
    calls = []

    def fn(*args, **kwargs):
        calls.append((args, kwargs))
        return answer

    monkeypatch.setattr(sources, name, fn)
    return calls


# ------------------------------------------------------------------------------------------------ verification
class Verifier:
    def __init__(self, move):
        self.move, self.calls = move, []

    def choose(self, h, state, components, avoid, probed):
        self.calls.append((h, avoid, probed))
        return self.move


def test_verification_proposes_the_verifiers_move_for_the_one_pose_class_only_while_verifying():
    v = Verifier(FACE)
    assert VerificationMoves().propose(view(verifier=v, hyps=["h"])) is None
    assert not v.calls
    failed = [EdgeMove(1)]
    assert VerificationMoves().propose(view(verifier=v, hyps=["h"], verifying=True, failed_here=failed)) is FACE
    assert v.calls == [("h", tuple(failed), [])]
    v.move = None  # no admissible verification move: the next source answers
    assert VerificationMoves().propose(view(verifier=v, hyps=["h"], verifying=True)) is None


# ------------------------------------------------------------------------------------------------ openings
def test_the_tracing_opening_asks_face_edge_vertex_in_turn_each_used_up_when_asked(monkeypatch):
    calls = spy(monkeypatch, "opening_move", None)
    rng = np.random.default_rng(0)
    src = TracingOpening(rng)
    failed = [FACE]
    for _ in range(4):
        assert src.propose(view(failed_here=failed)) is None
    assert [c[0][0] for c in calls] == ["face", "edge", "vertex"]
    assert all(c[0][4] is rng and c[0][5] == (FACE,) and c[0][6] == () for c in calls)


def test_the_tracing_opening_on_a_table_passes_the_pose_classes(monkeypatch):
    calls = spy(monkeypatch, "opening_move", FACE)
    table = PlannerConfig(table_z=0.0)
    assert TracingOpening(np.random.default_rng(0)).propose(view(config=table, hyps=["a", "b"])) is FACE
    assert calls[0][0][6] == ("a", "b")
    assert TracingOpening(np.random.default_rng(0)).propose(view(hyps=["a", "b"])) is FACE
    assert calls[1][0][6] == ()  # without a table the opening does not ask the hypotheses


def test_the_tracing_opening_of_a_real_start_is_a_random_face_move_drawn_from_the_policy_generator():
    state = started()
    a = TracingOpening(np.random.default_rng(7)).propose(state)
    b = TracingOpening(np.random.default_rng(7)).propose(state)
    assert isinstance(a, FaceMove) and np.array_equal(a.direction, b.direction)


def cheaper(tracing):
    return CheaperOpening(tracing, LibraryExtent.of(LIB.values()), np.random.default_rng(0))


def test_the_cheaper_opening_replans_the_tracing_opening_from_the_sensor_and_drops_it_for_a_probe(monkeypatch):
    calls = spy(monkeypatch, "cheaper_opening", PROBE)
    tracing = TracingOpening(np.random.default_rng(0), ("vertex",))
    on_edge = SensorState(np.zeros(3), 0, edge=1)
    monkeypatch.setattr(sources, "edge_run_of", lambda tree, edge: 0.02)
    assert cheaper(tracing).propose(view(sensor=on_edge)) is PROBE
    assert calls[0][0][0] == ["edge", "vertex"] and calls[0][0][7] == 0.02  # the remainder from an edge, its run
    assert tracing.remaining == []  # the probe measures the next face: no tracing move before it


def test_the_cheaper_opening_leaves_the_next_face_to_the_tracing_opening_when_a_probe_is_dearer(monkeypatch):
    spy(monkeypatch, "cheaper_opening", None)
    tracing = TracingOpening(np.random.default_rng(0), ())
    assert cheaper(tracing).propose(view()) is None
    assert tracing.remaining == ["face", "edge", "vertex"]


def test_the_cheaper_opening_ends_once_posed_and_proposes_no_probe_after_one_failed_from_here(monkeypatch):
    calls = spy(monkeypatch, "cheaper_opening", PROBE)
    tracing = TracingOpening(np.random.default_rng(0), ("edge",))
    assert cheaper(tracing).propose(view(hyps=["a"])) is None
    assert tracing.remaining == ["edge"]  # posed: the tracing opening runs on as planned
    assert cheaper(tracing).propose(view(failed_here=[PROBE])) is None
    assert tracing.remaining == ["face", "edge", "vertex"] and not calls


def probe_opening():
    return ProbeOpening(LibraryExtent.of(LIB.values()), np.random.default_rng(0))


def test_the_probe_opening_runs_until_posed_and_on_while_the_tree_is_too_large_to_test_hits_by_position(
    monkeypatch,
):
    calls = spy(monkeypatch, "opening_probe", PROBE)
    src = probe_opening()
    assert src.propose(view()) is PROBE
    assert calls[-1][1] == {"unmeasured": False}
    assert src.propose(view(hyps=["a", "b"], tree=Counts(PROBES_MAX_POSED))) is None
    assert src.propose(view(hyps=["a", "b"], tree=Counts(PROBES_MAX_POSED + 1))) is PROBE
    assert calls[-1][1] == {"unmeasured": True}  # toward the faces not measured yet
    assert src.propose(view(hyps=["a"], tree=Counts(PROBES_MAX_POSED + 1), verifying=True)) is None
    assert len(calls) == 2


def test_the_probe_opening_avoids_the_lines_probed_and_the_moves_failed_from_here(monkeypatch):
    calls = spy(monkeypatch, "opening_probe", None)
    other = replace(PROBE, start=np.ones(3))
    assert probe_opening().propose(view(failed_here=[FACE], probed=[other])) is None  # no line left
    assert calls[0][0][4] == (FACE, other)


# ------------------------------------------------------------------------------------------------ decisions
def test_the_policy_decides_with_two_or_more_pose_classes_and_no_verification():
    rng = np.random.default_rng(0)
    src = PolicyDecisions(rng)
    assert src.propose(view()) is None
    assert src.propose(view(hyps=["a"])) is None
    assert src.propose(view(hyps=["a", "b"], verifying=True)) is None
    point = src.propose(view(hyps=["a", "b"]))
    assert isinstance(point, DecisionPoint) and point.rng is rng
    assert list(point.context.hypotheses) == ["a", "b"]


def test_after_a_probe_failed_from_here_the_policies_decide_among_tracing_moves():
    all_moves = PlannerConfig(moves="all")
    assert decision_context(view(config=all_moves, failed_here=[PROBE])).config.moves == "tracing"
    assert decision_context(view(config=all_moves, failed_here=[FACE])).config.moves == "all"
    probing = PlannerConfig(moves="probing")  # probes are all there is: the rule does not apply
    assert decision_context(view(config=probing, failed_here=[PROBE])).config.moves == "probing"
    ctx = decision_context(view(failed_here=[FACE], probed=[PROBE]))
    assert ctx.avoid == (FACE, PROBE)


def test_the_random_fallback_always_proposes_a_decision_drawn_from_the_episode_generator():
    state = started()
    a = RandomFallback(np.random.default_rng(5)).propose(state)
    b = RandomFallback(np.random.default_rng(5)).propose(state)
    assert isinstance(a, Decision) and a.candidates == () and a.move.kind in ("face", "edge", "vertex")
    assert type(a.move) is type(b.move) and a.move.kind == b.move.kind


def test_the_random_fallback_raises_when_no_move_is_admissible():
    class Nothing:
        def choose(self, ctx, rng):
            raise PlanningError("no admissible move from the current sensor state")

    with pytest.raises(PlanningError):
        RandomFallback(np.random.default_rng(0), Nothing()).propose(view())


# ------------------------------------------------------------------------------------------------ order
def names(config):
    return [s.name for s in episode_sources(LIB, config, np.random.default_rng(0))]


def test_the_sources_and_their_order_follow_the_admissible_moves():
    tail = ["policy", "random fallback"]
    assert names(PlannerConfig(moves="tracing")) == ["verification", "tracing opening", *tail]
    assert names(PlannerConfig(moves="all")) == ["verification", "cheaper opening", "tracing opening", *tail]
    assert names(PlannerConfig(moves="all", table_z=0.0)) == ["verification", "tracing opening", *tail]
    assert names(PlannerConfig(moves="probing")) == ["verification", "probe opening", *tail]


def test_the_cheaper_opening_plans_the_tracing_opening_that_follows_it():
    srcs = episode_sources(LIB, PlannerConfig(moves="all"), np.random.default_rng(0))
    assert srcs[1].tracing is srcs[2]


# ------------------------------------------------------------------------------------------------ the loop
def steps(spec, sources=None, observer=None):
    ep = build_episode(spec, LIB)
    return loop_steps(spec, ep.library, ep.true_model, ep.world_from_model, ep.executor, ep.noise, ep.config,
                      ep.policy_rng, observer, sources=sources)  # fmt: skip


def planner(point):
    return PlannerPolicy().choose(point.context, point.rng)


def test_a_source_plugs_into_the_loop_and_hears_every_result():
    class EdgeFirst(MoveSource):
        """Edge moves while the sensor is on an edge; every result heard."""

        name = "edge first"

        def __init__(self):
            self.heard = []

        def propose(self, view):
            return EdgeMove(1) if view.sensor.edge is not None else None

        def on_result(self, view, move, result):
            self.heard.append((move.kind, result.ok, view.moves, view.sensor.edge is not None))

    spec = EpisodeSpec("BOX01", seed=2)
    first = EdgeFirst()
    rng = np.random.default_rng(0)
    record = drive(steps(spec, [first, RandomFallback(rng)]), planner)
    assert record.moves == len(first.heard) > 0
    assert [n for _, _, n, _ in first.heard] == list(range(1, record.moves + 1))
    assert [k for k, ok, _, _ in first.heard if ok] == record.move_kinds[1:]
    on_edge = [i for i, (*_, edge) in enumerate(first.heard[:-1]) if edge]
    assert on_edge and all(first.heard[i + 1][0] == "edge" for i in on_edge)  # the first source has the turn


def test_a_loop_without_a_source_that_proposes_ends_failed_naming_the_sources_asked():
    class Never(MoveSource):
        name = "never"

        def propose(self, view):
            return None

    record = drive(steps(EpisodeSpec("BOX01", seed=2), [Never()]), planner)
    assert record.outcome == "failed" and record.moves == 0
    assert record.detail == "no move: no move source proposed a move (asked: never)"


def test_an_error_of_the_driver_at_a_decision_point_ends_the_episode_as_failed():
    def refuse(point):
        raise PlanningError("the agent has no move")

    record = drive(steps(EpisodeSpec("LBLOCK01", seed=7, noise=0.5, verify="none", moves="tracing")), refuse)
    assert record.outcome == "failed" and record.detail == "no move: the agent has no move"
    assert record.moves >= 3 and record.decision_times_s == []  # the opening's moves, then the refusal


def test_decisions_are_timed_and_observed_for_the_policy_and_the_fallback_alone():
    seen = []
    obs = EpisodeObserver(on_decision=lambda n, d: seen.append((n, len(d.candidates) > 0)))
    record = drive(steps(EpisodeSpec("LBLOCK01", seed=7, noise=0.5), observer=obs), planner)
    assert len(seen) == len(record.decision_times_s) > 0
    assert record.moves >= len(seen) + 2  # the opening's moves are no decisions
    assert any(planned for _, planned in seen)


# ------------------------------------------------------------------------------------------------ endings
def ending_view(**kw):
    base = dict(failed_in_a_row=0, last_failure="", verifying=False, verifier=None, rec=None, cost=0.0, moves=0,
                tree=Counts(10))  # fmt: skip
    return SimpleNamespace(**{**base, **kw})


SPEC = EpisodeSpec("BOX01", seed=1, budget=100.0, max_moves=10)


def test_the_endings_are_checked_failed_in_a_row_first():
    assert ENDINGS[0] is failed_in_a_row
    assert failed_in_a_row(ending_view(failed_in_a_row=MAX_FAILED_MOVES - 1), SPEC) is None
    end = failed_in_a_row(ending_view(failed_in_a_row=MAX_FAILED_MOVES, last_failure="no-contact"), SPEC)
    assert end == Ending("failed", f"{MAX_FAILED_MOVES} failed moves in a row (last: no-contact)")
    # a verification is bounded by its own stall rule: failed moves in a row do not end it
    assert failed_in_a_row(ending_view(failed_in_a_row=MAX_FAILED_MOVES + 3, verifying=True), SPEC) is None


def test_the_verdict_ends_on_a_final_recognition_and_waits_for_the_verifier_when_verifying():
    for status in (RECOGNIZED, NO_MATCH):
        assert verdict(ending_view(rec=SimpleNamespace(status=status)), SPEC) == Ending(status)
    alike = (SimpleNamespace(name="A"), SimpleNamespace(name="B"))
    end = verdict(ending_view(rec=SimpleNamespace(status=AMBIGUOUS, classes=alike)), SPEC)
    assert end.outcome == AMBIGUOUS and "A, B" in end.detail
    assert verdict(ending_view(rec=SimpleNamespace(status=EXPLORING)), SPEC) is None

    class Verdicts:
        def __init__(self, says):
            self.says = says

        def verdict(self, tree, rec, cost):
            return self.says

        def outcome(self):
            return NO_MATCH

        def detail(self):
            return "verification: off"

    rec = SimpleNamespace(status=RECOGNIZED)
    assert verdict(ending_view(rec=rec, verifying=True, verifier=Verdicts("verifying")), SPEC) is None
    end = verdict(ending_view(rec=rec, verifying=True, verifier=Verdicts("rejected")), SPEC)
    assert end == Ending(NO_MATCH, "verification: off")


def test_the_budget_counts_cost_and_moves_but_not_verification_moves():
    assert out_of_budget(ending_view(cost=100.0, moves=9), SPEC) is None
    assert out_of_budget(ending_view(cost=100.5), SPEC) == Ending("budget")
    assert out_of_budget(ending_view(moves=10), SPEC) == Ending("budget")
    assert out_of_budget(ending_view(moves=12, verifier=SimpleNamespace(moves=3)), SPEC) is None


def test_too_many_interpretations_end_the_episode_naming_the_bound(monkeypatch):
    import haptic.episode.loop as loop

    monkeypatch.setattr(loop, "MAX_INTERPRETATIONS", 100)
    assert too_many_interpretations(ending_view(tree=Counts(100)), SPEC) is None
    end = too_many_interpretations(ending_view(tree=Counts(101)), SPEC)
    assert end == Ending("failed", "101 interpretations, more than the matcher holds (100)")


# ------------------------------------------------------------------------------------------------ bookkeeping
def test_a_failed_move_is_avoided_from_here_and_a_failed_probe_for_good():
    state = EpisodeState.begin(LIB, None, PlannerConfig(touch_evidence=False), None)
    state.failed(FACE, MoveResult(FACE, "no-contact", cost=1.5))
    state.failed(PROBE, MoveResult(PROBE, "unreachable", cost=2.0, state=SensorState(np.ones(3), 2)))
    assert state.avoid == (FACE, PROBE, PROBE) and state.probe_failed_here
    assert (state.failed_total, state.failed_in_a_row, state.last_failure) == (2, 2, "unreachable")
    assert state.cost == 3.5 and state.sensor.face == 2


def test_a_successful_move_clears_what_failed_from_here_and_books_the_traces():
    ep = build_episode(EpisodeSpec("BOX01", seed=3), LIB)
    state = EpisodeState.begin(ep.library, ep.noise, ep.config, None)
    state.failed(FACE, MoveResult(FACE, "no-contact", cost=1.0))
    start = ep.executor.start()
    state.took(start)
    assert state.failed_here == [] and state.failed_in_a_row == 0 and state.failed_total == 1
    assert len(state.kinds) == 1 and state.counts == [state.tree.count] and state.cum_cost == [state.cost]
    assert state.sensor is start.state and state.rec is not None


def test_an_ambiguous_ending_says_why(tmp_path):
    """Two library models that are one solid (WEDGE01 written twice under two names): the episode ends ambiguous
    between them, and its detail names both and says no move tells them apart (it said nothing)."""
    import shutil

    from haptic import EpisodeSpec as Spec
    from haptic import run_episode
    from haptic.geometry.io import DEFAULT_LIBRARY

    lib = tmp_path / "twins"
    lib.mkdir()
    for name in ("WEDGE01", "WEDGE02"):
        shutil.copy(DEFAULT_LIBRARY / "WEDGE01.json", lib / f"{name}.json")
    shutil.copy(DEFAULT_LIBRARY / "BOX01.json", lib / "BOX01.json")
    r = run_episode(Spec(model="WEDGE01", models=str(lib), seed=1))
    assert r.outcome == "ambiguous"
    assert "WEDGE01, WEDGE02" in r.detail and "no move tells them apart" in r.detail, r.detail
