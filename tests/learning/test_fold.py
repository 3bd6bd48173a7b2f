"""A fold: a vertex moved almost in its face's plane splits the face in two at a fraction of a degree. The two
planes a data edge divides are fitted through the edge the data measured (else their noisy line of intersection
lies centimetres off it), and the convex estimate whose planes meet four at a corner is still planned in."""

import numpy as np

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import Polyhedron, save_model
from haptic.learning.reconstruct import FOLD_FACTOR, face_planes
from haptic.matching.components import DataEdge, DataFace, DataVertex

# PYR01 with its vertex 2 moved 4 mm, almost in the base's plane: the base folds by 0.35° along its diagonal 1-3
FOLDED = Polyhedron.from_faces(
    np.array([[-0.05, -0.04, 0.0], [0.05, -0.04, 0.0], [0.052729563, 0.042912408, 0.000259551], [-0.05, 0.04, 0.0],
              [0.0, 0.0, 0.07]]),
    [[3, 2, 1], [3, 1, 0], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]], name="PYR01_FOLDED",
)  # fmt: skip



def fold_faces(rng: np.random.Generator) -> tuple[dict, np.ndarray, np.ndarray]:
    """The base's two halves as data faces (six points each, off their planes by up to 0.2 mm, naming data edge 2)
    and the ends of the fold's edge."""
    m = FOLDED
    a, b = 0, 1  # the two halves of the base
    e = next(k for k in range(m.n_edges) if {int(m.edge_left_face[k]), int(m.edge_right_face[k])} == {a, b})
    comps = {}
    for i, f in enumerate((a, b)):
        tri = m.vertices[list(m.faces[f])]
        w = rng.dirichlet(np.ones(3), size=6)
        pts = w @ tri + rng.uniform(-2e-4, 2e-4, size=(6, 1)) * m.face_normals[f]
        comps[i] = DataFace(i, m.face_normals[f], pts, 0.0157, 0.6e-3, adjacent=(2,))
    p, q = m.vertices[m.edges[e]]
    return comps, p, q

def off_line(planes, points) -> list[float]:
    """The distances of ``points`` from the line where the two ``planes`` meet [m]."""
    assert len(planes) == 2
    n1, n2 = planes[0].normal, planes[1].normal
    direction = np.cross(n1, n2)
    direction /= np.linalg.norm(direction)
    x, *_ = np.linalg.lstsq(np.array([n1, n2, direction]), np.array([planes[0].offset, planes[1].offset, 0.0]),
                            rcond=None)  # fmt: skip
    return [float(np.linalg.norm((e - x) - ((e - x) @ direction) * direction)) for e in points]


def test_a_fold_is_fitted_through_its_measured_edge():
    """Two faces at 0.35° with points off their planes by up to 0.2 mm, and the edge between them measured: the
    planes' line of intersection passes within the edge's bound of the edge's ends."""
    angle = np.arccos(FOLDED.face_normals[0] @ FOLDED.face_normals[1])
    assert angle < FOLD_FACTOR * 2 * 0.0157
    comps, p, q = fold_faces(np.random.default_rng(3))
    d = (q - p) / np.linalg.norm(q - p)
    comps[2] = DataEdge(2, d, p + 0.01 * d, float(np.linalg.norm(q - p)) - 0.02, 0.0157, 0.6e-3, 0.6e-3,
                        adjacent=(0, 1))  # fmt: skip
    assert max(off_line(face_planes(comps), (comps[2].point, comps[2].end_point))) < 0.6e-3


def test_a_fold_is_fitted_through_the_vertices_measured_at_its_edge_ends():
    """The edge measured over 20 mm in its middle, its direction tilted by its bound, and the vertices at both
    its ends measured: the traced boundary's planes' line runs through the vertices, not along the short
    stretch's tilt (which over the 13 cm diagonal would put the line 1 mm off at its ends)."""
    comps, p, q = fold_faces(np.random.default_rng(5))
    length = float(np.linalg.norm(q - p))
    d = (q - p) / length
    side = np.cross(d, FOLDED.face_normals[0])
    tilted = d + 0.0157 * side
    tilted /= np.linalg.norm(tilted)
    mid = 0.5 * (p + q)
    comps[2] = DataEdge(2, tilted, mid - 0.01 * tilted, 0.02, 0.0157, 0.6e-3, 0.6e-3, start_vertex=None,
                        end_vertex=None, adjacent=(0, 1))  # fmt: skip
    comps[3] = DataVertex(3, p, 0.6e-3, adjacent=(2,))
    comps[4] = DataVertex(4, q, 0.6e-3, adjacent=(2,))
    assert max(off_line(face_planes(comps, fold_vertices=True), (p, q))) < 0.6e-3


def test_a_folded_pyramid_is_learned_with_both_halves_of_its_base(tmp_path):
    """The whole learning episode (seed of the bench's run that ran out of its 150 moves, counting only the
    learning's own and never ending): closed in a few moves, with the fold's two faces."""
    path = tmp_path / "PYR01_FOLDED.json"
    save_model(FOLDED, path)
    rec = run_episode(EpisodeSpec(model=str(path), seed=309580410, noise=1.0, learn=str(tmp_path / "lib"),
                                  learn_name="FOLDED"))  # fmt: skip
    learned = rec.learned
    assert rec.outcome == "no-match" and learned["status"] == "closed", learned
    assert (learned["V"], learned["E"], learned["F"]) == (5, 9, 6)
    assert learned["moves"] < 40
