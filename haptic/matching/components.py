"""Data components: what the explorer reports to the matcher (seed §2.3).

Every component has an ``id`` (its position in the order of acquisition, starting at 0), the ids of earlier
components it is known to be adjacent to, and error bounds. The same records come from the geometric
executor and from the physics executor's segmenter, so the matcher does not know which produced them.

Edges are reported with the interval actually explored: ``p`` is one end of that interval, not in general a
vertex, and ``l`` is its length. An edge may be reported again with the same id when a later move extends its
explored interval (an edge move that runs to a vertex); the matcher then re-tests the interpretations that
hold it.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from haptic.errors import HapticError


def readonly_vector(x) -> np.ndarray:
    """``x`` as a float array that cannot be written (the arrays of frozen records)."""
    a = np.array(x, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class DataFace:
    """A face touched by the sensor: a plane with an outward normal and the points touched on it."""

    id: int
    """Order of acquisition (0-based)."""
    normal: np.ndarray
    """Outward unit normal ``n_d`` in the world frame, shape (3,)."""
    points: np.ndarray
    """Contact points on the face in the world frame, shape (k, 3), k ≥ 1 [m]."""
    normal_bound: float
    """Error bound on the normal direction [rad]."""
    position_bound: float
    """Error bound on each point's distance from the true plane [m]."""
    adjacent: tuple[int, ...] = ()
    """Ids of earlier components known to be adjacent (for a face: the edges it shares)."""

    kind = "face"

    def __post_init__(self) -> None:
        object.__setattr__(self, "normal", readonly_vector(self.normal))
        object.__setattr__(self, "points", readonly_vector(np.atleast_2d(self.points)))
        object.__setattr__(self, "adjacent", tuple(int(i) for i in self.adjacent))

    @property
    def offset(self) -> float:
        """Plane offset ``d`` with ``n·w − d = 0`` from the touched points [m]."""
        return float(np.mean(self.points @ self.normal))


@dataclass(frozen=True, eq=False)
class DataEdge:
    """An explored interval of an edge: ``{p + s b : 0 ≤ s ≤ l}``."""

    id: int
    """Order of acquisition; an extended edge is re-reported with its first id."""
    direction: np.ndarray
    """Unit direction ``b_d`` along the explored interval, world frame, shape (3,)."""
    point: np.ndarray
    """``p_d``: one end of the explored interval, world frame, shape (3,) [m]."""
    length: float
    """``l_d``: length of the explored interval (≥ 0) [m]."""
    direction_bound: float
    """Error bound on the direction [rad]."""
    position_bound: float
    """Error bound on the position of the line, perpendicular to it [m]."""
    length_bound: float
    """Error bound on each end of the explored interval, along the line [m]."""
    start_vertex: int | None = None
    """Id of the data vertex at ``p`` when the interval starts at a known vertex, else None.

    A topological claim, not only a position: the true edge runs from that vertex along ``+b`` (the vertex is
    the end of the true edge at the interval's start), so the matcher pairs it with the end of the model edge
    that ``b`` points away from, and it is not covered by ``length_bound``. An executor that reaches a vertex
    moving along ``+b`` reports it as ``end_vertex`` (with the interval clipped there), moving along ``−b`` as
    ``start_vertex`` -- whatever the sign of a short interval measured near the vertex."""
    end_vertex: int | None = None
    """Id of the data vertex at ``p + l b`` when the interval ends at a known vertex (the true edge ends there,
    seen along ``+b``), else None."""
    adjacent: tuple[int, ...] = ()
    """Ids of earlier components known to be adjacent (its faces, its vertices)."""
    side_points: tuple[tuple[int, np.ndarray], ...] = ()
    """Optional ``(face id, point)`` pairs: a contact point on that face close to this edge, world frame [m].

    It tells on which side of the edge the face lies (seed §2.4: the sign of the determinant of face normal,
    edge direction and relative position). The executor knows it (where the sensor crossed onto or off the
    edge). The face may be reported after the edge. Without one, the matcher uses the face's touched point
    nearest to the explored interval."""

    kind = "edge"

    def __post_init__(self) -> None:
        object.__setattr__(self, "direction", readonly_vector(self.direction))
        object.__setattr__(self, "point", readonly_vector(self.point))
        object.__setattr__(self, "adjacent", tuple(int(i) for i in self.adjacent))
        object.__setattr__(self, "side_points", tuple((int(f), readonly_vector(q)) for f, q in self.side_points))

    @property
    def end_point(self) -> np.ndarray:
        """``p + l b`` [m]."""
        return self.point + self.length * self.direction


