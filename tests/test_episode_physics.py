"""A short end-to-end physics episode: the simulated hand recognises a seed object correctly, with the
perception errors scored from outside the executor."""

import math
import shutil

import numpy as np
import pytest

from haptic.episode.loop import EpisodeObserver
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import build_episode, run_episode


def _watched(spec: EpisodeSpec):
    """Run the episode of ``spec``: the episode, its record, every move's recoveries and the failed moves' reasons."""
    said, failed = [], []
    obs = EpisodeObserver(on_move=lambda n, r, *a: said.extend(r.info.get("recoveries", ())),
                          on_failed_move=lambda n, r: failed.append(r.reason))  # fmt: skip
    ep = build_episode(spec)
    return ep, ep.run(None, obs), said, failed


def test_a_physics_episode_recognises_the_pyramid():
    rec = run_episode(EpisodeSpec(model="PYR01", seed=1, executor="physics", verify="none"))
    assert rec.outcome == "recognized", rec.detail
    assert rec.recognized == "PYR01" and rec.correct
    assert rec.pose_error_mm < 1.0 and rec.pose_error_deg < 1.0
    assert rec.sim_time_s > 0 and rec.wall_time_s < 60
    p = rec.perception
    for key in ("face_normal_deg", "edge_direction_deg", "edge_position_mm", "vertex_position_mm"):
        assert math.isfinite(p[key]["median"]) and p[key]["median"] < 1.0, (key, p[key])
    assert p["spurious"] == 0


def test_the_planner_counts_on_less_undercut_than_the_pad_reaches():
    # the pad's roll stops at max_undercut (35°); the planner's reach model counts on reach_undercut, a margin
    # short of it (31°): HEXPRISM01 lying on a side has faces leaning under 30° at any pose, which the planner
    # then offers, and a face leaning under 33° at a pose known to a degree is not promised
    from haptic.executor.touch_config import TouchConfig

    touch = TouchConfig()
    ep = build_episode(EpisodeSpec(model="HEXPRISM01", seed=2, executor="physics"))
    assert ep.config.max_undercut == touch.reach_undercut < touch.max_undercut
    assert math.radians(30.0) < ep.config.max_undercut < math.radians(33.0) < touch.max_undercut


def test_a_face_measured_with_the_hand_tilted_is_touched_again_tilted():
    # FRAME01 seeds 1 and 2 stand on an end, the hole's axis horizontal: the pad reaches the hole's walls only with
    # the hand tilted away from the rim above (a link of the finger meets it upright). Turned upright in the hole
    # after such a move, the finger jammed against the rim, and every later touch of the wall ran away; now the hand
    # backs out along the finger's axis before it turns upright, and touches such a face again tilted as it was
    # measured. The components stay within their bounds. (Seed 1: at seed 2 the verification no longer enters the
    # hole, whose corners it names out of reach, and no face measured tilted is touched again.)
    said = []
    obs = EpisodeObserver(on_move=lambda n, r, *a: said.extend(r.info.get("recoveries", ())))
    ep = build_episode(EpisodeSpec(model="FRAME01", seed=1, executor="physics", verify="full"))
    ep.run(None, obs)
    assert any("touched again with the hand tilted" in x for x in said), said
    assert _within_bounds(ep)


def test_a_face_move_sliding_down_to_the_table_goes_on_level_to_an_edge():
    # BOX01 seed 3 stands 60 mm tall on a side. The planner's face moves from a top corner diagonally down a side face
    # (heading 34 degrees below level) came within the pad's reach of the table some 7 mm short of the far upright
    # edge: 4 of 28 moves failed, "the finger would meet the table before an edge". The slide now goes on across the
    # face nearly level, toward the side it was heading, to the edge there, and measures it; the planner predicts
    # that edge (planning.table.level_leg).
    ep, rec, said, failed = _watched(EpisodeSpec(model="BOX01", seed=3, executor="physics", verify="full"))
    assert any("the slide went on level" in x for x in said), said
    assert not [x for x in failed if "table before an edge" in x], failed
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert _within_bounds(ep)


def test_touches_past_an_unreachable_edge_tell_the_box_family_apart():
    # BOX01P resting tilted: the moves that separate it from BOX01 and BOX01N all end stepping onto a face
    # leaning under the pad; their touches on the way still rule the look-alikes out
    rec = run_episode(EpisodeSpec(model="BOX01P", seed=2, executor="physics", verify="none"))
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert rec.failed_moves >= 1


def test_a_slot_against_the_table_shows_as_an_edge_on_the_side():
    # BOX01N resting with its slot against the table: from the side face, the pad rolls over the slot's edge
    # but cannot reach the slot's ceiling; the edge alone tells BOX01N from BOX01
    edge_only = []
    obs = EpisodeObserver(on_move=lambda n, r, count, rec: edge_only.append(r.info.get("next_face") is not None))
    rec = run_episode(EpisodeSpec(model="BOX01N", seed=3, executor="physics", verify="none"), observer=obs)
    assert rec.outcome == "recognized" and rec.correct, (rec.outcome, rec.detail)
    assert any(edge_only)


def test_touched_points_lie_on_the_true_surface():
    # the evidence the episode checks pose classes against: every touched point on a face of the object that
    # faces the way the sensed normal does
    from haptic.episode.perception import touched_points
    from haptic.planning.config import PlannerConfig
    from haptic.planning.reach import touch_distance
    from haptic.sim.scene import TABLE_TOP_Z

    seen, truth = [], {}
    cfg = PlannerConfig(table_z=TABLE_TOP_Z)
    obs = EpisodeObserver(
        on_start=lambda model, pose: truth.update(model=model, pose=pose),
        on_move=lambda n, r, count, rec: seen.append(touched_points(r, cfg)),
        on_failed_move=lambda n, r: seen.append(touched_points(r, cfg)),
    )
    run_episode(EpisodeSpec(model="BOX01N", seed=1, executor="physics", max_moves=12, verify="none"), observer=obs)
    pts, nrm = np.concatenate([p for p, _ in seen]), np.concatenate([n for _, n in seen])
    assert len(pts) > 100
    d = touch_distance(truth["model"], truth["pose"], pts, nrm)
    assert d.max() < cfg.touch_tol, d.max()


def test_faces_beside_a_seam_of_the_simulated_pieces_read_true():
    # BOX01P is simulated as convex pieces; at this pose the first two faces are traced next to seams between
    # coplanar pieces, whose edges touch the pad too (noiseless, the normals read 1.5° off before patches)
    rec = run_episode(EpisodeSpec(model="BOX01P", seed=22, executor="physics", noise=0.0, verify="none"))
    assert rec.outcome == "recognized" and rec.correct, rec.outcome
    assert rec.perception["face_normal_deg"]["max"] < 0.3, rec.perception["face_normal_deg"]


def test_a_pad_lifted_off_a_valley_reports_no_vertex():
    # FRAME01 standing on its side: following a concave valley of its sloped faces down toward the hole, the
    # finger's distal link meets the frame's rim and lifts the pad off the valley with the normal still across
    # it; that is no vertex (the surface did not fall away), and the library object is not rejected. (The
    # planner no longer offers that move -- the valley's end at the hole is a concave end the hand cannot tell --
    # so an edge lost here, if any, must still be no vertex.)
    lost = []

    def on_failed(n, r) -> None:
        if r.move.kind == "edge" and r.reason.endswith("lost"):
            lost.append(r)

    spec = EpisodeSpec(model="FRAME01", seed=1, executor="physics", verify="full", budget=40.0)
    rec = run_episode(spec, observer=EpisodeObserver(on_failed_move=on_failed))
    assert rec.outcome != "no-match", rec.detail
    assert rec.perception["spurious"] == 0
    assert all(r.status == "no-contact" for r in lost)


def _scaled_library(directory, extent: float, corpus: bool = False) -> str:
    """The seed library (or the formula corpus) with every model scaled to ``extent`` [m] across
    (``scripts/perception_report.py --sizes``, ``--corpus``), written to ``directory``."""
    from haptic.geometry import load_library
    from haptic.geometry.corpus import corpus_solids
    from haptic.geometry.io import save_model
    from haptic.geometry.perturb import scaled_to

    models = {s.name: p for s, p in corpus_solids()} if corpus else load_library()
    for name, poly in models.items():
        save_model(scaled_to(poly, extent, name), directory / f"{name}.json")
    return str(directory)


def _replay(directory, model: str, extent: float, max_moves: int, corpus: bool = False, seed: int = 1):
    """The first ``max_moves`` moves of the default episode of ``model`` at ``seed`` in the library scaled to
    ``extent``: the episode, its failed moves and every move's result."""
    failed, results = [], []
    obs = EpisodeObserver(on_move=lambda n, r, *a: results.append(r),
                          on_failed_move=lambda n, r: (failed.append(r), results.append(r)))  # fmt: skip
    spec = EpisodeSpec(model=model, seed=seed, executor="physics", models=_scaled_library(directory, extent, corpus),
                       max_moves=max_moves)  # fmt: skip
    ep = build_episode(spec)
    ep.run(None, obs)
    return ep, failed, results


def _within_bounds(ep) -> bool:
    from haptic.episode.evaluate import bound_ratios

    return max(r.ratio for r in bound_ratios(ep.executor.components, ep.true_model, ep.world_from_model)) <= 1.0


def test_an_edge_move_stopped_by_the_table_reports_no_vertex(tmp_path):
    # BOX01P 40 mm across, seed 1 (perception_report.py --sizes 40): two edge moves ran down an edge until the
    # pad met the table; each reported a "vertex" where the edge line meets the table plane. The second edge
    # ends 8 mm above the table and that vertex lay 14 mm past it (5.9 bounds), and the episode ended no-match.
    # Stopped by the table the move reports nothing: the edge may end above the table or at a chamfer.
    from haptic.sim.scene import TABLE_TOP_Z

    # The planner now counts such a move refused (tests/planning/test_edge_ends.py): whether or not one is made,
    # no vertex lies on the table plane and every component is within its bounds.
    ep, failed, _ = _replay(tmp_path, "BOX01P", 0.04, 11)
    vertices = [c for c in ep.executor.components if c.kind == "vertex"]
    assert vertices and all(v.position[2] > TABLE_TOP_Z + 0.002 for v in vertices)
    assert _within_bounds(ep)


def test_a_concave_edge_whose_end_the_pad_rolls_past_reports_no_vertex(tmp_path, monkeypatch):
    # FRAME01 40 mm across, seed 1: an edge move along a concave edge of the hole ran to its end, where the
    # faces' corners are obtuse: the pad's contacts rolled on along the rims and the vertex was put at their
    # median, 3.6 mm past the true end (2.7 bounds; the edge's extent 1.2 bounds), and the episode ended
    # no-match. The surface falling away does not locate a concave edge's end: the move reports nothing.
    # The planner counts a move toward such an end refused on the hand (tests/planning/test_edge_ends.py) where
    # its hypotheses agree; since no move starts at a vertex where a concave edge ends, the replay's first moves
    # differ and, the hypotheses not agreeing yet, two edge moves run along a concave edge of the hole to its
    # open ends: each reports nothing. Those moves were the verification's, toward the hole's corners, which it now
    # names out of reach up front (only such valleys lead to them): the replay counts them in reach as it did, for
    # the hand to meet such an end.
    import haptic.planning.verify as verify

    monkeypatch.setattr(verify, "_end_located", lambda *args: True)
    ep, failed, _ = _replay(tmp_path, "FRAME01", 0.04, 5)
    edges = ep.executor.segmenter.edges
    along_concave = [r for r in failed if r.move.kind == "edge" and not edges[r.state.edge].convex]
    assert all(not r.components for r in along_concave)  # some fail before the end: the table, a retouch
    assert any("could not locate the vertex" in r.reason for r in along_concave)
    assert _within_bounds(ep)


def test_a_face_move_that_rolls_round_a_vertex_reports_no_edge(tmp_path, monkeypatch):
    # bipyramid_06 of the formula corpus at 60 mm across, seed 1 when found (perception_report.py --corpus
    # --sizes 60; the seed has changed with the trajectories since: steady rows, the undercut limits, the
    # verification's aim at a vertex): a face
    # move rolled round the apex onto a face sharing no edge with the first; the "edge" reported between them
    # (n_a × n_b through the apex) lay 36 mm off every true edge (48 bounds) and the episode ended no-match.
    # The rolling normals leaned along that line more than the noise allows: no edge is reported (the move
    # then crosses again inside the edge, or fails). The verification on the hand now leaves such a move out
    # unless nothing else is left (it meets its edge at a glancing angle, verify.GRAZING): the replay asks it as
    # recorded, the rule switched off, to see what the hand does with it.
    import haptic.planning.verify as verify

    monkeypatch.setattr(verify, "_grazing", lambda *args: False)
    ep, failed, results = _replay(tmp_path, "bipyramid_06", 0.06, 11, corpus=True, seed=1)
    said = [r.reason for r in failed] + [x for r in results for x in (r.info or {}).get("recoveries", ())]
    assert any("more than the noise allows" in x for x in said), said
    assert _within_bounds(ep)


