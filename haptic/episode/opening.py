"""The opening sequence of an episode (seed §4.1): a face move, an edge move, a vertex move, each in a random
admissible direction, away from the table when there is one; with free-space probes alone (``--moves probing``),
probes from a spread of directions toward the object's region until the hypotheses have poses (and on, toward the
faces not measured yet, while the tree is too large for the probe matcher to test hits by position); with both
(``--moves all``), until the hypotheses have poses, each new face by the cheaper way (:func:`cheaper_opening`):
the tracing opening from where the sensor is, up to its next move that measures a face, or a probe."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from haptic.matching.components import DataFace
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import CostModel, Move, ProbeMove
from haptic.planning.opening_probes import LibraryExtent, opening_probes, region_centre
from haptic.planning.policies import same_move
from haptic.planning.predict import candidate_moves
from haptic.planning.probe_lines import ProbeConfig
from haptic.planning.table import table_safe_moves, vertex_sweep_off_table

OPENING_PROBE_CHOICES = 3
"""The opening probe is drawn from this many of the best-ranked lines not yet tried
(:func:`~haptic.planning.opening_probes.opening_probes`)."""


def opening_move(
    kind: str,
    state,
    components,
    config: PlannerConfig,
    rng: np.random.Generator,
    avoid: tuple = (),
    hypotheses: tuple = (),
) -> Move | None:
    """The seed's initial sequence (§4.1): a face move, an edge move, a vertex move, each in a random
    admissible direction (not one that already failed from here). With a table (``config.table_z``), away
    from it: not a move the data or the hypotheses predict to run into it, and among the rest those heading
    up rather than down (face and edge moves) or whose vertex circle stays clear of it."""
    moves = [
        m for m in candidate_moves(state, components, config)
        if m.kind == kind and not any(same_move(m, bad) for bad in avoid)
    ]
    if not moves:
        return None
    if config.table_z is not None:
        moves = away_from_table(table_safe_moves(moves, hypotheses, state, components, config), state,
                                 components, config)  # fmt: skip
    return moves[int(rng.integers(len(moves)))]


def away_from_table(moves: list[Move], state, components, config: PlannerConfig) -> list[Move]:
    """The moves of ``moves`` that head away from the table: face moves and edge moves not heading down by
    more than ~12°; vertex moves whose circle can sweep half a turn off the table (else the widest sweep)."""
    if not moves:
        return moves
    if moves[0].kind == "vertex":
        sweep = np.array([vertex_sweep_off_table(state, components, m.across_face, config) for m in moves])
        keep = sweep >= np.pi if (sweep >= np.pi).any() else sweep >= sweep.max() - 1e-9
        return [m for m, k in zip(moves, keep, strict=True) if k]
    if moves[0].kind == "face":
        up = np.array([float(m.direction[2]) for m in moves])
    else:
        b = components[state.edge].direction
        up = np.array([m.sense * float(b[2]) for m in moves])
    keep = up >= -0.2 if (up >= -0.2).any() else up >= up.max() - 1e-9
    return [m for m, k in zip(moves, keep, strict=True) if k]


def opening_probe(
    components,
    extent: LibraryExtent,
    config: PlannerConfig,
    rng: np.random.Generator,
    avoid: tuple = (),
    unmeasured: bool = False,
) -> ProbeMove | None:
    """A probe of the opening while the hypotheses have no poses yet (the tree pairs each hit with model faces
    by the face-pair angle, §2.6, and the distance of parallel faces, until three independent normals fix the
    poses): a random one of :func:`opening_choices`; None when none is left."""
    lines = opening_choices(components, extent, config, avoid, unmeasured)
    return lines[int(rng.integers(len(lines)))] if lines else None


def opening_choices(
    components, extent: LibraryExtent, config: PlannerConfig, avoid: tuple = (), unmeasured: bool = False
) -> list[ProbeMove]:
    """The :data:`OPENING_PROBE_CHOICES` best lines of :func:`~haptic.planning.opening_probes.opening_probes` toward the
    region the data faces leave for the object, less the lines already probed or failed (``avoid``)."""
    faces = _data_faces(components)
    cfg = ProbeConfig(table_z=config.table_z, table_clearance=config.table_clearance)
    lines = [m for m in opening_probes(faces, extent, cfg, unmeasured) if not any(same_move(m, bad) for bad in avoid)]
    return lines[:OPENING_PROBE_CHOICES]


def _data_faces(components) -> list[DataFace]:
    """The data faces among ``components`` (a mapping by id or a sequence)."""
    comps = components.values() if hasattr(components, "values") else components
    return [c for c in comps if isinstance(c, DataFace)]


def tracing_opening_cost(
    kinds: list[str], extent: LibraryExtent, config: PlannerConfig, edge_run: float | None = None
) -> float:
    """Expected cost of the opening's tracing moves ``kinds`` up to and including the first that measures a new
    face (a face move or a vertex move: §4, each ends acquiring a normal; an edge move measures a vertex only),
    from the library's averages (:class:`~haptic.planning.opening_probes.LibraryExtent`): a face move
    ``c_f · face_run + c_j + c_b + c_n``, an edge move ``c_e · edge_run + c_k`` (``edge_run`` the one given,
    :func:`edge_run_of` the edge the sensor is on, else the library's), a vertex move
    ``c_v · r_v · corner_angle + c_j + c_b + c_n`` (``r_v`` the vertex circle's radius) [units]."""
    c: CostModel = config.costs
    if edge_run is not None:
        extent = replace(extent, edge_run=edge_run)
    cost = 0.0
    for kind in kinds:
        if kind == "face":
            return cost + c.face_move(extent.face_run)
        if kind == "vertex":
            return cost + c.vertex_move(config.vertex_radius * extent.corner_angle)
        cost += c.edge_move(extent.edge_run)
    return cost


def opening_probe_cost(move: ProbeMove, position: np.ndarray, components, extent: LibraryExtent,
                       config: PlannerConfig) -> float:  # fmt: skip
    """Expected cost of an opening probe from the sensor at ``position``: ``c_p + c_s s``, ``s`` the transfer to
    the line's start and the run along it to the expected contact, ``depth`` before the point of the line
    nearest the region's estimated centre (:func:`~haptic.planning.opening_probes.region_centre`) [units]."""
    faces = _data_faces(components)
    start, u = np.asarray(move.start, dtype=float), np.asarray(move.direction, dtype=float)
    run = float((region_centre(faces, extent) - start) @ u) - extent.depth
    run = min(max(run, 0.0), float(move.length))
    return config.costs.probe_move(float(np.linalg.norm(start - np.asarray(position, dtype=float))) + run)


def cheaper_opening(
    kinds: list[str],
    state,
    components,
    extent: LibraryExtent,
    config: PlannerConfig,
    rng: np.random.Generator,
    avoid: tuple = (),
    edge_run: float | None = None,
) -> ProbeMove | None:
    """The opening of ``--moves all`` measures each new face the cheaper way: an opening probe
    (:func:`opening_probe`) when its expected cost (:func:`opening_probe_cost`, the mean over
    :func:`opening_choices`, whichever of them is drawn) is below that of the remaining tracing moves ``kinds``
    up to the next face (:func:`tracing_opening_cost`); None: the next tracing move. The generator is drawn
    from only when a probe is chosen."""
    lines = opening_choices(components, extent, config, avoid)
    if not lines:
        return None
    probe = float(np.mean([opening_probe_cost(m, state.position, components, extent, config) for m in lines]))
    if probe >= tracing_opening_cost(kinds, extent, config, edge_run):
        return None
    return lines[int(rng.integers(len(lines)))]


def tracing_remainder(state) -> list[str]:
    """The seed's opening sequence (§4.1) from the sensor's state: a vertex move at a vertex, an edge move then
    a vertex move on an edge, else a face move, an edge move and a vertex move."""
    if state.vertex is not None:
        return ["vertex"]
    if state.edge is not None:
        return ["edge", "vertex"]
    return ["face", "edge", "vertex"]


def edge_run_of(tree, edge_id: int) -> float | None:
    """Expected length of an edge move along data edge ``edge_id`` to the edge's end, from where along it the
    sensor met it unknown: half the length of the model edge each interpretation pairs it with, averaged over
    the interpretations (None without any) [m]."""
    if tree.count == 0:
        return None
    return 0.5 * float(tree.library.edge_length[tree.assignments[:, edge_id]].mean())
