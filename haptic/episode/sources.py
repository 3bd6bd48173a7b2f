"""Move sources: who proposes the episode's next move.

The loop (:func:`~haptic.episode.loop.loop_steps`) asks an ordered list of sources, each turn, for the next move;
the first that proposes one has it, and every source hears the result (:meth:`MoveSource.on_result`). A source
reads the episode's bookkeeping (:class:`~haptic.episode.state.EpisodeState`) and owns its rule; the loop knows
none of them. A proposal is a move chosen by the source's rule, a :class:`~haptic.planning.policies.Decision` a
policy took inside the source, or a :class:`DecisionPoint` for whoever drives the loop to decide (the episode's
policy, or an agent in :mod:`haptic.env`). A source that cannot propose although its rule says it must raises a
:class:`~haptic.errors.HapticError`: the episode ends as failed.

The episode's sources (:func:`episode_sources`), in order: :class:`VerificationMoves`, :class:`CheaperOpening`
(``--moves all`` without a table), :class:`TracingOpening` (not with ``--moves probing``), :class:`ProbeOpening`
(``--moves probing``), :class:`PolicyDecisions`, :class:`RandomFallback`. Every random choice draws from the
episode's policy generator, in this order.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from haptic.episode.opening import cheaper_opening, edge_run_of, opening_move, opening_probe, tracing_remainder
from haptic.episode.state import EpisodeState
from haptic.geometry import Polyhedron
from haptic.matching.free_space import MAX_POSED as PROBES_MAX_POSED
from haptic.planning.config import PlannerConfig
from haptic.planning.moves import Move, MoveResult
from haptic.planning.opening_probes import LibraryExtent
from haptic.planning.policies import Context, Decision, Policy, RandomPolicy

TRACING_OPENING = ("face", "edge", "vertex")
"""The seed's opening sequence (§4.1) from a face."""


@dataclass(frozen=True, eq=False)
class DecisionPoint:
    """Where the loop asks its policy for the next move (:func:`~haptic.episode.loop.loop_steps` yields one)."""

    context: Context
    """What the policy decides from: two or more pose classes left, no verification under way."""
    rng: np.random.Generator
    """The episode's policy generator (the one the opening moves draw from too)."""


Proposal = Move | Decision | DecisionPoint
"""What a source proposes: a move by its rule, a policy's decision, or a decision point for the loop's driver."""


class MoveSource(Protocol):
    """A source of moves for the episode loop."""

    name: str
    """What the source is called (in the list of :func:`episode_sources`)."""

    def propose(self, view: EpisodeState) -> Proposal | None:
        """The next move by this source's rule; None: the next source answers."""
        ...

    def on_result(self, view: EpisodeState, move: Move, result: MoveResult) -> None:
        """Hear how a move (this source's or another's) went, after the loop has booked it."""
        return None


def decision_context(view: EpisodeState) -> Context:
    """What a policy decides from: the pose classes, the sensor state, the data and the moves to avoid. After a
    probe failed from here (the hand could not get along its line) under ``--moves all``, tracing moves only,
    until one succeeds: probes aimed at the same region would fail the same way."""
    config = view.config
    if config.moves == "all" and view.probe_failed_here:
        config = replace(config, moves="tracing")
    return Context(view.hypotheses(), view.sensor, view.components, view.noise, config, avoid=view.avoid,
                   tree=view.tree, moves=view.moves, cost=view.cost)  # fmt: skip


class VerificationMoves(MoveSource):
    """While a verification is under way (verification on, one pose class left): the verifier's next move toward
    what the class's model predicts and the data lack (:meth:`~haptic.planning.verify.Verifier.choose`); None
    when it has no admissible move. Every ask counts as a verification move (not toward the episode's
    ``max_moves``)."""

    name = "verification"

    def propose(self, view: EpisodeState) -> Move | None:
        if not view.verifying:
            return None
        return view.verifier.choose(view.hypotheses()[0], view.sensor, view.components, tuple(view.failed_here),
                                    view.probed)  # fmt: skip


class TracingOpening(MoveSource):
    """The seed's opening (§4.1): the kinds of :attr:`remaining` in turn (a face move, an edge move, a vertex
    move), each a random admissible move of its kind (:func:`~haptic.episode.opening.opening_move`: not one that
    failed from here; with a table, away from it, as the pose classes predict when there are some). A kind is
    used up when asked, whether or not it had an admissible move. The opening runs to its end whatever the
    verdict: a verification without a move of its own takes the opening's next."""

    name = "tracing opening"

    def __init__(self, rng: np.random.Generator, remaining: tuple[str, ...] = TRACING_OPENING) -> None:
        self.rng = rng
        self.remaining = list(remaining)
        """Kinds of move still to come (:class:`CheaperOpening` plans them afresh)."""

    def propose(self, view: EpisodeState) -> Move | None:
        if not self.remaining:
            return None
        hyps = tuple(view.hypotheses()) if view.config.table_z is not None else ()
        return opening_move(self.remaining.pop(0), view.sensor, view.components, view.config, self.rng,
                            tuple(view.failed_here), hyps)  # fmt: skip


