"""The path of a free-space probe on the simulated hand: the one rule the physics executor
follows (:mod:`haptic.executor.physics_probe`) and the planner predicts its cost by
(:func:`~haptic.planning.probe_prediction.predict_probes`).

The fingers point down and end in a pad of radius ``r``; positions here are the pad's *centre*. From the
centre ``c`` on the surface of sensed outward normal ``n``, the hand

1. lifts off along the normal to ``l = c + LIFT n``;
2. rises straight up to the safe height ``z_safe`` -- the highest contact sensed so far plus ``r`` and
   :data:`CLEARANCE` (the object rests on the table and was touched only below it), at least the line's start
   and ``c`` --, moves across, and comes straight down to the pad centre's place at the line's start
   ``c_0 = start − r u`` (its leading point, the centre plus ``r`` along the line, is then at the start);
3. approaches along the line until contact (a hit) or to its end ``c_1 = c_0 + L u`` (a miss);
4. after a miss, rises from ``c_1`` to ``z_safe``, moves across, comes down to ``l`` and touches the face it
   left again (about ``LIFT``).

The free-space distance ``s`` of the cost ``c_p + c_s s`` (:meth:`~haptic.planning.moves.CostModel.probe_move`)
is the length of that path up to the contact, or all of it after a miss; a hit adds ``c_n`` for the stroke
that measures the face's normal. No mujoco here: plain arrays in, plain arrays out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from haptic.geometry.distance import surface_distance

LIFT = 0.008
"""The pad lifts this far off the surface along its normal before the transfer [m]."""
CLEARANCE = 0.03
"""The transfer passes this far above the highest contact sensed so far, plus the pad radius [m]."""


@dataclass(frozen=True, eq=False)
class HandStart:
    """Where the hand's pad is before a probe, as the planner knows it from the data."""

    tip: np.ndarray
    """The pad's centre, shape (3,) [m]: the contact point plus ``pad_radius`` along ``normal``."""
    normal: np.ndarray
    """Outward normal of the surface the pad rests on (it lifts off along it), shape (3,)."""
    highest: float
    """Height of the highest contact sensed so far [m]."""
    pad_radius: float
    """The pad's radius [m]."""
    max_undercut: float | None = None
    """The pad presses on no face whose outward normal leans under by more than this [rad] (None: no limit)."""

    @classmethod
    def at(cls, position: np.ndarray, normal: np.ndarray, contacts: np.ndarray, pad_radius: float,
           max_undercut: float | None = None) -> HandStart:  # fmt: skip
        """The pad touching ``position`` on a surface of outward ``normal``, with the contacts sensed so far
        ``contacts`` (n, 3) (``position`` among them)."""
        p, n = np.asarray(position, dtype=float), np.asarray(normal, dtype=float)
        z = np.asarray(contacts, dtype=float).reshape(-1, 3)[:, 2]
        top = max(float(p[2]), float(z.max()) if len(z) else float(p[2]))
        return cls(p + pad_radius * n, n, top, pad_radius, max_undercut)

    def rise(self, clearance: float = CLEARANCE, lift: float = LIFT) -> np.ndarray:
        """Pad centres on the way up before every transfer: from the lift off the surface straight up to the
        lowest safe height, shape (PAD_SAMPLES, 3) [m]."""
        lifted = self.tip + lift * self.normal
        z = max(self.highest + self.pad_radius + clearance, float(self.tip[2]))
        frac = np.linspace(0.0, 1.0, PAD_SAMPLES)[:, None]
        return lifted + frac * np.array([0.0, 0.0, max(z - float(lifted[2]), 0.0)])

    def distances(self, starts: np.ndarray, dirs: np.ndarray, lengths: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:func:`probe_distances` from here."""
        return probe_distances(self.tip, self.normal, self.highest, self.pad_radius, starts, dirs, lengths)


PAD_SAMPLES = 16
"""Pad centres along a line at which :func:`pad_touches_first` measures the pad's clearance of the object."""
PAD_TOLERANCE = 0.001
"""The pad counts as touching where its centre comes this much nearer the surface than its radius [m]."""


def pad_touches_first(poly, starts: np.ndarray, dirs: np.ndarray, ends: np.ndarray, incidence: np.ndarray,
                      pad_radius: float) -> np.ndarray:  # fmt: skip
    """Whether the pad, its leading point on each line (``starts``, unit ``dirs``, model frame, (K, 3)), touches
    ``poly`` before the head-on contact the line-cast predicts, shape (K,) bool: ``ends`` (K,) is the leading
    point's distance along the line to its contact (the line's length for a miss), ``incidence`` (K,) the
    ``|n·u|`` of the face hit (1 for a miss). The pad meets the face's plane ``r (1/|n·u| − 1)`` before its
    leading point does; any point of the surface within ``r`` of the pad's centre sooner -- an edge or a vertex
    beside the line, the rim of a slot the pad does not fit in, a face grazed by a line the leading point
    clears -- is what the pad touches instead: an edge where a face was predicted, a hit where a miss was."""
    r = pad_radius
    cos = np.clip(np.asarray(incidence, dtype=float), 0.2, 1.0)
    stop = np.asarray(ends, dtype=float) - r * (1.0 / cos - 1.0) - PAD_TOLERANCE
    frac = np.linspace(0.0, 1.0, PAD_SAMPLES)
    tau = np.maximum(stop, 0.0)[:, None] * frac[None, :]  # (K, S)
    centres = (starts - r * dirs)[:, None, :] + tau[..., None] * dirs[:, None, :]
    d = surface_distance(poly, centres.reshape(-1, 3)).reshape(len(starts), PAD_SAMPLES)
    return (d < r - PAD_TOLERANCE).any(axis=1)


STROKE_ROOM = 0.008
"""A hit measures its face's normal by an L stroke from the pad's contact: where that lies nearer than this to the
face's boundary the pad rolls onto the edge instead (measured on the hand: a slot's wall, 20 mm deep, at 6 mm
from its rim) [m]."""


def foot_near_boundary(poly, faces: np.ndarray, feet: np.ndarray, room: float = STROKE_ROOM) -> np.ndarray:
    """Whether each contact ``feet`` (K, 3, model frame) on model face ``faces`` (K,) lies within ``room`` of
    that face's boundary (its polygon's sides), shape (K,) bool."""
    out = np.zeros(len(feet), dtype=bool)
    for f in np.unique(faces):
        k = np.flatnonzero(faces == f)
        loop = poly.vertices[list(poly.faces[int(f)])]
        a, b = loop, np.roll(loop, -1, axis=0)
        ab = b - a
        w = feet[k, None, :] - a[None]
        t = np.clip(np.einsum("kij,ij->ki", w, ab) / np.einsum("ij,ij->i", ab, ab)[None], 0.0, 1.0)
        d = np.linalg.norm(w - t[..., None] * ab[None], axis=2).min(axis=1)
        out[k] = d < room
    return out


def pad_touches_path(poly, centres: np.ndarray, pad_radius: float) -> bool:
    """Whether the pad, centred at any of ``centres`` (n, 3, model frame), would touch or be inside ``poly``."""
    c = np.asarray(centres, dtype=float)
    return bool((surface_distance(poly, c) < pad_radius - PAD_TOLERANCE).any() or poly.contains(c).any())


def safe_height(highest: float, pad_radius: float, line_start_centre: np.ndarray, tip: np.ndarray,
                clearance: float = CLEARANCE):  # fmt: skip
    """``z_safe``: the height of the transfer over the object (module docstring, step 2) [m]; ``highest`` is the
    highest contact sensed so far, ``line_start_centre`` the pad centre at the line's start ``c_0`` (3,), or at
    each line's start (M, 3) (then one height per line, (M,)), ``tip`` the pad centre before the lift."""
    z0 = np.asarray(line_start_centre, dtype=float)[..., 2]
    z = np.maximum(np.maximum(highest + pad_radius + clearance, z0), float(np.asarray(tip)[2]))
    return float(z) if z.ndim == 0 else z


def over_the_top(frm: np.ndarray, z_safe: float, to: np.ndarray) -> np.ndarray:
    """The up-and-over waypoints from the pad centre ``frm`` to ``to``: straight up to ``z_safe``, across,
    straight down to ``to``, shape (3, 3) (``frm`` itself left out)."""
    frm, to = np.asarray(frm, dtype=float), np.asarray(to, dtype=float)
    return np.array([[frm[0], frm[1], z_safe], [to[0], to[1], z_safe], to])


def probe_distances(tip: np.ndarray, normal: np.ndarray, highest: float, pad_radius: float, starts: np.ndarray,
                    dirs: np.ndarray, lengths: np.ndarray, lift: float = LIFT,
                    clearance: float = CLEARANCE) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """For lines of ``starts`` (M, 3), unit ``dirs`` (M, 3) and ``lengths`` (M,) carried out from the pad centre
    ``tip`` on a surface of outward ``normal``: the free-space distance from ``tip`` to the pad's place at each
    line's start (lift, up, across, down), and the distance of a miss's way back from the line's end to the
    surface (up, across, down, touch again), each shape (M,) [m]. A hit at distance ``t`` along line ``i``
    travels ``to_start[i] + t``; a miss ``to_start[i] + lengths[i] + back[i]``."""
    tip = np.asarray(tip, dtype=float)
    lifted = tip + lift * np.asarray(normal, dtype=float)
    c0 = np.asarray(starts, dtype=float) - pad_radius * np.asarray(dirs, dtype=float)
    c1 = c0 + np.asarray(lengths, dtype=float)[:, None] * np.asarray(dirs, dtype=float)
    z_safe = safe_height(highest, pad_radius, c0, tip, clearance)
    across_to = np.hypot(c0[:, 0] - lifted[0], c0[:, 1] - lifted[1])
    across_back = np.hypot(c1[:, 0] - lifted[0], c1[:, 1] - lifted[1])
    to_start = lift + np.abs(z_safe - lifted[2]) + across_to + (z_safe - c0[:, 2])
    back = np.abs(z_safe - c1[:, 2]) + across_back + np.abs(z_safe - lifted[2]) + lift
    return to_start, back


__all__ = ["CLEARANCE", "LIFT", "PAD_SAMPLES", "PAD_TOLERANCE", "STROKE_ROOM", "HandStart", "foot_near_boundary",
           "over_the_top", "pad_touches_first", "pad_touches_path", "probe_distances",
           "safe_height"]  # fmt: skip
