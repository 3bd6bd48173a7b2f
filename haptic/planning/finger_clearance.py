"""Whether the finger above the pad is free along a probe: the index finger's phalanges, sampled along its
axis above the pad, must not meet any hypothesis's object while the pad runs a probe line (the checks of
:func:`finger_clear`, used when candidate probes are made for the simulated hand)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from haptic.geometry.distance import surface_distance
from haptic.geometry.raycast import line_hits
from haptic.planning.hypothesis import Hypothesis
from haptic.planning.moves import ProbeMove

FINGER_LIFT = 0.08
"""Height above the pad's centre through which the finger above it must be free [m] (as
:data:`haptic.planning.reach.LIFT`)."""


FINGER_SAMPLES = 8
"""Points along a line's pad path at which :func:`finger_clear` checks the finger above the pad (and points up
the finger at each)."""


FINGER_RADIUS = 0.0085
"""Radius of the finger's links above the pad (the index finger's capsules) [m]: a line into a slot the pad
fits in but the finger slanting after it does not is blocked."""


def finger_clear(hypotheses: Sequence[Hypothesis], moves: Sequence[ProbeMove], pad_radius: float,
                 lift: float = FINGER_LIFT, finger_radius: float = FINGER_RADIUS) -> np.ndarray:  # fmt: skip
    """Whether the finger above the pad -- pointing down, the column from the pad's top to ``lift`` above its
    centre, ``finger_radius`` thick -- stays clear of every hypothesis's object while the pad travels each line
    up to where that hypothesis predicts its contact (or to the line's end), shape (M,) bool. A line passing
    under an overhang of a hypothesis (a slot's ceiling, a ledge), or slanting into a slot the pad fits in and
    the finger after it does not, would have the finger's phalanx meet the object before the pad:
    a blocked move, no contact sensed."""
    m = len(moves)
    ok = np.ones(m, dtype=bool)
    if m == 0:
        return ok
    r = pad_radius
    starts = np.array([mv.start for mv in moves], dtype=float)
    dirs = np.array([mv.direction for mv in moves], dtype=float)
    lengths = np.array([mv.length for mv in moves], dtype=float)
    frac = np.linspace(0.0, 1.0, FINGER_SAMPLES)
    up = np.array([0.0, 0.0, 1.0])
    for h in hypotheses:
        inv = h.model_from_world
        t_end = np.minimum(line_hits(h.poly, inv.apply(starts), inv.rotate(dirs)).first, lengths)  # (M,)
        centres = (starts - r * dirs)[:, None, :] + (frac[None, :] * t_end[:, None])[..., None] * dirs[:, None, :]
        tops = inv.apply((centres + lift * up).reshape(-1, 3))
        down = np.broadcast_to(inv.rotate(-up), tops.shape)
        hit = line_hits(h.poly, tops, down).first <= lift - r
        # the finger is a capsule about the column: its points stay a finger's radius off the surface
        column = tops[:, None, :] + np.linspace(0.0, lift - r, FINGER_SAMPLES)[None, :, None] * down[:1, None, :]
        thick = surface_distance(h.poly, column.reshape(-1, 3)).reshape(len(tops), -1).min(axis=1) < finger_radius
        blocked = hit | thick | h.poly.contains(tops)
        ok &= ~blocked.reshape(m, FINGER_SAMPLES).any(axis=1)
    return ok


__all__ = ["FINGER_LIFT", "FINGER_RADIUS", "FINGER_SAMPLES", "finger_clear"]