class CheaperOpening(MoveSource):
    """The opening of ``--moves all`` (without a table): while the hypotheses have no poses, each new face the
    cheaper way. It plans the tracing opening afresh from where the sensor is
    (:func:`~haptic.episode.opening.tracing_remainder`, into ``tracing``) and proposes a probe instead when one
    measures the next face for less (:func:`~haptic.episode.opening.cheaper_opening`; the tracing opening is then
    dropped); not after a probe failed from here: probes aimed at the same region would fail the same way."""

    name = "cheaper opening"

    def __init__(self, tracing: TracingOpening, extent: LibraryExtent, rng: np.random.Generator) -> None:
        self.tracing, self.extent, self.rng = tracing, extent, rng

    def propose(self, view: EpisodeState) -> Move | None:
        if view.posed:
            return None
        sensor = view.sensor
        self.tracing.remaining = tracing_remainder(sensor)
        if view.probe_failed_here:
            return None
        run = edge_run_of(view.tree, sensor.edge) if sensor.edge is not None else None
        move = cheaper_opening(self.tracing.remaining, sensor, view.components, self.extent, view.config, self.rng,
                               view.avoid, run)  # fmt: skip
        if move is not None:
            self.tracing.remaining = []
        return move


class ProbeOpening(MoveSource):
    """The opening of ``--moves probing``: probes from a spread of directions toward the object's region
    (:func:`~haptic.episode.opening.opening_probe`) until the hypotheses have poses, and on, toward the faces
    not measured yet, while the tree is too large for the probe matcher to test hits by position (above
    :data:`~haptic.matching.free_space.MAX_POSED`); never during a verification. None when no line is left."""

    name = "probe opening"

    def __init__(self, extent: LibraryExtent, rng: np.random.Generator) -> None:
        self.extent, self.rng = extent, rng

    def propose(self, view: EpisodeState) -> Move | None:
        if view.verifying or (view.posed and view.tree.count <= PROBES_MAX_POSED):
            return None
        return opening_probe(view.components, self.extent, view.config, self.rng, view.avoid, unmeasured=view.posed)


class PolicyDecisions(MoveSource):
    """Two or more pose classes left and no verification under way: the episode's policy decides, from
    :func:`decision_context` (a :class:`DecisionPoint` for the loop's driver)."""

    name = "policy"

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng = rng

    def propose(self, view: EpisodeState) -> DecisionPoint | None:
        if view.verifying or len(view.hypotheses()) < 2:
            return None
        return DecisionPoint(decision_context(view), self.rng)


class RandomFallback(MoveSource):
    """Whatever no source before it proposed (fewer than two pose classes: none yet, or one under verification):
    a random admissible move (:class:`~haptic.planning.policies.RandomPolicy` from :func:`decision_context`); a
    :class:`~haptic.errors.PlanningError` when there is none."""

    name = "random fallback"

    def __init__(self, rng: np.random.Generator, policy: Policy | None = None) -> None:
        self.rng = rng
        self.policy = policy or RandomPolicy()

    def propose(self, view: EpisodeState) -> Decision:
        return self.policy.choose(decision_context(view), self.rng)


def episode_sources(
    library: dict[str, Polyhedron], config: PlannerConfig, rng: np.random.Generator
) -> list[MoveSource]:
    """The sources of an episode under ``config``, in the order the loop asks them (module docstring). With
    free-space probes alone (``config.moves`` "probing") the opening is probes; with both kinds of move ("all"),
    each new face of the opening by a tracing move or a probe, except on the simulated hand (a table): its
    probes cost more than predicted, and failed ones more again, so it keeps the seed's tracing opening."""
    probing = config.moves == "probing"
    choosing = config.moves == "all" and config.table_z is None
    extent = LibraryExtent.of(library.values()) if probing or choosing else None
    tracing = TracingOpening(rng, () if probing else TRACING_OPENING)
    sources: list[MoveSource] = [VerificationMoves()]
    if choosing:
        sources.append(CheaperOpening(tracing, extent, rng))
    sources.append(ProbeOpening(extent, rng) if probing else tracing)
    return [*sources, PolicyDecisions(rng), RandomFallback(rng)]
