"""The reach solver: targets for one to four fingertips, a configuration and a path inside the joint limits and
off the table, or a typed reason."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from conftest import BOX_CENTRE, box_parts, box_pose

from haptic.errors import SceneError
from haptic.sim.reach import FingertipTarget, ReachFailure, ReachSettings, ReachSolver
from haptic.sim.scene import FINGERS, TABLE_TOP_Z, compose_scene, scene_object_from_parts

DOWN = np.array([0.0, 0.0, -1.0])


@pytest.fixture(scope="module")
def solver() -> ReachSolver:
    return ReachSolver(compose_scene(None))


@pytest.fixture(scope="module")
def with_box() -> ReachSolver:
    """The solver with a hypothesised box on the table (the object it is asked about, not a ground truth)."""
    box = scene_object_from_parts("box", box_parts())
    return ReachSolver(compose_scene(box, box_pose()))


def pad_positions(solver: ReachSolver, qpos: np.ndarray) -> dict[str, np.ndarray]:
    cfg = solver.configuration
    cfg.update(qpos)
    out = {}
    for f in FINGERS:
        sid = mujoco.mj_name2id(solver.model, mujoco.mjtObj.mjOBJ_SITE, solver.site_name(f))
        out[f] = cfg.data.site_xpos[sid].copy()
    return out


def assert_path_is_admissible(solver: ReachSolver, path: np.ndarray) -> None:
    lo, hi = solver.model.jnt_range[:, 0], solver.model.jnt_range[:, 1]
    assert np.all(path >= lo - 1e-6) and np.all(path <= hi + 1e-6)
    clearances = [solver.table_clearance(q) for q in path]
    assert min(clearances) >= -1e-4, f"a step of the path enters the table by {-min(clearances) * 1000:.2f} mm"


def test_one_fingertip_over_the_table_is_reached_along_an_admissible_path(solver):
    target = np.array([0.60, 0.05, TABLE_TOP_Z + 0.06])
    r = solver.solve([FingertipTarget("index", target, DOWN)])
    assert r.ok, r.detail
    assert r.reason is None
    assert np.linalg.norm(pad_positions(solver, r.qpos)["index"] - target) < solver.settings.position_tol
    assert r.approach_error[0] < solver.settings.approach_tol
    assert len(r.path) >= 2
    assert_path_is_admissible(solver, r.path)


def test_four_fingertips_at_once(solver):
    centre = np.array([0.58, 0.0, TABLE_TOP_Z + 0.08])
    offsets = {"index": [0, 0.035, 0], "middle": [0, 0, 0], "ring": [0, -0.035, 0], "thumb": [0.04, 0.02, 0]}
    targets = [FingertipTarget(f, centre + np.array(o)) for f, o in offsets.items()]
    r = solver.solve(targets)
    assert r.ok, r.detail
    pads = pad_positions(solver, r.qpos)
    for t in targets:
        assert np.linalg.norm(pads[t.finger] - t.point_in_world) < solver.settings.position_tol
    assert_path_is_admissible(solver, r.path)


def test_a_target_beyond_the_arm_is_outside_the_workspace(solver):
    r = solver.solve([FingertipTarget("index", np.array([2.5, 0.0, 0.8]))])
    assert not r.ok
    assert r.reason is ReachFailure.WORKSPACE
    assert "mm from the shoulder" in r.detail


def test_a_target_under_the_table_top_is_refused_for_the_table_and_the_path_stays_above_it(solver):
    r = solver.solve([FingertipTarget("index", np.array([0.60, 0.0, TABLE_TOP_Z - 0.02]), DOWN)])
    assert not r.ok
    assert r.reason is ReachFailure.TABLE
    assert "table" in r.detail
    assert_path_is_admissible(solver, r.path)


def test_a_target_inside_the_hypothesised_object_is_refused_for_the_object(with_box):
    r = with_box.solve([FingertipTarget("index", BOX_CENTRE, DOWN)])
    assert not r.ok
    assert r.reason is ReachFailure.OBJECT, r.detail
    assert "object" in r.clearance


def test_the_pad_may_touch_the_hypothesised_object_it_is_sent_to(with_box):
    top = BOX_CENTRE + [0.0, 0.0, 0.03 + 0.012]  # the pad resting on the box's top face
    r = with_box.solve([FingertipTarget("index", top, DOWN)])
    assert r.ok, r.detail


def test_without_an_object_the_solver_knows_none(solver):
    assert "object" not in solver.solve([FingertipTarget("index", np.array([0.6, 0.0, 0.45]))]).clearance


@pytest.mark.parametrize(
    ("targets", "message"),
    [
        ([], "no fingertip targets"),
        ([FingertipTarget("pinky", np.zeros(3))], "valid fingers: index, middle, ring, thumb"),
        ([FingertipTarget("index", np.zeros(3)), FingertipTarget("index", np.ones(3))], "one target a finger"),
    ],
)
def test_bad_targets_are_named(solver, targets, message):
    with pytest.raises(SceneError, match=message):
        solver.solve(targets)


def test_the_fingertips_may_come_nearer_the_table_than_the_other_links():
    """A pad 8 mm over the table: refused where every link keeps 20 mm from it, reached where the target finger's
    fingertip (its distal link and pad) keeps 3 mm, with every other link still 20 mm clear along the path."""
    from haptic.sim.scene import PAD_RADIUS

    target = [FingertipTarget("index", np.array([0.60, 0.05, TABLE_TOP_Z + PAD_RADIUS + 0.008]), DOWN)]
    strict = ReachSolver(compose_scene(None), ReachSettings(clearance=0.02))
    r = strict.solve(target)
    assert not r.ok and r.reason is ReachFailure.TABLE, r.detail
    tips = ReachSolver(compose_scene(None), ReachSettings(clearance=0.02, tip_table_clearance=0.003))
    r = tips.solve(target)
    assert r.ok, r.detail
    body, near = tips._table_sets(["index"])
    assert len(near) == 2  # the index finger's distal link and pad
    table = tips._table_geoms
    for q in r.path:
        tips.configuration.update(q)
        assert tips._distance(body, table) > 0.02 - 1e-3
        assert tips._distance(near, table) > 0.003 - 1e-3
    tips.configuration.update(r.qpos)
    assert tips._distance(near, table) < 0.02  # the fingertip came nearer than the others may


def test_with_hold_clearance_the_path_keeps_its_clearance_from_the_object():
    """Two pads sent to either side of a hypothesised box, 25 mm off its sides, from the tracing posture above it:
    with ``hold_clearance`` no configuration of the path brings a link nearer the box than its clearance less that
    (the linearised limits alone let links pass within millimetres of it)."""
    box = scene_object_from_parts("box", box_parts())
    settings = ReachSettings(clearance=0.02, pads_touch=False, hold_clearance=0.005)
    solver = ReachSolver(compose_scene(box, box_pose()), settings)
    side = BOX_CENTRE + [0.0, 0.0, 0.01]
    targets = [FingertipTarget("index", side + [0.0, 0.065, 0.0], np.array([0.0, -1.0, 0.0])),
               FingertipTarget("thumb", side + [0.0, -0.065, 0.0], np.array([0.0, 1.0, 0.0]))]  # fmt: skip
    r = solver.solve(targets)
    assert len(r.path) > 5
    obj = solver._object_geoms
    least = []
    for q in r.path:
        solver.configuration.update(q)
        least.append(solver._distance(solver._hand_geoms, obj))
    assert min(least) >= 0.02 - 0.005 - 1e-3, f"{min(least) * 1000:.1f} mm"