def test_a_verification_face_move_round_a_vertex_along_the_arc_reports_no_edge(tmp_path, monkeypatch):
    # antiprism_04 of the formula corpus at 150 mm, seed 1 (perception_report.py --corpus --sizes 150): a
    # verification face move rolled round a vertex onto a face sharing only that vertex with the first, its normals
    # following the arc between the faces' closely (their median lean 0.84°, under the noise's 1.74°); the "edge"
    # reported was 45 bounds off every true edge and the episode ended no-match. The rolling normals still leaned
    # 0.55° to one side on average (true edges: at most 0.34° over 30 rolls): no edge between the faces. (Since the
    # segmentation picks a face's rows about its own normal and a square crossing follows the ridge first, this
    # episode's rolls round the vertex lean more than the noise allows at once, not only on average: either is told.)
    # The verification on the hand now leaves such a move out unless nothing else is left (it meets its edge at a
    # glancing angle, verify.GRAZING): the replay asks it as recorded, the rule switched off.
    import haptic.planning.verify as verify

    monkeypatch.setattr(verify, "_grazing", lambda *args: False)
    ep, failed, _ = _replay(tmp_path, "antiprism_04", 0.15, 6, corpus=True, seed=1)
    assert any("(a roll round a vertex)" in r.reason for r in failed), [r.reason for r in failed]
    assert _within_bounds(ep)


def test_a_face_move_round_a_vertex_onto_a_narrow_face_follows_the_ridge_first(tmp_path):
    # bipyramid_07 of the formula corpus at 60 mm, seed 1 (perception_report.py --corpus --sizes 60): a face move
    # rolled round the apex onto a face sharing only it, the crossing square to the line between the faces: the
    # normals' mean leaned 0.43° (true edges up to 0.34°, the test's limit 0.52°) and the "edge" reported was 33
    # bounds off every true edge (no-match). The stroke on the next face met an edge along both of its legs (the
    # face is a wedge at the apex): the move follows the ridge each way before it reports the edge, and there is none.
    # (Since a face move crossing square to the edge follows the ridge too, this episode's moves differ: its rolls
    # round a vertex are told by their normals or by the ridge. A vertex move whose circle rolls round the apex now
    # crosses again clear of it: the roll told shows among its recoveries.)
    failed, recovered = [], []
    obs = EpisodeObserver(on_move=lambda n, r, *a: recovered.extend(r.info.get("recoveries", ())),
                          on_failed_move=lambda n, r: failed.append(r.reason))  # fmt: skip
    spec = EpisodeSpec(model="bipyramid_07", seed=1, executor="physics",
                       models=_scaled_library(tmp_path, 0.06, corpus=True))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None, obs)
    told = ("no edge along the roll's axis", "acquiring the ridge", "more than the noise allows")
    assert any(x in w for w in failed + recovered for x in told), (failed, recovered)
    assert rec.outcome != "no-match", rec.detail
    assert _within_bounds(ep)


def test_a_face_move_crossing_square_round_a_vertex_follows_the_ridge_first(tmp_path):
    # antiprism_07 of the formula corpus at 60 mm, seed 3, --verify none (perception_report.py --corpus --sizes 60
    # --first-seed 3): the start landed on a triangle and the first face move headed into its apex, rolled round it
    # onto a heptagon sharing only the apex, 12° off square to the line between the faces: the normals' mean lean
    # 0.1°, the next face wide there (no leg of the stroke blocked). The "edge" reported lay 25.7 bounds off every
    # true edge and the object was recognised as hull_01. A face move crossing within 25° of square follows the
    # ridge before it reports the edge: there is none, and the move fails -- or crosses again along the edge, from a
    # point of the face it touched where the start beside the first crossing lies off the triangle, and reports the
    # edge it meets there.
    said = []
    obs = EpisodeObserver(on_move=lambda n, r, *a: said.extend((r.info or {}).get("recoveries", ())),
                          on_failed_move=lambda n, r: said.append(r.reason))  # fmt: skip
    spec = EpisodeSpec(model="antiprism_07", seed=3, executor="physics", verify="none",
                       models=_scaled_library(tmp_path, 0.06, corpus=True))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None, obs)
    assert any("acquiring the ridge" in w or "no edge along the roll's axis" in w for w in said), said
    assert rec.outcome != "recognized" or rec.correct, rec.recognized
    assert _within_bounds(ep)


def test_a_stroke_riding_the_rims_of_a_small_face_measures_no_face(tmp_path):
    # bipyramid_10 of the formula corpus at 30 mm, seed 3, --verify none (perception_report.py --corpus --sizes 30
    # --first-seed 3): a face move's stroke on a triangle 9 mm across kept every contact within 1.5 mm of its edges;
    # the rows holding one normal were those of the step in, the pad pressing in place 4° off the face, and the face
    # fitted from them lay 2.8 bounds off (no-match without verification). Steady rows spanning less than a face's
    # least extent measure no face: the move touches the next face afresh, or fails.
    spec = EpisodeSpec(model="bipyramid_10", seed=3, executor="physics", verify="none",
                       models=_scaled_library(tmp_path, 0.03, corpus=True))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None)
    assert rec.outcome != "no-match" and (rec.outcome != "recognized" or rec.correct), rec.detail
    assert _within_bounds(ep)


def test_an_edge_move_that_sets_off_past_the_edges_other_end_reports_no_vertex(tmp_path):
    # BOX01N at 60 mm, seed 2, --verify none (perception_report.py --sizes 60 --first-seed 2): an edge move along +e
    # returned next to the edge 23 mm behind its explored interval, past the edge's other end, and located that end's
    # vertex 0.2 mm behind its start; reported as the end it ran toward, the interval collapsed onto it and the edge's
    # two ends were one vertex: every component within its bounds, the true object pruned (no-match). A vertex
    # behind the move's start is not the end it ran toward: the move fails. Since the moves merged after it, a later
    # edge move returned next to an edge known over 1 mm at a contact 25 mm past that interval, beyond the slot that
    # breaks the collinear top edge, followed the edge on the slot's far side to its vertex, and the interval was
    # extended across the slot (edge extent 7.2 bounds; no-match): an edge move returns next to its edge within the
    # explored interval, to its ends' bound.
    spec = EpisodeSpec(model="BOX01N", seed=2, executor="physics", verify="none",
                       models=_scaled_library(tmp_path, 0.06))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None)
    edges = [c for c in ep.executor.components if c.kind == "edge"]
    assert all(e.start_vertex is None or e.start_vertex != e.end_vertex for e in edges)
    assert rec.outcome != "no-match", rec.detail
    assert _within_bounds(ep)


def test_an_edge_move_that_goes_on_round_a_shallow_vertex_reports_no_vertex(tmp_path):
    # prism_12 of the formula corpus at 60 mm (seed 1 when found; seed 2 shows it since the moves recover): an
    # edge move along a cap edge of the 12-gon went on round its end, where the next cap edge turns by only 30°,
    # and the vertex was put at the contacts there, 1.7 mm past the end (1.4 bounds). Those contacts lay 1.1 mm
    # off the edge's line (those of a pad rolling on a vertex 0.2-0.3 mm): the move reports nothing.
    # Since the strokes leave the edge they met and the crossings keep 6 mm from vertices, no edge move of seeds
    # 1-5 goes round that end; whatever the replay's moves, no component lies outside its bounds.
    ep, failed, _ = _replay(tmp_path, "prism_12", 0.06, 25, corpus=True, seed=2)
    assert all("off the edge's line" in r.reason for r in failed if r.move.kind == "edge" and "locate" in r.reason)
    assert _within_bounds(ep)


def test_a_vertex_move_whose_circle_meets_an_edge_of_another_vertex_reports_no_edge(tmp_path):
    # trapezohedron_12 of the formula corpus at 60 mm, seed 1 when found (2 since the verification aims a pad's
    # radius from a vertex: the trajectories differ): circling a vertex across a kite narrower than the
    # circle, the pad met an edge that does not leave that vertex; the edge was reported adjacent to it (within
    # its geometric bounds, but a wrong adjacency) and the tree pruned the truth: no-match. The edge's line
    # passes far from the vertex circled: the move reports nothing.
    from haptic.episode.evaluate import score_components

    ep, failed, results = _replay(tmp_path, "trapezohedron_12", 0.06, 8, corpus=True, seed=2)
    assert any(r.move.kind == "vertex" and "leaves another vertex" in r.reason for r in failed)
    assert score_components(ep.executor.components, ep.true_model, ep.world_from_model, results).missed == 0


def test_a_vertex_move_whose_circle_meets_an_edge_near_the_vertex_circled_reports_no_edge(tmp_path, monkeypatch):
    # trapezohedron_10 of the formula corpus at 30 mm, seed 2 (perception_report.py --corpus --sizes 30 --first-seed
    # 2): circling a vertex across a kite whose edge from it is 4.2 mm long, inside the 8 mm circle, the pad met the
    # kite's next edge, which leaves another vertex and passes 1.9 mm from the one circled. The vertex's and the
    # line's bounds added up (1.2 + 0.75 mm) let it through although each was 0.15 mm off: the edge was reported
    # adjacent to the vertex and the tree pruned the truth (no-match after 7 moves). Independent estimates, their
    # bounds add in quadrature (1.4 mm): the move reports nothing. The verification on the hand no longer asks a
    # circle that leaves its face through such an edge (verify._circle_leaves_corner): the replay asks it as
    # recorded, the rule switched off, to see what the hand does with it.
    import haptic.planning.verify as verify
    from haptic.episode.evaluate import score_components

    monkeypatch.setattr(verify, "_circle_leaves_corner", lambda *args: False)
    failed, results = [], []
    obs = EpisodeObserver(on_move=lambda n, r, *a: results.append(r),
                          on_failed_move=lambda n, r: (failed.append(r), results.append(r)))  # fmt: skip
    spec = EpisodeSpec(model="trapezohedron_10", seed=2, executor="physics", max_moves=9,
                       models=_scaled_library(tmp_path, 0.03, corpus=True))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None, obs)
    assert rec.outcome != "no-match", rec.detail
    assert any(r.move.kind == "vertex" and "leaves another vertex" in r.reason for r in failed)
    assert score_components(ep.executor.components, ep.true_model, ep.world_from_model, results).missed == 0
    assert _within_bounds(ep)


def test_an_edge_move_blocked_after_spanning_a_slot_reports_no_vertex(tmp_path):
    # BOX01N at 30 mm, seed 1, --verify none (perception_report.py --sizes 30 --verify none): an edge move ran down
    # the end face's edge to the 9 mm slot, which the 12 mm pad spans: touching both sides at once, its sensed contact
    # (the two patches' mean) lay on the edge's line, 1.0 mm inside the pad, until the slot's far side blocked it. The
    # vertex was put there and the edge's interval extended across the slot (edge extent 3.2 bounds, no-match). A
    # block after contacts inside the pad locates no vertex.
    spec = EpisodeSpec(model="BOX01N", seed=1, executor="physics", verify="none",
                       models=_scaled_library(tmp_path, 0.03))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None)
    assert rec.outcome != "no-match", rec.detail
    assert _within_bounds(ep)


class _Enough(Exception):
    """Ends a replay after the move that showed what it tests."""


def _until_recovery(ep, kind: str | None, says: str, fails: str | None = None) -> tuple[list, list]:
    """Run ``ep`` until a ``kind`` move (any kind where None) recovers saying ``says``, or a ``kind`` move fails with
    ``fails`` in its reason: the recoveries said and the reasons of those failures (the episode may end first)."""
    said, failed = [], []

    def moved(n, r, *a) -> None:
        if kind is None or r.move.kind == kind:
            said.extend(x for x in (r.info or {}).get("recoveries", ()) if says in x)
        if said:
            raise _Enough

    def not_moved(n, r) -> None:
        if fails is not None and (kind is None or r.move.kind == kind) and fails in r.reason:
            failed.append(r.reason)
            raise _Enough

    try:
        ep.run(None, EpisodeObserver(on_move=moved, on_failed_move=not_moved))
    except _Enough:
        pass
    return said, failed


@pytest.mark.xfail(strict=False, reason=(
    "with the crossings, strokes and verification rules merged after it, the replay's moves differ and no edge move "
    "of its first 60 sets off past its vertex (every component stays within its bounds); the case is shown by "
    "test_an_edge_move_that_set_off_past_its_end_sets_off_again_inside_the_edge"))
