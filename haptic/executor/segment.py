"""Segmentation: contact traces → data faces, edges and vertices with error bounds and adjacency (seed §2.3).

A face is the set of trace rows whose sensed normals agree (within a few σ): its normal combines the mean of the
sensed normals with a plane fit of the contact points (inverse-variance weights, the plane fit counting only
when the points span two dimensions -- docs/physics-notes.md, pitfall 6); its points are the contact points projected
onto the fitted plane. An edge is the line ``n_a × n_b`` through (convex) the contact points recorded while the
pad rolled over it -- they stay on the edge -- or (concave, where the pad cannot reach the corner) the
intersection of the two face planes; a long ridge trace refines both by a line fit. A vertex is the point of
the edge line where the pad's contacts stopped advancing along it.

Every error bound is ``k`` times the root sum of squares of a statistical σ (sensor noise over the samples
used, plus the fit residuals) and a systematic floor (pad compliance, contact-point bias), all in
:class:`SegmentBounds`. The segmenter reads only contact traces; it never sees the object.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from haptic.geometry.se3 import perpendicular, unit
from haptic.matching.acceptance import BoundFloors
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex, NoiseModel, SensorNoise
from haptic.matching.trace import ContactTrace

MEDIAN_ABS_NORMAL = 0.6745
"""The median of ``|x|`` for ``x`` normal with σ 1 [-]."""
MEDIAN_EFFICIENCY = math.sqrt(math.pi / 2.0)
"""The median of ``k`` normal samples of σ scatters by about this times ``σ / √k`` (their mean by ``σ / √k``) [-]."""


@dataclass(frozen=True)
class SegmentBounds:
    """The executor's sensing and segmentation settings: the per-sample sensor noise (that of
    :class:`~haptic.matching.components.NoiseModel`, :meth:`from_model`), the systematic floors from which
    error bounds are derived, and the thresholds by which the primitives, the physics executor and the
    segmenter tell faces, edges and vertices apart in the sensed normals and points."""

    normal_sigma: float = NoiseModel.normal_std
    """σn of one sensed contact normal, per tangent axis [rad]."""
    point_sigma: float = NoiseModel.point_std
    """σp of one sensed contact point, per axis [m]."""
    force_sigma: float = NoiseModel.force_std
    """σF of the sensed normal force [N]."""
    k: float = SensorNoise.k
    """A bound is k standard deviations."""
    normal_floor: float = math.radians(0.25)
    """Systematic σ of a face normal (pad compliance, contact-frame bias) [rad]."""
    direction_floor: float = math.radians(0.3)
    """Systematic σ of an edge direction [rad]."""
    position_floor: float = 2.5e-4
    """Systematic σ of a position across a face or an edge (contact-point bias ≈ half the pad penetration) [m]."""
    length_floor: float = 1.0e-3
    """Systematic σ of an explored interval's end along its edge (detection delay) [m]."""
    vertex_floor: float = 4e-4
    """Systematic σ of a vertex position [m]."""
    max_points: int = 24
    """Most contact points kept on a data face."""
    min_face_rows: int = 15
    """Fewest contact rows a face is fitted from."""
    face_cone: float = math.radians(4.0)
    """A row belongs to a face when its sensed normal is within this of the face normal [rad]."""
    face_cone_sigmas: float = 3.0
    """... or within this many σn of it, when that is wider: a cone narrower than the noise keeps the rows about
    the guess and pulls the face's mean normal toward it (at noise level 4, σn 4°, face normals 1.0-1.5 bounds off
    with the 4° cone) [-]."""
    sample_cone: float = math.radians(3.0)
    """A sensed normal within this of a face's is one of the face's samples (the primitives' running face
    normal); beyond it the normal has turned off the face (rolling over an edge) [rad]."""
    ridge_row_cone: float = math.radians(4.0)
    """A row of a ridge trace is on the ridge itself when its sensed normal is within this of perpendicular to
    the edge (not rolling on the vertex at its end) [rad]."""
    resting_cone: float = math.radians(5.0)
    """The pad still rests on a data face when its filtered normal is within this of the face's [rad]."""
    retouch_cone: float = math.radians(6.0)
    """Touching a known face again, the sensed normal is within this of the face's; farther, the pad met
    something else [rad]."""
    roll_axis_slack: float = math.radians(3.0)
    """Rolling over an edge whose next face is out of reach, the sensed normals stay this close (beyond the
    noise) to the plane perpendicular to the edge; a roll round a vertex turns them out of any one plane [rad] ..."""
    roll_axis_quantile: float = 0.9
    """... this quantile of them [-]."""
    roll_rms_sigmas: float = 2.0
    """... and their rms off that plane is at most this many times the noise's (``√(σn² + floor²)``): over a true
    edge it is the noise's own (0.016-0.018 at σn 1°, 0.0175 rad, over 4 rolls at 30-150 mm), while a roll that
    began round a vertex and went on over an edge leaves its normals off any one plane by more (0.056 on
    bipyramid_09 at 30 mm, seed 1, whose axis lay 18° off the edge), though within the quantile's slack [-]."""
    min_refine_rows: int = 3
    """A face's rows are picked again about their own mean normal when at least this many agree with the guess."""
    min_roll_rows: int = 3
    """Fewest rolling contacts between the two faces' normals that locate a convex edge or test a roll."""
    min_turned_rows: int = 5
    """Fewest rolling contacts, turned off the face, from which a roll alone gives an edge."""
    sweep_sigmas: float = 3.0
    """A roll alone gives an edge only when its normals swept along the arc off the face: the mean turn of its last
    third of rolling rows exceeds that of its first third by this many σ of that difference. Normals that stand
    turned by one angle fix no axis -- a contact on a vertex or a corner of the table's clearance stands so too
    (LBLOCK01 at 30 mm, seed 2: ten rows turned 8-11° at one point 2.4 mm from a vertex, the "edge" fitted to
    them 31° off the true one, 5.6 bounds) [-]."""
    min_plane_points: int = 6
    """A face's plane fit counts with at least this many points ..."""
    min_plane_spread: float = 1e-3
    """... spread (rms) at least this far along their second axis [m]."""
    two_d_extent: float = 1e-3
    """Pad centres spanning more than this across their principal axis are a 2-D stroke (the turn rate is
    measured over both axes) [m]."""
    max_spread_sigmas: float = 2.0 * math.sqrt(2.0)
    """A face's sensed normals spread (rms) at most this many σn ..."""
    spread_slack: float = math.radians(0.5)
    """... plus this [rad]; more, and the rows do not come from one plane."""
    min_line_points: int = 10
    """A line fit of contact points along an edge (the ridge) counts with at least this many points ..."""
    min_line_spread: float = 2e-3
    """... spread (rms) at least this far along it [m]."""
    line_spacing: float = 1e-3
    """Contact points along an edge are not independent samples: the pad's path wanders across the ridge (and
    its contact point with it, the more the shallower the edge) over about this length, so a line fit counts
    one independent point per this much of its extent. Counting every control tick, a ridge trace 15 mm long
    of 220 rows whose points lie 0.6 mm off a straight line claimed its direction to 0.5° and pulled the edge
    2-3° off, past its bound [m]."""
    fit_agreement_sigmas: float = 5.0
    """A point fit (plane, line) is combined with the normals' estimate when they agree within this many σ ..."""
    fit_agreement_slack: float = math.radians(1.0)
    """... plus this [rad]."""
    min_edge_sin: float = 0.2
    """The sine of the angle between two faces' normals below which an edge's σ stops growing (its floor) [-]."""
    side_reach: float = 4e-3
    """Side points of an edge lie this far in on each face from the explored interval [m]."""
    min_face_extent: float = 3e-3
    """The pad centres of a face's rows must span at least this along their principal axis [m]: on a face the
    pad slides with a constant normal, on a vertex or a ridge it cannot (the normal turns by Δ/r) [m]."""
    min_face_width: float = 1.5e-3
    """... and this across it, when a 2-D stroke is required (the start's L) [m]."""
    max_face_curvature: float = math.radians(1.0) / 1e-3
    """On a face the sensed normal does not turn as the pad slides; rolling on an edge or a vertex it turns by
    1/r (r = 12 mm pad: 4.8°/mm). Rows whose normal turns faster than this with the pad's position are not a
    face [rad/m]."""
    min_edge_angle: float = math.radians(10.0)
    """The two faces of an edge differ in normal by at least this; closer, the "edge" is noise on one face [rad]."""
    max_roll_skew: float = math.radians(20.0)
    """Rolling over (or climbing out of) an edge the sensed normal turns about the edge, so it stays
    perpendicular to ``n_a × n_b``; a roll whose normals lean further along it (median) went round another
    edge or vertex, and the next face was met elsewhere [rad]."""
    roll_skew_sigmas: float = 2.5
    """Over a true edge the sensed normals lean along it by the sensor noise alone: their median ``|n · e|`` is
    about 0.67 σn (0.009-0.016 measured over 14 edges of convex solids at σn 1°). A roll round a vertex onto a
    face that shares no edge with the first turns about another axis and leans along ``n_a × n_b`` by more
    (0.051 on bipyramid_06 at 60 mm, whose "edge" then lay 36 mm off every true edge), though less than
    :attr:`max_roll_skew`: a median beyond this many times the noise's (``0.67 √(σn² + floor²)``) is no roll over
    the edge between the faces [-]."""
    roll_lean_sigmas: float = 2.0
    """The same on average: over a true edge the mean of ``n · e`` (signed) is the noise's mean over the rolling
    rows (σn / √n) and a systematic lean of at most the normal's floor (0.02-0.35° over 63 true edges of convex
    solids at 60-150 mm), while a roll round a vertex that follows the arc from one face's normal to the other's
    closely enough to pass the median's test still leans one way (1.1-1.5° on 4 of 6 such rolls, whose "edges" lay
    20-50° off every true edge; 0.55° over 256 rows on antiprism_04 at 150 mm, its "edge" 45 bounds off, where
    the true edges of 30 rolls on antiprisms and bipyramids at 60-150 mm leaned at most 0.34°). A mean beyond
    this many times ``√(σn² / n + floor²)`` is no roll over the edge between the faces [-]."""
    min_skew_rows: int = 9
    """... tested with at least this many rolling contacts [-]."""
    start_lean_sigmas: float = 4.0
    """The first :attr:`min_skew_rows` rolling contacts (the last rows on the face among them) turn about the edge
    too: over a true edge their mean ``n · e`` is the noise's (``σn / √9``, with the floor; at most 2.5 times it
    over 144 crossings of true edges in 10 episodes at 30-150 mm), while a pad that rolled over another edge of the
    face and on round the vertex at its end (the roll then turning about the line to the face it landed on, which
    shares only the vertex) first turned about that edge (bipyramid_10 at 150 mm, seed 2: ten rows turned 8-12°
    about an axis 20-40° off the line between the faces, 6 times the noise's lean, every row after them on the arc
    between the faces; the "edge" 28° off the true one, 29 bounds). A mean beyond this many times the noise's is
    no roll over the edge between the faces [-]."""
    rim_sigmas: float = 3.5
    """A stroke's step onto the next face turns its normal (the mean of its first :attr:`steady_window` rows against
    that of its last) by more than :attr:`sample_cone`, and by more than this many σ of the noise's difference
    between the two means, where it rolled onto the rim of the face's far edge (``Toucher._stepped_onto_rim``) [-]."""
    steady_window: int = 9
    """A face's rows hold a steady normal: averaged over this many consecutive rows, the sensor's noise drops by
    its square root, while a pad that starts to roll over an edge (the last rows of a trace across the face,
    within :attr:`face_cone` of it for the first few degrees) turns its normal steadily to one side [-] ..."""
    lean_sigmas: float = 3.0
    """A face's rows split in two whose mean normals differ by more than this many σ of that difference: one part
    leaned, and the face's bound covers it (:func:`lean_widened`) [-]."""
    steady_sigmas: float = 3.0
    """... and a row whose averaged normal lies more than this many of that average's σ (with
    :attr:`normal_floor`) from the face's is dropped from the face's fit [-]."""
    steady_lean_sigmas: float = 5.5
    """The steady rows themselves split in two whose mean normals differ by more than this many σ of that
    difference, at any noise level: the pad rode within a fraction of a millimetre of a rim over part of the stroke,
    where its sensed normal leans toward the rim by 1-2° (on the formula corpus at 30 mm: rows within 0.3 mm of an
    edge of their face leaned toward it by 0.8-2.1° on average, within 0.3-0.6 mm 0.4-1.4°, farther none), inside
    :attr:`sample_cone` and, when half the rows lean, about the median :func:`steady_rows` centres on; the rows
    themselves do not say which part leaned (an edge beside the stroke need not have been met), and the face's bound
    covers both (:func:`lean_widened`). bipyramid_12 at 30 mm, seed 2: the next face of a vertex move, a triangle
    6.2 mm wide, its stroke's first half 0.1-0.5 mm from the face's edge beyond (not the one crossed) and leaning
    1.75° toward it, the face 1.06 bounds off (6.7 σ). Of 212 faces of 15 corpus models at 30 mm (seed 2) and the
    seed library at 60 mm (seed 1), 2 split by more (6.2 and 6.7 σ, both bipyramid_12's), 3 by 4.7-5.5 σ (one of them
    a face 1.73 bounds off that its move then discarded), the rest by less; a stroke ending in a roll whose first
    rolling rows :func:`steady_rows` keeps splits by about 5 σ, its fit within half its bound [-]."""
    max_roll_offset: float = 2e-3
    """The contact points of a roll over a convex edge lie on the edge, hence on both faces' planes; a roll
    farther than this (median) from either plane was not over the edge between them [m]."""

    @property
    def row_cone(self) -> float:
        """The cone about a face's normal within which a sensed normal is one of the face's rows: :attr:`face_cone`,
        or :attr:`face_cone_sigmas` σn when the sensor is noisier [rad]."""
        return max(self.face_cone, self.face_cone_sigmas * self.normal_sigma)

    def agree(self, a: np.ndarray, b: np.ndarray, sigma: float) -> bool:
        """Whether two estimates of one direction agree within :attr:`fit_agreement_sigmas` × ``sigma`` plus
        :attr:`fit_agreement_slack`."""
        return angle_between(a, b) < self.fit_agreement_sigmas * sigma + self.fit_agreement_slack

    @classmethod
    def from_noise(cls, force_std: float, normal_std: float, point_std: float, **kw) -> SegmentBounds:
        """Bounds for a sensor with these standard deviations [N, rad, m]."""
        return cls(normal_sigma=normal_std, point_sigma=point_std, force_sigma=force_std, **kw)

    @classmethod
    def from_model(cls, model: NoiseModel, **kw) -> SegmentBounds:
        """Bounds for the per-sample noise of ``model``: its σ at level 1 scaled by its level (:meth:`scaled`)."""
        return cls.from_noise(model.force_std, model.normal_std, model.point_std, **kw).scaled(model.level)

    def scaled(self, level: float) -> SegmentBounds:
        """The bounds for a sensor whose noise is ``level`` times this one's (the statistical σ scale; the
        systematic floors, pad compliance and detection delay, do not)."""
        return replace(self, normal_sigma=self.normal_sigma * level, point_sigma=self.point_sigma * level,
                       force_sigma=self.force_sigma * level)  # fmt: skip

    def bound(self, sigma: float, floor: float) -> float:
        return self.k * math.sqrt(sigma * sigma + floor * floor)

    def floors(self) -> BoundFloors:
        """How the components' bounds are made (:meth:`bound`), per quantity, for the acceptance test: a face's
        points are single samples, their floor the larger of :attr:`position_floor` and σp
        (:meth:`Segmenter.add_face`)."""
        return BoundFloors(self.k, face_normal=self.normal_floor,
                           face_point=max(self.position_floor, self.point_sigma), edge_direction=self.direction_floor,
                           edge_line=self.position_floor, vertex=self.vertex_floor)  # fmt: skip


