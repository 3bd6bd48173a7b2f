"""The path of a free-space probe on the simulated hand (issue 15 item 4): the one rule the physics executor
follows (:mod:`haptic.executor.physics_probe`) and the planner predicts its cost by
(:func:`~haptic.planning.probes.predict_probes`).

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

    @classmethod
    def at(cls, position: np.ndarray, normal: np.ndarray, contacts: np.ndarray, pad_radius: float) -> HandStart:
        """The pad touching ``position`` on a surface of outward ``normal``, with the contacts sensed so far
        ``contacts`` (n, 3) (``position`` among them)."""
        p, n = np.asarray(position, dtype=float), np.asarray(normal, dtype=float)
        z = np.asarray(contacts, dtype=float).reshape(-1, 3)[:, 2]
        return cls(p + pad_radius * n, n, max(float(p[2]), float(z.max()) if len(z) else float(p[2])), pad_radius)

    def distances(self, starts: np.ndarray, dirs: np.ndarray, lengths: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:func:`probe_distances` from here."""
        return probe_distances(self.tip, self.normal, self.highest, self.pad_radius, starts, dirs, lengths)


def safe_height(highest: float, pad_radius: float, line_start_centre: np.ndarray, tip: np.ndarray,
                clearance: float = CLEARANCE) -> float:  # fmt: skip
    """``z_safe``: the height of the transfer over the object (module docstring, step 2) [m]; ``highest`` is the
    highest contact sensed so far, ``line_start_centre`` the pad centre at the line's start ``c_0``, ``tip``
    the pad centre before the lift."""
    return max(highest + pad_radius + clearance, float(line_start_centre[2]), float(tip[2]))


def over_the_top(frm: np.ndarray, z_safe: float, to: np.ndarray) -> np.ndarray:
    """The up-and-over waypoints from the pad centre ``frm`` to ``to``: straight up to ``z_safe``, across,
    straight down to ``to``, shape (3, 3) (``frm`` itself left out)."""
    frm, to = np.asarray(frm, dtype=float), np.asarray(to, dtype=float)
    return np.array([[frm[0], frm[1], z_safe], [to[0], to[1], z_safe], to])


def path_length(points: np.ndarray) -> float:
    """Length of the polyline through ``points`` (n, 3) [m]."""
    p = np.asarray(points, dtype=float)
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) if len(p) > 1 else 0.0


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
    z_safe = np.maximum(np.maximum(highest + pad_radius + clearance, c0[:, 2]), tip[2])
    across_to = np.hypot(c0[:, 0] - lifted[0], c0[:, 1] - lifted[1])
    across_back = np.hypot(c1[:, 0] - lifted[0], c1[:, 1] - lifted[1])
    to_start = lift + np.abs(z_safe - lifted[2]) + across_to + (z_safe - c0[:, 2])
    back = np.abs(z_safe - c1[:, 2]) + across_back + np.abs(z_safe - lifted[2]) + lift
    return to_start, back


__all__ = ["CLEARANCE", "LIFT", "HandStart", "over_the_top", "path_length", "probe_distances", "safe_height"]