def test_an_edge_move_that_never_rides_the_ridge_locates_no_vertex(tmp_path):
    # trapezohedron_09 of the formula corpus at 60 mm, seed 1 (perception_report.py --corpus --sizes 60 --first-seed
    # 1): during the verification a vertex move's circle crossed an edge 2 mm from its far end, and the edge move
    # after it acquired the "ridge" 4.4 mm past that end, on the faces beyond: its tip went 0.4 mm along the edge
    # while the contacts slid back to 1.3 mm past the vertex, and the vertex was put there, 1.28 mm off (1.05
    # bounds). Refusing every vertex without a contact on the ridge before it sent WEDGE01 at 30 mm (seed 1) into a
    # no-match; acquired ahead of the vertex it locates by more than a vertex's bound, the move reports nothing (and
    # WEDGE01 at 30 mm stays recognised). Such a move now sets off again from the middle of the edge's explored
    # interval (and says so) instead of failing, and the moves before it differ: it comes later. The vertex located past
    # where the pad set off is still never reported. The replay stops after that move.
    said = "where the pad acquired the ridge"

    def shows(r) -> bool:
        return r.move is not None and r.move.kind == "edge" and (
            said in r.reason or any(said in w for w in r.info.get("recoveries", ())))

    moves = []

    def on_move(n, r, *a):
        moves.append(r)
        if shows(r) or len(moves) > 25:
            raise _Enough

    spec = EpisodeSpec(model="trapezohedron_09", seed=1, executor="physics",
                       models=_scaled_library(tmp_path, 0.06, corpus=True))  # fmt: skip
    ep = build_episode(spec)
    with pytest.raises(_Enough):
        ep.run(None, EpisodeObserver(on_move=on_move, on_failed_move=lambda n, r: on_move(n, r)))
    assert any(shows(r) for r in moves)
    assert _within_bounds(ep)


def test_face_moves_out_of_a_concave_corner_leave_it(tmp_path):
    # BOX01N seed 2 stands on an end with its slot upright, 30 mm wide for the 24 mm pad. Verifying it, face moves
    # started from the slot's concave edges, traced from the corner where the pad rested touching both faces: each
    # met the face across after 2-3 mm and reported a concave edge again, the verifier crossed from wall to wall,
    # and the stall rule ended it incomplete with 6 vertices not measured: the moves were aimed from the edge's
    # line, where the pad resting in the corner is its radius in from it. They are now aimed from there
    # (docs/physics-notes.md). A move aimed from there at a vertex of a wall narrower than the pad's radius (the
    # slot is 20 mm deep) headed back toward the corner, met the face across again after 10 mm and reported the
    # edge it started on; such a move now runs along the edge, clear of that face. Across the slot's floor, 6 mm
    # for the pad, a move meets the other wall: a concave edge, but not the one it left. The verification then went
    # back to the ridge of the slot's floor, which the pad cannot follow between the walls, over and over (the
    # tour's cheapest way to the last vertex runs along it) until the stall rule ended it one vertex short; an edge
    # move that failed along a model edge is no longer taken that way again, and the last vertex is reached round
    # the other arm. An edge move along one of the slot's concave edges first returned next to it by touching one of
    # its faces 4 mm from the edge, where the pad (12 mm) meets the face across first: 16 of 16 such returns failed
    # ("could not return next to the edge"), and the episode ended one corner of the floor short at its move budget.
    # The pad now returns into the corner along the bisector of the two faces' normals, touching both.
    del tmp_path
    start, ended = [None], []

    def on_move(n, r, count, rec):
        if r.move.kind == "face" and start[0] is not None and r.components:
            ended.append((start[0], r.info.get("kind"), r.components[0]))
        start[0] = r.state.edge

    spec = EpisodeSpec(model="BOX01N", seed=2, executor="physics", verify="full")
    ep = build_episode(spec)
    rec = ep.run(None, EpisodeObserver(on_move=on_move))
    edges = ep.executor.segmenter.edges

    def same_line(e, c) -> bool:  # the edge reported lies along edge record e's line
        a, u = edges[e].point, edges[e].direction
        off = lambda p: np.linalg.norm((p - a) - ((p - a) @ u) * u)  # noqa: E731
        ends = (c.point, c.point + c.length * c.direction)
        return abs(float(c.direction @ u)) > np.cos(np.radians(5.0)) and max(off(p) for p in ends) < 0.004

    from_corner = [(e, kind, c) for e, kind, c in ended if not edges[e].convex]
    assert from_corner
    assert not [c.id for e, kind, c in from_corner if kind == "concave" and same_line(e, c)]
    assert rec.outcome == "recognized" and rec.correct, rec.detail


def test_a_verification_up_to_hidden_vertices_says_so_and_is_not_confirmed():
    # BOX01N seed 3 rests with its slot against the table: every feature in the hand's reach is measured, and the
    # slot's vertices are hidden. The record says the verification is complete up to them (reach_complete) and
    # the episode ends ambiguous, never recognised: a difference under the object cannot be measured. FRAME01 seed
    # 1 stands on an end: the corners of its hole lie at the inner ends of the valleys between its sloping faces,
    # which no edge move locates, and the hole's walls are out of the reach of fingers pointing down. The
    # verification used to count them in reach and chase them until its budget ran out (77 moves, 30 of them
    # failed, not complete in reach); they are named out of reach up front, and it ends once the rest is measured.
    rec = run_episode(EpisodeSpec(model="BOX01N", seed=3, executor="physics", verify="full"))
    v = rec.verified
    assert rec.outcome == "ambiguous" and v["status"] == "incomplete"
    assert v["reach_complete"] and v["vertices_hidden"] > 0
    rec = run_episode(EpisodeSpec(model="FRAME01", seed=1, executor="physics", verify="full"))
    v = rec.verified
    assert rec.outcome == "ambiguous" and v["status"] == "incomplete"
    assert v["reach_complete"] and v["vertices_hidden"] >= 8 and v["moves"] <= 30, rec.detail



def test_vertices_whose_moves_change_only_the_tables_shadow_are_taken_on_trust(tmp_path):
    # cad_stepped3 of the sized formula corpus (37 mm high), seed 1, default options: every feature in the pad's reach
    # measured, the verification ended incomplete with 6 vertices out of reach off the table (under its steps) and 6
    # on the table that nothing in reach places. The 6 on the table have every face's corner, every edge and
    # themselves under the pad's reach for their contact normals: a move of any of them changes only surface no pad
    # clear of the table touches, and they are taken on trust, the claim's height the band's (26.3 mm, the faces
    # leaning under that rise from the table). The 6 under the steps are not: the corners of their faces reach above
    # the shadow unmeasured, and the episode stays ambiguous, saying so.
    rec = run_episode(EpisodeSpec(model="cad_stepped3", seed=1, executor="physics",
                                  models=_sized_corpus(tmp_path)))  # fmt: skip
    v = rec.verified
    assert rec.outcome == "ambiguous" and v["reach_complete"], rec.detail
    assert v["vertices_shadowed"] == 6 and v["vertices_hidden"] == 6, v
    assert v["table_shadow_mm"] == v["table_band_mm"] and 25.0 < v["table_shadow_mm"] < 28.0, v
    assert "6 out of the hand's reach off the table" in rec.detail and "on the table" not in rec.detail, rec.detail

@pytest.mark.slow
def test_vertices_out_of_the_tables_shadow_are_taken_with_their_corners_probed_and_their_ridges_crossed(tmp_path):
    # trapezohedron_08 of the sized formula corpus (112 mm), seed 1, default options: lying on a kite, two vertices
    # 11 mm up are out of reach, and nothing placed them by their corners (a kite leaning under 56° leaves the pad no
    # position within its corner): the verification ended incomplete. The table's shadow takes them with the two
    # upright kites measured within their corners at each and the edges rising out of the shadow measured: the
    # verification probes those corners, then crosses the edges, and confirms. Along the way, the index's level
    # stroke on a kite rising 12° spanned 1 mm across it, under the 1.5 mm a face needs, and the thumb is asked next;
    # after the thumb's probes the index lay on the table far from the object, and every later move failed rising
    # from there, until it is brought back over the face it left.
    failed = []
    obs = EpisodeObserver(on_failed_move=lambda n, r: failed.append(r.reason))
    rec = run_episode(EpisodeSpec(model="trapezohedron_08", seed=1, executor="physics",
                                  models=_sized_corpus(tmp_path)), observer=obs)  # fmt: skip
    v = rec.verified
    assert rec.outcome == "recognized" and rec.correct and v["status"] == "confirmed", rec.detail
    assert v["vertices_shadowed"] == 4 and v["ridges_asked"] and 25.0 < v["table_shadow_mm"] < 27.0, v
    probes = v["corner_probes"]
    assert probes["corners_probed"] == 3 and probes["fingers"].get("thumb", 0) >= 1, probes
    assert not [w for w in failed if "rising above the object" in w], failed


def test_a_stalled_verification_relocates_over_the_object_and_measures_what_is_in_reach():
    # BOX01P seed 1 stands upright, its tab 30 mm high on a side. The traced verification measured the top and the
    # tab's upper corners; the tour, pricing the way to the tab's lower corners as a straight line, then kept the pad
    # tracing the top's edges and measuring vertices it had, until the stall rule ended it with 4 vertices in reach
    # not measured. After moves that measure nothing the hand now relocates: a probe carries the pad over the
    # object onto a face beside what is missing, and every vertex in reach is measured (the episode stays
    # ambiguous: vertices under the tab and on the table are out of the hand's reach).
    kinds = []
    obs = EpisodeObserver(on_move=lambda n, r, count, rec: kinds.append(r.move.kind))
    rec = run_episode(EpisodeSpec(model="BOX01P", seed=1, executor="physics", verify="full"), observer=obs)
    assert "probe" in kinds
    assert rec.verified["reach_complete"], rec.detail
    assert rec.outcome in ("recognized", "ambiguous") and rec.recognized in ("BOX01P", None)


def test_an_edge_move_after_a_tilted_move_returns_beside_the_last_contact():
    # HEXPRISM01 seed 1: face moves onto the sides leaning under 30° are made with the hand tilted, which then backs
    # out along the finger's axis, centimetres from the edge just found. The edge move after such a move touched the
    # face again beside where the pad now was, past the edge's end, and found nothing there ("could not return
    # next to the edge: no-contact"); it returns beside the last contact.
    failed = []
    obs = EpisodeObserver(on_failed_move=lambda n, r: failed.append(r.reason))
    rec = run_episode(EpisodeSpec(model="HEXPRISM01", seed=1, executor="physics", verify="full"), observer=obs)
    assert not [w for w in failed if "could not return next to the edge: no-contact" in w], failed
    assert rec.outcome == "recognized" and rec.correct, rec.detail


def test_a_face_move_onto_a_face_under_an_overhang_reports_the_edge_alone():
    # BOX01N seed 1 stands on an end, its slot sideways: the slot's floor lies 30 mm under its ceiling. Face moves
    # rolled over the floor's edge (and the back wall's), and the stroke's step in stalled within a millimetre, the
    # finger's medial link on the ceiling; touched afresh there, five touches a move, each ran away or timed out:
    # five face moves failed, "stroke on the next face failed: blocked" (19 moves in all). A step held back with a
    # link touching the object ends the crossing: the roll gives the edge alone, as onto a face leaning under.
    done, failed = [], []
    obs = EpisodeObserver(on_move=lambda n, r, *a: done.append(r), on_failed_move=lambda n, r: failed.append(r.reason))
    ep = build_episode(EpisodeSpec(model="BOX01N", seed=1, executor="physics", verify="none"))
    rec = ep.run(None, obs)
    assert any(r.move is not None and r.move.kind == "face" and r.info.get("next_face") == "out of reach"
               for r in done)  # fmt: skip
    assert not [w for w in failed if "stroke on the next face failed" in w], failed
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert _within_bounds(ep)


def test_a_vertex_move_whose_next_face_is_out_of_reach_reports_the_edge_alone(tmp_path):
    # PYR01 30 mm across, seed 2: a vertex move circled the apex of the pyramid and rolled over a slant edge onto
    # the next side, which runs down to the table: the roll reached the table's clearance before the pad settled
    # on it and the move failed ("crossing the convex edge: the pad reached the table's clearance before the next
    # face"), as vertex moves did on the polyhedra at 30 mm 9 times in 71. The roll gives the edge leaving the
    # vertex, as a face move's does: reported alone, adjacent to the vertex, within its bounds.
    done, failed = [], []
    obs = EpisodeObserver(on_move=lambda n, r, *a: done.append(r), on_failed_move=lambda n, r: failed.append(r))
    spec = EpisodeSpec(model="PYR01", seed=2, executor="physics", verify="none",
                       models=_scaled_library(tmp_path, 0.03))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None, obs)
    alone = [r for r in done
             if r.move is not None and r.move.kind == "vertex" and r.info.get("next_face") == "out of reach"]
    assert alone, [(r.move, r.info) for r in done]
    edge = alone[0].components[0]
    by_id = {c.id: c for c in ep.executor.components}
    assert edge.kind == "edge" and any(by_id[i].kind == "vertex" for i in edge.adjacent), edge.adjacent
    assert not [r for r in failed if r.move.kind == "vertex"], [r.reason for r in failed]
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert _within_bounds(ep)


