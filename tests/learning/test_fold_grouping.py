"""The grouping of data faces into planes at a shallow fold: a vertex moved a few millimetres folds its faces by
under a degree, so near the fold a touched point and its normal agree with both halves' planes. Which half a
face is on is then told by the side of the fold's measured edge it lies on, and a face touched at the fold
itself by the data edges that divide it from faces of one half -- not by the order the faces came in."""

import numpy as np
import pytest

from haptic.learning.reconstruct import _merge_agreeing, at_shallow_folds, edge_faces, face_planes
from haptic.matching.components import DataEdge, DataFace
from tests.learning.test_fold import FOLDED

NORMAL_BOUND = 0.0157
POSITION_BOUND = 0.6e-3
HALVES = (0, 1)
"""FOLDED's base: faces 0 and 1, folded by 0.35° along their shared edge."""


def fold_edge() -> tuple[np.ndarray, np.ndarray]:
    """The ends of the edge between the base's halves."""
    m = FOLDED
    e = next(k for k in range(m.n_edges) if {int(m.edge_left_face[k]), int(m.edge_right_face[k])} == set(HALVES))
    p, q = m.vertices[m.edges[e]]
    return p, q


def off_fold(rng: np.random.Generator, half: int, clear: float = 5e-3) -> np.ndarray:
    """A point of the base's half ``half`` at least ``clear`` from the fold's line, off its plane by up to 0.2 mm."""
    m = FOLDED
    tri = m.vertices[list(m.faces[half])]
    p, q = fold_edge()
    d = (q - p) / np.linalg.norm(q - p)
    while True:
        x = rng.dirichlet(np.ones(3)) @ tri
        r = x - p
        if np.linalg.norm(r - (r @ d) * d) >= clear:
            return x + rng.uniform(-2e-4, 2e-4) * m.face_normals[half]


def touched(fid: int, half: int, points: np.ndarray, adjacent: tuple[int, ...] = ()) -> DataFace:
    return DataFace(fid, FOLDED.face_normals[half], np.asarray(points), NORMAL_BOUND, POSITION_BOUND, adjacent)


def fold_data_edge(eid: int, at: float, sides: tuple[tuple[int, int], ...], length: float = 6e-3) -> DataEdge:
    """A data edge ``length`` long on the fold's line from fraction ``at`` of it, its side points ``(face id,
    half)`` 3 mm off the line on each half (a face move that stops at the fold, an edge move along it)."""
    p, q = fold_edge()
    d = (q - p) / np.linalg.norm(q - p)
    start = p + at * (q - p)
    side_points = []
    for fid, half in sides:
        inward = np.cross(FOLDED.face_normals[half], d)
        c = FOLDED.vertices[list(FOLDED.faces[half])].mean(axis=0)
        inward = inward if (c - start) @ inward > 0 else -inward
        side_points.append((fid, start + 3e-3 * d + 3e-3 * inward))
    return DataEdge(eid, d, start, length, NORMAL_BOUND, POSITION_BOUND, POSITION_BOUND,
                    adjacent=tuple(f for f, _ in sides), side_points=tuple(side_points))  # fmt: skip


def halves_of(planes, truth: dict[int, int]) -> list[set[int]]:
    """The halves (of ``truth``: data face id → half) each plane's faces are on."""
    return [{truth[f] for f in p.faces} for p in planes]


