"""The opening sequence of an episode (seed §4.1): a face move, an edge move, a vertex move, each in a random
admissible direction, away from the table when there is one; with free-space probes alone (``--moves probing``),
probes from a spread of directions toward the object's region until the hypotheses have poses."""

from __future__ import annotations

import numpy as np

from haptic.matching.components import DataFace
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import Move, ProbeMove
from haptic.planning.policies import same_move
from haptic.planning.predict import candidate_moves
from haptic.planning.probes import LibraryExtent, ProbeConfig, opening_probes
from haptic.planning.table import table_safe_moves, vertex_sweep_off_table

OPENING_PROBE_CHOICES = 3
"""The opening probe is drawn from this many of the best-ranked lines not yet tried
(:func:`~haptic.planning.probes.opening_probes`)."""


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
) -> ProbeMove | None:
    """A probe of the opening of ``--moves probing``, while the hypotheses have no poses yet (the tree pairs
    each hit with model faces by the face-pair angle, §2.6, and the distance of parallel faces, until three
    independent normals fix the poses): a random one of the :data:`OPENING_PROBE_CHOICES` best lines of
    :func:`~haptic.planning.probes.opening_probes` toward the region the data faces leave for the object,
    less the lines already probed or failed (``avoid``); None when none is left."""
    comps = components.values() if hasattr(components, "values") else components
    faces = [c for c in comps if isinstance(c, DataFace)]
    cfg = ProbeConfig(table_z=config.table_z, table_clearance=config.table_clearance)
    lines = [m for m in opening_probes(faces, extent, cfg) if not any(same_move(m, bad) for bad in avoid)]
    if not lines:
        return None
    return lines[int(rng.integers(min(OPENING_PROBE_CHOICES, len(lines))))]