def test_faces_met_alone_are_not_crossed_again_round_and_round(tmp_path):
    # metabiaugmented_hexagonal_prism of the public polyhedra at 30 mm, seed 1, --verify none: four pose classes left
    # from move 2, and the planner crossed edges onto faces out of the pad's reach again and again -- face moves from
    # one face 9 times in a row, each giving the edge alone -- to the move budget (40): the classes it hoped to tell
    # apart by the next face's angle were never told apart. Such a crossing measures again what the data hold
    # (tests/planning/test_remeasure.py); recognised in 20 moves.
    from haptic.geometry import load_library
    from haptic.geometry.io import save_model
    from haptic.geometry.perturb import scaled_to

    for name, poly in load_library("assets/libraries/polyhedra").items():
        save_model(scaled_to(poly, 0.03, name), tmp_path / f"{name}.json")
    rec = run_episode(EpisodeSpec(model="metabiaugmented_hexagonal_prism", seed=1, executor="physics", verify="none",
                                  models=str(tmp_path)))  # fmt: skip
    assert rec.outcome == "recognized" and rec.correct, (rec.outcome, rec.moves, rec.detail)
    assert rec.moves <= 25, rec.moves


def test_a_roll_that_finds_the_pad_still_on_the_face_lets_the_slide_go_on():
    # LBLOCK01 seed 3, verifying: a face move's slide lost its contact on the face and took that for a convex edge;
    # the roll, its normal still the face's, headed back over the face until its travel ran out ("crossing the convex
    # edge: limit"). A roll whose normal has not turned after a few millimetres is on the face it left: the slide
    # goes on from there, once.
    ep, rec, said, failed = _watched(EpisodeSpec(model="LBLOCK01", seed=3, executor="physics", verify="full"))
    assert any("the pad stayed on the face: the slide went on" in x for x in said), said
    assert not [w for w in failed if "edge: limit" in w], failed
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert _within_bounds(ep)


def test_a_roll_held_back_by_a_link_of_the_finger_says_so():
    # BOX01N seed 1, verifying: a face move onto the floor of the slot under its ceiling, the hand tilted away from
    # the ceiling, rolled on without settling until its time ran out ("crossing the convex edge: limit"), the finger's
    # distal link on the object. The roll reports the link that held it back.
    failed = []
    obs = EpisodeObserver(on_failed_move=lambda n, r: failed.append(r.reason))
    ep = build_episode(EpisodeSpec(model="BOX01N", seed=1, executor="physics", verify="full"))
    ep.run(None, obs)
    assert not [w for w in failed if "edge: limit" in w], failed
    assert any("crossing the convex edge: the finger's" in w for w in failed), failed
    assert _within_bounds(ep)


def test_a_stroke_that_steps_onto_the_rim_of_another_edge_measures_no_face(tmp_path):
    # BOX01N 30 mm across, seed 1 (perception_report.py --sizes 30): a face move down over the top edge onto a
    # side 10 mm tall, above an overhang, rolled on to that side's lower edge as it stepped in; the stroke's legs
    # then ran along that edge, the pad riding it with a steady normal 20° below the side's, and the "face" was
    # 25 times its bound off the true one (no-match). LBLOCK01 at 30 mm, seed 1, did the same on a step 10 mm
    # wide (12 bounds). The stroke's first leg off the edge turned its normal by 6-11° (0.1-1.9° on a face):
    # the pad had reached the rim of another edge, and the move touches the next face afresh with an L or fails.
    # Since a face move crossing square to its edge follows the ridge first, this replay's moves differ and may not
    # step onto a rim; whatever they meet, every component lies within its bounds.
    ep, failed, _ = _replay(tmp_path, "BOX01N", 0.03, 11)
    assert _within_bounds(ep), [r.reason for r in failed]


@pytest.mark.parametrize("model", ["HEXPRISM01", "PYR01"])
def test_a_start_landing_next_to_the_rim_measures_the_face_within_its_bound(tmp_path, model):
    # 30 mm across, seed 2 (perception_report.py --sizes 30). HEXPRISM01: the start landed 0.3 mm from the top
    # face's rim and the L stroke began with the pad rolled on the edge, its normal 4-7° off the face. The face's
    # rows were picked about the primitive's running normal, seeded there, and the face came out 3.1° off (3.65
    # times its bound; the episode ended no-match) though most of the L's rows lay on the face; picked about the
    # median of the L's normals, it is 0.1° off. PYR01: the L's first leg ran along the rim, 0.1-0.7 mm from the
    # edge, its normal steady 3° off the face; the steady rows were that leg alone, a line, and the face 2.6° off
    # (3.18 bounds). Steady rows that do not span the L across measure no face: the start lands again nearby.
    from haptic.episode.evaluate import bound_ratios

    spec = EpisodeSpec(model=model, seed=2, executor="physics", models=_scaled_library(tmp_path, 0.03))
    ep = build_episode(spec)
    r = ep.executor.start()
    assert r.ok and [c.kind for c in r.components] == ["face"]
    ratios = bound_ratios(r.components, ep.true_model, ep.world_from_model)
    assert max(x.ratio for x in ratios if x.what == "face normal") < 0.5, ratios


def test_an_edge_move_that_acquires_a_parallel_ridge_reports_nothing(tmp_path):
    # BOX01P 60 mm across, seed 1 (perception_report.py --sizes 60): the back face meets the plateau's top and the
    # lower top along two parallel edges 12 mm apart, between faces of the same normals. A second edge move along
    # the plateau's back edge returned next to it past its end and acquired the lower edge's ridge; its contacts
    # moved the edge's line there and its vertex lay 12 mm below the edge's end, on no edge of the line: the true
    # object was pruned and the episode ended no-match, though every component lay within its bounds of some
    # feature. A ridge acquired off the edge's line is another edge: the move fails.
    failed = []
    obs = EpisodeObserver(on_failed_move=lambda n, r: failed.append(r.reason))
    spec = EpisodeSpec(model="BOX01P", seed=1, executor="physics", models=_scaled_library(tmp_path, 0.06))
    ep = build_episode(spec)
    rec = ep.run(None, obs)
    # (since a face move crossing square to its edge follows the ridge first, the moves differ and the second edge
    # move may not be made: the episode must still end other than no-match, every component within its bounds)
    assert rec.outcome != "no-match", (rec.detail, failed)
    assert _within_bounds(ep)


def test_a_stroke_leg_that_a_finger_link_stopped_does_not_measure_the_face(tmp_path):
    # bipyramid_08 of the formula corpus at 150 mm, seed 1 (perception_report.py --corpus --sizes 150): the stroke
    # on the next face stepped in, then slid along the edge until the finger's medial link met the object; that
    # leg's rows alone made the face (the step's are left out, next to the edge's rims), the pad lifted and tilted
    # by the link over its last millimetres: the face 1.55° off, 1.73 times its bound. With the step's rows the face
    # holds.
    from haptic.episode.evaluate import bound_ratios

    ep, _, _ = _replay(tmp_path, "bipyramid_08", 0.15, 12, corpus=True, seed=1)
    ratios = bound_ratios(ep.executor.components, ep.true_model, ep.world_from_model)
    assert max(r.ratio for r in ratios if r.what == "face normal") <= 1.0


def test_a_next_face_met_near_its_end_is_touched_again_along_the_edge(monkeypatch):
    # BOX01 seed 2: after an edge move to a top vertex, a face move across a side 4 mm under its top edge crossed
    # the vertical edge next to the vertex; the stroke on the next face rode the top rim, and so did every touch of
    # it afresh, their normals leaning 8° up along the edge: "too few contacts on the next face", the move failed.
    # The face touched past the edge but measured too little is touched again 7 mm down the edge, clear of its end.
    # That move was predicted to meet its edge at 4.6°, and the verification on the hand now leaves such a move out
    # unless nothing else is left (verify.GRAZING; the episode is then recognized with no failed move either way):
    # the replay asks it as recorded, the rule switched off, to see what the hand does with it.
    import haptic.planning.verify as verify

    monkeypatch.setattr(verify, "_grazing", lambda *args: False)
    results = []
    obs = EpisodeObserver(on_move=lambda n, r, *a: results.append(r), on_failed_move=lambda n, r: results.append(r))
    ep = build_episode(EpisodeSpec(model="BOX01", seed=2, executor="physics", verify="full"))
    rec = ep.run(None, obs)
    shifted = [r for r in results if any("clear of its end" in s for s in r.info.get("recoveries", ()))]
    assert shifted and all(r.ok for r in shifted)
    assert not [r for r in results if "too few contacts" in r.reason]
    assert rec.outcome == "recognized" and rec.correct, rec.detail


@pytest.mark.slow
@pytest.mark.xfail(strict=False, reason="the episode's course depends on floating-point details of the machine and the "
                   "installed libraries: on some (numpy 2.4.6, scipy 1.17.1) HEXPRISM01 seed 2 reaches that corner "
                   "another way and the vertex move's stroke there runs away again (docs/physics-notes.md)")
def test_a_vertex_move_onto_a_side_leaning_under_measures_it_tilted_past_the_ridge():
    # HEXPRISM01 seed 2 lies on a side: a vertex move circling an end crossed onto a side leaning under 29°. The
    # roll settled on the ridge 14° short of the side, the stroke there ran away, and touched afresh past the edge
    # the pad read the ridge again (a normal turned partway about the edge); touched again 5 mm along the edge it
    # read the side, but every L there stopped within 2.5 mm, the distal link on the ridge above the side (the side
    # leans under the ridge between it and the next side): "stroke on the next face failed: runaway". An L a link
    # of the finger stopped is made again with the hand tilted away from that link, and the side it measures is the
    # next face when turned farther about the edge than the ridge reading.
    ep, rec, said, failed = _watched(EpisodeSpec(model="HEXPRISM01", seed=2, executor="physics", verify="full"))
    assert not [w for w in failed if "stroke on the next face failed" in w], failed
    assert any("stepping onto the next face, the finger's index_distal met the object: the hand tilted" in x
               for x in said), said  # fmt: skip
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert _within_bounds(ep)


def test_a_tetrahedron_taller_than_the_model_is_not_confirmed_with_its_base_on_the_table(tmp_path):
    # TETRA01R made 3 % taller (scripts/bench_learn.py --executor physics --models-only
    # PYR01,TETRA01L,TETRA01R,WEDGE01,BOX01 --variants dim, seed 1777477784) rests on its base: the hand measures the
    # apex and the three side faces. The model fitted them at a pose tilting its base off the table, and the
    # acceptance test, with only the model's lowest point as the table's datum, passed it (37.56 against 37.70):
    # confirmed as TETRA01R. Each vertex of the facet the model rests on is a datum on the table plane, and the
    # pose is refitted to the data and the table together: the variant is turned away, the model itself confirmed.
    from haptic.geometry import load_library
    from haptic.geometry.io import save_model
    from haptic.geometry.perturb import scale_dimension

    taller = scale_dimension(load_library()["TETRA01R"], 2, 1.03, name="TETRA01R__dim2_1.03")
    path = tmp_path / "TETRA01R__dim2_1.03.json"
    save_model(taller, path)
    rec = run_episode(EpisodeSpec(model=str(path), seed=1777477784, executor="physics", verify="full"))
    assert rec.outcome != "recognized", (rec.recognized, rec.verified)
    rec = run_episode(EpisodeSpec(model="TETRA01R", seed=1777477784, executor="physics", verify="full"))
    assert rec.outcome == "recognized" and rec.correct, rec.detail


def test_a_vertex_at_noise_level_4_is_located_where_the_pad_rolls_on_it(tmp_path):
    # BOX01 at 150 mm, seed 1, noise level 4 (perception_report.py --sizes 150 --noise 4): an edge move ran to the
    # edge's end and located the vertex at the median of the rows whose normal leaned 5° along the edge. With σn 4°
    # a sixth of the rows on the ridge leaned that far by noise alone, and the vertex lay 14 mm short of the end
    # (2.55 times its bound; no-match). A lean within 3 σn of the sensor is noise on the ridge: the vertex is where
    # the pad rolls on it, within its bound.
    spec = EpisodeSpec(model="BOX01", seed=1, executor="physics", noise=4.0, models=_scaled_library(tmp_path, 0.15))
    ep = build_episode(spec)
    ep.run(None)
    assert [c for c in ep.executor.components if c.kind == "vertex"]
    assert _within_bounds(ep)


def test_a_roll_that_reaches_the_tables_clearance_measures_no_face(tmp_path):
    # prism_08 of the formula corpus at 100 mm, seed 3 (perception_report.py --corpus --sizes 100 --first-seed 3):
    # lying on a side, the octagon's faces next to the table lean under at 45°. A face move down a side rolled over
    # the edge to such a face and the pad reached the table's clearance (2 mm) with its normal 28° below the
    # horizontal, no longer turning: the roll "settled", and the stroke there rode the edge, a face 43.6 bounds off
    # (no-match). A roll that reaches the table's clearance has not reached the next face: the edge is reported
    # alone from the roll, as over a face leaning under out of reach, or the move fails.
    spec = EpisodeSpec(model="prism_08", seed=3, executor="physics",
                       models=_scaled_library(tmp_path, 0.10, corpus=True))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None)
    assert rec.outcome != "no-match", rec.detail
    assert _within_bounds(ep)


