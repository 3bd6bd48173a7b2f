"""The bookkeeping of one episode (:class:`EpisodeState`): what the loop updates after every move and the move
sources (:mod:`haptic.episode.sources`) read to propose the next one.

Everything here comes from the executor's data components and move results: the true model and pose are not
part of it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from haptic.episode.perception import hand_points, on_the_table, touched_points
from haptic.geometry import Polyhedron
from haptic.matching.acceptance import own_bounds_keep
from haptic.matching.components import DataComponent, SensorNoise
from haptic.matching.free_space import FreeSegment, apply_probes
from haptic.matching.recognition import RECOGNIZED, Recognition, recognize
from haptic.matching.tree import InterpretationTree
from haptic.planning.config import PlannerConfig
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import Move, MoveResult, SensorState
from haptic.planning.verify import Verifier

MAX_GROUPED_INTERPRETATIONS = 4000
"""Most interpretations whose poses are computed to group them into pose classes (all of them in one batch);
above it the episode has no pose classes yet, and the loop's last source takes a random move."""


def hypotheses_from(tree: InterpretationTree, rec: Recognition) -> list[Hypothesis]:
    """One hypothesis per pose class, from the class's first interpretation."""
    out = []
    for c in rec.classes:
        it = tree.interpretation(c.leaves[0], with_pose=True, refine=True)
        out.append(
            Hypothesis(
                model=c.name,
                poly=c.model,
                world_from_model=it.world_from_model or c.world_from_model,
                faces=it.faces,
                edges=it.edges,
                vertices=it.vertices,
                size=len(c.leaves),
                leaves=tuple(c.leaves),
            )
        )
    return out


