"""Free-space probes in the episode loop (geometric executor): one planner ranks them with the tracing moves."""

import pytest

from haptic.cli import main
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.errors import HapticError
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import CostModel

CHEAP = PlannerConfig(costs=CostModel(c_p=0.5))


@pytest.mark.parametrize(("model", "seed"), [("BOX01", 1), ("LBLOCK01", 2), ("WEDGE01", 1)])
def test_cheap_probes_are_chosen_and_the_episode_recognises_correctly(model, seed):
    rec = run_episode(EpisodeSpec(model=model, seed=seed, moves="all", verify="none"), config=CHEAP)
    assert rec.outcome == "recognized" and rec.correct, rec
    assert rec.probes >= 1 and rec.move_kinds.count("probe") == rec.probes
    assert rec.move_set == "all" and 0 <= rec.probe_misses <= rec.probes


def test_tracing_admits_no_probes_whatever_they_cost():
    rec = run_episode(EpisodeSpec(model="BOX01", seed=1, verify="none", moves="tracing"), config=CHEAP)
    assert rec.correct and rec.probes == 0 and "probe" not in rec.move_kinds and rec.move_set == "tracing"


def test_random_policy_takes_probes_too():
    kinds = set()
    for seed in range(4):  # until an episode takes one
        spec = EpisodeSpec(model="BOX01", seed=seed, policy="random", moves="all", verify="none")
        rec = run_episode(spec, config=CHEAP)
        kinds |= set(rec.move_kinds)
        if "probe" in kinds:
            break
    assert "probe" in kinds


@pytest.mark.parametrize(
    ("fields", "words"),
    [
        ({"moves": "sometimes"}, ("sometimes", "tracing, probing, all")),
        ({"moves": "probing", "executor": "physics"}, ("geometric", "tracing, all")),
    ],
)
def test_move_sets_not_available_are_refused_by_name(fields, words):
    with pytest.raises(HapticError) as err:
        EpisodeSpec(model="BOX01", seed=0, **fields)
    assert all(w in str(err.value) for w in words)


def test_probes_are_admitted_on_the_simulated_hand():
    spec = EpisodeSpec(model="BOX01", seed=0, moves="all", executor="physics")
    assert spec.moves == "all"
    assert EpisodeSpec(model="BOX01", seed=0, moves="all", executor="physics", policy="optimal").moves == "all"


@pytest.mark.parametrize(("model", "seed"), [("BOX01", 1), ("WEDGE01", 1), ("LBLOCK01", 2), ("TETRA01L", 3)])
@pytest.mark.parametrize("policy", ["planner", "greedy", "random"])
def test_probes_alone_recognise_correctly(model, seed, policy):
    rec = run_episode(EpisodeSpec(model=model, seed=seed, policy=policy, moves="probing", verify="none"))
    assert rec.outcome == "recognized" and rec.correct, rec
    assert rec.move_set == "probing" and set(rec.move_kinds[1:]) == {"probe"}  # [0]: the start
    assert rec.probes == rec.moves and rec.probes >= 2


def test_probes_alone_on_the_look_alike_library():
    from haptic.geometry.library_cache import cached_library

    models = "assets/libraries/lookalike"
    lib = cached_library(models)
    for name in sorted(lib)[:2]:
        rec = run_episode(EpisodeSpec(model=name, seed=0, moves="probing", models=models, verify="none"), lib)
        assert rec.outcome == "recognized" and rec.correct, rec


def test_probes_alone_are_verified_with_the_tracing_moves():
    rec = run_episode(EpisodeSpec(model="WEDGE01", seed=1, moves="probing", verify="fast"))
    assert rec.correct and rec.verified["status"] == "confirmed"
    recognising = rec.move_kinds[1 : 1 + rec.moves - rec.verified["moves"]]
    assert recognising and set(recognising) == {"probe"}


def test_cli_explores_with_probes_alone(tmp_path, capsys):
    assert main(["explore", "--object", "WEDGE01", "--seed", "1", "--moves", "probing", "--verify", "none"]) == 0
    assert "probe" in capsys.readouterr().out