def _sized_corpus(directory, lo: float = 0.03, hi: float = 0.15) -> str:
    """The formula corpus as ``scripts/make_corpus.py OUT --sizes 30:150 --encodings obj6`` writes it: each solid
    scaled about its centroid to a size (its largest vertex distance) drawn from ``lo`` to ``hi`` [m]; the obj6
    library's directory."""
    from haptic.geometry import Polyhedron
    from haptic.geometry.corpus import corpus_solids, write_corpus

    rng = np.random.default_rng(0)
    solids = []
    for spec, poly in corpus_solids(seed=0):
        v = poly.vertices
        k = rng.uniform(lo, hi) / float(np.linalg.norm(v[:, None] - v[None], axis=2).max())
        c = poly.centroid
        solids.append((spec, Polyhedron.from_faces(c + k * (v - c), poly.faces, name=poly.name)))
    return str(write_corpus(directory, seed=0, solids=solids, encodings=("obj6",))["obj6"])


def test_an_edge_move_that_locates_the_end_it_set_off_past_does_not_turn_the_object_away(tmp_path):
    # trapezohedron_12 of the sized formula corpus (77 mm), seed 1, default options: during the verification an edge
    # move set off 2 mm past one end of a 9 mm edge toward the other and located a vertex 0.3 mm from the end it
    # left. Reported as the end it ran toward, the edge's interval collapsed onto it, its two ends were one vertex,
    # the matcher pruned every interpretation and the true object was turned away (no-match).
    rec = run_episode(EpisodeSpec(model="trapezohedron_12", seed=1, executor="physics",
                                  models=_sized_corpus(tmp_path)))  # fmt: skip
    assert rec.outcome != "no-match", rec.detail


def test_an_edge_move_whose_return_beside_the_last_contact_fails_returns_beside_the_edges_middle(tmp_path):
    # trapezohedron_06 of the sized formula corpus, seed 1, default options: a vertex move left the pad 5 mm past the
    # far end of an 8 mm edge, and the edge move along it toward that end, returning next to the edge beside the last
    # contact, touched the faces round that end (normals 7° and 24° off the edge's faces) and failed; the vertex
    # there was measured by nothing else, and the verification went round the object for 20 more moves until its
    # budget ended it "incomplete after 31 moves: ... 1 vertices ... not measured". Returned beside the middle of
    # the edge behind its end, the move locates the vertex, and the verification ends with every vertex in the
    # hand's reach measured
    rec = run_episode(EpisodeSpec(model="trapezohedron_06", seed=1, executor="physics",
                                  models=_sized_corpus(tmp_path)))  # fmt: skip
    assert rec.verified["reach_complete"], rec.detail
    assert rec.perception["outside_bounds"] == 0


@pytest.mark.slow
def test_an_edge_move_that_set_off_past_its_end_onto_the_next_edge_sets_off_again_from_the_middle(tmp_path):
    # trapezohedron_11 of the sized formula corpus, seed 1, default options: an edge move along a 13 mm kite edge,
    # known 2 mm long from a crossing, set off 5 mm past the vertex it ran toward, acquired the next kite edge (25°
    # from it) 2.4 mm past the explored interval and rolled off its end there, 1.5 mm off the edge's line: "could not
    # locate the vertex". Set off again from the middle of the explored interval, the move locates it
    failed, recovered = [], []
    obs = EpisodeObserver(on_move=lambda i, res, *a: recovered.extend(res.info.get("recoveries", ())),
                          on_failed_move=lambda i, res: failed.append(res.reason or ""))  # fmt: skip
    rec = run_episode(EpisodeSpec(model="trapezohedron_11", seed=1, executor="physics",
                                  models=_sized_corpus(tmp_path)), observer=obs)  # fmt: skip
    assert not [why for why in failed if "could not locate the vertex" in why], failed
    assert any("could not locate the vertex" in why and "set off again" in why for why in recovered), recovered
    assert rec.outcome != "no-match" and (rec.outcome != "recognized" or rec.correct), rec.detail


def test_a_next_face_touched_along_the_edge_after_a_rim_reading_is_the_next_face(tmp_path):
    # platonic_dodecahedron of the sized formula corpus, seed 1, default options: two face moves rolled over an edge
    # near its end, and the touches afresh past it read the rims of the faces round the vertex (normals turned 58°
    # and 59° from the face left, no face in their L); touched again along the edge, clear of the end, the pad
    # measured the next face at the solid's 63.4°, 24° and 21° from the rim reading, and a 12° cone turned it away:
    # both crossings failed "too few contacts on the next face", and the verification ended "incomplete after 34
    # moves: ... 2 vertices ... not measured". Taken as the next face, the crossing goes on (one fails cleanly on,
    # its edge's ridge a vertex), and every vertex in the hand's reach is measured
    rec = run_episode(EpisodeSpec(model="platonic_dodecahedron", seed=1, executor="physics",
                                  models=_sized_corpus(tmp_path)))  # fmt: skip
    assert rec.verified["reach_complete"], rec.detail
    assert rec.perception["outside_bounds"] == 0


def test_a_verification_whose_every_way_to_a_vertex_failed_ends_saying_so(tmp_path, monkeypatch):
    # trapezohedron_06 of the sized formula corpus, seed 1, default options, the edge move returning beside the last
    # contact alone (as before it returned beside the middle of the edge): the one edge move in the hand's reach
    # toward a vertex failed, is not asked again, and the verification went round the object for 20 moves measuring
    # nothing until its budget ended it, "incomplete after 31 moves: ... 1 vertices ... not measured". With no way
    # to the vertex left, it ends there and names the move that failed
    from haptic.executor.physics import PhysicsExecutor

    def beside_the_last_contact(self, rec, u, face, pieces, s0=None):
        if s0 is None:
            s0 = rec.param(self.contact_point() if self.toucher.contact[2] is not None else self.state.position)
        return self._return_beside(rec, u, face, pieces, s0)

    monkeypatch.setattr(PhysicsExecutor, "_return_next_to_edge", beside_the_last_contact)
    rec = run_episode(EpisodeSpec(model="trapezohedron_06", seed=1, executor="physics",
                                  models=_sized_corpus(tmp_path)))  # fmt: skip
    assert "every edge move in the hand's reach toward them failed" in rec.detail, rec.detail
    assert "could not return next to the edge" in rec.detail
    assert rec.verified["moves"] < 20 and rec.verified["vertices_unreached"], rec.verified


@pytest.mark.slow
def test_a_verification_that_failed_a_way_in_finds_another(tmp_path):
    # antiprism_05 of the sized formula corpus, seed 1, default options: the verification ended "incomplete after
    # 30 moves" with one face and one edge unmeasured, 8 after it last measured something: face moves failed to
    # cross to them, and the verification went back over the faces and edges measured, where the stall rule ended
    # it before it came round to another way in
    rec = run_episode(EpisodeSpec(model="antiprism_05", seed=1, executor="physics",
                                  models=_sized_corpus(tmp_path)))  # fmt: skip
    assert rec.outcome == "recognized" and rec.correct, rec.detail


@pytest.mark.slow
def test_a_verification_with_no_move_left_ends_saying_so():
    # FRAME01 seed 2, default options: every move from the vertex the verification reached failed (the way on was
    # through the frame's hole), the verifier had no admissible move left, and the loop's random fallback moves
    # from there failed in turn until the stall rule ended it ("incomplete after 20 moves"); with none left the
    # verification ended there and said why. The hole's corners are now named out of reach up front (only the
    # valleys between the sloping faces lead to them, and no edge move locates their ends): the verification does
    # not go there, and ends once the rest is measured, saying which vertices the hand cannot measure
    rec = run_episode(EpisodeSpec(model="FRAME01", seed=2, executor="physics"))
    assert rec.outcome == "ambiguous" and not rec.correct
    assert rec.verified["reach_complete"] and "8 out of the hand's reach" in rec.detail, rec.detail


@pytest.mark.slow
def test_a_verification_going_round_one_way_takes_another(tmp_path):
    # trapezohedron_04 of the sized formula corpus (115 mm), seed 1, default options: a face move failed to cross
    # to the face leaning under that was missing, and the verification went round one vertex over the same three
    # faces, face move and edge move in turn, until the stall rule ended it ("incomplete after 30 moves")
    rec = run_episode(EpisodeSpec(model="trapezohedron_04", seed=1, executor="physics",
                                  models=_sized_corpus(tmp_path)))  # fmt: skip
    assert rec.outcome == "recognized" and rec.correct, rec.detail

def test_a_roll_at_an_edges_end_with_the_next_face_out_of_reach_reports_no_edge(tmp_path, monkeypatch):
    # HEXPRISM01 at 30 mm, seed 2 (perception_report.py --sizes 30 --first-seed 2): a face move rolled over an edge
    # whose next face leant out of reach with the pad's centre 0.2-0.5 mm past the edge's end; the edge's direction,
    # the axis the rolling normals turned about, took in their turn round the vertex and lay 2.1° off (2.1 bounds),
    # and the episode ended no-match. Following the ridge from the roll meets that vertex at once: no edge. A later
    # roll ended 0.2 mm from a vertex too (its axis 5.8° off, 5.4 bounds), but the ridge was followed 4 mm away from
    # the vertex first and the vertex's distance taken from there (3.8 mm): it is measured from where the roll ended.
    # The roll that fails so came from a verification face move predicted to meet its edge at 0.9°, which the
    # verification on the hand now leaves out unless nothing else is left (verify.GRAZING; the episode then ends as
    # before, one vertex unmeasured, with a failed move less): the replay asks it as recorded, the rule switched off.
    # Such a face move now crosses again farther inside the edge when the roll went on down to the table's clearance
    # (as here): it says why, and recovers. The planner now also leaves out an edge move along an edge whose faces
    # the pad cannot touch next to it off the table (table.edge_return_in_reach), which took the episode another
    # way, with no failed move (recognised): the replay switches that rule off too.
    import haptic.planning.table as table
    import haptic.planning.verify as verify

    monkeypatch.setattr(verify, "_grazing", lambda *args: False)
    monkeypatch.setattr(table, "edge_return_in_reach", lambda *args: True)
    said = []
    spec = EpisodeSpec(model="HEXPRISM01", seed=2, executor="physics", models=_scaled_library(tmp_path, 0.03))
    ep = build_episode(spec)
    rec = ep.run(None, EpisodeObserver(on_move=lambda n, r, *a: said.extend((r.info or {}).get("recoveries", ())),
                                       on_failed_move=lambda n, r: said.append(r.reason)))  # fmt: skip
    assert any("the roll crossed the edge" in why for why in said), said
    assert rec.outcome != "no-match", rec.detail
    assert _within_bounds(ep)


def test_a_stroke_along_a_rim_does_not_tilt_the_face_it_refits(tmp_path):
    # prism_12 of the formula corpus at 150 mm, seed 3 (perception_report.py --corpus --sizes 150 --first-seed 3):
    # a face move's stroke slid along the rim of an edge, its normal steady 2.3° off the face, within the face cone;
    # its 556 rows refitted the face, 2.3° off with a σ of 0.04°, and the edge crossed next lay 2.3° off (2.6
    # bounds): the episode ended no-match. Rows whose mean normal is off the face's fit beyond their bound do not
    # refit it.
    spec = EpisodeSpec(model="prism_12", seed=3, executor="physics",
                       models=_scaled_library(tmp_path, 0.15, corpus=True))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None)
    assert rec.outcome != "no-match", rec.detail
    assert _within_bounds(ep)


@pytest.mark.xfail(strict=False, reason=(
    "with the face, stall and reach work merged the episode no longer makes that roll: the replay no longer shows it"))
def test_a_roll_that_began_round_a_vertex_with_the_next_face_out_of_reach_reports_no_edge(tmp_path):
    # bipyramid_09 of the formula corpus at 30 mm, seed 1 (perception_report.py --corpus --sizes 30): a face move
    # rolled round the apex and on over an edge whose next face leant out of reach; the axis the rolling normals turned
    # about lay 18° off the edge (7.9° once refined by the ridge: 5 bounds), and the episode ended no-match. Over a
    # true edge the normals lie off the plane perpendicular to its axis by the noise alone (rms 0.0175 at σn 1°);
    # these by 0.056 (3.2°): the roll gives no edge.
    failed = []
    spec = EpisodeSpec(model="bipyramid_09", seed=1, executor="physics",
                       models=_scaled_library(tmp_path, 0.03, corpus=True))  # fmt: skip
    ep = build_episode(spec)
    rec = ep.run(None, EpisodeObserver(on_failed_move=lambda n, r: failed.append(r)))
    assert any("off the plane of any one axis" in r.reason for r in failed)
    assert rec.outcome != "no-match", rec.detail
    assert _within_bounds(ep)


def test_a_stroke_whose_second_leg_rides_a_rim_measures_no_face(tmp_path):
    # FRAME01 at 30 mm, seed 1 (perception_report.py --sizes 30): touched afresh after stepping onto a rim, the next
    # face's L-shaped stroke held the face's normal on its first leg and one 2.4° off on its second, which rode the rim
    # of an edge; the steady rows were mostly the second leg's, and the face lay 1.7° off (2.1 bounds): no-match. The
    # legs' steady normals differ by more than the noise allows, but so do a thumb's on a face it measures within its
    # bound: no face should be measured from such a stroke, and the legs alone do not tell.
    spec = EpisodeSpec(model="FRAME01", seed=1, executor="physics", models=_scaled_library(tmp_path, 0.03))
    ep = build_episode(spec)
    rec = ep.run(None)
    assert rec.outcome != "no-match", rec.detail