@dataclass
class EpisodeState:
    """What an episode knows so far, from its data alone: the loop updates it with every move result
    (:meth:`took`, :meth:`failed`); the move sources and the ending conditions read it."""

    tree: InterpretationTree
    """The matcher's interpretation tree over the data so far."""
    noise: SensorNoise
    """The sensor-noise model (for outcome bounds)."""
    config: PlannerConfig
    """Candidate generation, costs, the table and touch evidence."""
    verifier: Verifier | None = None
    """The verification stage (``--verify fast|full``; None: none)."""
    components: dict[int, DataComponent] = field(default_factory=dict)
    """Data components so far, by id (the latest version of a re-reported edge)."""
    sensor: SensorState | None = None
    """Where the sensor is (None before the start)."""
    rec: Recognition | None = None
    """The verdict on the data so far (:meth:`assess`; None before the start)."""
    cost: float = 0.0
    """Path cost so far, failed moves included [units]."""
    moves: int = 0
    """Moves carried out or failed (the start not counted)."""
    failed_total: int = 0
    """Moves that failed."""
    failed_in_a_row: int = 0
    """Moves that failed since the last that succeeded (less those whose touches told something)."""
    last_failure: str = ""
    """Status of the last move that failed."""
    failed_here: list[Move] = field(default_factory=list)
    """Moves that failed from the current sensor state (cleared when a move succeeds)."""
    touched: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    """Touched points and sensed normals of each move (``config.touch_evidence``)."""
    hand: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    """Points on the object links other than the pad touched, and their bounds, of each move."""
    free: list[FreeSegment] = field(default_factory=list)
    """Free space the probes travelled (a miss's line, a hit's approach)."""
    probe_faces: list[int] = field(default_factory=list)
    """Data ids of the faces probes hit."""
    probed: list[Move] = field(default_factory=list)
    """Probes carried out or failed: the same line again would tell nothing new (or fail again)."""
    counts: list[int] = field(default_factory=list)
    """Interpretations after the start and after each successful move."""
    classes: list[int] = field(default_factory=list)
    """Pose classes after the start and after each successful move (the interpretations while there are none)."""
    cum_cost: list[float] = field(default_factory=list)
    """Path cost after the start and after each successful move [units]."""
    kinds: list[str] = field(default_factory=list)
    """Kind of the start's move ("start" when it reports none) and of each successful move."""
    decision_times: list[float] = field(default_factory=list)
    """Wall time of each decision a policy took [s]."""
    placement_faces: int = 0
    """Of :attr:`probe_faces`, those placements touched."""
    placements: list[dict] = field(default_factory=list)
    """Each placement of several fingertips carried out or failed: its ``status`` and, per finger, what it did
    (the executor's ``info["fingers"]``)."""
    _hypotheses: tuple[Recognition | None, list[Hypothesis]] = (None, [])

    @classmethod
    def begin(
        cls, library: dict[str, Polyhedron], noise: SensorNoise, config: PlannerConfig, verifier: Verifier | None
    ) -> EpisodeState:
        """The state before the start: an empty tree over ``library``."""
        return cls(InterpretationTree(library), noise, config, verifier)

    @property
    def posed(self) -> bool:
        """Whether the matcher has grouped the interpretations into pose classes (the data fix their poses)."""
        return self.rec is not None and bool(self.rec.classes)

    @property
    def verifying(self) -> bool:
        """Whether a verification is under way: verification is on and one pose class is left."""
        return self.verifier is not None and self.rec is not None and self.rec.status == RECOGNIZED

    @property
    def avoid(self) -> tuple[Move, ...]:
        """Moves not to propose: those that failed from here, and the probes' lines so far."""
        return (*self.failed_here, *self.probed)

    @property
    def probe_failed_here(self) -> bool:
        """Whether a probe failed from the current sensor state (the hand could not get along its line)."""
        return any(m.kind == "probe" for m in self.failed_here)

    def hypotheses(self) -> list[Hypothesis]:
        """One hypothesis per pose class (:func:`hypotheses_from`; none while the data fix no pose), computed
        once per verdict."""
        if not self.posed:
            return []
        if self._hypotheses[0] is not self.rec:
            self._hypotheses = (self.rec, hypotheses_from(self.tree, self.rec))
        return list(self._hypotheses[1])

    def assess(self) -> Recognition:
        """The verdict on the data so far (with the table and the touched points, when known)."""
        r = recognize(self.tree, max_interpretations=MAX_GROUPED_INTERPRETATIONS)
        if self.config.table_z is None:
            return r
        hand = None
        if any(len(b) for _, b in self.hand):
            hand = (np.concatenate([p for p, _ in self.hand]), np.concatenate([b for _, b in self.hand]))
        if not self.touched:
            return on_the_table(r, self.tree, self.components, self.config, hand=hand)
        both = (np.concatenate([p for p, _ in self.touched]), np.concatenate([n for _, n in self.touched]))
        return on_the_table(r, self.tree, self.components, self.config, both, hand)

    def took(self, result: MoveResult) -> None:
        """Book a move that succeeded (or the start): its components into the tree, its free space and touches,
        its cost, the new verdict and the traces."""
        self.failed_in_a_row = 0
        self.failed_here.clear()
        for c in result.components:
            self.components[c.id] = c
        self.tree.add_move(result.components)
        self.free.extend(result.free_space)
        if result.move is not None and result.move.kind in ("probe", "placement"):  # faces hit along lines
            self.probe_faces.extend(c.id for c in result.components)
            self.placement_faces += len(result.components) if result.move.kind == "placement" else 0
        if result.move is not None and result.move.kind == "probe":
            self.probed.append(result.move)
        if self.free:  # after every add: poses tighten, and leaves unposed or too many before become testable
            apply_probes(self.tree, self.free, self.probe_faces)
        if self.verifier is not None:  # with learned models in the library: each model held to its own bounds
            keep = own_bounds_keep(self.tree, self.verifier.k_sigma, self.verifier.floors)
            if keep is not None and not keep.all():
                self.tree.retain(keep)
        if self.config.touch_evidence:
            self.touched.append(touched_points(result, self.config))
        self.hand.append(hand_points(result))
        self._placed(result)
        self.cost += result.cost
        self.rec = self.assess()
        self.sensor = result.state
        self.counts.append(self.tree.count)
        self.classes.append(len(self.rec.classes) if self.rec.classes else self.tree.count)
        self.cum_cost.append(self.cost)
        self.kinds.append(result.move.kind if result.move is not None else "start")

    def _placed(self, result: MoveResult) -> None:
        if result.move is not None and result.move.kind == "placement":
            fingers = [{"finger": f["finger"], "status": f["status"], **({"reason": f["reason"]} if f.get("reason")
                                                                          else {})}
                       for f in result.info.get("fingers", ())]  # fmt: skip
            self.placements.append({"status": str(result.status), "fingers": fingers,
                                    **({"reason": result.reason} if result.reason else {})})

    def failed(self, move: Move, result: MoveResult) -> None:
        """Book a move that failed: its cost, where the sensor ended (when known), and its touches: when they
        set pose classes aside, the failure does not count toward those in a row."""
        self._placed(result)
        self.failed_total += 1
        self.failed_in_a_row += 1
        self.last_failure = result.status
        self.failed_here.append(move)
        if self.verifier is not None and self.verifying:
            self.verifier.failed(move, result.reason or str(result.status))
        if move.kind == "probe":  # its line is where it is, whatever the state: not offered again
            self.probed.append(move)
        self.cost += result.cost
        if result.state is not None:
            self.sensor = result.state
        if self.config.touch_evidence and self.rec is not None:
            self.touched.append(touched_points(result, self.config))
            self.hand.append(hand_points(result))
            before = len(self.rec.classes)
            self.rec = self.assess()
            if len(self.rec.classes) < before:  # the failed move's touches told something
                self.failed_in_a_row = 0
