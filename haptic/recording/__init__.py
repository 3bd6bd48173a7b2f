"""Rerun recordings of episodes: the only package of haptic that imports ``rerun`` (recorder, blueprint, drawing,
style, reading back).

:class:`EpisodeRecorder` turns the hooks of :class:`~haptic.episode.loop.EpisodeObserver` into a rerun recording,
saved to an ``.rrd`` file (written to a temporary file beside the target and renamed when the episode ended,
so a failed episode never leaves a partial recording at the target path) and/or streamed to a spawned viewer.

Timelines: ``move`` (sequence: 0 is the start, then one step per move) and, when the executor reports contact
traces (the physics executor's ``MoveResult.trace``), ``sim_time`` (simulated time [s]); a physics recording
opens on ``sim_time``. Everything drawn has a value on both timelines (per control tick on ``sim_time``, the
state at the end of each move on ``move``).

The default blueprint (:func:`default_blueprint`, sent when the first move arrives) frames the work: the
``object`` view's eye is on the object's region, the ``fingertip`` view follows the active pad close up; the
plots are the interpretations and pose classes (log10), the normal force and the path cost, each on its own
axis; the candidate table and the logs beside them.

Entities (world frame, metres, Z up; marks are sized to the object or in screen points, so they read at the
default framing; labels show on hover):

- ``world/truth``: Transform3D ``world_from_model`` of the true pose (static)
- ``world/truth/object``: the true model's mesh, model frame (static; the ground-truth layer)
- ``world/truth/edges``: its edges as line strips (static)
- ``world/estimate``, ``.../edges``: the recognised model at its estimated pose, once recognised
- ``world/robot/<link>``: Transform3D of each robot link (``MoveResult.links`` poses), per sampled tick
  (``sim_time``) and at the end of each move (``move``)
- ``world/robot/<link>/<kind>s``: the link's collision geoms (capsules, spheres, cylinders, boxes, ellipsoids,
  meshes) in the link frame, static (``MoveResult.links.geoms``); ``world/table``: the table top
- ``world/hand/pad``: Transform3D (a translation) to the active fingertip pad's centre (the trace's tip), per
  tick and at the end of each move (without traces: the sensor's position after each move): the origin of the
  ``fingertip`` view, which so follows the pad
- ``world/trace/path``: the sensor's path, one line strip per move, accumulated, coloured by move kind
  (:data:`KIND_COLORS`; the legend is the interpretation plot's)
- ``world/trace/failed``: fingertip paths of failed moves, accumulated (physics)
- ``world/sensor``: sensor position after the latest move
- ``world/contacts/points``, ``/normals``: the latest move's contact points and their normals (arrows)
- ``world/data/faces/patches``: data faces as small patches in their planes, accumulated
- ``world/data/faces/normals``: one arrow per data face (its normal), labelled ``f<id>``
- ``world/data/faces/points``: the points touched on the data faces
- ``world/data/edges``: one segment per data edge (its explored interval), ``e<id>``
- ``world/data/vertices``: one point per data vertex, ``v<id>``
- ``world/decision/candidates``: each candidate move of the decision, coloured by score
- ``world/decision/chosen``: the chosen move
- ``world/hand/fingertip``: pad centre per control tick (physics only)
- ``world/hand/contact/points``, ``/normals``: sensed contact per control tick (physics only)
- ``world/hand/links``, ``world/hand/skeleton``: link origins and the links joined as line strips
  (``MoveResult.links.chains``), drawn only when a result reports links without their geometry
- ``plots/interpretations``, ``plots/pose_classes``: log10 of the surviving interpretations and pose classes
  after each move (-1 stands for none); a failed move repeats the count
- ``plots/moves/<kind>``: a marker per move on the interpretation plot, coloured by move kind (``start``,
  ``face``, ``edge``, ``vertex``, ``failed``: a red cross): the legend of the trace's colours
- ``plots/path_cost``: cumulative path cost [units]
- ``plots/force``: sensed normal force per control tick [N] on ``sim_time``; on ``move``, each move's mean
  force while in contact (physics only)
- ``decision/scores``: per decision, a table of its candidate moves (kind and direction) with their scores,
  expected cost and eliminations, best first
- ``log/moves``, ``log/decisions``, ``log/episode``: text logs

Read a recording back with :func:`load_recording` (rerun's :class:`rerun.chunk.RrdReader`).
"""

from haptic.errors import RecordingError
from haptic.recording.blueprint import Framing, default_blueprint
from haptic.recording.reading import EntityData, load_recording
from haptic.recording.recorder import EpisodeRecorder

__all__ = ["EntityData", "EpisodeRecorder", "Framing", "RecordingError", "default_blueprint", "load_recording"]