def test_a_vertex_move_whose_circle_start_touches_the_far_rim_starts_halfway_to_the_edge(tmp_path):
    # bipyramid_12 of the formula corpus at 70 mm, seed 1: the verification's vertex moves round the equator's
    # vertices, where the faces' corners are narrow, touched the circle's start (8 mm from the vertex, 25° from the
    # edge) with a normal 6-7° off the face: the pad met the rim of the face's far edge, and 5 of 47 moves failed
    # "could not reach the face next to the vertex". The circle now starts halfway to the edge instead. The episode
    # is stopped once a vertex move has met it.
    spec = EpisodeSpec(model="bipyramid_12", seed=1, executor="physics",
                       models=_scaled_library(tmp_path, 0.07, corpus=True))  # fmt: skip
    ep = build_episode(spec)
    said, failed = _until_recovery(ep, "vertex", "the circle started halfway",
                                   fails="could not reach the face next to the vertex")  # fmt: skip
    assert said and not failed, failed
    assert _within_bounds(ep)


def test_a_vertex_move_whose_roll_went_round_the_edges_end_crosses_again_inside_it(tmp_path):
    # trapezohedron_06 of the sized formula corpus (33 mm), seed 1: four vertex moves' circles met the next edge and
    # rolled round its end (the normals leaning 3-7° along it, more than the noise allows), and each failed "no edge
    # between the faces". The circle's roll is now crossed again as a face move's is: back on the face before where
    # it met the edge, shifted along the edge back inside it. With the short edges crossed at their middles that
    # episode no longer makes such a circle; bipyramid_08 (seed 1) does, and is replayed until a vertex move has
    # crossed again.
    spec = EpisodeSpec(model="bipyramid_08", seed=1, executor="physics", models=_sized_corpus(tmp_path))
    ep = build_episode(spec)
    said, failed = _until_recovery(ep, "vertex", "crossed again", fails="a roll round a vertex")
    assert said and not failed, failed
    assert _within_bounds(ep)


def test_a_face_move_whose_crossing_rolled_round_a_vertex_crosses_again_beside_it():
    # PYR01 seed 1 (physics_episodes.py --verify full): the fourth move traced a side face down at a slant into the
    # foot of a slanted edge, at the base vertex; the pad rolled round the vertex onto the ridge along the base, and
    # every touch of the next face afresh past the edge landed on the rims round it: the move failed ("too few
    # contacts on the next face"). It now crosses again shifted square to its travel, away from the vertex the roll
    # went round, and reports the edge and the next face within their bounds.
    results = []
    obs = EpisodeObserver(on_move=lambda n, r, *a: results.append(r), on_failed_move=lambda n, r: results.append(r))
    ep = build_episode(EpisodeSpec(model="PYR01", seed=1, executor="physics", max_moves=5))
    ep.run(None, obs)
    face = [r for r in results if r.move is not None and r.move.kind == "face"]
    assert all(r.ok for r in face), [r.reason for r in face if not r.ok]
    assert any("crossed again" in why for r in face for why in r.info.get("recoveries", ()))
    assert _within_bounds(ep)


def _moves(model: str, seed: int, library: str, max_moves: int) -> tuple:
    """The first ``max_moves`` moves of the default episode of ``model`` at ``seed`` in ``library``: the episode
    and every move's result."""
    results = []
    obs = EpisodeObserver(on_move=lambda n, r, *a: results.append(r), on_failed_move=lambda n, r: results.append(r))
    ep = build_episode(EpisodeSpec(model=model, seed=seed, executor="physics", models=library, max_moves=max_moves))
    ep.run(None, obs)
    return ep, results


def test_a_face_move_whose_start_beside_the_crossing_lies_off_the_face_crosses_again_from_a_touched_point(tmp_path):
    # antiprism_04 of the sized formula corpus, seed 1: the fifth move traced a face into an edge near its end; the
    # pad rolled round the vertex (the normals leaning 19.1° along the edge), and the start for crossing again, 8 mm
    # back and shifted along the edge away from the vertex, lay off the face (a triangle narrowing to that vertex):
    # the pad touched a normal off the face and the move failed. It now sets off from the point of the face it
    # touched nearest that start, toward the shifted crossing, and reports the edge and the next face within their
    # bounds. (bipyramid_07's seventh move showed the same until the verification's moves changed: its episode now
    # makes no such crossing.)
    from haptic.executor.physics import NEXT_FACE_LOST

    ep, results = _moves("antiprism_04", 1, _sized_corpus(tmp_path), 8)
    face = [r for r in results if r.move is not None and r.move.kind == "face"]
    again = [r for r in face if any("from where the face was touched" in x for x in r.info.get("recoveries", ()))]
    assert again and all(r.ok for r in again), [r.reason for r in again]
    crossing = ("no edge between the faces", "stroke on the next face", *NEXT_FACE_LOST)
    assert not any(r.reason.startswith(crossing) for r in face if not r.ok), [r.reason for r in face if not r.ok]
    assert _within_bounds(ep)



@pytest.mark.slow
def test_box01n_seed_1_is_recognised_without_verification():
    # BOX01N seed 1, --verify none: its slot's floor lies under the slot's overhang, and face moves stroking onto it
    # are blocked (five such failures in 19 moves). The episode is that sensitive: crossing again from a start summed
    # in another order (a few ulps apart) ended a later failed slide 38 mm elsewhere, and the planner's next choices
    # failed 20 moves before the 40-move budget ran out
    rec = run_episode(EpisodeSpec(model="BOX01N", seed=1, executor="physics", verify="none"))
    assert rec.outcome == "recognized" and rec.correct, (rec.outcome, rec.moves, rec.detail)


def _edge_moves(model: str, seed: int, max_moves: int):
    """The first ``max_moves`` moves of the default physics episode of the seed library's ``model`` at ``seed``: the
    episode, and the result of each edge move with whether its edge was concave."""
    results = []
    obs = EpisodeObserver(on_move=lambda n, r, *a: results.append(r), on_failed_move=lambda n, r: results.append(r))
    ep = build_episode(EpisodeSpec(model=model, seed=seed, executor="physics", max_moves=max_moves))
    ep.run(None, obs)
    edges = ep.executor.segmenter.edges
    moves = [(r, not edges[r.state.edge].convex) for r in results
             if r.move is not None and r.move.kind == "edge" and r.state is not None and r.state.edge in edges]
    return ep, moves


def test_an_edge_move_along_a_valley_locates_its_end_on_the_rims_of_its_faces():
    # LBLOCK01 seed 2 (physics_episodes.py --verify full): the second and third moves followed the L's inner valley
    # to each end, where its faces end at the caps square to it and the surface falls away; the pad rolled onto the
    # two rims, and each move failed "could not locate the vertex" (the merged contact lies on neither rim). Read
    # apart, each rim contact gives its rim's line (square to the contact's normal within the face's plane), which
    # meets the valley's line at its end.
    ep, moves = _edge_moves("LBLOCK01", 2, 3)
    valley = [r for r, concave in moves if concave]
    assert valley and all(r.ok and any(c.kind == "vertex" for c in r.components) for r in valley), [
        r.reason for r in valley]
    assert _within_bounds(ep)


@pytest.mark.xfail(strict=False, reason=(
    "with the ridge checks beside a third face the episode goes another way and makes no edge move along a valley in "
    "its first 20 moves (nor do BOX01P seeds 1-9 or BOX01N seeds 2 and 3); the valley servo it shows is unchanged"))
def test_an_edge_move_up_an_upright_valley_rides_its_corner_to_the_end():
    # BOX01P seed 3 (physics_episodes.py --verify full): the eighth move ran up an upright valley from beside its
    # foot; the ridge servo, pressing the pad sideways to turn the sensed normal onto the bisector, rocked it from
    # one face to the other (the sensed normal jumping between the faces'), it never gathered speed along the
    # valley, stalled, and no vertex was located where nothing blocked it. Drawn into the corner instead, the pad
    # rides it up to the end and locates the vertex.
    ep, moves = _edge_moves("BOX01P", 3, 8)
    valley = [r for r, concave in moves if concave]
    assert valley and all(r.ok for r in valley), [r.reason for r in valley]
    assert _within_bounds(ep)


def _until_edge_move(tmp_path, model: str, done) -> tuple:
    """The default physics episode of ``model`` of the sized formula corpus at seed 1, stopped once ``done(result)``
    holds for an edge move's result: the episode and every edge move's result until then (the episode may end
    first)."""

    class Seen(Exception):
        pass

    edge = []

    def keep(n, r, *a) -> None:
        if r.move is not None and r.move.kind == "edge":
            edge.append(r)
            if done(r):
                raise Seen

    ep = build_episode(EpisodeSpec(model=model, seed=1, executor="physics", models=_sized_corpus(tmp_path)))
    try:
        ep.run(None, EpisodeObserver(on_move=keep, on_failed_move=keep))
    except Seen:
        pass
    return ep, edge


def test_an_edge_move_beside_a_shallow_edge_acquires_its_ridge_not_the_face(tmp_path):
    # hull_07 of the sized formula corpus, seed 1 (physics_episodes.py --verify full): the second move, along an edge
    # turning by less than twice the ridge cone, "acquired" its ridge at once with the pad resting on the face 3 mm
    # in from it (the face's normal within the cone of the bisector), and failed: "the ridge acquired lies 2.8 mm
    # off the edge's line: another edge". The pad is on the ridge only nearer the bisector than either face.
    ep, edge = _until_edge_move(tmp_path, "hull_07", lambda r: True)
    assert edge and edge[0].ok, edge[0].reason if edge else "no edge move"
    assert _within_bounds(ep)


def test_an_edge_move_that_set_off_past_its_end_sets_off_again_inside_the_edge(tmp_path):
    # trapezohedron_10 of the sized formula corpus, seed 1 (physics_episodes.py --verify full): six edge moves set
    # off past the end they ran toward and located it behind where the pad acquired the ridge; each failed (the
    # check that keeps such a vertex out: it lay up to a bound off). The move now returns next to the edge in the
    # middle of its explored interval and sets off again from there.
    ep, edge = _until_edge_move(tmp_path, "trapezohedron_10", lambda r: any(
        "set off again" in why for why in r.info.get("recoveries", ())))
    assert edge and any("set off again" in why for why in edge[-1].info.get("recoveries", ())), [
        r.reason for r in edge if not r.ok]
    assert not [r.reason for r in edge if not r.ok and "set off past it" in r.reason]
    assert _within_bounds(ep)


@pytest.mark.xfail(strict=False, reason=(
    "two face moves of this episode whose rolls ran to their limit sliding on the face they left (moves 20 and 23) "
    "now go on sliding to their edge: the moves differ from there, and none of the first 27 sets off past the slot "
    "(every component stays within its bounds)"))
def test_an_edge_move_that_sets_off_past_a_gap_in_its_line_sets_off_again_inside_the_edge(tmp_path):
    # cad_slotted of the sized formula corpus, seed 1: the 27th move, along a top edge whose explored interval ended
    # 10 mm short of the slot, returned next to the edge 40 mm past that interval, beyond the 30 mm slot, on the
    # collinear edge across it; it followed that edge to its far end, and the interval, extended there, spanned the
    # slot, 21 bounds past the edge's end (the verification refused it: no-match). A ridge acquired more than the
    # pad's radius past the explored interval now sends the pad back to the interval's middle to set off again.
    ep, results = _moves("cad_slotted", 1, _sized_corpus(tmp_path), 27)
    edge = [r for r in results if r.move is not None and r.move.kind == "edge"]
    again = [r for r in edge if any("past the edge's explored interval" in w for w in r.info.get("recoveries", ()))]
    assert again and all(r.ok for r in again), [r.reason for r in again]
    assert _within_bounds(ep)


def test_a_verification_whose_every_candidate_the_hand_cannot_make_ends_without_a_move(tmp_path):
    # FRAME01 at 30 mm, seed 1 (perception_report.py --sizes 30): every verification candidate but vertex moves whose
    # circles leave their corner was left out, and those the hand cannot make at all; the planner, left with no move
    # to head for the nearest missing feature with, raised instead of saying so
    spec = EpisodeSpec(model="FRAME01", seed=1, executor="physics", models=_scaled_library(tmp_path, 0.03))
    rec = run_episode(spec)
    assert not (rec.recognized and not rec.correct), rec.detail


def test_a_vertex_move_round_a_valleys_end_circles_clear_of_the_valleys_other_face():
    # LBLOCK01 seed 2 (physics_episodes.py --verify none): once the edge moves located the ends of the L's valley,
    # a vertex move set off to circle one of them across the L's floor; the circle (8 mm) lies nearer the valley than
    # the pad (12 mm) can touch the floor without meeting the wall, and the touch timed out ("could not reach the
    # face next to the vertex: timeout/limit"). The circle now starts where the pad clears the wall.
    results = []
    obs = EpisodeObserver(on_move=lambda n, r, *a: results.append(r), on_failed_move=lambda n, r: results.append(r))
    ep = build_episode(EpisodeSpec(model="LBLOCK01", seed=2, executor="physics", max_moves=4))
    ep.run(None, obs)
    circles = [r for r in results if r.move is not None and r.move.kind == "vertex"
               and any("valley's end" in w for w in r.info.get("recoveries", ()))]  # fmt: skip
    assert circles and all(r.ok for r in circles), [r.reason for r in circles]
    assert _within_bounds(ep)


