"""The matcher's library arrays: per-model neighbour lists equal to whole-library adjacency, built once."""

import numpy as np
import pytest

from haptic.geometry import load_library
from haptic.geometry.generate import generate_library
from haptic.matching.library import LibraryArrays


def _dense(lib: LibraryArrays) -> dict:
    """Whole-library adjacency straight from the definitions (the reference for small libraries)."""
    nf, ne, nv = (lib.count(k) for k in range(3))
    fe = np.zeros((nf, ne), bool)
    fe[lib.edge_left_face, np.arange(ne)] = True
    fe[lib.edge_right_face, np.arange(ne)] = True
    ev = np.zeros((ne, nv), bool)
    ev[np.arange(ne), lib.edge_source] = ev[np.arange(ne), lib.edge_dest] = True
    fv = np.zeros((nf, nv), bool)
    for i, m in enumerate(lib.models):
        for f, loop in enumerate(m.faces):
            fv[lib.offsets[0, i] + f, np.asarray(loop) + lib.offsets[2, i]] = True
    ff = (fe.astype(int) @ fe.T.astype(int)) > 0
    ee = (ev.astype(int) @ ev.T.astype(int)) > 0
    vv = (ev.T.astype(int) @ ev.astype(int)) > 0
    for a in (ff, ee, vv):
        np.fill_diagonal(a, False)
    return {(0, 0): ff, (0, 1): fe, (0, 2): fv, (1, 0): fe.T, (1, 1): ee, (1, 2): ev, (2, 0): fv.T, (2, 1): ev.T,
            (2, 2): vv}  # fmt: skip


@pytest.mark.parametrize("source", ["seed", "generated"])
def test_neighbour_lists_match_whole_library_adjacency(source):
    models = load_library() if source == "seed" else generate_library(12, seed=3)
    lib = LibraryArrays(tuple(models.values()) if isinstance(models, dict) else tuple(models))
    for key, dense in _dense(lib).items():
        table = lib.neighbors[key]
        for i, row in enumerate(dense):
            got = table[i][table[i] >= 0]
            assert np.array_equal(got, np.flatnonzero(row)), (key, i)  # ascending, as the tree's order needs
        i, j = np.nonzero(np.ones_like(dense))
        assert np.array_equal(lib.adjacency[key][i, j], dense[i, j])
    f, e = np.meshgrid(np.arange(lib.count(0)), np.arange(lib.count(1)), indexing="ij")
    expect = np.where(lib.edge_left_face[e] == f, 1, np.where(lib.edge_right_face[e] == f, -1, 0))
    assert np.array_equal(lib.side[f, e], expect)
    # no component is adjacent to a component of another model
    for (a, b), table in lib.neighbors.items():
        rows = np.repeat(np.arange(len(table)), table.shape[1]).reshape(table.shape)
        ok = table >= 0
        assert np.array_equal(lib.model_of[a][rows[ok]], lib.model_of[b][table[ok]])


def test_built_once_per_library_content():
    a = LibraryArrays.build(load_library())
    assert LibraryArrays.build(load_library()) is a  # equal content, new objects: the same arrays
    other = LibraryArrays.build(load_library("assets/libraries/lookalike"))
    assert other is not a and other.n_models == 34
    assert LibraryArrays.build(list(load_library().values())[:3]) is not a