@dataclass(frozen=True, eq=False)
class FaceFit:
    """A plane estimated from contact rows."""

    normal: np.ndarray
    """Outward unit normal (3,)."""
    offset: float
    """``n · w = offset`` on the plane [m]."""
    points: np.ndarray
    """Contact points projected onto the plane (k, 3) [m]."""
    normal_sigma: float
    """Statistical σ of the normal [rad]."""
    offset_sigma: float
    """Statistical σ of the plane position [m]."""
    count: int
    """Rows used."""


@dataclass(frozen=True, eq=False)
class LineFit:
    """A line estimated for an edge, with the explored parameter interval."""

    point: np.ndarray
    """A point on the line (3,) [m]."""
    direction: np.ndarray
    """Unit direction (3,)."""
    direction_sigma: float
    """[rad]."""
    position_sigma: float
    """[m]."""
    s_range: tuple[float, float]
    """Explored interval ``[s_lo, s_hi]`` along ``direction`` from ``point`` [m]."""


def face_rows(
    trace: ContactTrace, normal_guess: np.ndarray, cone: float, min_rows: int = SegmentBounds.min_refine_rows
) -> np.ndarray:
    """Mask of the rows whose sensed normal lies within ``cone`` of the face normal (refined once, about their
    mean normal, when at least ``min_rows`` agree with the guess)."""
    ok = trace.in_contact
    n = np.where(ok[:, None], trace.normal_in_world, 0.0)
    c = math.cos(cone)
    mask = ok & (n @ normal_guess > c)
    if mask.sum() >= min_rows:
        mask = ok & (n @ unit(n[mask].sum(axis=0)) > c)
    return mask


