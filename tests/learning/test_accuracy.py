"""A learned model is as accurate as the bounds it carries: every measured vertex holds each plane through the
estimate's vertex it measures, not only the planes its data edges lie between."""

import numpy as np

from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import Polyhedron, load_model, save_model
from haptic.geometry.se3 import quat_to_matrix

# TETRA01R with its vertex 1 moved 2 mm
MOVED = Polyhedron.from_faces(
    np.array([[0.0, 0.0, 0.0], [-0.101703543, -0.000799432, -0.000677384], [-0.025, 0.08, 0.0], [-0.035, 0.025, 0.07]]),
    [[1, 2, 0], [3, 1, 0], [3, 2, 1], [3, 0, 2]], name="TETRA01R_MOVED",
)  # fmt: skip



def learned_and_recognised(model: Polyhedron, seed: int, again: int, tmp_path) -> tuple[dict, float, str | None]:
    """Learn ``model`` in the episode of ``seed`` into an empty library, then explore it at ``again`` with that
    library: the learning's record, the largest distance of a learned vertex from the true ones [m], and the
    model recognised the second time."""
    obj = tmp_path / f"{model.name}.json"
    save_model(model, obj)
    lib = tmp_path / "lib"
    lib.mkdir()
    rec = run_episode(EpisodeSpec(model=str(obj), seed=seed, noise=1.0, learn=str(lib), learn_name="L"))
    assert rec.learned["status"] == "closed"
    learned = load_model(rec.learned["path"])
    r, t = quat_to_matrix(np.array(rec.pose["quat_wxyz"])), np.array(rec.pose["translation_m"])
    truth = np.asarray(model.vertices) @ r.T + t
    off = np.linalg.norm(np.asarray(learned.vertices)[:, None] - truth[None], axis=2).min(axis=1)
    second = run_episode(EpisodeSpec(model=str(obj), seed=again, noise=1.0, models=str(lib)))
    return rec.learned, float(off.max()), second.recognized

def test_a_plane_touched_near_one_corner_is_held_by_the_vertices_measured_on_it(tmp_path):
    """Seed 1858836761 closes the surface in the recognition episode itself; one face was touched along a strip
    4 mm wide, and the vertex at its far corner was reached along the other two faces' edges. Fitted without
    it, that face tilted 0.5 degrees and put the vertex 1.36 mm off the truth; the learned file says 0.6 mm."""
    _, off, recognised = learned_and_recognised(MOVED, 1858836761, 1723552086, tmp_path)
    assert off < 1e-3
    assert recognised == "L"


# WEDGE01 with its vertex 0 moved 2 mm along its vertex normal: its two faces there fold by a fraction of a degree
MOVED_WEDGE = Polyhedron.from_faces(
    np.array([[-0.001154701, -0.001154701, -0.001154701], [0.1, 0.0, 0.0], [0.0, 0.0, 0.06], [0.0, 0.08, 0.0],
              [0.1, 0.08, 0.0], [0.0, 0.08, 0.06]]),
    [[0, 1, 2], [5, 4, 3], [1, 0, 3], [3, 4, 1], [4, 5, 2, 1], [3, 0, 2], [5, 3, 2]], name="WEDGE01_MOVED",
)  # fmt: skip


def test_a_traced_fold_runs_through_the_vertices_at_its_ends(tmp_path):
    """Seed 266112162: the object is traced as non-convex, and its two folds were measured as short stretches of
    edge; fitted through those alone, the folds' planes put a vertex 1.18 mm off and the tree lost the learned
    model's interpretation in 4 of 5 later episodes (no-match)."""
    learned, off, recognised = learned_and_recognised(MOVED_WEDGE, 266112162, 2093225279, tmp_path)
    assert not learned["convex"]
    assert off < 1e-3
    assert recognised == "L"
