"""Sizes, colours and distances of the drawings of an episode recording."""

from __future__ import annotations

from typing import TYPE_CHECKING

import rerun as rr

if TYPE_CHECKING:
    pass


APPLICATION_ID = "haptic"
"""Rerun application id of every episode recording (the viewer keeps one blueprint per application)."""

VIEWER_PORT = 9876
"""Port of a spawned viewer."""

PATCH_RADIUS = 0.006
"""Half-size of a data face's patch beyond its touched points [m]."""
NORMAL_SCALE = 0.4
"""Length of a face-normal arrow, as a fraction of the object's radius."""
CONTACT_NORMAL_SCALE = 0.25
"""Length of a contact-normal arrow, as a fraction of the object's radius."""
CANDIDATE_SCALE = 0.5
"""Length of the best candidate move's arrow, as a fraction of the object's radius (the others scale down
with their score, to half of it)."""
CANDIDATE_PROBES = 5
"""Most candidate probes drawn as lines at a decision (the best-scoring; the table lists more)."""
DEFAULT_RADIUS = 0.04
"""Object radius assumed before the episode's object is known [m]."""
MOVE_CONTACTS = 60
"""Most contact points of one move in ``world/contacts/points`` (a physics trace is subsampled to it)."""
MOVE_NORMALS = 12
"""Most contact normals of one move drawn in ``world/contacts/normals`` (evenly spaced along the move)."""
ROBOT_ALPHA = 0.6
"""Opacity of the robot's geometry (the contact under a pad shows through it)."""
TRACE_MAX_POINTS = 400
"""Most points of one move's strip in ``world/trace/path`` (a physics trace is subsampled to it)."""
OBJECT_VIEW_DISTANCE = 2.5
"""Distance of the ``object`` view's eye from the object's centre, in object radii (at least
:data:`MIN_VIEW_DISTANCE`)."""
MIN_VIEW_DISTANCE = 0.12
"""Closest the ``object`` view's eye starts to the object's centre [m]."""
FINGERTIP_VIEW_DISTANCE = 0.09
"""Distance of the ``fingertip`` view's eye from the pad [m]."""
VIEW_DIRECTION = (0.75, -0.9, 0.75)
"""Direction (world) from the looked-at point to the eye of both views: from the far side of the table and
above, so the arm reaches in from behind the object."""
NO_COUNT = -1.0
"""What the log10 plots show for zero interpretations or pose classes."""
START_TEXT = "**the start**: the hand comes down onto the object; the planner decides from the first contacts on"
"""The candidate table before the first decision."""
MAX_TABLE_ROWS = 12
"""Most candidate moves listed in a decision's table (best first)."""

# sizes in screen points (rerun draws negative radii as points on screen, whatever the zoom)
TRACE_RADIUS = rr.components.Radius.ui_points(2.0)
CONTACT_RADIUS = rr.components.Radius.ui_points(4.0)
ARROW_RADIUS = rr.components.Radius.ui_points(1.5)
EDGE_RADIUS = rr.components.Radius.ui_points(3.0)
VERTEX_RADIUS = rr.components.Radius.ui_points(6.0)

KIND_COLORS: dict[str, tuple[int, int, int]] = {
    "start": (170, 170, 170),
    "face": (70, 130, 230),
    "edge": (240, 150, 40),
    "vertex": (190, 90, 220),
    "probe": (235, 60, 160),
    "placement": (40, 190, 170),
    "failed": (230, 50, 50),
}
"""Colour of each move kind (path strips, move markers on the interpretation plot, candidates)."""
PROBE_HIT_COLOR = KIND_COLORS["probe"]
"""A probe that met the object: its line from its start to the contact, the contact and its normal."""
PROBE_MISS_COLOR = (40, 40, 40)
FINGER_COLORS: dict[str, tuple[int, int, int]] = {
    "index": (40, 190, 170),
    "middle": (250, 210, 40),
    "ring": (120, 220, 60),
    "thumb": (250, 120, 90),
}
"""Colour of each finger of a placement: its line from its start to the contact (or its whole line, dimmed, when it
met nothing), its contact and its normal."""
"""A probe that met nothing: its whole line (free space)."""
PROBE_RADIUS = rr.components.Radius.ui_points(2.5)
FACE_COLOR = (70, 130, 230, 140)
EDGE_COLOR = (240, 150, 40)
VERTEX_COLOR = (220, 40, 60)
CONTACT_COLOR = (250, 220, 50)
TRUTH_COLOR = (235, 225, 190, 120)
ESTIMATE_COLOR = (60, 200, 90)
INTERPRETATIONS_COLOR = (225, 225, 225)
POSE_CLASSES_COLOR = (60, 190, 170)
