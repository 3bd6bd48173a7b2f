"""scripts/pad_shadow.py: how deep a free pad clear of the table feels a vertex's moves apart from the model."""

import importlib.util
from pathlib import Path

import numpy as np

from haptic.geometry import SE3, load_library
from haptic.geometry.perturb import move_vertex
from haptic.geometry.shapes import box

ROOT = Path(__file__).resolve().parents[1]
TABLE = 0.35
RADIUS = 0.012


def _script():
    spec = importlib.util.spec_from_file_location("pad_shadow", ROOT / "scripts" / "pad_shadow.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _on_table(poly) -> SE3:
    return SE3(np.eye(3), np.array([0.55, 0.0, TABLE - poly.vertices[:, 2].min()]))


def _corner(poly, z: float) -> int:
    return int(np.flatnonzero(np.all(np.isclose(poly.vertices, [0.0, 0.0, z]), axis=1))[0])


def test_a_low_box_corner_on_the_table_is_not_felt_and_a_tall_ones_is():
    """A box 8 mm high: a pad clear of the table (its lowest point 2 mm up) pressing the box's walls has its centre
    14 mm up, over the box, and touches nothing of the walls' corners at a bottom vertex; no move of that vertex is
    felt (the table's shadow). A box 30 mm high: the same move tilts the walls' corners up to 30 mm, where the pad
    presses them, and is felt by about the wall's tilt there."""
    ps = _script()
    low = box(0.06, 0.04, 0.008)
    v = _corner(low, 0.0)
    for mm in (2, 4, 8):
        depth, faces = ps.felt(low, move_vertex(low, v, mm * 1e-3), _on_table(low), TABLE, RADIUS)
        assert depth <= ps.FELT and faces == []
    tall = box(0.06, 0.04, 0.03)
    v = _corner(tall, 0.0)
    depth, faces = ps.felt(tall, move_vertex(tall, v, 0.004), _on_table(tall), TABLE, RADIUS)
    walls = {int(f) for f in tall.vertex_faces[v] if abs(tall.face_normals[int(f)][2]) < 0.5}
    assert depth > ps.FELT and set(faces) <= walls and faces


def test_a_slot_corner_moved_in_its_end_faces_plane_is_felt_at_the_slots_rim():
    """BOX01N standing on its bottom, the slot up: its slot's floor corner on the front face, moved 4 mm along the
    slot (in the front face's plane, which stays), moves the rim of the front face at the slot's mouth, where a pad
    pressing the front face from outside feels it."""
    ps = _script()
    poly = load_library()["BOX01N"]
    v = 4  # (65, 0, 40): the slot's floor meets its wall and the front face
    front = 0
    moves = dict(ps.moves_of(poly, v))
    assert all(m is not None for name, m in moves.items() if name.startswith("normal"))
    along = next(name for name in moves if name.startswith("+n") and abs(poly.face_normals[int(name[2:].split()[0])]
                                                                          @ poly.face_normals[front]) < 1e-9)
    depth, faces = ps.felt(poly, moves[along], _on_table(poly), TABLE, RADIUS)
    assert depth > ps.FELT and front in faces


def test_the_scripts_episodes_are_the_pairs_or_every_object_at_every_seed_and_a_bad_item_is_named():
    import pytest

    from haptic.episode.spec import episode_pairs
    from haptic.errors import HapticError

    assert episode_pairs("BOX01N:1,FRAME01:3", None, "1", lambda: []) == [("BOX01N", 1), ("FRAME01", 3)]
    assert episode_pairs(None, "A,B", "1,2", lambda: []) == [("A", 1), ("A", 2), ("B", 1), ("B", 2)]
    assert episode_pairs(None, None, "3", lambda: ["X"]) == [("X", 3)]
    with pytest.raises(HapticError, match="BOX01N"):
        episode_pairs("BOX01N", None, "1", lambda: [])


def test_out_of_reach_is_the_verifications_hidden_vertices_before_any_move():
    """The scripts' vertices out of reach at an episode's true pose are those the verification's own test counts
    hidden when nothing is measured yet: FRAME01 standing on a side (seed 1), the corners of its hole."""
    from types import SimpleNamespace

    from haptic.episode.spec import EpisodeSpec
    from haptic.episode.worlds import build_episode
    from haptic.planning.verify import hidden_vertices, out_of_reach

    ep = build_episode(EpisodeSpec(model="FRAME01", seed=1, executor="physics", verify="full"))
    poly, pose, cfg = ep.true_model, ep.world_from_model, ep.config
    reach, hidden, unpinned = out_of_reach(poly, pose, cfg)
    cov = SimpleNamespace(reachable_vertices=reach[2], vertices=set())
    assert hidden == hidden_vertices(poly, pose, cov, cfg) == list(range(8, 16))
    assert all(isinstance(v, int) for v in unpinned)
