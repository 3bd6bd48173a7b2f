"""The start of the physics executor: the landing search for a first face.

The object rests somewhere over the object region (a workspace prior; its pose is unknown). The pad descends
from above the region at the points of a landing grid, nearest its centre first, raising its approach when the
object stands taller, until it touches something that is not the table; then a short L stroke acquires the
touched face's normal. :class:`LandingSearch` is that part of :class:`~haptic.executor.physics.PhysicsExecutor`
(its methods use the executor's toucher, segmenter, settings and generator).
"""

from __future__ import annotations

import math

import numpy as np

from haptic.executor.primitives import PrimitiveResult
from haptic.executor.segment import FaceFit, normal_turn_rate
from haptic.executor.workspace import landing_points
from haptic.geometry.se3 import perpendicular, unit
from haptic.matching.trace import ContactTrace
from haptic.planning.moves import Move, MoveResult, SensorState
from haptic.sim.scene import TABLE_TOP_Z

RAISE_ROUND_OFF = 1e-6
"""The approach can still be raised while it is more than this below its highest [m] (round-off)."""
MAX_STUCK = 4
"""Start: moves across above the object region, at the highest approach, that may time out in a row before
the start gives up (the arm is held back: every further landing would be too)."""


class LandingSearch:
    """The start's landing search and first face, a part of the physics executor: it uses the executor's
    ``settings``, ``toucher``, ``segmenter``, ``workspace``, ``bounds`` and ``rng``, stores the first face with
    ``_store_face`` and sets ``state`` and ``_on_face``."""

    def _start(self, move: Move, pieces: list[PrimitiveResult]) -> MoveResult:
        s, t = self.settings, self.toucher
        z_top = TABLE_TOP_Z + s.approach_height
        z_max = TABLE_TOP_Z + max(s.max_approach_height, s.approach_height)
        last = "no-contact"
        landings = landing_points(s.search_spacing, s.search_margin, self.rng, s.search_jitter, s.search_order_jitter)
        budget = s.max_landings if s.max_landings is not None else len(landings) + s.edge_retries
        i = -1
        stuck = 0  # moves across, at the highest approach, that timed out in a row
        passes = 1  # passes over the landing grid begun
        touches = strokes = 0  # landings that touched the object; of them, those whose L stroke measured no face
        while True:
            if i + 1 >= min(len(landings), budget):
                if passes >= s.search_passes:
                    break
                # the grid's points all missed an object that stands between them, or touched only a ridge or an
                # apex of a low one: again at its cells' centres, descending lower (drawn only now, so that a first
                # pass that finds a face draws what it always did)
                passes += 1
                more = landing_points(s.search_spacing, s.search_margin, self.rng, s.search_jitter,
                                      s.search_order_jitter, offset=0.5 * ((passes - 1) % 2))  # fmt: skip
                landings.extend(more)
                budget += len(more) if s.max_landings is None else 0
                continue
            i += 1
            xy = landings[i]
            above = np.array([xy[0], xy[1], z_top])
            if t.tip[2] < z_top - s.approach_slack:  # lift straight up first
                up = t.tip.copy()
                up[2] = z_top
                pieces.append(t.move_free(up, timeout=t.config.via_timeout, tol=t.config.via_tol))
            r = t.move_free(above, timeout=t.config.free_timeout, tol=t.config.via_tol)
            pieces.append(r)
            can_raise = z_top < z_max - RAISE_ROUND_OFF
            if r.status == "timeout" and can_raise:
                # blocked on the way across: the object stands taller than the approach height. Go higher
                z_top, i = min(z_top + s.approach_raise, z_max), i - 1
                continue
            stuck = stuck + 1 if r.status == "timeout" else 0
            if stuck >= MAX_STUCK:
                return MoveResult(move=move, status="unreachable", state=None,
                                  reason=f"the hand cannot move across the object region: {stuck} moves "
                                         "above it in a row did not get there")  # fmt: skip
            if not r.ok:
                last = r.status
                if r.status == "unstable":
                    break
                continue
            # fast guarded descent to just above the table, then back off and touch again slowly
            floor = s.search_floor if passes == 1 else s.low_search_floor
            r = t.approach(np.array([0.0, 0.0, -1.0]), z_top - TABLE_TOP_Z - floor, speed=s.search_speed, settle=False)
            pieces.append(r)
            if r.ok and r.info["point"][2] > z_top - s.touched_at_once - t.pad_radius and can_raise:
                # touched at once (the side of something reaching up to the approach height): go higher
                z_top, i = min(z_top + s.approach_raise, z_max), i - 1
                continue
            if r.ok:
                back = t.tip + np.array([0.0, 0.0, s.landing_back_off])
                pieces.append(t.move_free(back, timeout=t.config.back_off_timeout, tol=t.config.target_tol))
                r = t.approach(np.array([0.0, 0.0, -1.0]), s.landing_touch)
                pieces.append(r)
            if not r.ok:
                last = r.status
                if r.status == "unstable":
                    break
                continue
            if self.workspace.is_table(r.info["normal"], r.info["point"]):
                continue
            touches += 1
            fit, trace = self._normal_stroke(r.info["normal"], pieces)
            if fit is None:  # touched the object near an edge: try close by first
                strokes += 1
                near = r.info["point"][:2] + self.rng.normal(0.0, s.landing_jitter, (s.near_landings, 2))
                landings[i + 1 : i + 1] = list(near)
                continue
            face = self.segmenter.add_face(fit, ())
            self.store_face(face.id, trace, fit)
            self.on_face = face.id
            self.state = SensorState(position=self.contact_point(), face=face.id)
            return MoveResult(move=move, status="ok", components=(face,), state=self.state,
                              info={"travel": sum(p.distance for p in pieces)})  # fmt: skip
        return MoveResult(move=move, status=last if last != "ok" else "no-contact", state=None,
                          reason=f"no face found over the object region: {i + 1} landings in {passes} passes over "
                                 f"the grid touched the object {touches} times, {strokes} of them where the L "
                                 "stroke measured no face")  # fmt: skip

    def _normal_stroke(self, n0: np.ndarray, pieces: list[PrimitiveResult]) -> tuple[FaceFit | None, ContactTrace]:
        """An L stroke from the landing point for the face's normal; tries other headings when it meets an edge."""
        s, t = self.settings, self.toucher
        a = perpendicular(n0)
        phi0 = self.rng.uniform(0, 2 * np.pi)
        for k in range(s.stroke_headings):
            phi = phi0 + k * np.pi / 2
            d1 = math.cos(phi) * a + math.sin(phi) * np.cross(n0, a)
            d2 = np.cross(n0, d1)
            legs = []
            for d in (d1, d2):
                r = t.trace_face(d, n0, s.normal_stroke, phase="stroke")
                legs.append(r)
                pieces.append(r)
                if not r.ok or r.event != "done":
                    break
            if all(r.ok and r.event == "done" for r in legs) and len(legs) == 2:
                trace = ContactTrace.concatenate([r.trace for r in legs])
                if not self.on_one_face(trace):
                    return None, trace  # the pad rolled on an edge or a vertex: land again elsewhere
                return self.segmenter.fit_face_trace(trace, self.stroke_normal(trace), two_d=True), trace
            if legs[-1].status == "unstable":
                return None, ContactTrace.concatenate([])
            # met an edge: back off the way it came and turn
            back = (
                t.trace_face(-legs[-1].info.get("direction", d1), n0, s.normal_stroke, phase="stroke")
                if (legs[-1].ok)
                else None
            )
            if back is not None:
                pieces.append(back)
            if t.contact[1] is None:
                return None, ContactTrace.concatenate([])
            n0 = t.normal.copy()
        return None, ContactTrace.concatenate([])

    @staticmethod
    def stroke_normal(trace: ContactTrace) -> np.ndarray:
        """The guess about which the start's face rows are picked: the median of the L stroke's sensed normals.
        Every row lies on one face (:meth:`on_one_face`), but a landing next to the face's rim starts the L with
        the pad on the rim, its normal turned a few degrees round the edge, and the primitive's running face
        normal, seeded there, stays within its sample cone of it: rows picked about it were those on the rim
        (HEXPRISM01 at 30 mm, seed 2: the face 3.1° off, 3.65 times its bound), while most rows lie on the face."""
        ok = trace.in_contact
        return unit(np.median(trace.normal_in_world[ok], axis=0))

    def on_one_face(self, trace: ContactTrace) -> bool:
        """Whether every contact row of the start's L stroke lies on one face. On a face the sensed normal does
        not turn as the pad slides; landed on (or next to) an edge or a vertex, the pad rolls on it and the
        normal turns by 1/r along the stroke -- slowly enough for the edge detector not to fire, and the rows
        within the face cone of the turning normals then fit a wrong plane. Every contact row counts here, not
        only those in the cone."""
        ok = trace.in_contact
        if ok.sum() < self.bounds.min_face_rows:
            return False
        tips = trace.tip_in_world[ok]
        q = tips - tips.mean(axis=0)
        _, _, vt = np.linalg.svd(q, full_matrices=False)
        return normal_turn_rate(q @ vt[:2].T, trace.normal_in_world[ok]) <= self.bounds.max_face_curvature


__all__ = ["MAX_STUCK", "LandingSearch"]
