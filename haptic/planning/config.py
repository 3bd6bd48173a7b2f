"""The planner's settings: candidate generation, prediction, the table and the bound on pose classes scored."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from haptic.planning.moves import VERTEX_RADIUS, CostModel


@dataclass(frozen=True)
class PlannerConfig:
    """Options of candidate generation and prediction."""

    n_directions: int = 8
    """Face-move directions sampled over the half-plane into the face (§4.1.3: discrete angles)."""
    vertex_radius: float = VERTEX_RADIUS
    """Radius of the circular path of a vertex move [m]: the executor's, which the episode's world sets."""
    costs: CostModel = field(default_factory=CostModel)
    """Cost constants (§3.1)."""
    min_face_travel: float = 0.006
    """Face moves predicted (median over hypotheses) to meet an edge sooner than this are not offered: a
    finger that starts that close to an edge cannot settle on the face first [m]."""
    min_vertex_clearance: float = 0.004
    """Face moves predicted to meet their edge closer than this to a vertex are not offered: a fingertip
    crossing there touches two edges at once [m]."""
    min_crossed_edge: float = 0.007
    """With a table, the shortest edge a verification asks a face move to cross (a move aimed at its middle), and
    counts on one crossing (:func:`~haptic.planning.verify.entered_edges`) [m]. The hand keeps its crossings 6 mm
    clear of a vertex where a move does (``PhysicsSettings.crossing_clearance``): an edge shorter than twice that is
    crossed at its middle, half this from its ends at the least. trapezohedron_09 of the formula corpus (seed 1)
    crossed its 7.3 mm kite edges there; nearer an end, the pad rolls round the vertex."""
    table_z: float | None = None
    """Height of the table top in the world frame, a workspace prior the robot knows (set for the physics
    executor's scene, never from the object) [m]. None: no table (the geometric executor), no table checks."""
    pad_radius: float = 0.012
    """Radius of the fingertip pad (the robot's own geometry), for the table checks [m]."""
    table_clearance: float = 0.004
    """A pad position whose lowest point would come closer than this to the table top counts as on the table:
    the executor's own limit (2 mm) plus a margin for the hypotheses' pose error [m]."""
    steep_descent: float = 0.5
    """A face move whose direction points down more steeply than this (the sine of its descent) is "steep"."""
    steep_descent_risk: float = 0.0
    """Failure risk charged to steep face moves (their efficiency is discounted by it): the physics hand,
    fingers pointing down, often loses the surface rolling down over the edge such a trace meets. 0: none."""
    table_rest_tol: float = 0.003
    """With a table, a pose class whose model would reach more than this below the table top, or whose lowest
    point would float more than this above it, is not a pose the object can rest in [m]."""
    max_undercut: float | None = None
    """With a table, how far a face's outward normal may lean back under, past horizontal, for the pad of the
    downward-pointing fingers to roll onto it over a convex edge (the robot's own reach, set for the physics
    executor) [rad]. A face move predicted to roll over an edge onto a face leaning further ends there and
    reports the edge alone (:attr:`~haptic.planning.predict.Prediction.edge_only`); a vertex move doing so
    counts as refused like one running into the table. None: no limit."""
    felt_edge: float | None = None
    """With a table, the least turn between two faces' normals that the pad sliding across their convex edge feels
    (the physics executor's ``TouchConfig.edge_angle``): over a shallower edge the slide goes on onto the next face,
    and what the table lets the move do is judged where it ends (:func:`~haptic.planning.table.move_outlook`). None:
    every edge is felt."""
    edge_reentry: float | None = None
    """With a table, how far in from an edge the hand touches one of its faces again before following it (the
    physics executor's ``PhysicsSettings.edge_reentry``): an edge move along a convex edge whose faces the pad cannot
    touch that far in off the table counts as refused (:func:`~haptic.planning.table.edge_return_in_reach`) [m].
    None: every edge's return counts as in reach."""
    concave_end_block: float | None = None
    """With a table, where the hand can tell a concave edge's end: only where a face there blocks the pad
    travelling along the edge (its outward normal against the travel by more than this cosine). Past an end
    where the surface falls away the pad in the corner rolls on along the two faces' rims, so an edge move
    toward it locates no vertex and counts as refused (set for the physics executor). None: every end is
    located (a point sensor)."""
    leave_concave_vertices: bool = True
    """Whether an edge or vertex move may start at a vertex where a concave edge ends. On the hand (False) the
    12 mm pad resting there touches the face across the concave edge: acquiring the ridge, or circling the vertex
    8 mm out, ends at the limit (in the logged verification moves over the non-convex seed episodes, 0 of 8 such
    edge moves and 0 of 17 such vertex moves succeeded, against 12 of 12 and 14 of 14 from other vertices), so
    they count as refused."""
    touch_evidence: bool = False
    """Every touched point is checked against each pose class's surface (the episode does so with the
    physics executor's traces), so a face move that cannot step onto its next face still tells how far its
    face reaches; scored so."""
    touch_tol: float = 0.0025
    """A touched point farther than this from every face of a pose class whose normal agrees with the sensed
    one contradicts the class [m]."""
    touch_outliers: int = 3
    """Contradicting points it takes to set a pose class aside (a stray reading is not enough)."""
    touch_spacing: float = 0.001
    """Touched points are thinned to about one per this much of the trace [m]."""
    table_risk: float = 0.5
    """Candidate moves that at least this fraction of the hypotheses predict to bring the pad onto the table
    are not offered (the executor would refuse or abort them); the rest are discounted by their risk."""
    max_hypotheses: int | None = 256
    """Most pose classes a policy scores moves against; above it, a reduced set chosen model by model
    (:mod:`haptic.planning.bound`). None: no bound. 256 is above the most pose classes the shipped libraries
    leave at a planner decision (255, look-alike library, with the loop posing up to
    ``haptic.episode.state.MAX_GROUPED_INTERPRETATIONS`` interpretations), so their decisions are unchanged."""
    fingers: int = 1
    """Fingers the hand may use at once (``FINGER_COUNTS``): 1, the index finger alone (no placements); 2 or 4,
    placements of two up to that many fingertips (:mod:`haptic.planning.placements`) join the candidates."""
    placement_reach: Callable | None = None
    """Whether the hand can take a placement up, as the episode's world knows it: called with a candidate
    :class:`~haptic.planning.moves.PlacementMove` and the hypotheses (the most likely first), it returns the
    placement with the fingers that reach its lines (the same lines, perhaps other fingers), or None when none do.
    Asked for the most efficient placements of a decision in turn (at most ``placement_checks``); the first it
    reaches is the one placement offered. None: every candidate is offered (the ideal sensor)."""
    placement_checks: int = 3
    """Most placements of one decision asked about (``placement_reach``)."""
    finger_reach: Callable | None = None
    """Which finger, if any, can carry out a free-space probe line, as the episode's world knows it: called with a
    :class:`~haptic.planning.moves.ProbeMove` and the hypotheses (the most likely first), it returns the probe with
    the finger (``ProbeMove.finger``) and the hand's way to it, or None when no finger reaches the line. The
    verification asks it for the faces the exploring finger pointing down cannot press
    (:mod:`haptic.planning.finger_faces`). None: no such probe is offered (a point sensor)."""
    moves: str = "tracing"
    """Admissible kinds of move (``MOVE_SETS``): "tracing" (face, edge and vertex moves), "probing" (free-space
    probes) or "all" (both, ranked together by one efficiency, seed §1.1)."""

    @property
    def touch_margin(self) -> float:
        """How far past a pose class's edge a trace must touch its face for the touched points to set the
        class aside (``touch_outliers`` points beyond ``touch_tol``) [m]."""
        return self.touch_tol + self.touch_outliers * self.touch_spacing

