"""A move carried out exactly in one hypothesis's world (noiseless): the data it would produce and the sensor
state it would end in. The look-ahead (:mod:`haptic.planning.search`) predicts the next moves from there; the
candidate filter of :mod:`haptic.planning.move_scores` asks it which vertex moves only circle back.

A free-space probe (:func:`simulate_probe`) ends as the executors end one: a hit is a face touched at the
contact, adjacent to nothing known, with the sensor resting on it; a miss adds no component and leaves the
sensor where it was (it returns to the face it left). What a miss tells -- the line is free of the object --
is no component: the search carries it as the hypotheses it eliminates
(:func:`~haptic.planning.search.probe_branches`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from haptic.geometry.raycast import line_hits
from haptic.geometry.se3 import cross
from haptic.geometry.tracing import VertexHit, circle_vertex, trace_edge
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex, SensorNoise
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import EdgeMove, FaceMove, Move, ProbeMove, SensorState, VertexMove, start_state
from haptic.planning.table import hand_trace

STEP_ONTO = 0.003
"""How far onto the next face a simulated face or vertex move steps for its normal [m]."""
EDGE_PROBE = 0.004
"""Length of edge explored when an edge is first met [m]."""


def circled_vertex(h: Hypothesis, move: VertexMove, state: SensorState, config: PlannerConfig) -> VertexHit | None:
    """Where vertex move ``move`` leaves the vertex in hypothesis ``h``'s world (the edge and face beyond it); None
    when ``h`` cannot say (no pose, the edge, vertex or face not matched, no such corner), or when the move would
    only circle back to an edge and face already explored (:func:`simulate` is None for it then)."""
    if h.world_from_model is None:
        return None
    e0, v_m, a_m = (h.edges.get(state.edge), h.vertices.get(state.vertex), h.faces.get(move.across_face))
    if e0 is None or v_m is None or a_m is None:
        return None
    try:
        vh = circle_vertex(h.poly, v_m, e0, a_m, config.vertex_radius)
    except ValueError:
        return None
    if vh.edge in h.edges.values() and vh.next_face in h.faces.values():
        return None
    return vh


def simulate(
    h: Hypothesis,
    move: Move,
    state: SensorState,
    components: Mapping[int, DataComponent],
    config: PlannerConfig,
    noise: SensorNoise | None = None,
) -> tuple[Hypothesis, SensorState, dict[int, DataComponent]] | None:
    """The move carried out exactly in hypothesis ``h``'s world: its extended correspondence, the new sensor
    state and the new (noiseless) data components; None when ``h`` cannot say (no pose, meets a vertex) or
    when a vertex move would only circle back to an edge and face already explored. A probe:
    :func:`simulate_probe`."""
    state = start_state(move, state)
    if h.world_from_model is None:
        return None
    if isinstance(move, ProbeMove):
        return simulate_probe(h, move, state, components, noise)
    t = h.world_from_model
    poly = h.poly
    p_m = t.inverse().apply(state.position)
    nxt = max(components) + 1 if components else 0
    new: dict[int, DataComponent] = {}
    faces, edges, vertices = dict(h.faces), dict(h.edges), dict(h.vertices)

    k = noise.k if noise is not None else 0.0
    nb = k * noise.normal_sigma if noise is not None else 0.0
    db = k * noise.direction_sigma if noise is not None else 0.0
    pb = k * noise.position_sigma if noise is not None else 0.0
    lb = k * noise.length_sigma if noise is not None else 0.0

    def face_comp(fid: int, g: int, point_m: np.ndarray, adjacent) -> DataFace:
        return DataFace(fid, t.rotate(poly.face_normals[g]), t.apply(point_m)[None, :], nb, pb, adjacent)

    if isinstance(move, FaceMove | VertexMove):
        if isinstance(move, FaceMove):
            tr = hand_trace(h, move, state, config)
            if tr is None:
                return None
            e_m, g_m, at_m, from_face = tr.hit.edge, tr.hit.next_face, tr.hit.point, state.face
        else:
            vh = circled_vertex(h, move, state, config)
            if vh is None:
                return None  # cannot say, or circles back to an edge and face already explored
            v_m = h.vertices[state.vertex]
            e_m, g_m, from_face = vh.edge, vh.next_face, move.across_face
            away = poly.edge_directions[e_m] * (1.0 if poly.edges[e_m, 0] == v_m else -1.0)
            at_m = poly.vertices[v_m] + config.vertex_radius * away
        b_m = poly.edge_directions[e_m]
        s = float(np.clip((at_m - poly.edge_points[e_m]) @ b_m, 0.0, poly.edge_lengths[e_m]))
        lo = max(0.0, s - EDGE_PROBE / 2)
        hi = min(float(poly.edge_lengths[e_m]), s + EDGE_PROBE / 2)
        eid, fid = nxt, nxt + 1
        adj = (from_face,) if isinstance(move, FaceMove) else (state.vertex, from_face)
        inward = cross(poly.face_normals[g_m], b_m)
        if poly.edge_left_face[e_m] != g_m:
            inward = -inward
        onto = at_m + STEP_ONTO * inward
        f_from = h.faces[from_face]
        back = cross(poly.face_normals[f_from], b_m)
        if poly.edge_left_face[e_m] != f_from:
            back = -back
        sides = ((from_face, t.apply(at_m + STEP_ONTO * back)), (fid, t.apply(onto)))
        new[eid] = DataEdge(
            eid, t.rotate(b_m), t.apply(poly.edge_points[e_m] + lo * b_m), hi - lo, db, pb, lb,
            adjacent=adj, side_points=sides,
        )  # fmt: skip
        new[fid] = face_comp(fid, g_m, onto, (eid,))
        edges[eid], faces[fid] = e_m, g_m
        vertex = state.vertex if isinstance(move, VertexMove) else None
        new_state = SensorState(t.apply(onto), fid, eid, vertex, (from_face, fid))
    elif isinstance(move, EdgeMove):
        e_m = h.edges.get(state.edge)
        data_edge = components.get(state.edge)
        if e_m is None or not isinstance(data_edge, DataEdge):
            return None
        sense_m = move.sense if t.rotate(poly.edge_directions[e_m]) @ data_edge.direction > 0 else -move.sense
        eh = trace_edge(poly, e_m, p_m, sense_m)
        vid = nxt
        v_w = t.apply(poly.vertices[eh.vertex])
        b, p, length = data_edge.direction, data_edge.point, data_edge.length
        if move.sense > 0:
            ext = replace(data_edge, length=max(length, float((v_w - p) @ b)), end_vertex=vid)
        else:
            end = p + length * b
            ext = replace(data_edge, point=v_w, length=max(0.0, float((end - v_w) @ b)), start_vertex=vid)
        new[ext.id] = ext
        new[vid] = DataVertex(vid, v_w, pb, (ext.id,))
        vertices[vid] = eh.vertex
        new_state = SensorState(v_w, state.face, state.edge, vid, state.edge_faces)
    else:
        raise TypeError(f"unknown move {move!r}")
    merged = dict(components)
    merged.update(new)
    return replace(h, faces=faces, edges=edges, vertices=vertices), new_state, merged


def simulate_probe(
    h: Hypothesis,
    move: ProbeMove,
    state: SensorState,
    components: Mapping[int, DataComponent],
    noise: SensorNoise | None = None,
) -> tuple[Hypothesis, SensorState, dict[int, DataComponent]] | None:
    """Probe ``move`` carried out exactly in hypothesis ``h``'s world (the line cast at its posed model, as
    :func:`~haptic.planning.probe_prediction.predict_probes` casts it). A hit: a new data face at the contact with the
    outward normal of the model face hit (bounds from ``noise``, as every simulated face), adjacent to nothing;
    the correspondence extended by it; the sensor on it, at no edge or vertex. A miss: ``h``, ``state`` and the
    components unchanged. None when ``h`` has no pose."""
    t = h.world_from_model
    if t is None:
        return None
    inv = h.model_from_world
    s_m = inv.apply(np.asarray(move.start, dtype=float))
    u_m = inv.rotate(np.asarray(move.direction, dtype=float))
    hits = line_hits(h.poly, s_m[None], u_m[None])
    t_hit, g = float(hits.first[0]), int(hits.face[0])
    merged = dict(components)
    if not t_hit <= float(move.length) or g < 0:
        return h, state, merged
    fid = max(components) + 1 if components else 0
    k = noise.k if noise is not None else 0.0
    nb = k * noise.normal_sigma if noise is not None else 0.0
    pb = k * noise.position_sigma if noise is not None else 0.0
    contact = t.apply(s_m + t_hit * u_m)
    merged[fid] = DataFace(fid, t.rotate(h.poly.face_normals[g]), contact[None, :], nb, pb, ())
    faces = dict(h.faces)
    faces[fid] = g
    return replace(h, faces=faces), SensorState(contact, fid), merged