@dataclass(frozen=True, eq=False)
class DataVertex:
    """A vertex met by the sensor."""

    id: int
    """Order of acquisition."""
    position: np.ndarray
    """Position in the world frame, shape (3,) [m]."""
    position_bound: float
    """Error bound on the position [m]."""
    adjacent: tuple[int, ...] = ()
    """Ids of earlier components known to be adjacent (its edges)."""

    kind = "vertex"

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", readonly_vector(self.position))
        object.__setattr__(self, "adjacent", tuple(int(i) for i in self.adjacent))


DataComponent = DataFace | DataEdge | DataVertex


@dataclass(frozen=True)
class SensorNoise:
    """The sensor-noise model; error bounds are ``k`` standard deviations.

    The defaults are those of the physics notes' fingertip (σn 1°, σp 0.2 mm) at the level of a segmented
    component (fits over many samples are tighter than single samples).
    """

    normal_sigma: float = np.deg2rad(0.3)
    """Standard deviation of a face normal's direction [rad]."""
    direction_sigma: float = np.deg2rad(0.3)
    """Standard deviation of an edge direction [rad]."""
    position_sigma: float = 0.2e-3
    """Standard deviation of a position perpendicular to a component [m]."""
    length_sigma: float = 0.3e-3
    """Standard deviation of an interval end along an edge [m]."""
    k: float = 3.0
    """Error bound = k σ."""

    def scaled(self, level: float) -> SensorNoise:
        """The same model with every σ multiplied by ``level`` (0 = noiseless)."""
        return SensorNoise(
            self.normal_sigma * level,
            self.direction_sigma * level,
            self.position_sigma * level,
            self.length_sigma * level,
            self.k,
        )


@dataclass(frozen=True)
class NoiseModel:
    """The one sensor-noise model of an episode: a noise level times the fingertip's sensor noise, from which
    every noise an episode knows is derived, at two scales of one sensor:

    - per sample (``force_std``, ``normal_std``, ``point_std``, ``joint_std`` at level 1: the levels of
      docs/physics-notes.md): what the simulated sensors add to each reading
      (:meth:`haptic.sim.physics.SimulatedSensorNoise.from_model`) and what the segmenter's σ start from
      (:meth:`haptic.executor.segment.SegmentBounds.from_model`);
    - per fitted component (``component`` at level 1): the σ, hence the error bounds, of a face, edge or vertex
      fitted over many samples (:attr:`fitted`): the geometric executor's noise and the planner's outcome
      bounds.

    ``level`` multiplies every σ (0: noiseless). :func:`haptic.episode.worlds.noise_models` builds the
    simulated hand's from one model."""

    level: float = 1.0
    """Multiplies every standard deviation (``--noise``)."""
    force_std: float = 0.02
    """σF per sample at level 1: touch / contact normal force [N]."""
    normal_std: float = np.deg2rad(1.0)
    """σn per sample at level 1: contact normal direction, per tangent axis [rad]."""
    point_std: float = 2e-4
    """σp per sample at level 1: contact point, per axis [m]."""
    joint_std: float = 0.0
    """Joint encoder σ per sample at level 1 [rad]."""
    component: SensorNoise = field(default_factory=SensorNoise)
    """The σ of fitted components at level 1."""

    @property
    def fitted(self) -> SensorNoise:
        """The fitted components' noise at this level."""
        return self.component.scaled(self.level)

    def at_least(self, level: float) -> NoiseModel:
        """The same model at ``max(self.level, level)``."""
        return replace(self, level=max(self.level, level))


