"""A face trace solves exactly only the sides it can meet: the same hits, to the last bit, as solving every side."""

import numpy as np

import haptic.geometry.tracing as tracing
from haptic.geometry import load_library
from haptic.geometry.generate import generate_library


def _traces(models, rng, n):
    out = []
    for _ in range(n):
        m = models[int(rng.integers(len(models)))]
        f = int(rng.integers(m.n_faces))
        start = tracing.random_face_point(m, f, rng, margin=float(rng.choice([0.0, 0.002])))
        if rng.random() < 0.2:  # from a corner or along a side
            k = int(rng.integers(len(m.faces[f])))
            start = m.vertices[m.faces[f][k]].copy()
        d = rng.normal(size=3)
        if rng.random() < 0.2:
            e = m.face_edges[f][int(rng.integers(len(m.face_edges[f])))]
            d = m.edge_directions[e] * rng.choice([1, -1]) + rng.normal(size=3) * float(rng.choice([0.0, 1e-9, 1e-4]))
        out.append((m, f, start, d))
    return out


def test_trace_face_meets_what_solving_every_side_meets(monkeypatch):
    rng = np.random.default_rng(3)
    models = list(load_library().values()) + generate_library(10, seed=7)
    cases = _traces(models, rng, 3000)
    fast = [tracing.trace_face(m, f, p, d) for m, f, p, d in cases]
    monkeypatch.setattr(tracing, "_MARGIN", np.inf)  # no side left out
    full = [tracing.trace_face(m, f, p, d) for m, f, p, d in cases]
    met = 0
    for a, b in zip(fast, full, strict=True):
        assert (a is None) == (b is None)
        if a is not None:
            met += 1
            assert (a.edge, a.next_face, a.distance) == (b.edge, b.next_face, b.distance)
            np.testing.assert_array_equal(a.point, b.point)
    assert met > 2000
