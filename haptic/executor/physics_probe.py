"""The free-space probe (seed §1.1) on the simulated hand: :meth:`PhysicsExecutor.execute` of a
:class:`~haptic.planning.moves.ProbeMove` (:func:`probe_move`).

The index pad's *leading point* -- its centre plus the pad radius along the line's direction -- travels the
line, so the planner's line-cast predictions hold for a head-on contact and the line itself is free wherever
the pad passed. Step by step, every motion guarded (any fingertip's touch, or the pad held back from its
command, ends it):

1. *Leave the surface*: lift along the sensed normal (``ProbeSettings.lift``).
2. *Transfer, up and over*: rise straight up to a safe height -- the highest contact sensed so far plus the pad
   radius and ``ProbeSettings.clearance`` (the object rests on the table and was touched only below it), at
   least the line's start; never above the hand's reach over the region, where the clearance is cut short
   (``ProbeSettings.min_clearance`` at least) --, across, and straight down to the
   pad centre's place at the line's start. A touch on the way is a failed move (``unreachable``), never a hit.
   The path is the planner's (:mod:`haptic.planning.handpath`: :func:`~haptic.planning.handpath.safe_height`,
   :func:`~haptic.planning.handpath.over_the_top`), so its cost prediction follows the hand.
3. *Guarded approach* along the line at ``ProbeSettings.probe_speed`` until the index pad touches, or to the
   line's end (a miss). A touch by another fingertip, or the hand held back, fails the move.
4. *A hit*: back off, touch again slowly and settle, then an L stroke from the contact for the face's normal
   (the start's stroke, :meth:`PhysicsExecutor._normal_stroke`): the segmenter's plane fit of those contacts,
   with bounds from their scatter. The face is reported adjacent to nothing; the sensor rests on it. A contact
   the stroke finds on an edge or a vertex, or the table, fails the move.
5. *A miss*: back the way it came, over the top to where the pad left the surface, and touch the face it
   left again (the sensor state is the one before the probe, as the geometric executor's).

Either way the leading point's path up to the first touch (cut short by ``ProbeSettings.free_margin``: the
pad's compliance and the detection delay) or the whole line is reported free (:class:`FreeSegment`): the
measured pad centres (forward kinematics) plus the pad radius along the line, with a bound of the segmenter's
position bound plus the largest sideways deviation of the measured path from its straight line. The cost is
``c_p + c_s s`` over the distance ``s`` travelled in free space (lift, transfer, approach, and the way back
after a miss), plus ``c_n`` for the normal stroke of a hit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from haptic.executor.primitives import PrimitiveResult
from haptic.executor.segment import FaceFit
from haptic.geometry.se3 import angle, perpendicular, unit
from haptic.matching.free_space import FreeSegment
from haptic.matching.trace import ContactTrace
from haptic.planning.handpath import CLEARANCE, LIFT, over_the_top, safe_height
from haptic.planning.moves import MoveResult, ProbeMove, SensorState
from haptic.sim.scene import TABLE_TOP_Z

PhysicsExecutor = Any
"""The :class:`~haptic.executor.physics.PhysicsExecutor` whose hand carries out the probe (its toucher, segmenter,
bounds, costs and state); the type is not imported here, since that module dispatches to this one."""


@dataclass(frozen=True)
class ProbeSettings:
    """Geometry and speeds of the probe on the hand."""

    lift: float = LIFT
    """Lift off the surface along its normal before the transfer [m]."""
    clearance: float = CLEARANCE
    """The transfer passes this far above the highest contact sensed so far (plus the pad radius) [m], and no
    higher than the hand's reach over the region (``PhysicsSettings.max_approach_height``), as a placement's rise;
    ..."""
    min_clearance: float = 0.01
    """... where the reach leaves less than this, the probe fails (the line's start above the reach fails it too)
    [m]. Over a 150 mm solid standing 160 mm tall (augmented_truncated_tetrahedron of the public polyhedra at 150 mm,
    seed 2) the full clearance put the transfer 3 mm above the reach, and all four probes its verification asked
    for failed; the reach leaves 33 mm."""
    transfer_speed: float = 0.15
    """Speed of the transfer [m/s]."""
    probe_speed: float = 0.05
    """Speed of the guarded approach along the line [m/s]."""
    back_off: float = 0.004
    """After the first touch the pad backs off this far and touches again slowly [m]."""
    free_margin: float = 0.0015
    """A hit's free segment ends this far before the leading point's place at the first touch (pad compliance,
    detection delay) [m]."""
    transfer_lag: float = 0.012
    """The transfer is blocked when the pad lags its command by more than this [m] ..."""
    probe_lag: float = 0.004
    """... the approach along the line by more than this [m]."""
    min_free_length: float = 1e-4
    """A free segment shorter than this is not reported [m]."""


SETTINGS = ProbeSettings()


def _free_distance(pieces: list[PrimitiveResult]) -> float:
    return float(sum(p.distance for p in pieces))


def _leading_segment(tips: np.ndarray, u: np.ndarray, radius: float, cut: float, bound: float,
                     min_length: float = SETTINGS.min_free_length) -> FreeSegment | None:  # fmt: skip
    """The free segment of the leading point for the pad centres ``tips`` (n, 3) measured along a line of
    direction ``u``: from the first centre plus ``radius`` along ``u``, as far as they went less ``cut``; its
    bound is ``bound`` plus the largest sideways deviation of the centres from that line. None when shorter than
    ``min_length``."""
    if len(tips) < 2:
        return None
    p0 = tips[0]
    s = (tips - p0) @ u
    length = float(s.max()) - cut
    if length <= min_length:
        return None
    side = tips - p0 - s[:, None] * u[None, :]
    dev = float(np.linalg.norm(side, axis=1).max())
    return FreeSegment(p0 + radius * u, u, length, bound + dev)


RISE_TRIES = 4
"""A rise above the object (:func:`rise`) is tried again at most this many times after it was held back [-] ..."""
STEP_OUT = 0.008
"""... each time a touch held it back stepping this far level away from the touch first [m]."""
LEVEL_NORMAL = 0.3
"""A touch whose sensed normal's level part is shorter than this (a face above, nearly level) gives no way out to the
side: the rise fails [-]."""


def rise(t, z: float, speed: float, lag: float, pieces: list[PrimitiveResult],
         tries: int = RISE_TRIES) -> PrimitiveResult:  # fmt: skip
    """The pad guarded straight up to height ``z`` (toucher ``t``'s :meth:`move_guarded`), recovering where it is held
    back: with nothing sensed touching (the arm's posture: a joint at its limit pulls the pad off its line) the arm
    goes in joint space to the posture of its home family above (:meth:`back_to_home_posture`) and rises again; at a
    touch of a fingertip or a link (a face leaning over the finger, an overhang) it steps :data:`STEP_OUT` level along
    the sensed normal, away from the object, and rises again from there; at most ``tries`` times. Every piece is
    appended to ``pieces``; the last one returned (``"done"`` when the pad got up)."""
    res = t.move_guarded(np.array([t.tip[0], t.tip[1], z]), speed, max_lag=lag)
    pieces.append(res)
    for _ in range(tries):
        if res.ok and res.event == "done":
            break
        link = t.link_touch() if res.event == "blocked" else None
        if res.event == "blocked" and link is None:
            if not t.back_to_home_posture(np.array([t.tip[0], t.tip[1], z])):
                break
        elif (res.ok and res.event == "contact") or link is not None:
            sensed = res.info["normal"] if link is None else link.normal_in_world
            n = np.asarray(sensed, dtype=float) * np.array([1.0, 1.0, 0.0])
            if float(np.linalg.norm(n)) < LEVEL_NORMAL:
                break
            out = t.move_free(t.tip + STEP_OUT * unit(n), timeout=t.config.lift_timeout, tol=t.config.lift_tol,
                              retry=False)  # fmt: skip
            pieces.append(out)
            if not out.ok:
                break
        else:
            break
        res = t.move_guarded(np.array([t.tip[0], t.tip[1], z]), speed, max_lag=lag)
        pieces.append(res)
    return res


def probe_move(ex: PhysicsExecutor, move: ProbeMove, pieces: list[PrimitiveResult],
               settings: ProbeSettings = SETTINGS) -> MoveResult:  # fmt: skip
    """Carry out ``move`` with ``ex``'s hand (module docstring); a failure is a status, never an exception."""
    t, st, seg = ex.toucher, ex.state, ex.segmenter
    if (problem := move.problem()) is not None:
        return ex.invalid_result(move, problem)
    start = np.asarray(move.start, dtype=float)
    u = np.asarray(move.direction, dtype=float)
    length = float(move.length)
    r = t.pad_radius
    centre0 = start - r * u  # the pad centre when its leading point is at the line's start
    centre1 = centre0 + length * u
    floor = TABLE_TOP_Z + ex.settings.pad_clearance
    if min(centre0[2], centre1[2]) - r < floor:
        return ex.invalid_result(move, "the line would bring the pad onto the table")
    z_reach = TABLE_TOP_Z + ex.settings.max_approach_height
    highest = _highest_contact(ex)
    if float(centre0[2]) > z_reach:
        return ex.failed_result(move, "unreachable", "the line's start is above the hand's reach over the region")
    if z_reach < highest + r + settings.min_clearance:
        return ex.failed_result(move, "unreachable", "the hand's reach over the region leaves the pad no way over "
                                                     "the object")  # fmt: skip
    z_safe = min(safe_height(highest, r, centre0, t.tip, settings.clearance), z_reach)
    was_on = ex.on_face if (ex.on_face == st.face and t.contact[1] is not None) else None
    free: list[PrimitiveResult] = []  # the pieces through free space, for the distance

    def leg(point: np.ndarray, speed: float, lag: float, phase: str = "free") -> PrimitiveResult:
        res = t.move_guarded(point, speed, phase=phase, max_lag=lag)
        pieces.append(res)
        free.append(res)
        return res

    # 1. leave the surface
    n_left = t.normal.copy() if t.contact[1] is not None and t.normal is not None else np.array([0.0, 0.0, 1.0])
    if t.contact[1] is not None:
        res = t.move_free(t.tip + settings.lift * n_left, timeout=t.config.lift_timeout, tol=t.config.lift_tol)
        pieces.append(res)
        free.append(res)
        if not res.ok:
            return ex.failed_result(move, res, f"leaving the surface: {res.event}")
    lifted = t.tip.copy()
    ex.on_face = None
    went_along = False  # the pad has been on the line (the way back may follow it)

    def fail(res, reason: str) -> MoveResult:
        """The failed move's result, after going back the way it came (off the object first, when touching)."""
        out = ex.failed_result(move, res, reason)
        if t.contact[1] is not None and t.normal is not None:
            pieces.append(t.move_free(t.tip + settings.lift * t.normal, timeout=t.config.lift_timeout,
                                      tol=t.config.lift_tol))  # fmt: skip
        if went_along:
            _return(ex, lifted, z_safe, n_left, was_on, settings, pieces, [], centre0)
        else:
            _return(ex, lifted, z_safe, n_left, was_on, settings, pieces, [])
        return out
    # 2. up (round what holds the pad back: :func:`rise`), across, down to the line's start
    for name, w in zip(("rising", "moving across", "descending to the line"), over_the_top(lifted, z_safe, centre0),
                       strict=True):  # fmt: skip
        if float(np.linalg.norm(w - t.tip)) < t.config.target_tol:
            continue
        if name == "rising":
            n0 = len(pieces)
            res = rise(t, z_safe, settings.transfer_speed, settings.transfer_lag, pieces)
            free.extend(pieces[n0:])
        else:
            res = leg(w, settings.transfer_speed, settings.transfer_lag)
        if not res.ok or res.event != "done":
            why = f"touched the object {name} (finger {res.info['finger']})" if res.event == "contact" else res.event
            return fail("unreachable" if res.ok else res, f"transfer to the probe's line: {why}")
    # 3. the guarded approach along the line
    went_along = True
    approach = leg(centre1, settings.probe_speed, settings.probe_lag, phase="approach")
    bound = ex.bounds.bound(ex.bounds.point_sigma, ex.bounds.position_floor)
    tips = approach.trace.tip_in_world
    if approach.ok and approach.event == "contact" and approach.info["finger"] != t.finger:
        return fail("unreachable", f"the {approach.info['finger']} fingertip touched the object first")
    if not approach.ok:
        return fail(approach, f"approach along the line: {approach.event}")
    if approach.event == "done":  # a miss: the whole line is free
        segment = _leading_segment(tips, u, r, 0.0, bound, settings.min_free_length)
        back = _return(ex, lifted, z_safe, n_left, was_on, settings, pieces, free, centre0)
        s = _free_distance(free)
        return MoveResult(move=move, status="ok", distance=s, cost=ex.costs.probe_move(s), state=st,
                          free_space=(segment,) if segment is not None else (),
                          info={"contact": None, "returned": back})  # fmt: skip
    # 4. a hit: the path to the first touch is free; touch again slowly, settle, stroke for the normal
    segment = _leading_segment(tips, u, r, settings.free_margin, bound, settings.min_free_length)
    travel = float(approach.info["travel"])
    s = _free_distance(free)
    retreat = t.move_free(t.tip - settings.back_off * u, timeout=t.config.back_off_timeout, tol=t.config.target_tol)
    pieces.append(retreat)
    touch = t.approach(u, settings.back_off + t.config.approach_overshoot)
    pieces.append(touch)
    if not touch.ok:
        return fail(touch, f"touching the contact again: {touch.event}")
    if ex.workspace.is_table(touch.info["normal"], touch.info["point"]):
        return fail("unreachable", "the probe touched the table")
    fit, trace = _measure_face(ex, touch.info["point"], touch.info["normal"], pieces)
    if fit is None:
        return fail("unreachable", "the probe touched an edge or a vertex: no face normal there")
    face = seg.add_face(fit, ())
    ex.store_face(face.id, trace, fit)
    ex.on_face = face.id
    ex.state = SensorState(position=ex.contact_point(), face=face.id)
    return MoveResult(move=move, status="ok", components=(face,), distance=s,
                      cost=ex.costs.probe_move(s) + ex.costs.c_n, state=ex.state,
                      free_space=(segment,) if segment is not None else (),
                      info={"contact": travel, "hit_point": touch.info["point"].tolist()})  # fmt: skip


def _measure_face(ex: PhysicsExecutor, point: np.ndarray, n0: np.ndarray,
                  pieces: list[PrimitiveResult]) -> tuple[FaceFit | None, ContactTrace]:  # fmt: skip
    """The face under the contact at ``point`` (sensed normal ``n0``): an L stroke from it (legs of
    ``normal_stroke``), in up to four headings a quarter turn apart -- touching ``point`` again between tries --
    until one stays on one face (its normal does not turn as the pad slides: not rolling on an edge or a vertex
    nearby) and fits a plane. (None, trace) when none does."""
    t, s, seg = ex.toucher, ex.settings, ex.segmenter
    a = perpendicular(n0)
    phi0 = ex.rng.uniform(0.0, 2.0 * math.pi)
    floor = TABLE_TOP_Z + t.pad_radius + s.table_margin
    trace = ContactTrace.concatenate([])
    for k in range(s.stroke_headings):
        if k > 0:
            again = t.lift_and_approach(point, n0, floor_z=floor)
            pieces.append(again)
            if not again.ok or angle(again.info["normal"], n0) > ex.bounds.retouch_cone:
                return None, trace
        phi = phi0 + k * math.pi / 2.0
        d1 = math.cos(phi) * a + math.sin(phi) * np.cross(n0, a)
        legs = []
        for d in (d1, np.cross(n0, d1)):
            r = t.trace_face(d, n0, s.normal_stroke, phase="stroke")
            legs.append(r)
            pieces.append(r)
            if not r.ok or r.event != "done":
                break
        if legs[-1].status == "unstable":
            return None, trace
        trace = ContactTrace.concatenate([r.trace for r in legs])
        if len(legs) == 2 and all(r.ok and r.event == "done" for r in legs) and ex.on_one_face(trace):
            fit = seg.fit_face_trace(trace, legs[-1].info["face_normal"], two_d=True)
            if fit is not None:
                return fit, trace
    return None, trace


def _highest_contact(ex: PhysicsExecutor) -> float:
    """The highest contact point sensed in any move so far [m] (the table top when none)."""
    z = TABLE_TOP_Z
    for tr in ex.traces:
        ok = tr.in_contact
        if ok.any():
            z = max(z, float(tr.point_in_world[ok, 2].max()))
    t = ex.toucher
    if t.contact[2] is not None:
        z = max(z, float(t.contact[2][2]))
    return z


def _return(ex: PhysicsExecutor, lifted: np.ndarray, z_safe: float, n_left: np.ndarray, was_on: int | None,
            settings: ProbeSettings, pieces: list[PrimitiveResult], free: list[PrimitiveResult],
            line_start: np.ndarray | None = None) -> bool:  # fmt: skip
    """After a miss (or a failure): up from where the pad is -- when that is blocked (under an overhang), back to
    the pad centre's place at the line's start ``line_start`` first --, across and down to where the pad left
    the surface, and touch the face it left again (when it was on one). Whether the pad rests on that face
    again."""
    t = ex.toucher

    def go(w: np.ndarray) -> PrimitiveResult:
        res = t.move_guarded(w, settings.transfer_speed, max_lag=settings.transfer_lag)
        pieces.append(res)
        free.append(res)
        return res

    way = over_the_top(t.tip, z_safe, lifted)
    up = go(way[0])
    if (not up.ok or up.event != "done") and line_start is not None:
        # under an overhang: off the object, back along the line (free: the pad came that way), then up
        if t.contact[1] is not None and t.normal is not None:
            off = t.move_free(t.tip + settings.lift * t.normal, timeout=t.config.lift_timeout, tol=t.config.lift_tol)
            pieces.append(off)
            free.append(off)
        for w in (line_start, np.array([line_start[0], line_start[1], z_safe])):
            up = go(w)
            if not up.ok or up.event != "done":
                return False
    elif not up.ok or up.event != "done":
        return False
    for w in way[1:]:
        if float(np.linalg.norm(w - t.tip)) < t.config.target_tol:
            continue
        res = go(w)
        if not res.ok or res.event != "done":
            return False
    if was_on is None:
        return False
    res = t.approach(-n_left, 2 * settings.lift + t.config.approach_overshoot)
    pieces.append(res)
    free.append(res)
    n_face = ex.segmenter.faces[was_on].component.normal
    if not res.ok or angle(unit(res.info["normal"]), n_face) > ex.bounds.retouch_cone:
        return False
    ex.on_face = was_on
    return True


__all__ = ["LEVEL_NORMAL", "RISE_TRIES", "SETTINGS", "STEP_OUT", "ProbeSettings", "probe_move", "rise"]