def steady_rows(trace: ContactTrace, mask: np.ndarray, bounds: SegmentBounds) -> np.ndarray:
    """Of a face's rows ``mask`` (time order), those whose normal holds steady: the running mean of
    :attr:`~SegmentBounds.steady_window` rows lies within :attr:`~SegmentBounds.steady_sigmas` of its σ of the
    face's normal (the mean of the rows kept, from their median). Rows where the pad began to roll over an edge
    turn the running mean off to one side, so that a face fitted from them is tilted toward the next face (up to
    1.3° on a narrow face, past its bound) though every row lies within the face cone. ``mask`` itself when
    fewer rows than a window, or fewer than :attr:`~SegmentBounds.min_face_rows`, would be kept."""
    idx = np.flatnonzero(mask)
    w = bounds.steady_window
    if len(idx) < max(w, bounds.min_face_rows):
        return mask
    n = trace.normal_in_world[idx]
    half = w // 2
    padded = np.concatenate([np.repeat(n[:1], half, axis=0), n, np.repeat(n[-1:], w - 1 - half, axis=0)])
    c = np.concatenate([np.zeros((1, 3)), np.cumsum(padded, axis=0)])
    run = c[w:] - c[:-w]
    run /= np.linalg.norm(run, axis=1)[:, None]
    cut = math.cos(bounds.steady_sigmas * math.sqrt(bounds.normal_sigma**2 / w + bounds.normal_floor**2))
    centre = unit(np.median(run, axis=0))
    for _ in range(2):
        keep = run @ centre >= cut
        if keep.sum() < bounds.min_face_rows:
            return mask
        centre = unit(n[keep].sum(axis=0))
    out = np.zeros_like(mask)
    out[idx[keep]] = True
    return out


def fit_face(points: np.ndarray, normals: np.ndarray, bounds: SegmentBounds) -> FaceFit:
    """Combine the mean sensed normal (σn/√N) with the plane fit of the points (residual / spread) by inverse
    variance; the plane fit counts only when the points span two dimensions (pitfall 6)."""
    nn = len(normals)
    n_mean = unit(normals.sum(axis=0))
    s_mean = bounds.normal_sigma / math.sqrt(max(nn, 1))
    centroid = points.mean(axis=0)
    normal, s_n = n_mean, s_mean
    if len(points) >= bounds.min_plane_points:
        q = points - centroid
        _, sv, vt = np.linalg.svd(q, full_matrices=False)
        spread2 = sv[1] / math.sqrt(len(points))  # rms extent along the second axis [m]
        resid = sv[2] / math.sqrt(len(points))
        if spread2 > bounds.min_plane_spread:
            n_fit = vt[2] if vt[2] @ n_mean > 0 else -vt[2]
            s_fit = max(resid, bounds.point_sigma) / (spread2 * math.sqrt(len(points)))
            if bounds.agree(n_fit, n_mean, math.hypot(s_fit, s_mean)):
                w1, w2 = 1.0 / s_mean**2, 1.0 / s_fit**2
                normal = unit(w1 * n_mean + w2 * n_fit)
                s_n = 1.0 / math.sqrt(w1 + w2)
    d = points @ normal
    offset = float(d.mean())
    resid = float(np.sqrt(np.mean((d - offset) ** 2))) if len(d) > 1 else bounds.point_sigma
    s_off = max(resid, bounds.point_sigma) / math.sqrt(len(d))
    projected = points - (d - offset)[:, None] * normal
    return FaceFit(normal, offset, projected, s_n, s_off, nn)


def lean_widened(fit: FaceFit, normals: np.ndarray, bounds: SegmentBounds, sigmas: float | None = None) -> FaceFit:
    """``fit`` with its normal's σ widened so that its bound covers a systematic lean of part of its rows.

    The face's rows (``normals``, time order) split in two where their mean normals differ most, in units of the
    noise of that difference (σn √(1/a + 1/b), each part at least :attr:`~SegmentBounds.steady_window` rows): by
    more than :attr:`~SegmentBounds.lean_sigmas` of it and more than the floor's bound, one part leaned (a leg of the
    stroke riding a rim) and the face's normal may lie as far off the fit as either part's mean: the bound grows by
    that. Only where the noise blinds the rim tests, whose cut (:attr:`~SegmentBounds.rim_sigmas` σ of the
    difference of two nine-row means) then exceeds their fixed cone :attr:`~SegmentBounds.sample_cone` (noise
    level 2 and above). At noise level 4 (σn 4°) they let through a leg leaning 3-5° (BOX01N at 60 mm, seed 1:
    a step in whose normal turned from 1.8 to 5.2° off the top face, 3.5° on average, the other leg 1.1°, and the
    face 2.3° off against a bound of 1.3°: no-match), which the legs' means tell apart.

    ``sigmas``: the split's threshold at every noise level instead (the steady rows,
    :attr:`~SegmentBounds.steady_lean_sigmas`)."""
    n = len(normals)
    m = bounds.steady_window
    blind = bounds.rim_sigmas * bounds.normal_sigma * math.sqrt(2.0 / m) > bounds.sample_cone
    if n < 2 * m or (sigmas is None and not blind):
        return fit
    c = np.cumsum(normals, axis=0)
    j = np.arange(m, n - m + 1)
    a, b = c[j - 1], c[-1] - c[j - 1]
    cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
    split = np.arccos(np.clip(cos, -1.0, 1.0))
    score = split / (bounds.normal_sigma * np.sqrt(1.0 / j + 1.0 / (n - j)))
    i = int(np.argmax(score))
    if score[i] <= (bounds.lean_sigmas if sigmas is None else sigmas) or split[i] <= bounds.k * bounds.normal_floor:
        return fit
    lean = max(angle_between(a[i], fit.normal), angle_between(b[i], fit.normal))
    wide = bounds.bound(fit.normal_sigma, bounds.normal_floor) + lean
    sigma = math.sqrt(max((wide / bounds.k) ** 2 - bounds.normal_floor**2, fit.normal_sigma**2))
    return replace(fit, normal_sigma=sigma)