def test_bench_moves_at_a_small_size():
    """scripts/bench_moves.py at a small size: every setting recognises its draws correctly, tracing uses no
    probe, and the cheapest probes are used."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    try:
        from bench_moves import markdown, ratios, run
    finally:
        sys.path.pop(0)
    rows = run(episodes=6, seed=0, probe_costs=(0.5,))
    assert [r["setting"] for r in rows] == ["tracing", "probing, c_p 0.5", "all, c_p 0.5"]
    assert all(r["correct %"] == 100.0 for r in rows)
    assert rows[0]["probes"] == 0 and rows[2]["probes"] >= 1
    assert rows[1]["with a probe"] == 6 and rows[1]["probes"] >= 2 * 6
    assert markdown(rows).count("\n") == 4
    assert len(ratios(rows)) == 1 and "c_p 0.5" in ratios(rows)[0]


def test_a_failed_probe_is_not_tried_again_and_tracing_moves_follow_it():
    """An executor whose probes all fail (as the hand's do when it cannot get along a line): each line is tried
    once, and the move after a failed probe is a tracing move; the episode still recognises by tracing."""
    from haptic.episode.worlds import build_episode
    from haptic.planning.move_scores import same_move
    from haptic.planning.moves import MoveResult

    episode = build_episode(EpisodeSpec(model="BOX01", seed=1, moves="all", verify="none"), config=CHEAP)
    inner = episode.executor
    kinds, lines = [], []

    class FailingProbes:
        def start(self):
            return inner.start()

        def execute(self, move):
            kinds.append(move.kind)
            if move.kind == "probe":
                assert not any(same_move(move, m) for m in lines), "a failed line was offered again"
                lines.append(move)
                return MoveResult(move=move, status="unreachable", state=inner.state, reason="blocked")
            return inner.execute(move)

    episode.executor = FailingProbes()
    rec = episode.run()
    assert "probe" in kinds and rec.outcome == "recognized" and rec.correct
    after = [kinds[i + 1] for i, k in enumerate(kinds[:-1]) if k == "probe"]
    assert after and all(k != "probe" for k in after)


def test_an_episode_whose_tree_outgrows_the_bound_fails_instead_of_exhausting_memory(monkeypatch):
    """Probes alone on a look-alike box: the tree holds 1 800 interpretations after the third normal (before the
    opening went on toward unmeasured faces, hits on the same faces grew it to millions, and gigabytes). With a
    bound below that, the episode ends "failed", naming it, with the tree held below twice the bound plus one
    add."""
    import haptic.episode.loop as loop
    from haptic.geometry.library_cache import cached_library

    monkeypatch.setattr(loop, "MAX_INTERPRETATIONS", 1500)
    models = "assets/libraries/lookalike"
    spec = EpisodeSpec(model="LA_BOX_100x80x60", seed=299909236, models=models, verify="none", moves="probing")
    rec = run_episode(spec, cached_library(models), config=PlannerConfig(costs=CostModel(c_p=0.5)))
    assert rec.outcome == "failed" and "more than the matcher holds (1500)" in rec.detail
    assert 1500 < rec.interpretations[-1] and not rec.correct


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        ([], "all"),
        (["--executor", "physics"], "tracing"),
        (["--executor", "physics", "--moves", "all"], "all"),
        (["--moves", "tracing"], "tracing"),
    ],
)
def test_the_command_lines_default_move_set_is_all_and_tracing_on_the_hand(argv, expected, monkeypatch, capsys):
    """``explore`` without ``--moves``: every kind of move on the geometric executor, the tracing moves on the
    simulated hand (``default_moves``); an explicit ``--moves`` is taken as given."""
    import haptic.episode.worlds as worlds

    seen = []

    def fake(spec, library=None, observer=None, config=None, policy=None):
        seen.append(spec.moves)
        raise HapticError("stopped before the episode")

    monkeypatch.setattr(worlds, "run_episode", fake)
    assert main(["explore", "--object", "BOX01", *argv]) != 0
    assert seen == [expected]
    assert "stopped before the episode" in capsys.readouterr().err