@pytest.mark.parametrize("seed", range(6))
def test_the_halves_of_a_fold_are_grouped_by_the_side_of_its_edge(seed):
    """Faces of both halves in an order that grouped them by arrival: the first of one half and the first of the
    other agree and start one plane, and the edge then measured between two more starts a second. Grouped by
    the side of the measured edge (traced along the fold), each plane holds the faces of one half."""
    rng = np.random.default_rng(seed)
    order = [0, 1, 0, 1, 1, 0, 0, 1, 0, 1]  # the half of each data face, in the order they came in
    comps: dict = {}
    truth: dict[int, int] = {}
    for fid, half in enumerate(order):
        comps[fid] = touched(fid, half, [off_fold(rng, half), off_fold(rng, half)])
        truth[fid] = half
    # two edges on the fold, each between a face of either half
    length = float(np.linalg.norm(np.subtract(*fold_edge())))
    comps[20] = fold_data_edge(20, 0.3, ((2, 0), (3, 1)))
    comps[21] = fold_data_edge(21, 0.05, ((5, 0), (4, 1)), 0.9 * length)
    planes = face_planes(comps)
    assert sorted(map(sorted, halves_of(planes, truth))) == [[0], [1]]


@pytest.mark.parametrize("seed", range(6))
def test_a_face_touched_at_the_fold_is_grouped_by_the_edges_that_divide_it(seed):
    """A face touched only on the fold's line (a move along it), the first after one half's first face, and
    divided by a data edge from a later face of that half: it agrees with both halves' planes, and joining the
    half it came after would leave that half's later faces a plane of their own. It joins the other half."""
    rng = np.random.default_rng(seed)
    p, q = fold_edge()
    on_line = np.array([p + 0.45 * (q - p), p + 0.5 * (q - p)])
    comps: dict = {0: touched(0, 1, [off_fold(rng, 1), off_fold(rng, 1)]),
                   1: touched(1, 0, on_line, adjacent=(30,))}  # fmt: skip
    truth = {0: 1, 1: 0}
    for fid, half in enumerate([1, 0, 1, 0, 1, 0], start=2):
        comps[fid] = touched(fid, half, [off_fold(rng, half), off_fold(rng, half)])
        truth[fid] = half
    length = float(np.linalg.norm(q - p))
    comps[30] = fold_data_edge(30, 0.45, ((1, 0), (2, 1)))  # the face on the line, and one of the half after
    comps[31] = fold_data_edge(31, 0.05, ((3, 0), (4, 1)), 0.9 * length)
    assert at_shallow_folds(comps, [c for c in comps.values() if isinstance(c, DataFace)], edge_faces(comps)) == {1}
    planes = face_planes(comps)
    assert len(planes) == 2
    assert sorted(map(sorted, halves_of(planes, truth))) == [[0], [1]]


@pytest.mark.parametrize("seed", range(4))
def test_one_halfs_faces_left_in_two_groups_are_merged(seed):
    """Moving faces one at a time to the plane each fits best can leave one half of a fold in two groups: the one a
    data edge divides from a face of the other half and the one none does. Two groups no data edge divides whose
    faces all agree with one plane are one plane; the other half, divided from both by data edges, stays apart."""
    rng = np.random.default_rng(seed)
    comps: dict = {}
    truth: dict[int, int] = {}
    for fid, half in enumerate([1, 1, 0, 0, 0, 1, 1]):
        comps[fid] = touched(fid, half, [off_fold(rng, half), off_fold(rng, half)])
        truth[fid] = half
    comps[20] = fold_data_edge(20, 0.3, ((2, 0), (1, 1)))
    comps[21] = fold_data_edge(21, 0.6, ((4, 0), (6, 1)))
    ef = edge_faces(comps)
    apart = {f: {g for fs in ef.values() if f in fs for g in fs if g != f} for f in truth}
    groups = [[comps[0], comps[1]], [comps[2], comps[3], comps[4]], [comps[5], comps[6]]]
    merged = _merge_agreeing(groups, apart)
    assert sorted(sorted(truth[f.id] for f in g) for g in merged) == [[0, 0, 0], [1, 1, 1, 1]]
    # divided by a data edge, the two groups of half 1 stay two
    comps[22] = fold_data_edge(22, 0.5, ((0, 1), (5, 1)))
    ef = edge_faces(comps)
    apart = {f: {g for fs in ef.values() if f in fs for g in fs if g != f} for f in truth}
    assert len(_merge_agreeing(groups, apart)) == 3