def normal_turn_rate(coords: np.ndarray, normals: np.ndarray) -> float:
    """How fast the normals turn with the pad's position: the largest singular value of the least-squares
    slope of the normals' tangent components over ``coords`` (k, m) (pad centres in m in-plane axes) [rad/m].
    Zero on a face; 1/r while rolling on an edge or a vertex."""
    n0 = unit(normals.sum(axis=0))
    a = perpendicular(n0)
    b = np.cross(n0, a)
    y = np.column_stack([normals @ a, normals @ b])
    x = np.column_stack([coords - coords.mean(axis=0), np.ones(len(coords))])
    sol, *_ = np.linalg.lstsq(x, y - y.mean(axis=0), rcond=None)
    return float(np.linalg.svd(sol[:-1], compute_uv=False)[0])


def _extent(points: np.ndarray, axes: bool = False):
    """The extent of ``points`` (k, 3) along their first two principal axes [m] (and those axes, rows of vt)."""
    q = points - points.mean(axis=0)
    _, _, vt = np.linalg.svd(q, full_matrices=False)
    ext = np.ptp(q @ vt[:2].T, axis=0)
    return (ext, vt) if axes else ext


def roll_sweep(normals: np.ndarray, n_a: np.ndarray) -> float:
    """How far rolling ``normals`` (time order) turned on from face ``n_a``: the mean angle off ``n_a`` of their last
    third less that of their first third [rad]. A pad rolling over an edge turns its normal steadily; one standing
    on a vertex or a corner keeps it where it is, up to the noise."""
    turn = np.arccos(np.clip(normals @ n_a, -1.0, 1.0))
    w = max(1, len(turn) // 3)
    return float(turn[-w:].mean() - turn[:w].mean())


def roll_axis_floor(sin2: np.ndarray, bounds: SegmentBounds) -> float:
    """The systematic σ of an edge's direction fitted to rolling normals alone, turned off the face by ``sin2`` (the
    squared sines of their turns): a lean common to every sensed normal (:attr:`~SegmentBounds.normal_floor`, pad
    compliance and contact-frame bias) along the edge is no noise that averages out over the rows; the axis tilts by
    it over the turn's lever, ``Σ sin² / Σ sin`` (at most 1, and no less than :attr:`~SegmentBounds.min_edge_sin`, as
    between two faces). trapezohedron_09 at 30 mm, seed 1: a roll turning 8-44° off the face (97 rows) gave an axis
    1.2° off the edge against a bound of 1.13° (σ 0.22° from the noise alone), its normals leaning along the edge by
    up to 2° as the roll went on [rad]."""
    lever = float(sin2.sum()) / max(float(np.sqrt(sin2).sum()), 1e-12)
    return bounds.normal_floor / max(lever, bounds.min_edge_sin)


def angle_between(a: np.ndarray, b: np.ndarray) -> float:
    return math.acos(max(-1.0, min(1.0, float(unit(a) @ unit(b)))))


def edge_direction(face_a: FaceFit, face_b: FaceFit, bounds: SegmentBounds) -> tuple[np.ndarray, float]:
    """``n_a × n_b`` normalised, and its σ from the normals' σ and the dihedral angle."""
    c = np.cross(face_a.normal, face_b.normal)
    s = math.sqrt(float(c @ c))
    sigma = math.hypot(face_a.normal_sigma, face_b.normal_sigma) / max(s, bounds.min_edge_sin)
    return c / s, sigma


def plane_intersection(
    face_a: FaceFit, face_b: FaceFit, near: np.ndarray, bounds: SegmentBounds
) -> tuple[np.ndarray, float]:
    """The point of the intersection line of two planes nearest ``near``, and its position σ."""
    na, nb = face_a.normal, face_b.normal
    b = unit(np.cross(na, nb))
    a = np.vstack([na, nb, b])
    rhs = np.array([face_a.offset, face_b.offset, float(b @ near)])
    p = np.linalg.solve(a, rhs)
    s = math.sqrt(float(np.cross(na, nb) @ np.cross(na, nb)))
    # plane offsets and the normals' tilt over the distance to the touched points
    lever = max(float(np.linalg.norm(face_a.points.mean(axis=0) - p)), float(np.linalg.norm(face_b.points.mean(0) - p)))
    tilt = lever * math.hypot(face_a.normal_sigma, face_b.normal_sigma)
    sigma = math.hypot(math.hypot(face_a.offset_sigma, face_b.offset_sigma), tilt) / max(s, bounds.min_edge_sin)
    return p, sigma


def line_from_points(
    points: np.ndarray, direction: np.ndarray, direction_sigma: float, bounds: SegmentBounds
) -> LineFit:
    """A line through contact points on an edge: direction ``direction`` (from the faces), refined by the
    points' principal axis when they are spread along it; the explored interval is the points' extent."""
    c = points.mean(axis=0)
    b, s_b = unit(direction), direction_sigma
    q = points - c
    if len(points) >= bounds.min_line_points:
        _, sv, vt = np.linalg.svd(q, full_matrices=False)
        length_rms = sv[0] / math.sqrt(len(points))
        if length_rms > bounds.min_line_spread:
            b_fit = vt[0] if vt[0] @ b > 0 else -vt[0]
            resid = math.hypot(sv[1], sv[2]) / math.sqrt(len(points))
            # independent points: one per line_spacing of the points' extent (rms × √12 for an even spread)
            n_eff = min(len(points), max(2.0, length_rms * math.sqrt(12.0) / bounds.line_spacing))
            s_fit = max(resid, bounds.point_sigma) / (length_rms * math.sqrt(n_eff))
            if bounds.agree(b_fit, b, math.hypot(s_fit, s_b)):
                w1, w2 = 1.0 / s_b**2, 1.0 / s_fit**2
                b = unit(w1 * b + w2 * b_fit)
                s_b = 1.0 / math.sqrt(w1 + w2)
    s = q @ b
    perp = q - np.outer(s, b)
    resid = float(np.sqrt(np.mean(np.sum(perp**2, axis=1)))) if len(points) > 1 else bounds.point_sigma
    s_pos = max(resid, bounds.point_sigma) / math.sqrt(len(points))
    return LineFit(c, b, s_b, s_pos, (float(s.min()), float(s.max())))


MM = 1e3
"""Millimetres per metre (the unit of lengths in messages)."""
AT_END = 1e-9
"""A vertex's parameter within this of an end of an edge's explored interval is at that end (round-off) [m]."""


def _end_vertices(rec: EdgeRecord) -> tuple[list[int], list[int]]:
    """The data vertices at the start and at the end of an edge's explored interval."""
    lo, hi = rec.interval
    return ([v for v, s in rec.vertices.items() if abs(s - lo) < AT_END],
            [v for v, s in rec.vertices.items() if abs(s - hi) < AT_END])  # fmt: skip


# ----------------------------------------------------------------------------------------------------------- book


@dataclass
class FaceRecord:
    """What the segmenter keeps of a data face."""

    fit: FaceFit
    component: DataFace


@dataclass
class EdgeRecord:
    """What the segmenter keeps of a data edge: its line, explored interval and neighbours."""

    point: np.ndarray  # base point on the line
    direction: np.ndarray  # b_d (fixed sign from the first report)
    direction_sigma: float
    position_sigma: float
    interval: tuple[float, float]  # explored [s_lo, s_hi] along direction from point
    faces: tuple[int, int | None]  # (face traced from, face stepped onto; None: it was out of reach)
    convex: bool
    inward: dict[int, np.ndarray] = field(default_factory=dict)  # face id -> in-plane unit vector into the face
    side_points: list[tuple[int, np.ndarray]] = field(default_factory=list)
    vertices: dict[int, float] = field(default_factory=dict)  # data vertex id -> s
    adjacent: tuple[int, ...] = ()
    component: DataEdge | None = None

    def at(self, s: float) -> np.ndarray:
        return self.point + s * self.direction

    def param(self, w: np.ndarray) -> float:
        return float((w - self.point) @ self.direction)


class Segmenter:
    """Turns primitive traces into data components; assigns ids in order of acquisition and adjacency (§2.3).

    Conventions, shared with the geometric executor: a face move reports the new edge (adjacent to the face
    traced from) and then the new face (adjacent to the edge); an edge move re-reports its edge with the
    explored interval extended to the vertex, then the new vertex (adjacent to the edge); a vertex move
    reports the new edge (adjacent to the vertex and the face circled across) and the new face. A face or vertex
    move whose slide crossed a face over an edge too shallow to feel (:meth:`face_crossed`) reports that face first
    (adjacent to nothing: the shallow edge was not located), then the edge rolled over from it and the new face.
    """

    def __init__(self, bounds: SegmentBounds | None = None) -> None:
        self.bounds = bounds or SegmentBounds()
        self.faces: dict[int, FaceRecord] = {}
        self.edges: dict[int, EdgeRecord] = {}
        self.vertices: dict[int, DataVertex] = {}
        self.components: list[DataComponent] = []
        self._next = 0
        self.face_refusal = ""
        """Why the last :meth:`fit_face_trace` gave no face ("" when it gave one)."""

    def _id(self) -> int:
        i = self._next
        self._next += 1
        return i

    @property
    def next_id(self) -> int:
        return self._next

    # -- faces ---------------------------------------------------------------------------------------------
    def fit_face_trace(self, trace: ContactTrace, normal_guess: np.ndarray, two_d: bool = False) -> FaceFit | None:
        """The plane of the rows of ``trace`` that agree with ``normal_guess``; None with fewer than
        ``min_face_rows`` rows, when the normals spread more than noise allows, or when the pad centres of the
        rows do not span ``min_face_extent`` (and ``min_face_width`` across, with ``two_d``): the pad touched a
        vertex or an edge, not a face."""
        b = self.bounds
        mask = face_rows(trace, unit(np.asarray(normal_guess, float)), b.row_cone, b.min_refine_rows)
        if mask.sum() < self.bounds.min_face_rows:
            return self._refuse(f"{int(mask.sum())} rows in the face's cone")
        tips = trace.tip_in_world[mask]
        q = tips - tips.mean(axis=0)
        ext, vt = _extent(tips, axes=True)
        if ext[0] < self.bounds.min_face_extent or (two_d and ext[1] < self.bounds.min_face_width):
            return self._refuse(f"the rows span {ext[0] * 1e3:.1f} mm" + (f" × {ext[1] * 1e3:.1f}" if two_d else ""))
        if normal_turn_rate(q @ vt[: 2 if ext[1] > self.bounds.two_d_extent else 1].T, trace.normal_in_world[mask]) > (
            self.bounds.max_face_curvature
        ):
            return self._refuse("the normals turn along the stroke")
        normals = trace.normal_in_world[mask]
        mean = unit(normals.sum(axis=0))
        spread = float(np.sqrt(np.mean(np.sum((normals - mean) ** 2, axis=1))))  # rms angle [rad]
        if spread > self.bounds.max_spread_sigmas * self.bounds.normal_sigma + self.bounds.spread_slack:
            return self._refuse("the normals spread")  # the rows do not come from one plane (a roll, a vertex)
        cone = normals  # every row in the face's cone, in time order: a part leaning widens the bound
        mask = steady_rows(trace, mask, self.bounds)
        if _extent(trace.tip_in_world[mask])[0] < self.bounds.min_face_extent:
            # the rows that hold one normal are the pad pressing in place, the rest turning: the stroke rode a rim
            # (bipyramid_10 at 30 mm, seed 3: every contact within 1.5 mm of the face's edges, the steady rows those
            # of the step in, 4° off the face, spanning 1 mm, and the face 2.8 bounds off)
            return self._refuse("the steady rows press in place")
        if two_d and _extent(trace.tip_in_world[mask])[1] < self.bounds.min_face_width:
            # the steady rows are one leg of the L: the other's normal held elsewhere (the pad rode a rim along the
            # first leg, its normal turned 3° round the edge), and no row measures the face across
            return self._refuse("the steady rows are one leg")
        self.face_refusal = ""
        fit = fit_face(trace.point_in_world[mask], trace.normal_in_world[mask], self.bounds)
        wide = (lean_widened(fit, cone, self.bounds),
                lean_widened(fit, trace.normal_in_world[mask], self.bounds, self.bounds.steady_lean_sigmas))
        return max(wide, key=lambda f: f.normal_sigma)

    def _refuse(self, why: str) -> None:
        """No face from a trace, and why (:attr:`face_refusal`, which a move's failure names)."""
        self.face_refusal = why

    def add_face(self, fit: FaceFit, adjacent: tuple[int, ...] = ()) -> DataFace:
        b = self.bounds
        pts = fit.points
        if len(pts) > b.max_points:
            pts = pts[np.linspace(0, len(pts) - 1, b.max_points).round().astype(int)]
        comp = DataFace(
            id=self._id(),
            normal=fit.normal,
            points=pts,
            normal_bound=b.bound(fit.normal_sigma, b.normal_floor),
            # the points are single samples, each off the face by σp per axis: within the floor at noise level 1,
            # beyond it at level 4 (σp 0.8 mm: touched points next to an edge lay 1.1-2.1 bounds past it)
            position_bound=b.bound(fit.offset_sigma, max(b.position_floor, b.point_sigma)),
            adjacent=adjacent,
        )
        self.faces[comp.id] = FaceRecord(fit, comp)
        self.components.append(comp)
        return comp

    # -- edges ---------------------------------------------------------------------------------------------
    def edge_line(
        self, fit_a: FaceFit, fit_b: FaceFit, convex: bool, roll: ContactTrace, corner_hint: np.ndarray
    ) -> LineFit:
        """The line of the edge between faces a and b. Convex: through the contact points recorded while the
        pad rolled over it (normals between the two faces); concave: the planes' intersection, the explored
        interval where the pad was in the corner (``roll`` rows)."""
        bounds = self.bounds
        b_dir, s_b = edge_direction(fit_a, fit_b, bounds)
        if convex:
            ok = roll.in_contact
            n = roll.normal_in_world[ok]
            pts = roll.point_in_world[ok]
            c = math.cos(bounds.sample_cone)
            between = (n @ fit_a.normal < c) & (n @ fit_b.normal < c)
            if between.sum() >= bounds.min_roll_rows:
                return line_from_points(pts[between], b_dir, s_b, bounds)
        p, s_p = plane_intersection(fit_a, fit_b, corner_hint, bounds)
        ok = roll.in_contact
        if ok.any():
            s = (roll.point_in_world[ok] - p) @ b_dir
            rng = (float(s.min()), float(s.max()))
        else:
            rng = (0.0, 0.0)
        return LineFit(p, b_dir, s_b, s_p, rng)

    def edge_from_roll(self, fit_a: FaceFit, roll: ContactTrace) -> tuple[LineFit, np.ndarray] | str:
        """The line of a convex edge from face a and a roll over it alone, when the next face is out of reach
        (it leans under): the rolling normals turn about the edge, so its direction is the axis
        perpendicular to ``n_a`` and to every rolling normal (least squares), and the rolling contacts lie on
        it. Returns the line and the last rolling normal, or why the roll cannot give an edge: too few
        rolling contacts, a turn under ``min_edge_angle``, contacts off face a's plane, or normals that did
        not turn about one axis."""
        b = self.bounds
        ok = roll.in_contact
        n, pts = roll.normal_in_world[ok], roll.point_in_world[ok]
        n_a = fit_a.normal
        turned = n @ n_a < math.cos(b.sample_cone)
        if turned.sum() < b.min_turned_rows:
            return "too few contacts while rolling over the edge"
        n, pts = n[turned], pts[turned]
        sin2 = 1.0 - np.clip(n @ n_a, -1.0, 1.0) ** 2
        if math.asin(math.sqrt(float(sin2.max()))) < b.min_edge_angle:
            return "the normal turned too little over the edge"
        swept = roll_sweep(n, n_a)
        w = max(1, len(n) // 3)
        if swept < b.sweep_sigmas * math.hypot(b.normal_sigma, b.normal_floor) * math.sqrt(2.0 / w):
            return (f"the rolling normals swept {math.degrees(swept):.1f}° along the arc off the face: they stood "
                    "turned, not rolling about an edge")  # fmt: skip
        off = float(np.median(np.abs(pts @ n_a - fit_a.offset)))
        if off > b.max_roll_offset:
            return f"the roll lies {off * MM:.1f} mm off the face's plane"
        # the edge direction e ⊥ n_a: e = cos φ u + sin φ w; each rolling normal gives n·e = 0
        u = perpendicular(n_a)
        w = np.cross(n_a, u)
        m = np.column_stack([n @ u, n @ w])
        _, _, vt = np.linalg.svd(m, full_matrices=False)
        e = unit(vt[-1, 0] * u + vt[-1, 1] * w)
        resid = n @ e
        # with no second face to check the edge against, every rolling normal must have turned about it
        if float(np.quantile(np.abs(resid), b.roll_axis_quantile)) > math.sin(b.roll_axis_slack) + b.k * b.normal_sigma:
            return "the roll turned about more than one axis (round a vertex?)"
        rms = float(np.sqrt(np.mean(resid**2)))
        if rms > b.roll_rms_sigmas * math.hypot(b.normal_sigma, b.normal_floor):
            return (f"the rolling normals lie {math.degrees(rms):.1f}° (rms) off the plane of any one axis, more than "
                    "the noise allows (a roll round a vertex?)")  # fmt: skip
        sigma_n = max(rms, b.normal_sigma)
        s_e = math.hypot(sigma_n / math.sqrt(float(sin2.sum())), roll_axis_floor(sin2, b), fit_a.normal_sigma)
        return line_from_points(pts, e, s_e, b), n[-1].copy()

    def edge_inconsistency(self, fit_a: FaceFit, fit_b: FaceFit, convex: bool, roll: ContactTrace) -> str | None:
        """Why the roll from face a onto face b cannot have been over the edge between them (None: it can):
        the faces' normals are too close for an edge, the rolling normals did not turn about ``n_a × n_b``,
        or (convex) the rolling contacts lie off either face's plane, or (too few of them between the faces'
        normals to locate the edge) all off the line where the planes meet (:meth:`roll_off_line`). Such a move
        met the next face after going round some other edge or vertex, or across a face between the two:
        reporting an edge between a and b would be spurious."""
        b = self.bounds
        if angle_between(fit_a.normal, fit_b.normal) < b.min_edge_angle:
            return "the two faces' normals are too close for an edge"
        ok = roll.in_contact
        if not ok.any():
            return None
        n = roll.normal_in_world[ok]
        pts = roll.point_in_world[ok]
        c = math.cos(b.sample_cone)
        between = (n @ fit_a.normal < c) & (n @ fit_b.normal < c)
        if between.sum() < b.min_roll_rows:
            return self.roll_off_line(fit_a, fit_b, pts) if convex else None
        e = unit(np.cross(fit_a.normal, fit_b.normal))
        skew = float(np.median(np.abs(n[between] @ e)))
        if skew > math.sin(b.max_roll_skew):
            return "the roll turned about another axis than the edge between the faces"
        noise = MEDIAN_ABS_NORMAL * math.hypot(b.normal_sigma, b.normal_floor)
        if between.sum() >= b.min_skew_rows and skew > b.roll_skew_sigmas * noise:
            return (f"the rolling normals lean {math.degrees(skew):.1f}° along the edge between the faces, more than "
                    "the noise allows (a roll round a vertex)")  # fmt: skip
        lean = abs(float(np.mean(n[between] @ e)))
        if between.sum() >= b.min_skew_rows and lean > b.roll_lean_sigmas * math.hypot(
            b.normal_sigma / math.sqrt(float(between.sum())), b.normal_floor
        ):
            return (f"the rolling normals lean {math.degrees(lean):.1f}° along the edge between the faces on average, "
                    "more than the noise allows (a roll round a vertex)")  # fmt: skip
        start = n[between][: b.min_skew_rows]
        lean = abs(float(np.mean(start @ e)))
        if between.sum() >= b.min_skew_rows and lean > b.start_lean_sigmas * math.hypot(
            b.normal_sigma / math.sqrt(len(start)), b.normal_floor
        ):
            return (f"the first rolling normals lean {math.degrees(lean):.1f}° along the edge between the faces, more "
                    "than the noise allows (the pad rolled over another edge, then round a vertex)")  # fmt: skip
        if convex:
            q = pts[between]
            off = max(float(np.median(np.abs(q @ fit_a.normal - fit_a.offset))),
                      float(np.median(np.abs(q @ fit_b.normal - fit_b.offset))))  # fmt: skip
            if off > b.max_roll_offset:
                return f"the roll lies {off * MM:.1f} mm off the faces' planes"
            return self.ridge_ridden(fit_a, fit_b, q)
        return None

    def roll_off_line(self, fit_a: FaceFit, fit_b: FaceFit, rolled: np.ndarray) -> str | None:
        """Why a convex edge between faces a and b cannot lie on the line where their planes meet (None: it can),
        for a roll that left too few contacts between the faces' normals to locate the edge (:meth:`edge_line`
        then places it on that line). The pad rolling over an edge touches it, so some contact of the roll (the
        last rows on face a among them, ``rolled``) lies on the line, within the line's position σ and a contact
        point's; none does when the pad slid across a third face between a and b whose edges turn the normal by
        less than the edge angle each, then met a turn past it: the planes of a and b meet where neither face
        is. metabiaugmented_hexagonal_prism at 70 mm (of the public collection of Johnson solids), seed 1: from a
        pyramid's triangle across the 26 mm square beside it (5.3° each side) onto the other pyramid's triangle,
        a roll of 22 contacts 13-14 mm from that line, the "edge" reported there 13 bounds off the true ones;
        over true edges with as few rolling contacts (turns of 13-14°) the nearest lay 0.03-0.08 mm from it."""
        b = self.bounds
        p, s_p = plane_intersection(fit_a, fit_b, rolled.mean(axis=0), b)
        e = unit(np.cross(fit_a.normal, fit_b.normal))
        w = rolled - p
        w -= np.outer(w @ e, e)
        near = math.sqrt(float(np.min(np.sum(w * w, axis=1))))
        bound = b.bound(math.hypot(s_p, b.point_sigma), b.position_floor)
        if near <= bound:
            return None
        return (f"the roll's contacts lie {near * MM:.1f} mm or more from the line where the faces' planes meet, "
                f"more than its bound ({bound * MM:.1f} mm): the pad crossed a face between them, its edges too "
                "shallow to feel")  # fmt: skip

    def face_crossed(self, slide: ContactTrace, fit_a: FaceFit) -> tuple[FaceFit, ContactTrace] | None:
        """The face a slide from face a went onto over an edge too shallow to feel before it met the edge it stopped
        at, fitted from its last steady rows, and those rows; None when the slide's normals show none.

        The slide stops at an edge where its normal turns from face a's by :attr:`min_edge_angle`; an edge of a
        smaller turn it slides over, onto a face between a and the edge it rolls over next, whose line then lies
        nowhere near ``n_a × n_b`` (:meth:`roll_off_line`), the rolling normals leaning along it by the shallow turn.
        The slide's normals tell that face: the last of its rows (``slide``, time order) to hold one normal over two
        :attr:`steady_window` running means (within :attr:`steady_sigmas` of their σ), turned from ``n_a`` by more
        than :attr:`sample_cone` (the primitives' own cut for a normal off the face) and less than the edge angle, and
        the rows about them amid running means as close to theirs (back to the shallow edge, within the face cone and
        nearer theirs than face a's; on to the roll, within the noise), not those at either end of such a mean, which
        may have begun to turn. The roll's first rows may hold a normal as steadily (a slow turn at a slant: on the
        augmented sphenocorona of the same collection, seed 1, 9.5° off the start face and 3° round from the face
        before them) and give no face: then the stretch before them, if the pad slid on past it, those rows aside, by
        no more than :attr:`min_face_extent`. They are a face only as any stroke's rows
        are (:meth:`fit_face_trace`: enough rows, extent, no turn along them, no spread), turned from face a by more
        than the bound of the two fits' difference, their contacts off the line where the two planes meet (on
        average, by more than that line's bound: a ride along a rim of face a leaves them on it).
        metabiaugmented_hexagonal_prism at 70 mm (of the public
        collection of Johnson solids), seed 1: slides from a square of the prism over its 5.3° edge onto a pyramid's
        triangle and on over the triangle's 73° edge, their rolling normals leaning 2.4-3.6° along ``n_a × n_b``."""
        b = self.bounds
        w = b.steady_window
        idx = np.flatnonzero(slide.in_contact)
        if len(idx) < 2 * w:
            return None
        n = slide.normal_in_world[idx]
        c = np.concatenate([np.zeros((1, 3)), np.cumsum(n, axis=0)])
        run = c[w:] - c[:-w]
        run /= np.linalg.norm(run, axis=1)[:, None]
        cut = math.cos(b.steady_sigmas * math.sqrt(b.normal_sigma**2 / w + b.normal_floor**2))
        off = run @ fit_a.normal
        steady = np.flatnonzero((np.einsum("ij,ij->i", run[:-w], run[w:]) >= cut) & (off[:-w] < math.cos(b.sample_cone))
                                & (off[:-w] > math.cos(b.min_edge_angle)))  # fmt: skip
        tips = slide.tip_in_world[idx]
        refusal = self.face_refusal
        past = np.ones(len(idx), dtype=bool)  # rows after the stretch tried, but those of stretches that were no face
        while len(steady):
            i = int(steady[-1])
            guess = unit(run[i] + run[i + w])
            # back to the shallow edge: every running mean within the face cone of theirs, nearer it than face a's;
            # on to the roll: those within the noise of theirs (the roll's first degrees are within the cone)
            back = (run @ guess >= math.cos(b.row_cone)) & (run @ guess > run @ fit_a.normal)
            lo, hi = i, i + w
            while lo > 0 and back[lo - 1]:
                lo -= 1
            while hi + 1 < len(run) and run[hi + 1] @ guess >= cut:
                hi += 1
            steady = steady[steady <= i - w]  # (next, a window back: the first guess may lie on a slow turn)
            first, last = lo + w // 2, hi + w // 2  # the rows amid those windows: none turning
            after = past.copy()
            after[: last + 1] = False
            if after.any() and float(np.max(np.linalg.norm(tips[after] - tips[last], axis=1))) > b.min_face_extent:
                return None  # the pad slid on past these rows: they are not the face the roll left
            rows = slide.select(idx[first : last + 1])
            fit = self.fit_face_trace(rows, guess)
            self.face_refusal = refusal
            if fit is not None and angle_between(fit.normal, fit_a.normal) > max(
                b.sample_cone, b.bound(math.hypot(fit.normal_sigma, fit_a.normal_sigma), b.normal_floor)
            ):
                # across the face from the shallow edge, not on it: a stroke that rode the rim of an edge of face a at a
                # glance holds a turned normal as steadily, its contacts on that edge, where the planes meet (BOX01
                # seed 2: 42 rows turned 8.6°, 0.37 mm from that line on average against a bound of 2.7 mm; the
                # faces crossed on the collection's solids 3-20 mm from it against 1.1-1.3 mm)
                pts = rows.point_in_world[rows.in_contact]
                p, s_p = plane_intersection(fit_a, fit, pts.mean(axis=0), b)
                e = unit(np.cross(fit_a.normal, fit.normal))
                q = pts - p
                q -= np.outer(q @ e, e)
                off = float(np.mean(np.linalg.norm(q, axis=1)))
                if off <= b.bound(math.hypot(s_p, b.point_sigma), b.position_floor):
                    return None
                return fit, rows
            past[first : last + 1] = fit is not None  # a stretch that was a face, though too close to a's, counts
        return None

    def ridge_ridden(self, fit_a: FaceFit, fit_b: FaceFit, rolled: np.ndarray) -> str | None:
        """Why the rows of ``fit_b`` are the ridge of the convex edge rolled over (contact points ``rolled``), not
        the next face (None: they lie on the face, off the edge).

        Past a convex edge the pad touches the next face at a distance from the edge, the stroke's step in off it;
        resting on the ridge it touches the edge itself, its normal partway round, and legs along the edge keep that
        normal as steadily as on a face (its rows pass every test of a face). A roll that ended partway (its settle
        test fired on noise: at noise level 4 two filtered normals a millimetre of travel apart differ by 2° per
        axis, as much as a roll turns over it) then gives a "face" between the two. So the face's contacts must lie
        into it from the edge's line (along ``n_b (n_a · n_b) − n_a``, square to the edge in face b's plane) by more
        than the noise of their mean and of the roll's: LBLOCK01 at 150 mm, seed 1, noise level 4: the roll settled
        36° round a 90° edge, the step in rolled the pad on by 10°, and the legs along the edge gave a face 16
        bounds off, its contacts 0.02 mm from the edge on average, where the next faces of 14 other crossings in
        that episode lay 1.1-5.6 mm in."""
        b = self.bounds
        n_a, n_b = fit_a.normal, fit_b.normal
        w = unit(n_b * float(n_a @ n_b) - n_a)
        pts = fit_b.points
        d = (pts - rolled.mean(axis=0)) @ w
        into = float(d.mean())
        spread = float(np.sqrt(np.mean((d - into) ** 2))) if len(d) > 1 else b.point_sigma
        sigma = math.hypot(max(spread, b.point_sigma) / math.sqrt(len(d)), b.point_sigma / math.sqrt(len(rolled)))
        if into > b.k * sigma:
            return None
        return (f"the next face's contacts lie {into * MM:.2f} mm into it from the edge, within the noise of the edge "
                "(the pad rode the ridge, its normal partway round)")  # fmt: skip

    def add_edge(
        self,
        line: LineFit,
        faces: tuple[int, int | None],
        convex: bool,
        normals: tuple[np.ndarray, np.ndarray],
        adjacent: tuple[int, ...],
        vertex: tuple[int, float] | None = None,
    ) -> DataEdge:
        """Report a new edge between ``faces`` of outward ``normals`` (``faces[1]`` may be the id the next face
        will get, or None when it is out of reach and ``normals[1]`` is the last normal rolled onto).
        ``vertex``: a known data vertex on this edge and its parameter.

        Which side of the edge each face lies on follows from the normals and the convexity (a convex edge's
        face a extends away from ``n_b``, a concave edge's towards it), not from contact points next to the
        edge, whose offset across the edge is often below the noise; the side points reported are on each face
        ``side_reach`` in from the middle of the explored interval."""
        eid = self._id()
        rec = EdgeRecord(
            point=line.point, direction=line.direction, direction_sigma=line.direction_sigma,
            position_sigma=line.position_sigma, interval=line.s_range, faces=faces, convex=convex,
            adjacent=adjacent,
        )  # fmt: skip
        if vertex is not None:
            rec.vertices[vertex[0]] = vertex[1]
        mid = rec.at(0.5 * (rec.interval[0] + rec.interval[1]))
        for fid, n_f, n_o in ((faces[0], normals[0], normals[1]), (faces[1], normals[1], normals[0])):
            if fid is None:  # the next face was out of reach
                continue
            w = unit(n_o - float(n_o @ n_f) * n_f)
            w = unit(w - float(w @ rec.direction) * rec.direction)
            rec.inward[fid] = -w if convex else w
            rec.side_points.append((fid, mid + self.bounds.side_reach * rec.inward[fid]))
        self.edges[eid] = rec
        return self._emit_edge(eid)

    def beside_parallel_face(self, eid: int, face: int, fit_next: FaceFit) -> bool:
        """Whether the next face of an edge met from ``face`` (one of edge ``eid``'s faces), fitted as
        ``fit_next``, is parallel to the edge's other face within their normal bounds. Its edge with ``face`` then
        lies on edge ``eid``'s line or on one parallel to it: a vertex circle on ``face`` round an end of edge
        ``eid`` that met it met that edge again past the vertex, or an edge collinear with it across a gap (BOX01N's
        end face, circled round a corner of its slot's mouth: the top edge beyond the slot), never an edge leaving
        the vertex circled (two faces of one plane along one line meet at no vertex there)."""
        rec = self.edges[eid]
        other = next((g for g in rec.faces if g is not None and g != face), None)
        if other is None or other not in self.faces:
            return False
        b = self.bounds
        h = self.faces[other].component
        allowed = math.hypot(h.normal_bound, b.bound(fit_next.normal_sigma, b.normal_floor))
        return angle_between(h.normal, fit_next.normal) <= allowed

    def _emit_edge(self, eid: int) -> DataEdge:
        rec = self.edges[eid]
        b = self.bounds
        lo, hi = rec.interval
        start = next((v for v, s in rec.vertices.items() if abs(s - lo) < AT_END), None)
        end = next((v for v, s in rec.vertices.items() if abs(s - hi) < AT_END), None)
        comp = DataEdge(
            id=eid,
            direction=rec.direction,
            point=rec.at(lo),
            length=max(hi - lo, 0.0),
            direction_bound=b.bound(rec.direction_sigma, b.direction_floor),
            position_bound=b.bound(rec.position_sigma, b.position_floor),
            length_bound=b.bound(0.0, b.length_floor),
            start_vertex=start,
            end_vertex=end,
            adjacent=rec.adjacent,
            side_points=tuple(rec.side_points),
        )
        rec.component = comp
        self.components.append(comp)
        return comp

    def refine_edge(self, eid: int, ridge_points: np.ndarray | None, fits: tuple[FaceFit, FaceFit]) -> None:
        """Refine an edge's line with the contact points of a ridge trace along it (convex edges), keeping the
        sign of its direction."""
        rec = self.edges[eid]
        if ridge_points is None or len(ridge_points) < self.bounds.min_line_points or not rec.convex:
            return
        b_dir, s_b = edge_direction(*fits, self.bounds)
        if b_dir @ rec.direction < 0:
            b_dir = -b_dir
        old_ends = [rec.at(s) for s in rec.interval]
        old_v = {v: rec.at(s) for v, s in rec.vertices.items()}
        starts, stops = _end_vertices(rec)
        line = line_from_points(ridge_points, b_dir, s_b, self.bounds)
        rec.point, rec.direction = line.point, line.direction
        rec.direction_sigma, rec.position_sigma = line.direction_sigma, line.position_sigma
        ends = [rec.param(w) for w in old_ends] + list(line.s_range)
        rec.vertices = {v: rec.param(w) for v, w in old_v.items()}
        # an end at a vertex stays there: ridge contacts past it lie on the next edge, turning little from this one
        lo = rec.vertices[starts[0]] if starts else min(ends)
        hi = rec.vertices[stops[0]] if stops else max(ends)
        rec.interval = (lo, hi)

    def behind_interval(self, eid: int, s_vertex: float, s_from: float, sense: int) -> bool:
        """Whether a vertex located at parameter ``s_vertex`` by an edge move in ``sense`` (+1 along the data edge's
        direction, −1 against it) that set off at ``s_from`` is not the end the move ran toward: less than
        :attr:`SegmentBounds.length_floor` ahead of the farther back of its start and edge ``eid``'s explored interval's
        back end, or, while no vertex of the edge is known behind the interval, behind the interval itself.

        A pad setting off behind the interval with no vertex known there may have set off past the edge's other end,
        on the faces beyond it, and come back over that end, which it then locates ahead of its start but behind the
        interval (trapezohedron_11 of the formula corpus, seed 1: a move against the edge's direction acquired the
        ridge 3.2 mm behind the interval, past the edge's end, was blocked 0.5 mm on where the faces there meet the
        edge's line, 2.9 mm ahead of its start, 0.3 mm behind the interval; the edge, re-reported as starting at that
        vertex and running on past it, pruned the true object: no-match). The end the move runs to lies ahead of the
        interval's back end, though not by the floor: an interval from a crossing or a roll may reach over it
        (antiprism_11, seed 1: a crossing's interval 1.1 mm long straddled the vertex the move then located 0.95 mm
        ahead of its back end; trapezohedron_06: an interval from a vertex move's roll reaching over its far end). With
        a vertex known behind the interval the pad set off on the edge when it set off ahead of that vertex (one
        located at that vertex is checked on its own)."""
        rec = self.edges[eid]
        lo, hi = rec.interval
        back = lo if sense > 0 else hi
        start = min(back, s_from) if sense > 0 else max(back, s_from)
        if sense * (s_vertex - start) < self.bounds.length_floor:
            return True
        if any(sense * (s - back) < 0 for s in rec.vertices.values()):
            return False
        return sense * (s_vertex - back) < 0

    def extend_edge(
        self, eid: int, s_from: float, s_vertex: float, vertex_sigma: float, sense: int
    ) -> tuple[DataEdge, DataVertex]:
        """An edge move in ``sense`` (+1 along the data edge's direction, −1 against it) reached a vertex at
        parameter ``s_vertex`` having started at ``s_from``: re-report the edge with its interval extended to
        the vertex, and report the vertex (adjacent to the edge).

        The vertex is the end of the interval the move ran toward, whatever the measured parameters say: a
        contact point measured a fraction of a millimetre past the corner must not turn the vertex into the
        other end of the edge (``start_vertex``/``end_vertex`` state which way the edge runs from it); the mover
        checks first that it is not the edge's other end (:meth:`behind_interval`)."""
        rec = self.edges[eid]
        b = self.bounds
        vid = self._id()
        lo, hi = rec.interval
        starts, stops = _end_vertices(rec)
        # the end the move started from stays at its vertex where one is known (the move may start from a contact
        # past it, on the next edge turning little from this one)
        if sense > 0:
            hi_new = s_vertex
            known = [rec.vertices[v] for v in starts if rec.vertices[v] < s_vertex]
            lo_new = known[0] if known else min(lo, s_from, s_vertex)
            for v, s in list(rec.vertices.items()):
                if s > hi_new:
                    del rec.vertices[v]
        else:
            lo_new = s_vertex
            known = [rec.vertices[v] for v in stops if rec.vertices[v] > s_vertex]
            hi_new = known[0] if known else max(hi, s_from, s_vertex)
            for v, s in list(rec.vertices.items()):
                if s < lo_new:
                    del rec.vertices[v]
        rec.interval = (lo_new, hi_new)
        rec.vertices[vid] = s_vertex
        pos = rec.at(s_vertex)
        vertex = DataVertex(
            id=vid,
            position=pos,
            position_bound=b.bound(math.hypot(vertex_sigma, rec.position_sigma), b.vertex_floor),
            adjacent=(eid,),
        )
        # the edge first (same id, extended), then the vertex -- the edge's end refers to the new vertex id
        edge = self._emit_edge(eid)
        self.components.append(vertex)
        self.vertices[vid] = vertex
        return edge, vertex


__all__ = [
    "AT_END",
    "MEDIAN_EFFICIENCY",
    "MM",
    "EdgeRecord",
    "FaceFit",
    "FaceRecord",
    "LineFit",
    "SegmentBounds",
    "Segmenter",
    "edge_direction",
    "face_rows",
    "fit_face",
    "line_from_points",
    "plane_intersection",
    "roll_sweep",
]