def test_a_vertex_circle_that_rolled_round_the_vertex_crosses_again_out_along_the_edge_clear_of_it(tmp_path):
    # bipyramid_08 of the sized formula corpus (130 mm), seed 1: the fifth move circled the apex at 8 mm and met
    # the next edge 8.7 mm from it; the pad (12 mm) rolled round the apex, and the next face touched afresh was
    # another round it. The shift told by the roll's lean ran back toward the apex, the start lay off the face, and
    # the move failed ("no edge between the faces: ... (a roll round a vertex)"). It now crosses again out along the
    # edge, from the vertex circled through where the circle met it, the pad's radius and more clear of the vertex.
    ep, results = _moves("bipyramid_08", 1, _sized_corpus(tmp_path), 5)
    vertex = [r for r in results if r.move is not None and r.move.kind == "vertex"]
    again = [r for r in vertex if any("clear of the vertex" in w for w in r.info.get("recoveries", ()))]
    assert again and all(r.ok for r in again), [r.reason for r in vertex]
    assert _within_bounds(ep)


def test_a_stroke_on_a_face_leaning_under_that_a_finger_link_stops_tilts_the_hand(tmp_path):
    # antiprism_03 of the sized formula corpus (78 mm), seed 1, default options: a vertex move and three face moves
    # rolled over an edge onto a face leaning 24° under; every leg of the stroke there ended within a millimetre, the
    # finger's distal link meeting the edge above and lifting the pad off, and so did every touch of it afresh past
    # the edge: four moves failed "too few contacts on the next face". The hand now tilts away from the link's
    # contact and strokes the face again, which measures it.
    ep, rec, said, failed = _watched(EpisodeSpec(model="antiprism_03", seed=1, executor="physics",
                                                 models=_sized_corpus(tmp_path)))  # fmt: skip
    assert any("met the object: the hand tilted" in x and "next face" in x for x in said), said
    assert not [x for x in failed if "too few contacts" in x], failed
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert _within_bounds(ep)


def test_a_stroke_on_the_next_face_stopped_by_another_link_tilts_the_tilted_hand_anew(tmp_path):
    # antiprism_05 of the sized formula corpus, seed 1, default options: a face move whose trace the distal link
    # stopped went on with the hand tilted away from it; past the edge the medial link met the face it left as the
    # pad stepped onto the next face, every leg ended within a millimetre and the move failed "too few contacts on
    # the next face". The hand tilts anew, away from the medial link's contact, and the stroke measures the face.
    ep, rec, said, failed = _watched(EpisodeSpec(model="antiprism_05", seed=1, executor="physics",
                                                 models=_sized_corpus(tmp_path)))  # fmt: skip
    assert any("next face, the finger's index_medial met the object: the hand tilted" in x for x in said), said
    assert not [x for x in failed if "too few contacts" in x], failed
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert _within_bounds(ep)


def test_a_stroke_riding_the_far_rim_of_a_narrow_next_face_keeps_the_face_within_its_bound(tmp_path):
    # bipyramid_12 of the formula corpus at 30 mm, seed 2 (perception_report.py --corpus --sizes 30 --first-seed 2):
    # a vertex move at the apex crossed onto a triangle 6.2 mm wide and stroked it along the edge crossed, the first
    # half of the stroke 0.1-0.5 mm from the triangle's other long edge, its sensed normal leaning 1.75° toward it:
    # the face 0.88° off, 1.06 bounds (the only component outside its bounds in the 300 episodes on aec5f4b). The
    # steady rows split by 6.7 σ; the face's bound covers both halves (SegmentBounds.steady_lean_sigmas).
    ep, _, _ = _replay(tmp_path, "bipyramid_12", 0.03, 6, corpus=True, seed=2)
    assert len(ep.executor.components) > 11
    assert _within_bounds(ep)


def test_a_face_move_onto_a_narrow_face_near_its_apex_crosses_again_square_where_it_is_wider(tmp_path):
    # trapezohedron_12 of the sized formula corpus (77 mm), seed 1, default options: the verification asked five
    # face moves across long edges of its kites (20° at the apex) 3.2-7.4 mm from the apex, where the next kite is
    # 1.2-2.7 mm wide. The roll settled on it, the stroke stepped onto the rim of its other edge, and the face
    # touched afresh was one round the apex: "no edge between the faces: ... (a roll round a vertex)". The shift
    # told by the lean of the roll's normals (noise alone) ran on past the apex, the start lay off the face, and the
    # episode stalled with 7 vertices not measured. The face touched afresh cuts the edge at the apex and leans
    # toward it: the move crosses again square to the edge, out where the kite is wide enough. With the short edges
    # crossed at their middles that verification goes another way; bipyramid_11 (seed 1), whose triangles narrow to
    # 20° at its apexes, makes such a crossing, and is replayed until a face move has crossed again square to the
    # edge.
    spec = EpisodeSpec(model="bipyramid_11", seed=1, executor="physics", models=_sized_corpus(tmp_path))
    ep = build_episode(spec)
    said, failed = _until_recovery(ep, "face", "square to it", fails="a roll round a vertex")
    assert said and not failed, failed
    assert _within_bounds(ep)


def test_a_face_move_that_slid_into_the_edges_end_at_a_glancing_angle_crosses_again_square_to_it(tmp_path):
    # prism_09 of the sized formula corpus, seed 1, default options: a face move slid up a side face 11° from the
    # top edge it met and met it at its vertex, 0.2 mm from the end; the pad rolled round the vertex ("no edge between
    # the faces: ... (a roll round a vertex)"). Crossed again 9 mm inside the edge along the same heading, the slide
    # rode the edge's rim at that glancing angle back to the same vertex, twice, and the move failed. It now crosses
    # again square to the edge, and the episode is replayed until a face move has done so.
    spec = EpisodeSpec(model="prism_09", seed=1, executor="physics", models=_sized_corpus(tmp_path))
    ep = build_episode(spec)
    said, failed = _until_recovery(ep, "face", "square to it", fails="a roll round a vertex")
    assert said and not failed, failed
    assert "lean" in said[0], said
    assert _within_bounds(ep)


def test_a_vertex_move_onto_a_narrow_triangle_near_its_apex_crosses_again_square_where_it_is_wider(
    tmp_path, monkeypatch
):
    # bipyramid_11 of the sized formula corpus (55 mm), seed 1, default options: late in the verification a vertex
    # circle met a long edge 7.5 mm from the apex, where the next triangle (20° there) is 2.8 mm wide. The roll
    # settled on it, the stroke found too little of it, the face touched afresh was one round the apex, and the
    # shift told by the roll's own lean ran back toward the apex: "no edge between the faces: ... (a roll round a
    # vertex)". The circle now crosses again square to the edge, out where the triangle is wide enough, as a face
    # move does. With the ridge checks beside a third face that episode goes another way; bipyramid_10 (seed 1)
    # makes such a circle, and is replayed until a vertex move has crossed again square to the edge. An earlier
    # circle of that episode now crosses a third time farther out (its crossing made again rolled round the apex
    # too) and the episode goes another way: the replay makes it as recorded, that rule switched off.
    from haptic.executor.physics import PhysicsExecutor

    clear = PhysicsExecutor._clear_of_vertex
    monkeypatch.setattr(PhysicsExecutor, "_clear_of_vertex", lambda self, n_f, corner, vtx, rolled=None:
                        clear(self, n_f, corner, vtx))  # fmt: skip
    spec = EpisodeSpec(model="bipyramid_10", seed=1, executor="physics", models=_sized_corpus(tmp_path))
    ep = build_episode(spec)
    said, _ = _until_recovery(ep, "vertex", "square to it")
    assert said
    assert _within_bounds(ep)


def test_a_vertex_move_whose_crossing_made_again_rolled_round_the_apex_too_crosses_farther_out(tmp_path):
    # bipyramid_11 of the sized formula corpus, seed 1, default options: a vertex circle round an apex of eleven
    # triangles met an edge 7.9 mm from it, where the next triangle is 2.7 mm wide; the pad rolled round the apex
    # ("no edge between the faces: ... (a roll round a vertex)"), the crossing made again 18.4 mm out rolled round
    # it too, and the last one, the pad's radius plus 6 mm from the vertex, crossed 18.0 mm out, the same: the move
    # failed. The last crossing now lies 6 mm farther out than the one made again, and the episode is replayed until
    # a vertex move has crossed so.
    spec = EpisodeSpec(model="bipyramid_11", seed=1, executor="physics", models=_sized_corpus(tmp_path))
    ep = build_episode(spec)
    said, failed = _until_recovery(ep, "vertex", "clear of the vertex", fails="a roll round a vertex")
    assert said and not failed, failed
    assert _within_bounds(ep)


def test_a_roll_round_a_vertex_down_to_the_tables_clearance_crosses_again_inside_the_edge(tmp_path):
    # platonic_octahedron of the sized formula corpus, seed 1: the first face move traced the level top face into an
    # edge at its vertex; the pad rolled round the vertex and down the faces there to the table's clearance, 20 mm
    # below where it met the edge, and no edge came from the roll ("the roll turned about more than one axis"): the
    # move failed. It now crosses again farther inside the edge, away from that vertex, and measures the edge and
    # the next face within their bounds.
    ep, results = _moves("platonic_octahedron", 1, _sized_corpus(tmp_path), 1)
    face = [r for r in results[1:] if r.move is not None and r.move.kind == "face"]  # the start aside
    assert face and face[0].ok, face[0].reason if face else results
    assert any("the table's clearance before the next face" in x and "crossed again" in x
               for x in face[0].info.get("recoveries", ())), face[0].info
    assert _within_bounds(ep)


def test_a_face_measured_tilted_that_reads_off_when_touched_upright_is_touched_again_tilted(tmp_path):
    # bipyramid_08 of the sized formula corpus, seed 1: a vertex move measured a face leaning 17° under with the hand
    # tilted 30° away from a link of the finger that met the object. The next two face moves returned to that face
    # upright, 3 mm from its upper edge, and read normals 13-18° off it: "could not return to the current face", twice.
    # A face measured tilted is touched again tilted the same way when the upright touch reads off it, as when the
    # upright approach fails. The episode is stopped at its seventh move.
    class Seen(Exception):
        pass

    said, failed = [], []

    def on_move(n, r, *a) -> None:
        said.extend(x for x in r.info.get("recoveries", ()) if "touched again with the hand tilted" in x)
        if n >= 7:
            raise Seen

    def on_failed(n, r) -> None:
        failed.append(r.reason)
        if n >= 7:
            raise Seen

    ep = build_episode(EpisodeSpec(model="bipyramid_08", seed=1, executor="physics", models=_sized_corpus(tmp_path)))
    with pytest.raises(Seen):
        ep.run(None, EpisodeObserver(on_move=on_move, on_failed_move=on_failed))
    assert said and not any(w.startswith("could not return to the current face") for w in failed), failed
    assert _within_bounds(ep)


@pytest.mark.slow
def test_a_face_move_whose_ridge_acquisition_meets_a_slots_wall_acquires_it_again_a_pads_radius_away(tmp_path):
    # cad_slotted of the sized formula corpus, seed 1, default options: face moves up the floor of its slot (30 mm
    # wide, for the 24 mm pad) crossed the top edge 12.6 mm from a wall; the stroke on the top face left the pad 7 mm
    # from the wall, and rolling back onto the ridge to check the edge the pad met the wall's rim and never settled:
    # four moves failed "no edge between the faces: acquiring the ridge: limit". The ridge is now acquired again a
    # pad's radius from where the pad met the wall, back toward the crossing. The episode is stopped once a face
    # move has done so.
    spec = EpisodeSpec(model="cad_slotted", seed=1, executor="physics", models=_sized_corpus(tmp_path))
    ep = build_episode(spec)
    said, failed = _until_recovery(ep, "face", "acquired again a pad's radius from it", fails="acquiring the ridge")
    assert said and not failed, failed
    assert _within_bounds(ep)


@pytest.mark.slow
def test_a_slide_down_a_tall_face_held_by_the_fingers_on_the_top_goes_on_level(tmp_path):
    # BOX01 at 150 mm on an end, seed 1 (perception_report.py --sizes 150): a face move slid down a side face 150 mm
    # tall, and 100 mm below the top the middle and ring fingers came to rest on the top face and held the hand
    # ("trace across the face: blocked"; the same move failed so on BOX01N and BOX01P at 150 mm). The slide goes on
    # nearly level, as when the table stops it, to the edge at the face's side.
    ep, failed, results = _replay(tmp_path, "BOX01", 0.15, 8)
    said = [w for r in results for w in (r.info or {}).get("recoveries", ())]
    assert not failed, [r.reason for r in failed]
    assert any("rested on the object above: the slide went on level" in w for w in said), said
    assert _within_bounds(ep)


