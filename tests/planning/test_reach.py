"""What the fingertip can reach of an object on the table, and when two hypotheses differ only out of reach."""

import numpy as np

from haptic.geometry import SE3, Polyhedron, load_library
from haptic.planning.config import PlannerConfig
from haptic.planning.reach import indistinguishable, observable_edges, reachable

LIB = load_library()
CFG = PlannerConfig(table_z=0.0, max_undercut=np.deg2rad(30.0))
UPRIGHT, UPSIDE_DOWN = np.eye(3), np.diag([1.0, -1.0, -1.0])


def resting(poly, rotation):
    low = (poly.vertices @ rotation.T)[:, 2].min()
    return SE3(rotation, np.array([0.2, 0.1, -low]))


def shallow_slot(depth: float) -> Polyhedron:
    """BOX01N with its slot ``depth`` deep instead of 20 mm."""
    slotted = LIB["BOX01N"]
    v = slotted.vertices.copy()
    v[np.isclose(v[:, 2], 0.04), 2] = 0.06 - depth
    return Polyhedron.from_faces(v, [list(f) for f in slotted.faces], name="SHALLOW")


def test_a_shallow_slot_facing_the_table_is_out_of_reach():
    # 5 mm deep against the table: the pad cannot come down the side far enough to roll over the slot's edge
    box, slotted = LIB["BOX01"], shallow_slot(0.005)
    assert indistinguishable(box, resting(box, UPSIDE_DOWN), slotted, resting(slotted, UPSIDE_DOWN), CFG)
    assert len(observable_edges(slotted, resting(slotted, UPSIDE_DOWN), CFG)) == 0


def test_a_deep_slot_facing_the_table_shows_its_edge_on_the_sides():
    # 20 mm deep: the pad slides down a side to the slot's edge and rolls over it (the slot's ceiling leans
    # under out of reach): the edge alone tells BOX01N from BOX01
    box, slotted = LIB["BOX01"], LIB["BOX01N"]
    pose = resting(slotted, UPSIDE_DOWN)
    ridge = observable_edges(slotted, pose, CFG)
    assert len(ridge) >= 8 and np.allclose(ridge[:, 2], 0.02)
    assert not indistinguishable(box, resting(box, UPSIDE_DOWN), slotted, pose, CFG)
    assert len(observable_edges(box, resting(box, UPRIGHT), CFG)) == 0  # a box's bottom edges touch the table


def test_a_slot_on_top_is_in_reach():
    box, slotted = LIB["BOX01"], LIB["BOX01N"]
    assert not indistinguishable(box, resting(box, UPRIGHT), slotted, resting(slotted, UPRIGHT), CFG)


def test_a_shifted_pose_is_told_apart():
    box = LIB["BOX01"]
    a = resting(box, UPRIGHT)
    b = SE3(a.rotation, a.translation + np.array([0.005, 0.0, 0.0]))
    assert not indistinguishable(box, a, box, b, CFG)


def test_the_bottom_and_the_strip_next_to_the_table_are_not_reachable():
    box = LIB["BOX01"]
    pts, nrm = reachable(box, resting(box, UPRIGHT), CFG)
    assert len(pts) > 100
    assert pts[:, 2].min() > CFG.pad_radius  # sides only above the pad's reach of the table
    assert (nrm[:, 2] > -0.5).all()  # nothing on the bottom face
    assert np.isclose(pts[:, 2].max(), 0.06)  # the top face is reachable