NOISE_LEVELS = (0.0, 10.0)
"""The accepted range of a noise level (``--noise``): 0 (noiseless) to 10 × the default σ. Beyond it the error
bounds are so wide that the matcher keeps interpretations by the million (the tree's memory grows without a
useful verdict); see README, "Noise"."""


def check_noise_level(level: float, option: str = "--noise") -> float:
    """``level`` as a float when it is a finite number within :data:`NOISE_LEVELS`, else a
    :class:`~haptic.errors.HapticError` naming the option and the valid range."""
    lo, hi = NOISE_LEVELS
    try:
        x = float(level)
    except (TypeError, ValueError):
        raise HapticError(f"{option} takes a number from {lo:g} to {hi:g}, got {level!r}") from None
    if not np.isfinite(x) or not lo <= x <= hi:
        raise HapticError(f"{option} {level!r} is out of range: a noise level is a finite number from {lo:g} "
                          f"(noiseless) to {hi:g} (x the default sensor noise)")  # fmt: skip
    return x


# ------------------------------------------------------------------------------------------- serialisation


def component_to_dict(c: DataComponent) -> dict:
    """A JSON-friendly dict of one data component (floats at full precision; ``kind`` names its class)."""
    if isinstance(c, DataFace):
        return {
            "kind": "face", "id": c.id, "normal": c.normal.tolist(), "points": c.points.tolist(),
            "normal_bound": c.normal_bound, "position_bound": c.position_bound, "adjacent": list(c.adjacent),
        }  # fmt: skip
    if isinstance(c, DataEdge):
        return {
            "kind": "edge", "id": c.id, "direction": c.direction.tolist(), "point": c.point.tolist(),
            "length": c.length, "direction_bound": c.direction_bound, "position_bound": c.position_bound,
            "length_bound": c.length_bound, "start_vertex": c.start_vertex, "end_vertex": c.end_vertex,
            "adjacent": list(c.adjacent), "side_points": [[f, q.tolist()] for f, q in c.side_points],
        }  # fmt: skip
    if isinstance(c, DataVertex):
        return {
            "kind": "vertex", "id": c.id, "position": c.position.tolist(), "position_bound": c.position_bound,
            "adjacent": list(c.adjacent),
        }  # fmt: skip
    raise TypeError(f"not a data component: {type(c).__name__}")


def component_from_dict(d: Mapping) -> DataComponent:
    """The inverse of :func:`component_to_dict`."""
    d = dict(d)
    kind = d.pop("kind")
    if kind == "face":
        return DataFace(**d)
    if kind == "edge":
        d["side_points"] = tuple((int(f), q) for f, q in d.get("side_points", ()))
        return DataEdge(**d)
    if kind == "vertex":
        return DataVertex(**d)
    raise ValueError(f"unknown data component kind {kind!r} (expected face, edge or vertex)")


def to_json(components: Iterable[DataComponent], indent: int | None = None, **extra) -> str:
    """A sequence of data reports (re-reported edges included, in order) as JSON:
    ``{"components": [...], **extra}`` (``extra``: JSON-friendly metadata, e.g. the model and true pose)."""
    return json.dumps({**extra, "components": [component_to_dict(c) for c in components]}, indent=indent)


def from_json(text: str) -> list[DataComponent]:
    """The data reports of :func:`to_json` (also accepts a bare JSON list of component dicts)."""
    obj = json.loads(text)
    items = obj["components"] if isinstance(obj, Mapping) else obj
    return [component_from_dict(d) for d in items]


__all__ = [
    "DataComponent",
    "DataEdge",
    "DataFace",
    "DataVertex",
    "NOISE_LEVELS",
    "SensorNoise",
    "check_noise_level",
    "component_from_dict",
    "component_to_dict",
    "from_json",
    "to_json",
]