@pytest.mark.slow
def test_a_face_move_whose_ridge_probe_meets_a_slots_wall_follows_back_from_where_it_set_off():
    # BOX01N seed 2 (physics_episodes.py --verify full) stands on an end with its slot upright, 30 mm wide for the 24
    # mm pad. A face move up the slot's floor crossed its top edge; following the ridge to check the edge, the way
    # out met a wall after 1.5 mm and left the pad's contact on the wall's rim, and the way back pressed there until
    # its time ran out: "no edge along the roll's axis (the ridge spans 1.5 mm: a vertex?)". A way back that finds no
    # ridge now sets off again from the ridge acquired again where the way out began. The episode is stopped once a
    # face move has done so.
    ep = build_episode(EpisodeSpec(model="BOX01N", seed=2, executor="physics", verify="full"))
    said, failed = _until_recovery(ep, "face", "the pad found none: acquired again where it set off",
                                   fails="no edge along the roll's axis")  # fmt: skip
    assert said and not failed, failed
    assert _within_bounds(ep)


@pytest.mark.slow
def test_a_way_over_the_top_held_below_the_height_it_crosses_at_goes_round_once(tmp_path):
    # cad_slotted of the sized formula corpus, seed 1, default options: a reposition into the slot went round over
    # the top and was held with the finger's distal link on the object 10 mm below the height the way was to cross
    # at. Taken round a second time, clear of the highest point touched (as for BOX01N at 150 mm, whose links rested
    # on the top face's rim 55 mm above that height), the episode went another way: 50 moves instead of 42, and the
    # verification ended "incomplete after 44 moves: ... 1 vertices ... not measured". A way over the top goes round
    # again only when a link touches the object above the height it was to cross at, and the verification measures
    # every vertex in the hand's reach.
    rec = run_episode(EpisodeSpec(model="cad_slotted", seed=1, executor="physics", models=_sized_corpus(tmp_path)))
    assert rec.verified["reach_complete"], rec.detail
    assert rec.perception["outside_bounds"] == 0


@pytest.mark.slow
def test_a_ridge_check_heading_down_stops_at_the_tables_clearance():
    # HEXPRISM01 seed 1 (physics_episodes.py --verify full) lies on a side. A face move across a side leaning under
    # crossed onto an end and checked the edge between them, which runs down to the table at 60°: the way out
    # followed the ridge 4.7 mm on down, the pad into the table's clearance, resting on the table and the ridge at
    # once, and the way back lost the contact after 1.9 mm: "no edge between the faces: following the edge: lost",
    # and the move after it failed too. Such a check is made again, the ridge followed down no farther than the
    # table's clearance.
    ep, rec, said, failed = _watched(EpisodeSpec(model="HEXPRISM01", seed=1, executor="physics", verify="full"))
    assert not [w for w in failed if "following the edge" in w], failed
    assert any("followed again no lower than the table's clearance" in w for w in said), said
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert _within_bounds(ep)


@pytest.mark.slow
def test_a_vertex_move_onto_a_face_leaning_under_measures_it_by_several_short_ls(monkeypatch):
    # HEXPRISM01 seed 3 (physics_episodes.py --verify full) lies on a side. A vertex move circled a top corner of an
    # end and rolled, the hand tilted away from the end, onto a side leaning under 30°: the stroke's step in was held
    # by the distal link, and five touches afresh past the edge read the side's normal, but each L's legs along the
    # edge were stopped by the distal link on the ridge above within 1.5 mm, and three L's first legs, 1-3 mm long
    # and 5-10 mm apart, each measured too little of the face: "stroke on the next face failed: blocked". Such Ls
    # that agree measure the face together. The episode is stopped once a vertex move has done so. An L touched
    # afresh that a link stopped is now made again with the hand tilted away from the link, which measures the side
    # at the first touch (test_a_vertex_move_onto_a_side_leaning_under_measures_it_tilted_past_the_ridge): switched
    # off here, the Ls measure it together as before.
    from haptic.executor.physics import PhysicsExecutor

    real = PhysicsExecutor._stroke_tilted
    monkeypatch.setattr(PhysicsExecutor, "_stroke_tilted",
                        lambda self, *a, step_in=None: None if step_in is not None else real(self, *a))  # fmt: skip
    ep = build_episode(EpisodeSpec(model="HEXPRISM01", seed=3, executor="physics", verify="full"))
    said, failed = _until_recovery(ep, "vertex", "Ls touched afresh together",
                                   fails="stroke on the next face failed")  # fmt: skip
    assert said and not failed, failed
    assert _within_bounds(ep)


@pytest.mark.parametrize(("model", "moves"), [("cad_lbracket", 1), ("hull_06", 4)])
def test_a_next_face_lost_after_a_slanted_crossing_is_touched_afresh_in_the_rolls_frame(tmp_path, model, moves):
    # hull_06 of the sized formula corpus, seed 1: the fourth move slid across the top 20° off the line of the edge it
    # crossed, 2.8 mm from the edge's end; the roll read the next face 0.7° off and the edge 0.5° off, but the stroke
    # there ran into the corner (its rows spanning 1.4 mm), and the touches afresh, the edge taken square to the
    # travel (70° off it), read the rims round the corner six times: "too few contacts on the next face". cad_lbracket,
    # seed 1: the first move crossed the top's edge onto an inner wall of the L 8 mm from its inner corner, 22° off
    # square; touched afresh so, the pad read rims or nothing. Touched afresh once more with the edge as the roll
    # measured it, both measure the next face (hull_06 clear of the edge's end, cad_lbracket straight down the wall).
    from haptic.executor.physics import NEXT_FACE_LOST

    results = []
    obs = EpisodeObserver(on_move=lambda n, r, *a: results.append(r), on_failed_move=lambda n, r: results.append(r))
    ep = build_episode(EpisodeSpec(model=model, seed=1, executor="physics", verify="full",
                                   models=_sized_corpus(tmp_path), max_moves=moves))  # fmt: skip
    ep.run(None, obs)
    face = [r for r in results if r.move is not None and r.move.kind == "face"]
    rolled = [r for r in face if any("the edge as the roll measured it" in x for x in r.info.get("recoveries", ()))]
    assert rolled and all(r.ok for r in rolled), [r.reason for r in face]
    assert not any(r.reason.startswith(NEXT_FACE_LOST) for r in face if not r.ok), [r.reason for r in face]
    assert _within_bounds(ep)


@pytest.mark.slow
def test_the_way_over_to_the_tracing_posture_recovers_from_a_joint_at_its_limit():
    # square_antiprism of the public polyhedra (117 mm), seed 1, default options: the verification's last probes went
    # by the reach solver's path, which starts in the tracing posture with the pad 55 mm higher than where it had
    # risen to, 6 cm beyond the object's middle; straight up from there the arm's posture pulled the pad 2.6 cm off its
    # line with nothing touching, and the move failed "moving over to the tracing posture: blocked", four probes in a
    # row (by the index and the thumb). Up as every rise goes (by the arm's home posture where a joint holds it
    # back), the first probe is made and the recognition confirmed in fewer moves.
    failed = []
    obs = EpisodeObserver(on_failed_move=lambda n, r: failed.append(f"{r.move.kind}: {r.reason}"))
    rec = run_episode(EpisodeSpec(model="square_antiprism", models="assets/libraries/polyhedra", seed=1,
                                  executor="physics"), observer=obs)  # fmt: skip
    assert rec.outcome == "recognized" and rec.correct, rec.detail
    assert not any("tracing posture" in why for why in failed), failed
    assert rec.probes >= 1


@pytest.mark.slow
def test_a_face_move_across_a_face_between_two_shallow_edges_reports_no_edge(tmp_path):
    # metabiaugmented_hexagonal_prism at 70 mm, seed 1: a face move slid from one pyramid's triangle over a
    # 5.3° edge, across the 26 mm square beside it and over another 5.3° edge onto the other pyramid's triangle,
    # where the normal had turned 10.5° from the first face: "an edge", its roll too quick to leave contacts between
    # the faces' normals, placed where the two triangles' planes meet, in the middle of the square, 13 bounds off
    # every true edge. The true interpretation, the one pose class left for the 36 moves before, was eliminated
    # (no-match). The roll's contacts lie 13 mm from that line: no edge between the faces.
    # (the public polyhedra's prism alone in its library: its first 42 moves are those of the 28 solids' episode)
    shutil.copy("assets/libraries/polyhedra/metabiaugmented_hexagonal_prism.obj", tmp_path)
    ep, rec, _, failed = _watched(EpisodeSpec(model="metabiaugmented_hexagonal_prism", seed=1, executor="physics",
                                              verify="full", models=str(tmp_path)))  # fmt: skip
    assert any("the pad crossed a face between them" in w for w in failed), failed
    assert _within_bounds(ep)
    assert rec.outcome != "no-match", rec.detail


@pytest.mark.slow
def test_a_move_that_slid_over_an_edge_too_shallow_to_feel_reports_the_face_it_rolled_off(tmp_path):
    # metabiaugmented_hexagonal_prism at 70 mm, seed 1 (alone in its library): face and vertex moves slide from a
    # square of the prism over its 5.3° edge onto a pyramid's triangle and roll over the triangle's next edge. The
    # edge was taken between the square and the face past the roll, its rolling normals leaning 2.4-3.6° along that
    # line: no edge between faces that share none, and the move failed ("a roll round a vertex"). The slide's last
    # steady rows are the triangle's: the move reports that face (adjacent to nothing: the shallow edge was not
    # located), the edge between it and the next face, and that face, every one within its bounds.
    shutil.copy("assets/libraries/polyhedra/metabiaugmented_hexagonal_prism.obj", tmp_path)
    crossed, failed = [], []
    obs = EpisodeObserver(on_move=lambda n, r, *a: crossed.append(r) if "crossed_face" in r.info else None,
                          on_failed_move=lambda n, r: failed.append(r.reason))  # fmt: skip
    ep = build_episode(EpisodeSpec(model="metabiaugmented_hexagonal_prism", seed=1, executor="physics",
                                   verify="full", models=str(tmp_path)))  # fmt: skip
    rec = ep.run(None, obs)
    assert crossed, failed
    for r in crossed:
        face, edge, _ = r.components
        assert face.id == r.info["crossed_face"] and face.kind == "face" and face.adjacent == ()
        assert edge.kind == "edge" and edge.adjacent[-1] == face.id
    assert _within_bounds(ep)
    assert rec.outcome != "no-match", rec.detail


def test_a_step_onto_the_next_face_stopped_by_the_table_gives_the_edge_alone(tmp_path):
    # augmented_triangular_prism of the public polyhedra at 30 mm, seed 1: face moves rolled over an edge onto a
    # side face whose strip above the table was narrower than the pad's step onto it; the step met the table, and
    # two moves failed "stepping onto the next face, the pad met the table at the edge". The roll had turned over
    # the edge: the move now gives the edge from it alone, as where the roll itself reaches the table's clearance
    from haptic.geometry import load_library
    from haptic.geometry.io import save_model
    from haptic.geometry.perturb import scaled_to

    for name, poly in load_library("assets/libraries/polyhedra").items():
        save_model(scaled_to(poly, 0.03, name), tmp_path / f"{name}.json")
    alone, failed = [], []
    obs = EpisodeObserver(on_move=lambda n, r, *a: alone.extend([r] if (r.info or {}).get("next_face") else []),
                          on_failed_move=lambda n, r: failed.append(r.reason))  # fmt: skip
    ep = build_episode(EpisodeSpec(model="augmented_triangular_prism", seed=1, executor="physics", verify="full",
                                   models=str(tmp_path)))  # fmt: skip
    rec = ep.run(None, obs)
    assert not any(why.startswith("stepping onto the next face, the pad met the table") for why in failed), failed
    assert alone, "no edge reported alone"
    assert rec.outcome != "no-match" and _within_bounds(ep)


def test_an_l_bracket_on_its_foot_is_told_apart_by_the_foots_top_and_its_verification_stalls_on_its_target(tmp_path):
    # part_lbracket of scripts/make_parts.py (the foot 40 mm long and 10 mm thick, the leg 60 mm tall), seed 1:
    # standing on its foot, two poses turned 180° about the leg were left after 4 moves, "differ only where no finger
    # reaches" -- but the foot's top is touched from above, and a slide down the leg meets it 10 mm above the table.
    # Now one pose is left; the verification measures the vertices off the table it can, and the four at the foot's
    # top ends it, 16 moves after the last vertex it measured, rather than tracing the top's edges on and on.
    import sys
    from pathlib import Path

    from haptic.planning.verify import HAND_STALL_MOVES

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    import make_parts

    assert make_parts.main([str(tmp_path / "parts")]) == 0
    rec = run_episode(EpisodeSpec(model="part_lbracket", seed=1, executor="physics", models=str(tmp_path / "parts")))
    assert rec.classes[-1] == 1 and "no finger reaches" not in rec.detail
    v = rec.verified
    assert v["status"] == "incomplete" and v["vertices_reachable"] - v["vertices"] == 4, rec.detail
    assert v["moves"] <= 2 * HAND_STALL_MOVES
