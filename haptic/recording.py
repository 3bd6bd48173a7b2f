"""Rerun recordings of episodes: the only module of the package that imports ``rerun``.

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
- ``world/robot/<link>``: Transform3D of each robot link (``info["hand_links"]`` poses), per sampled tick
  (``sim_time``) and at the end of each move (``move``)
- ``world/robot/<link>/<kind>s``: the link's collision geoms (capsules, spheres, cylinders, boxes, ellipsoids,
  meshes) in the link frame, static (``info["link_geoms"]``); ``world/table``: the table top
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
  (``info["hand_link_chains"]``), drawn only when a result reports links without their geometry
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

from __future__ import annotations

import math
import os
import shutil
import sys
import tempfile
import uuid
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from haptic.episode.loop import EpisodeObserver
from haptic.errors import RecordingError
from haptic.geometry import SE3, Polyhedron
from haptic.geometry.se3 import plane_basis
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex

if TYPE_CHECKING:
    from haptic.episode.loop import EpisodeRecord
    from haptic.matching.recognition import Recognition
    from haptic.planning.moves import Move, MoveResult, SensorState
    from haptic.planning.policies import Decision

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
    "failed": (230, 50, 50),
}
"""Colour of each move kind (path strips, move markers on the interpretation plot, candidates)."""
FACE_COLOR = (70, 130, 230, 140)
EDGE_COLOR = (240, 150, 40)
VERTEX_COLOR = (220, 40, 60)
CONTACT_COLOR = (250, 220, 50)
TRUTH_COLOR = (235, 225, 190, 120)
ESTIMATE_COLOR = (60, 200, 90)
INTERPRETATIONS_COLOR = (225, 225, 225)
POSE_CLASSES_COLOR = (60, 190, 170)


# ---------------------------------------------------------------------------------------------- blueprint


@dataclass(frozen=True)
class Framing:
    """Where the default blueprint's 3-D views start looking (world frame)."""

    object_eye: tuple[float, float, float] | None = None
    """Eye of the ``object`` view [m] (None: the viewer's own framing of everything)."""
    object_target: tuple[float, float, float] | None = None
    """Point the ``object`` view looks at and orbits: the object's centre [m]."""
    fingertip_eye: tuple[float, float, float] | None = None
    """Eye of the ``fingertip`` view relative to the pad [m] (the view's origin is ``world/hand/pad``, which
    moves with the pad, so the eye follows it)."""
    timeline: str = "move"
    """Timeline the recording opens on (``sim_time`` when there are physics traces)."""


def default_blueprint(framing: Framing | None = None) -> rrb.Blueprint:
    """The layout a recording opens with: on the left the ``object`` 3-D view (its eye on the object's region)
    over the ``fingertip`` view (following the active pad close up) and the latest decision's candidate table;
    on the right the interpretations and pose classes (log10, with a marker per move coloured by its kind and
    failed moves crossed), the normal force, the path cost and the logs."""
    f = framing or Framing()
    up = (0.0, 0.0, 1.0)
    obj_eye = (
        rrb.EyeControls3D(position=f.object_eye, look_target=f.object_target, eye_up=up)
        if f.object_eye is not None else None
    )  # fmt: skip
    tip_eye = (
        rrb.EyeControls3D(position=f.fingertip_eye, look_target=(0.0, 0.0, 0.0), eye_up=up)
        if f.fingertip_eye is not None else None
    )  # fmt: skip
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(
                rrb.Spatial3DView(origin="world", name="object", eye_controls=obj_eye,
                                  background=rrb.BackgroundKind.GradientBright),
                rrb.Horizontal(
                    rrb.Spatial3DView(origin="world/hand/pad", contents="/world/**", name="fingertip",
                                      eye_controls=tip_eye, background=rrb.BackgroundKind.GradientBright),
                    rrb.TextDocumentView(origin="decision", name="candidate moves"),
                    column_shares=[1, 1],
                ),
                row_shares=[3, 2],
            ),
            rrb.Vertical(
                rrb.TimeSeriesView(
                    origin="plots", name="interpretations, pose classes (log10)",
                    contents=["plots/interpretations", "plots/pose_classes", "plots/moves/**"],
                    plot_legend=rrb.PlotLegend(corner=rrb.Corner2D.RightTop),
                ),  # fmt: skip
                rrb.TimeSeriesView(origin="plots", contents=["plots/force"], name="normal force [N]"),
                rrb.TimeSeriesView(origin="plots", contents=["plots/path_cost"], name="path cost [units]"),
                rrb.TextLogView(origin="log", name="log"),
                row_shares=[3, 2, 2, 2],
            ),
            column_shares=[3, 2],
        ),
        rrb.TimePanel(timeline=f.timeline, state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.BlueprintPanel(state="collapsed"),
    )


# ---------------------------------------------------------------------------------------------- recorder


def _viewer_executable() -> str:
    """The ``rerun`` viewer executable (on PATH, or beside this Python's executable), or raise."""
    found = shutil.which("rerun") or shutil.which("rerun", path=str(Path(sys.executable).parent))
    if found is None:
        raise RecordingError(
            "--spawn: no rerun viewer executable found on PATH or beside "
            f"{sys.executable}; install it (pip install rerun-sdk) or use --record OUT.rrd"
        )
    return found


def _check_display() -> None:
    """Raise when no window can be opened (Linux without X11 or Wayland)."""
    if sys.platform.startswith("linux") and not any(
        os.environ.get(v) for v in ("DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET")
    ):
        raise RecordingError(
            "--spawn: no display to open the rerun viewer on (DISPLAY and WAYLAND_DISPLAY are unset); "
            "use --record OUT.rrd and open it with `rerun OUT.rrd` where there is a display"
        )


def _listening(port: int, timeout: float = 2.0) -> bool:
    """Whether something accepts connections on ``127.0.0.1:port`` (the spawned viewer is up)."""
    import socket

    try:
        with socket.create_connection(("127.0.0.1", port), timeout=timeout):
            return True
    except OSError:
        return False


@dataclass
class _State:
    """What the recorder has seen so far in the episode."""

    components: dict[int, DataComponent] = field(default_factory=dict)
    strips: list[np.ndarray] = field(default_factory=list)
    strip_kinds: list[str] = field(default_factory=list)
    failed_strips: list[np.ndarray] = field(default_factory=list)
    position: np.ndarray | None = None
    sim_time: float | None = None
    cost: float = 0.0
    decided: set[int] = field(default_factory=set)
    state: SensorState | None = None
    link_labels_logged: bool = False
    skeleton_style_logged: bool = False
    trace_style_logged: bool = False
    decision_shown: bool = False
    radius: float = DEFAULT_RADIUS
    """Object radius [m]: the scale of the marks."""
    centre: np.ndarray | None = None
    """Object centre, world [m] (for the ``object`` view's eye)."""
    blueprint_sent: bool = False
    geom_links: set[str] | None = None
    """Links whose geometry is drawn (None: no geometry reported yet)."""
    move: int = 0
    """The move being logged."""
    counts: tuple[float, float | None] = (math.nan, None)
    """Latest log10 interpretations and pose classes plotted."""


class EpisodeRecorder:
    """Records one episode for the rerun viewer.

    ``EpisodeRecorder(path)`` saves headless to ``path`` (an ``.rrd``); ``spawn=True`` also opens a viewer
    (raises :class:`RecordingError` with one line when none can start). Pass :meth:`observer` to
    :func:`~haptic.episode.worlds.run_episode`, then call :meth:`close`: the file appears at ``path`` only when the
    episode ended (``on_end`` was called) or ``close(keep=True)``; otherwise the temporary file is removed.
    Also a context manager (an exception discards the recording).
    """

    def __init__(self, path: str | os.PathLike | None = None, *, spawn: bool = False, name: str | None = None) -> None:
        if path is None and not spawn:
            raise RecordingError("a recording needs a file (--record OUT.rrd) or a viewer (--spawn)")
        self.path: Path | None = Path(path) if path is not None else None
        """Target .rrd file (None: viewer only)."""
        self.completed = False
        """Whether the episode ended (``on_end`` was called)."""
        self._tmp: Path | None = None
        self._closed = False
        self._kept = False
        self._s = _State()
        if spawn:
            _check_display()
            exe = _viewer_executable()
        self.stream = rr.RecordingStream(APPLICATION_ID, recording_id=uuid.uuid4(), send_properties=True)
        """The rerun recording stream (log more to it if you like)."""
        if not rr.is_enabled(self.stream):
            raise RecordingError("rerun logging is disabled (the RERUN environment variable is set to off)")
        self.stream.set_log_time_enabled(False)
        sinks: list[Any] = []
        if self.path is not None:
            if self.path.is_dir():
                raise RecordingError(f"--record {self.path}: is a directory; give a file name such as episode.rrd")
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", suffix=".part", dir=self.path.parent)
            except OSError as exc:
                raise RecordingError(f"--record {self.path}: cannot write there ({exc.strerror})") from exc
            os.close(fd)
            self._tmp = Path(tmp)
            sinks.append(rr.FileSink(self._tmp))
        if spawn:
            try:
                rr.spawn(port=VIEWER_PORT, connect=False, executable_path=exe, recording=self.stream)
            except (RuntimeError, OSError) as exc:
                self._discard()
                first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
                raise RecordingError(f"--spawn: the rerun viewer did not start: {first}") from exc
            if not _listening(VIEWER_PORT):
                self._discard()
                raise RecordingError(
                    f"--spawn: the rerun viewer did not start (nothing listens on port {VIEWER_PORT}); "
                    "use --record OUT.rrd and open it with `rerun OUT.rrd`"
                )
            sinks.append(rr.GrpcSink(f"rerun+http://127.0.0.1:{VIEWER_PORT}/proxy"))
        self.stream.set_sinks(*sinks)
        if name:
            self.stream.send_recording_name(name)
        self._log_static()

    # ------------------------------------------------------------------------------------------ lifecycle

    def observer(self) -> EpisodeObserver:
        """The :class:`~haptic.episode.loop.EpisodeObserver` that feeds this recorder."""
        from dataclasses import fields

        hooks = {
            "on_start": self.on_start,
            "on_move": self.on_move,
            "on_decision": self.on_decision,
            "on_end": self.on_end,
            "on_failed_move": self.on_failed_move,
        }
        known = {f.name for f in fields(EpisodeObserver)}
        return EpisodeObserver(**{k: v for k, v in hooks.items() if k in known})

    def close(self, keep: bool | None = None) -> Path | None:
        """Finish the recording. ``keep`` (default: whether the episode ended) renames the complete file to
        :attr:`path` and returns it; otherwise the temporary file is removed and None returned. Idempotent."""
        if self._closed:
            return self.path if self.path is not None and self.path.exists() and self._kept else None
        self._closed = True
        self._kept = self.completed if keep is None else bool(keep)
        try:
            self._send_blueprint()
            self.stream.flush(timeout_sec=30.0)
        finally:
            self.stream.disconnect()
        if self._tmp is None or self.path is None:
            return None
        if not self._kept:
            self._discard()
            return None
        try:
            from rerun.chunk import RrdReader

            RrdReader(self._tmp).store()  # the footer (manifest) is there: the file is complete
        except Exception as exc:  # noqa: BLE001 -- any failure to read it back means it is incomplete
            self._discard()
            raise RecordingError(f"--record {self.path}: the recording was not written completely ({exc})") from exc
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(self._tmp, 0o666 & ~umask)  # mkstemp makes it private; a recording is an ordinary file
        os.replace(self._tmp, self.path)
        self._tmp = None
        return self.path

    def _discard(self) -> None:
        if self._tmp is not None:
            self._tmp.unlink(missing_ok=True)
            self._tmp = None

    def __enter__(self) -> EpisodeRecorder:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close(keep=False if exc_type is not None else None)

    # ------------------------------------------------------------------------------------------ hooks

    def on_start(self, true_model: Polyhedron, world_from_model: SE3) -> None:
        """The ground-truth layer: the true model in its true pose (static); the scale of the marks and the
        ``object`` view's target from its size and place."""
        rec, s = self.stream, self._s
        rec.send_recording_name(f"{true_model.name}")
        rec.log("world/truth", _transform(world_from_model), static=True)
        rec.log("world/truth/object", _mesh(true_model, TRUTH_COLOR), static=True)
        rec.log("world/truth/edges", _wireframe(true_model, (120, 120, 120), rr.components.Radius.ui_points(1.0)),
                static=True)  # fmt: skip
        v = np.asarray(true_model.vertices, dtype=float) @ np.asarray(world_from_model.rotation).T
        v = v + np.asarray(world_from_model.translation, dtype=float)
        lo, hi = v.min(axis=0), v.max(axis=0)
        s.centre = (lo + hi) / 2
        s.radius = max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)
        rec.set_time("move", sequence=0)
        rec.log("decision/scores", rr.TextDocument(START_TEXT, media_type=rr.MediaType.MARKDOWN))

    def on_move(
        self, i: int, result: MoveResult, n_interpretations: int, recognition: Recognition | None = None
    ) -> None:
        """One successful move (``i`` = 0 for the start): path, contacts, components, counts."""
        rec, s = self.stream, self._s
        trace = _trace_of(result)
        if trace is not None and len(trace.time):
            s.sim_time = float(trace.time[-1])
        if not s.blueprint_sent:
            self._send_blueprint(trace)
        self._set_time(i)
        for c in result.components:
            s.components[c.id] = c
        kind = getattr(result.move, "kind", "start") if i > 0 else "start"
        prev = s.position
        new = np.asarray(result.state.position, dtype=float) if result.state is not None else None

        # the path: the physics trace when there is one, else the sensed waypoints
        if trace is not None and len(trace.time):
            path = _subsample(np.asarray(trace.tip_in_world, dtype=float), TRACE_MAX_POINTS)
        else:
            path = _waypoints(prev, result, new)
        if len(path) == 1:
            path = np.vstack([path, path])
        if len(path):
            s.strips.append(path)
            s.strip_kinds.append(kind)
            rec.log(
                "world/trace/path",
                rr.LineStrips3D(
                    s.strips,
                    colors=[KIND_COLORS.get(k, KIND_COLORS["start"]) for k in s.strip_kinds],
                    radii=TRACE_RADIUS,
                    labels=[f"move {j}: {k}" for j, k in enumerate(s.strip_kinds)],
                    show_labels=False,
                ),
            )
        if result.state is not None:
            s.state = result.state
        if new is not None:
            s.position = new
            rec.log("world/sensor", rr.Points3D([new], radii=VERTEX_RADIUS, colors=[(255, 255, 255)],
                                                labels=["sensor"], show_labels=False))  # fmt: skip
            if trace is None or not len(trace.time):  # no pad trace: the fingertip view follows the sensor
                rec.log("world/hand/pad", rr.Transform3D(translation=new))

        # contacts of this move
        if trace is not None and len(trace.time):
            ok = np.isfinite(np.asarray(trace.normal_in_world, dtype=float)[:, 0])
            pts = _subsample(np.asarray(trace.point_in_world, dtype=float)[ok], MOVE_CONTACTS)
            nrm = _subsample(np.asarray(trace.normal_in_world, dtype=float)[ok], MOVE_CONTACTS)
            self._log_trace(trace)
        else:
            pts, nrm = _contacts(result.components)
        rec.log("world/contacts/points", rr.Points3D(pts, radii=CONTACT_RADIUS, colors=[CONTACT_COLOR]))
        k = _subsample(np.arange(len(pts)), MOVE_NORMALS)
        rec.log(
            "world/contacts/normals",
            rr.Arrows3D(origins=pts[k], vectors=nrm[k] * CONTACT_NORMAL_SCALE * s.radius, colors=[CONTACT_COLOR],
                        radii=ARROW_RADIUS),
        )  # fmt: skip
        self._log_hand(result, trace)

        self._log_components()

        # the counts, on a log axis, with a marker of the move's kind
        s.cost += float(result.cost)
        n_classes = len(recognition.classes) if recognition is not None and recognition.classes else None
        self._log_counts(_log_count(n_interpretations), _log_count(n_classes) if n_classes is not None else None,
                         kind)  # fmt: skip
        rec.log("plots/path_cost", rr.Scalars(s.cost))
        if recognition is not None and recognition.status == "recognized" and recognition.world_from_model:
            model = next((c.model for c in recognition.classes if c.name == recognition.model), None)
            if model is not None:
                rec.log("world/estimate", _transform(recognition.world_from_model))
                rec.log("world/estimate/edges", _wireframe(model, ESTIMATE_COLOR, EDGE_RADIUS))
        if i not in s.decided:
            self._no_decision(i, kind)

        status = recognition.status if recognition is not None else "-"
        comps = ", ".join(f"{c.kind} {c.id}" for c in result.components) or "none"
        rec.log(
            "log/moves",
            rr.TextLog(
                f"move {i} ({kind}): {comps}; {n_interpretations} interpretations"
                + (f", {n_classes} pose classes" if n_classes is not None else "")
                + f"; cost {float(result.cost):.2f} (total {s.cost:.2f}); {status}",
                level=rr.TextLogLevel.INFO,
            ),
        )

    def on_failed_move(self, i: int, result: MoveResult) -> None:
        """A move that failed (no components): its trace, when there is one, in ``world/trace/failed``, a cross
        on the interpretation plot (the counts unchanged) and a warning in ``log/moves``. (Called by the loop
        when :class:`~haptic.episode.loop.EpisodeObserver` has an ``on_failed_move`` hook.)"""
        rec, s = self.stream, self._s
        trace = _trace_of(result)
        if trace is not None and len(trace.time):
            s.sim_time = float(trace.time[-1])
        if not s.blueprint_sent:
            self._send_blueprint(trace)
        self._set_time(i)
        if trace is not None and len(trace.time):
            self._log_trace(trace)
        self._log_hand(result, trace)
        if trace is not None and len(trace.time):
            path = _subsample(np.asarray(trace.tip_in_world, dtype=float), TRACE_MAX_POINTS)
            if len(path) >= 2:
                s.failed_strips.append(path)
                rec.log("world/trace/failed", rr.LineStrips3D(s.failed_strips, colors=[KIND_COLORS["failed"]],
                                                              radii=TRACE_RADIUS))  # fmt: skip
        if result.state is not None:
            s.state = result.state
            s.position = np.asarray(result.state.position, dtype=float)
        s.cost += float(result.cost)
        rec.log("plots/path_cost", rr.Scalars(s.cost))
        if math.isfinite(s.counts[0]):
            self._log_counts(*s.counts, "failed")
        if i not in s.decided:
            self._no_decision(i, getattr(result.move, "kind", "?"))
        reason = result.info.get("reason", "") if isinstance(result.info, dict) else ""
        rec.log(
            "log/moves",
            rr.TextLog(
                f"move {i} ({_move_name(result.move)}) failed: {result.status}" + (f" ({reason})" if reason else ""),
                level=rr.TextLogLevel.WARN,
            ),
        )

    def on_decision(self, i: int, decision: Decision) -> None:
        """The planner's choice for move ``i``: every candidate with its score, as arrows and as a table (kept
        per decision on both timelines)."""
        rec, s = self.stream, self._s
        self._set_time(i)
        s.decided.add(i)
        cands = list(decision.candidates)
        if cands:
            scores = np.array([float(c.score) for c in cands])
            finite = np.isfinite(scores)
            lo, hi = (float(scores[finite].min()), float(scores[finite].max())) if finite.any() else (0.0, 0.0)
            rel = np.where(finite, (scores - lo) / (hi - lo), 0.0) if hi > lo else np.ones(len(cands))
            origins, vectors, colors, labels = [], [], [], []
            for c, r in zip(cands, rel, strict=True):
                d = self._move_direction(c.move)
                if d is None:
                    continue
                origins.append(s.position)
                vectors.append(d * CANDIDATE_SCALE * s.radius * (0.5 + 0.5 * r))
                colors.append(_score_color(r))
                labels.append(f"{_move_name(c.move)} {c.score:.3g}")
            if origins:
                rec.log(
                    "world/decision/candidates",
                    rr.Arrows3D(origins=origins, vectors=vectors, colors=colors, labels=labels, radii=ARROW_RADIUS,
                                show_labels=False),
                )  # fmt: skip
            lines = [
                f"  {_move_name(c.move):<16} score {c.score:10.4g}  cost {c.expected_cost:7.2f}  "
                f"eliminated {c.expected_eliminated:6.2f}"
                for c in sorted(cands, key=lambda c: -c.score if math.isfinite(c.score) else math.inf)
            ]
        else:
            lines = []
        d = self._move_direction(decision.move)
        if d is not None and s.position is not None:
            rec.log(
                "world/decision/chosen",
                rr.Arrows3D(origins=[s.position], vectors=[d * CANDIDATE_SCALE * s.radius * 1.2],
                            colors=[(255, 255, 255)], radii=rr.components.Radius.ui_points(2.5),
                            labels=[_move_name(decision.move)], show_labels=False),
            )  # fmt: skip
        s.decision_shown = True
        rec.log("decision/scores", rr.TextDocument(_decision_table(i, decision), media_type=rr.MediaType.MARKDOWN))
        rec.log(
            "log/decisions",
            rr.TextLog(
                f"move {i}: chose {_move_name(decision.move)} among {len(cands)} candidates"
                + ("\n" + "\n".join(lines) if lines else ""),
                level=rr.TextLogLevel.INFO,
            ),
        )

    def on_end(self, record: EpisodeRecord) -> None:
        """The outcome, as a text log; marks the recording complete."""
        r = record
        text = (
            f"{r.outcome}" + (f": {r.recognized}" if r.recognized else "") + f" (true {r.model}); "
            f"{r.moves} moves, path cost {r.path_cost:.1f}, interpretations "
            + " -> ".join(str(c) for c in r.interpretations)
        )
        if r.pose_error_mm is not None:
            text += f"; pose error {r.pose_error_mm:.2f} mm, {r.pose_error_deg:.2f} deg"
        level = rr.TextLogLevel.INFO if r.correct else rr.TextLogLevel.WARN
        self.stream.log("log/episode", rr.TextLog(text, level=level))
        self.completed = True

    # ------------------------------------------------------------------------------------------ helpers

    def _log_static(self) -> None:
        rec = self.stream
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        series = {
            "plots/interpretations": (INTERPRETATIONS_COLOR, "interpretations (log10)"),
            "plots/pose_classes": (POSE_CLASSES_COLOR, "pose classes (log10)"),
            "plots/path_cost": ((120, 200, 90), "path cost [units]"),
            "plots/force": ((200, 120, 220), "normal force [N]"),
        }
        for path, (color, label) in series.items():
            rec.log(path, rr.SeriesLines(colors=[color], names=[label], widths=[2.0]), static=True)
        for kind, color in KIND_COLORS.items():
            marker, size = ("Cross", 9.0) if kind == "failed" else ("Circle", 5.0)
            rec.log(f"plots/moves/{kind}", rr.SeriesPoints(colors=[color], names=[f"{kind} move"], markers=[marker],
                                                           marker_sizes=[size]), static=True)  # fmt: skip

    def _send_blueprint(self, trace: Any = None) -> None:
        """The default blueprint, once: the ``object`` view's eye on the object's region, the ``fingertip`` view
        on the pad where the first trace starts, the ``sim_time`` timeline when there is a trace."""
        s = self._s
        if s.blueprint_sent:
            return
        s.blueprint_sent = True
        direction = np.asarray(VIEW_DIRECTION, dtype=float)
        direction /= np.linalg.norm(direction)
        kw: dict[str, Any] = {}
        if s.centre is not None:
            dist = max(OBJECT_VIEW_DISTANCE * s.radius, MIN_VIEW_DISTANCE)
            kw.update(object_eye=tuple(s.centre + dist * direction), object_target=tuple(s.centre))
        kw.update(fingertip_eye=tuple(FINGERTIP_VIEW_DISTANCE * direction))
        if trace is not None and len(trace.time):
            kw.update(timeline="sim_time")
            self.stream.send_columns(
                "decision/scores", indexes=[rr.TimeColumn("sim_time", duration=[float(trace.time[0])])],
                columns=rr.TextDocument.columns(text=[START_TEXT], media_type=[rr.MediaType.MARKDOWN]),
            )  # fmt: skip
        self.stream.send_blueprint(default_blueprint(Framing(**kw)), make_active=True, make_default=True)

    def _set_time(self, i: int) -> None:
        self._s.move = int(i)
        self.stream.set_time("move", sequence=int(i))
        if self._s.sim_time is not None:
            self.stream.set_time("sim_time", duration=self._s.sim_time)

    def _log_counts(self, interpretations: float, classes: float | None, kind: str) -> None:
        """log10 interpretations (and pose classes) at the current time, and a marker of the move's kind."""
        rec = self.stream
        rec.log("plots/interpretations", rr.Scalars(interpretations))
        if classes is not None:
            rec.log("plots/pose_classes", rr.Scalars(classes))
        rec.log(f"plots/moves/{kind if kind in KIND_COLORS else 'start'}", rr.Scalars(interpretations))
        self._s.counts = (interpretations, classes)

    def _no_decision(self, i: int, kind: str) -> None:
        """The candidate table at a move the planner did not choose (the start, an opening move)."""
        s = self._s
        if s.decision_shown:
            self.stream.log("world/decision", rr.Clear(recursive=True))
            s.decision_shown = False
        what = "the start" if i == 0 else f"an opening {kind} move"
        self.stream.log("decision/scores", rr.TextDocument(f"**move {i}**: {what}, not a planner decision",
                                                           media_type=rr.MediaType.MARKDOWN))  # fmt: skip

    def _log_components(self) -> None:
        """The data components so far (edges at their latest explored interval)."""
        rec, r = self.stream, self._s.radius
        comps = sorted(self._s.components.values(), key=lambda c: c.id)
        faces = [c for c in comps if isinstance(c, DataFace)]
        edges = [c for c in comps if isinstance(c, DataEdge)]
        vertices = [c for c in comps if isinstance(c, DataVertex)]
        if faces:
            verts, tris = [], []
            for f in faces:
                v, t = _patch(f)
                tris.append(t + sum(len(x) for x in verts))
                verts.append(v)
            rec.log(
                "world/data/faces/patches",
                rr.Mesh3D(
                    vertex_positions=np.vstack(verts), triangle_indices=np.vstack(tris), albedo_factor=FACE_COLOR
                ),
            )
            centres = np.array([f.points.mean(axis=0) for f in faces])
            rec.log(
                "world/data/faces/normals",
                rr.Arrows3D(origins=centres, vectors=np.array([f.normal for f in faces]) * NORMAL_SCALE * r,
                            colors=[FACE_COLOR[:3]], radii=ARROW_RADIUS, labels=[f"f{f.id}" for f in faces],
                            show_labels=False),
            )  # fmt: skip
            rec.log(
                "world/data/faces/points",
                rr.Points3D(np.vstack([f.points for f in faces]), radii=rr.components.Radius.ui_points(2.0),
                            colors=[FACE_COLOR[:3]]),
            )  # fmt: skip
        if edges:
            rec.log(
                "world/data/edges",
                rr.LineStrips3D([np.array([e.point, e.end_point]) for e in edges], colors=[EDGE_COLOR],
                                radii=EDGE_RADIUS, labels=[f"e{e.id}" for e in edges], show_labels=False),
            )  # fmt: skip
        if vertices:
            rec.log(
                "world/data/vertices",
                rr.Points3D([v.position for v in vertices], radii=VERTEX_RADIUS, colors=[VERTEX_COLOR],
                            labels=[f"v{v.id}" for v in vertices], show_labels=False),
            )  # fmt: skip

    def _log_trace(self, trace: Any) -> None:
        """A physics contact trace, one row per control tick on the ``sim_time`` timeline; the pad's pose and
        the last tick's contact also at the current ``move``."""
        rec, r = self.stream, self._s.radius
        t = rr.TimeColumn("sim_time", duration=np.asarray(trace.time, dtype=float))
        tip = np.asarray(trace.tip_in_world, dtype=float)
        rec.send_columns("world/hand/fingertip", indexes=[t], columns=rr.Points3D.columns(positions=tip))
        rec.send_columns("world/hand/pad", indexes=[t], columns=rr.Transform3D.columns(translation=tip))
        rec.log("world/hand/pad", rr.Transform3D(translation=tip[-1]))
        force = np.asarray(trace.force, dtype=float)
        rec.send_columns("plots/force", indexes=[t], columns=rr.Scalars.columns(scalars=force))
        pressing = force[force > 0]
        if len(pressing):  # on the move timeline: the move's mean force while in contact
            rec.send_columns("plots/force", indexes=[rr.TimeColumn("move", sequence=[self._s.move])],
                             columns=rr.Scalars.columns(scalars=[float(pressing.mean())]))  # fmt: skip
        pts = np.asarray(trace.point_in_world, dtype=float)
        nrm = np.asarray(trace.normal_in_world, dtype=float)
        ok = np.isfinite(nrm[:, 0]) & np.isfinite(pts[:, 0])
        lengths = ok.astype(int)
        rec.send_columns(
            "world/hand/contact/points", indexes=[t],
            columns=rr.Points3D.columns(positions=pts[ok]).partition(lengths),
        )  # fmt: skip
        rec.send_columns(
            "world/hand/contact/normals", indexes=[t],
            columns=rr.Arrows3D.columns(origins=pts[ok], vectors=nrm[ok] * CONTACT_NORMAL_SCALE * r).partition(lengths),
        )  # fmt: skip
        if not self._s.trace_style_logged:  # sizes and colours of the per-tick marks, once
            rec.log("world/hand/contact/points", rr.Points3D.from_fields(radii=CONTACT_RADIUS, colors=[(255, 120, 40)]),
                    static=True)  # fmt: skip
            rec.log("world/hand/contact/normals", rr.Arrows3D.from_fields(radii=ARROW_RADIUS, colors=[(255, 120, 40)]),
                    static=True)  # fmt: skip
            rec.log("world/hand/fingertip", rr.Points3D.from_fields(radii=rr.components.Radius.ui_points(3.0),
                                                                    colors=[(255, 255, 255)]), static=True)  # fmt: skip
            self._s.trace_style_logged = True

    def _log_hand(self, result: MoveResult, trace: Any) -> None:
        info = result.info if isinstance(result.info, dict) else {}
        geoms = info.get("link_geoms")
        if geoms and self._s.geom_links is None:
            self._log_geoms(geoms)
        links = info.get("hand_links")
        if not links:
            return
        if self._s.geom_links:
            self._log_link_poses(links, info.get("hand_links_time"))
        else:
            self._log_links(links, trace, info.get("hand_links_time"), info.get("hand_link_chains"))

    def _log_geoms(self, geoms: Any) -> None:
        """The robot's collision geometry, static, in its links' frames (``world/robot/<link>/<kind>s``), and the
        fixed pieces of the workspace (``world/table``). Geoms of unknown kinds are skipped with a warning."""
        rec = self.stream
        groups: dict[tuple[str | None, str], list[Any]] = {}
        for g in geoms:
            groups.setdefault((getattr(g, "link", None), str(getattr(g, "kind", "?"))), []).append(g)
        links: set[str] = set()
        for (link, kind), items in groups.items():
            base = f"world/robot/{_entity_name(link)}" if link is not None else "world/table"
            try:
                archetypes = _geom_archetypes(kind, items, ROBOT_ALPHA if link is not None else 1.0)
            except ValueError as exc:
                warnings.warn(f"link_geoms: {exc}; skipped", stacklevel=3)
                continue
            for suffix, archetype in archetypes:
                rec.log(f"{base}/{suffix}", archetype, static=True)
            if link is not None:
                links.add(str(link))
        self._s.geom_links = links

    def _log_link_poses(self, links: dict, times: Any) -> None:
        """A Transform3D per drawn link: one row per sampled tick on ``sim_time`` and the last pose at the
        current ``move``. Links without a pose (n, 7) are skipped with a warning."""
        rec, s = self.stream, self._s
        t = np.asarray(times, dtype=float).reshape(-1) if times is not None else None
        for name in sorted(s.geom_links or ()):
            a = np.asarray(links.get(name, ()), dtype=float)
            if a.ndim != 2 or a.shape[1] != 7 or not len(a):
                warnings.warn(f"hand_links[{name!r}]: no (n, 7) poses (got shape {a.shape}); its geometry stays put",
                              stacklevel=3)  # fmt: skip
                continue
            quat = a[:, [4, 5, 6, 3]]  # (w, x, y, z) -> rerun's (x, y, z, w)
            path = f"world/robot/{_entity_name(name)}"
            if t is not None and len(t) == len(a):
                rec.send_columns(path, indexes=[rr.TimeColumn("sim_time", duration=t)],
                                 columns=rr.Transform3D.columns(translation=a[:, :3], quaternion=quat))  # fmt: skip
            rec.log(path, rr.Transform3D(translation=a[-1, :3], quaternion=quat[-1]))

    def _log_links(self, links: dict, trace: Any, times: Any = None, chains: Any = None) -> None:
        """``info["hand_links"]``: link name -> (n, 3) positions, (n, 4, 4) poses or (n, 7) position +
        quaternion (w, x, y, z), world frame; n rows at the sim times ``times`` (n,) [s] when given, else
        aligned with the trace's ticks (or 1: the pose at the end of the move). ``chains``: polylines of link
        names, drawn as line strips in ``world/hand/skeleton``. Malformed entries are skipped with a
        warning."""
        rec, s = self.stream, self._s
        names, positions = [], []
        for name, value in links.items():
            a = np.asarray(value, dtype=float)
            if a.ndim == 1:
                a = a[None]
            if a.ndim == 2 and a.shape[1] in (3, 7):
                p = a[:, :3]
            elif a.ndim == 3 and a.shape[1:] == (4, 4):
                p = a[:, :3, 3]
            else:
                warnings.warn(f"hand_links[{name!r}]: shape {a.shape} is not (n, 3), (n, 7) or (n, 4, 4); skipped",
                              stacklevel=2)  # fmt: skip
                continue
            names.append(str(name))
            positions.append(p)
        if not positions or len({len(p) for p in positions}) != 1:
            if positions:
                warnings.warn("hand_links: links with different numbers of rows; skipped", stacklevel=2)
            return
        n, k = len(positions[0]), len(positions)
        stacked = np.stack(positions, axis=1)  # (n, k, 3)
        if not s.link_labels_logged:
            rec.log("world/hand/links", rr.Points3D.from_fields(labels=names, radii=0.003, show_labels=False),
                    static=True)  # fmt: skip
            s.link_labels_logged = True
        t = np.asarray(times, dtype=float).reshape(-1) if times is not None else None
        if t is not None and len(t) != n:
            warnings.warn(f"hand_links_time: {len(t)} times for {n} rows; ignored", stacklevel=2)
            t = None
        if t is None and trace is not None and len(trace.time) == n and n > 1:
            t = np.asarray(trace.time, dtype=float)
        strips = _chain_index(names, chains)
        if t is not None and n:
            index = [rr.TimeColumn("sim_time", duration=t)]
            rec.send_columns(
                "world/hand/links", indexes=index,
                columns=rr.Points3D.columns(positions=stacked.reshape(-1, 3)).partition([k] * n),
            )  # fmt: skip
            if strips:
                flat = [stacked[i, c] for i in range(n) for c in strips]
                rec.send_columns(
                    "world/hand/skeleton", indexes=index,
                    columns=rr.LineStrips3D.columns(strips=flat).partition([len(strips)] * n),
                )  # fmt: skip
        else:
            rec.log("world/hand/links", rr.Points3D(stacked[-1]))
            if strips:
                rec.log("world/hand/skeleton", rr.LineStrips3D([stacked[-1, c] for c in strips]))
        if strips and not s.skeleton_style_logged:
            rec.log("world/hand/skeleton", rr.LineStrips3D.from_fields(radii=0.002, colors=[(200, 200, 210)]),
                    static=True)  # fmt: skip
            s.skeleton_style_logged = True

    def _move_direction(self, move: Move) -> np.ndarray | None:
        """A unit world direction for drawing a move from the sensor's position (None when unknown)."""
        s = self._s
        if s.position is None:
            return None
        kind = getattr(move, "kind", None)
        if kind == "face":
            d = np.asarray(move.direction, dtype=float)
        elif kind == "edge":
            st_edge = self._current("edge")
            if st_edge is None:
                return None
            d = np.asarray(st_edge.direction, dtype=float) * int(move.sense)
        elif kind == "vertex":
            f = s.components.get(int(move.across_face))
            if not isinstance(f, DataFace):
                return None
            d = f.points.mean(axis=0) - s.position
            d = d - (d @ f.normal) * f.normal
        else:
            return None
        norm = float(np.linalg.norm(d))
        return d / norm if norm > 1e-9 and math.isfinite(norm) else None

    def _current(self, kind: str) -> DataComponent | None:
        """The component of the sensor's state of that kind (the latest reported state)."""
        st = self._s.state
        cid = getattr(st, kind, None) if st is not None else None
        return self._s.components.get(cid) if cid is not None else None


# ---------------------------------------------------------------------------------------------- geometry


def _transform(t: SE3) -> rr.Transform3D:
    return rr.Transform3D(translation=np.asarray(t.translation, dtype=float), mat3x3=np.asarray(t.rotation))


def _mesh(model: Polyhedron, color: tuple[int, ...]) -> rr.Mesh3D:
    """Flat-shaded mesh in the model frame (vertices repeated per triangle so each face keeps its normal)."""
    tris = np.asarray(model.triangles)
    pos = np.asarray(model.vertices, dtype=float)[tris].reshape(-1, 3)
    nrm = np.repeat(np.asarray(model.face_normals, dtype=float)[np.asarray(model.triangle_faces)], 3, axis=0)
    return rr.Mesh3D(
        vertex_positions=pos, triangle_indices=np.arange(len(pos)).reshape(-1, 3), vertex_normals=nrm,
        albedo_factor=color,
    )  # fmt: skip


def _wireframe(model: Polyhedron, color: tuple[int, ...], radius: float) -> rr.LineStrips3D:
    v = np.asarray(model.vertices, dtype=float)
    return rr.LineStrips3D([v[list(e)] for e in np.asarray(model.edges)], colors=[color], radii=radius)


def _patch(face: DataFace) -> tuple[np.ndarray, np.ndarray]:
    """A square in the face's plane around its touched points (half-size: their spread + PATCH_RADIUS)."""
    n = face.normal
    a, b = plane_basis(n)
    c = face.points.mean(axis=0)
    c = c - (c @ n - face.offset) * n
    rel = face.points - c
    ha = float(np.abs(rel @ a).max()) + PATCH_RADIUS
    hb = float(np.abs(rel @ b).max()) + PATCH_RADIUS
    v = np.array([c - ha * a - hb * b, c + ha * a - hb * b, c + ha * a + hb * b, c - ha * a + hb * b])
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def _edge_crossing(start: np.ndarray, direction: np.ndarray, edge: DataEdge) -> np.ndarray | None:
    """Where the ray ``start + t direction`` passes closest to the edge's line (the point on the line)."""
    d = np.asarray(direction, dtype=float)
    b = edge.direction
    w = start - edge.point
    m = np.array([[d @ d, -(d @ b)], [d @ b, -(b @ b)]])
    if abs(np.linalg.det(m)) < 1e-12:
        return None
    _, u = np.linalg.solve(m, [-(w @ d), -(w @ b)])
    return edge.point + u * b


def _waypoints(prev: np.ndarray | None, result: MoveResult, new: np.ndarray | None) -> np.ndarray:
    """The sensed points of a move in the order they were met, from the previous sensor position to the new
    one: the geometric executor's path (it has no fingertip trajectory)."""
    pts: list[np.ndarray] = [prev] if prev is not None else []
    move = result.move
    for c in result.components:
        if isinstance(c, DataFace):
            pts.extend(c.points)
        elif isinstance(c, DataVertex):
            pts.append(c.position)
        elif isinstance(c, DataEdge):
            if getattr(move, "kind", None) == "edge":
                continue  # the path runs along the edge to the vertex (or its end), added below
            start = pts[-1] if pts else None
            hit = None
            if start is not None and getattr(move, "kind", None) == "face":
                hit = _edge_crossing(start, move.direction, c)
            elif c.side_points:
                q = c.side_points[0][1]
                pts.append(q)
                hit = c.point + ((q - c.point) @ c.direction) * c.direction
            if hit is not None:
                pts.append(hit)
    if getattr(move, "kind", None) == "edge" and not any(isinstance(c, DataVertex) for c in result.components):
        e = next((c for c in result.components if isinstance(c, DataEdge)), None)
        if e is not None and prev is not None:
            ends = [e.point, e.end_point]
            pts.append(max(ends, key=lambda q: float(np.linalg.norm(q - prev))))
    if new is not None:
        pts.append(new)
    out: list[np.ndarray] = []
    for p in pts:
        p = np.asarray(p, dtype=float)
        if not out or np.linalg.norm(p - out[-1]) > 1e-9:
            out.append(p)
    return np.array(out).reshape(-1, 3)


def _contacts(components: tuple[DataComponent, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Contact points and normals of a move from its components (geometric executor): face points with the
    face normal."""
    pts, nrm = [], []
    for c in components:
        if isinstance(c, DataFace):
            pts.extend(c.points)
            nrm.extend([c.normal] * len(c.points))
    if not pts:
        return np.zeros((0, 3)), np.zeros((0, 3))
    return np.array(pts), np.array(nrm)


def _subsample(a: np.ndarray, k: int) -> np.ndarray:
    """At most ``k`` rows of ``a``, evenly spaced, first and last kept."""
    if len(a) <= k:
        return a
    return a[np.unique(np.linspace(0, len(a) - 1, k).round().astype(int))]


def _trace_of(result: MoveResult) -> Any:
    """The move's contact trace (``result.trace``) when it looks like one, else None."""
    tr = getattr(result, "trace", None)
    needed = ("time", "tip_in_world", "point_in_world", "normal_in_world", "force")
    if tr is None or not all(hasattr(tr, a) for a in needed):
        return None
    return tr


def _score_color(r: float) -> tuple[int, int, int]:
    """Dark blue (worst) to yellow (best)."""
    r = float(min(max(r, 0.0), 1.0))
    lo, hi = np.array([40, 30, 120]), np.array([250, 230, 40])
    return tuple(int(x) for x in lo + r * (hi - lo))


def _chain_index(names: list[str], chains: Any) -> list[np.ndarray]:
    """Row indices of each polyline of link names (chains naming an unknown link, or with fewer than two
    links, are left out)."""
    if not chains:
        return []
    where = {name: j for j, name in enumerate(names)}
    out = []
    for chain in chains:
        idx = [where.get(str(name)) for name in chain]
        if len(idx) >= 2 and None not in idx:
            out.append(np.array(idx))
    return out


def _log_count(n: float) -> float:
    """What the log10 plots show for ``n`` interpretations or pose classes (:data:`NO_COUNT` for none)."""
    return math.log10(n) if n >= 1 else NO_COUNT


def _entity_name(name: Any) -> str:
    """A link name as one entity-path part (slashes and spaces replaced)."""
    return str(name).replace("/", "_").replace(" ", "_") or "_"


def _quat_xyzw(wxyz: np.ndarray) -> np.ndarray:
    return np.asarray(wxyz, dtype=float)[..., [1, 2, 3, 0]]


def _rotate(wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``v`` (3,) rotated by the unit quaternion (w, x, y, z)."""
    w, q = float(wxyz[0]), np.asarray(wxyz[1:], dtype=float)
    return v + 2.0 * np.cross(q, np.cross(q, v) + w * v)


def _geom_archetypes(kind: str, geoms: list[Any], alpha: float = 1.0) -> list[tuple[str, Any]]:
    """Rerun archetypes drawing ``geoms`` (all of one kind, in their link's frame; their opacity times
    ``alpha``): (entity suffix, archetype) pairs. Raises ValueError for a kind rerun cannot draw here."""
    pose = np.array([np.asarray(g.pose, dtype=float) for g in geoms]).reshape(len(geoms), 7)
    size = np.array([np.asarray(g.size, dtype=float) for g in geoms]).reshape(len(geoms), 3)
    colors = [tuple(int(round(255 * float(c) * (alpha if j == 3 else 1.0))) for j, c in enumerate(g.rgba))
              for g in geoms]  # fmt: skip
    pos, quat = pose[:, :3], pose[:, 3:]
    solid = rr.components.FillMode.Solid
    if kind == "sphere":
        return [("spheres", rr.Ellipsoids3D(half_sizes=np.repeat(size[:, :1], 3, axis=1), centers=pos,
                                            colors=colors, fill_mode=solid))]  # fmt: skip
    if kind == "ellipsoid":
        return [("ellipsoids", rr.Ellipsoids3D(half_sizes=size, centers=pos, quaternions=_quat_xyzw(quat),
                                               colors=colors, fill_mode=solid))]  # fmt: skip
    if kind == "capsule":  # MuJoCo: centred, along z from -h to +h; rerun: from the origin to (0, 0, length)
        start = np.array([p - _rotate(q, np.array([0.0, 0.0, h])) for p, q, h in zip(pos, quat, size[:, 1],
                                                                                      strict=True)])  # fmt: skip
        return [("capsules", rr.Capsules3D(lengths=2 * size[:, 1], radii=size[:, 0], translations=start,
                                           quaternions=_quat_xyzw(quat), colors=colors, fill_mode=solid))]  # fmt: skip
    if kind == "cylinder":
        cylinders = rr.Cylinders3D(lengths=2 * size[:, 1], radii=size[:, 0], centers=pos,
                                   quaternions=_quat_xyzw(quat), colors=colors, fill_mode=solid)  # fmt: skip
        return [("cylinders", cylinders)]
    if kind == "box":
        return [("boxes", rr.Boxes3D(half_sizes=size, centers=pos, quaternions=_quat_xyzw(quat), colors=colors,
                                     fill_mode=solid))]  # fmt: skip
    if kind == "mesh":
        out = []
        for j, (g, p, q, c) in enumerate(zip(geoms, pos, quat, colors, strict=True)):
            if g.vertices is None or g.triangles is None:
                raise ValueError(f"mesh geom {g.name!r} has no vertices or triangles")
            v = np.array([p + _rotate(q, x) for x in np.asarray(g.vertices, dtype=float)])
            out.append((f"mesh{j}", rr.Mesh3D(vertex_positions=v, triangle_indices=np.asarray(g.triangles),
                                               albedo_factor=c)))  # fmt: skip
        return out
    raise ValueError(f"geom kind {kind!r} (drawn: sphere, ellipsoid, capsule, cylinder, box, mesh)")


def _bar(r: float, width: int = 20) -> str:
    """A text bar of ``r`` in [0, 1], in ASCII (the viewer's fonts lack block characters)."""
    n = round(max(0.0, min(1.0, r)) * width)
    return "`" + "=" * n + " " * (width - n) + "`"


def _decision_table(i: int, decision: Decision) -> str:
    """Markdown: the decision's candidate moves, best first, with a bar of their score against the best."""
    cands = sorted(decision.candidates, key=lambda c: -c.score if math.isfinite(c.score) else math.inf)
    head = f"**move {i}**: chose **{_move_name(decision.move)}**"
    if not cands:
        return head + " (no scored candidates: the fallback policy)"
    best = max((float(c.score) for c in cands if math.isfinite(c.score)), default=0.0)
    rows = [head + f" among {len(cands)} candidates", "",
            "| move | score | | exp. cost | exp. eliminated |", "|---|---|---|--:|--:|"]  # fmt: skip
    shown = cands[:MAX_TABLE_ROWS]
    for c in shown:
        name = f"**{_move_name(c.move)}** (chosen)" if c.move == decision.move else _move_name(c.move)
        r = float(c.score) / best if best > 0 and math.isfinite(c.score) else 0.0
        rows.append(f"| {name} | {_bar(r)} | {c.score:.3g} | {c.expected_cost:.2f} | "
                    f"{c.expected_eliminated:.2f} |")  # fmt: skip
    if len(cands) > len(shown):
        rows.append(f"| ... {len(cands) - len(shown)} more | | | | |")
    return "\n".join(rows)


def _move_name(move: Move) -> str:
    """The move's kind and direction: ``face (+0.92, +0.33, -0.22)`` (a world direction), ``edge +``,
    ``vertex across f2``."""
    kind = getattr(move, "kind", "?")
    if kind == "face":
        d = np.asarray(move.direction, dtype=float)
        return f"face ({d[0]:+.2f}, {d[1]:+.2f}, {d[2]:+.2f})"
    if kind == "edge":
        return f"edge {'+' if move.sense > 0 else '-'}"
    if kind == "vertex":
        return f"vertex across f{move.across_face}"
    return str(move)


# ---------------------------------------------------------------------------------------------- reading back


@dataclass
class EntityData:
    """One entity of a recording read back."""

    path: str
    """Entity path, e.g. ``/plots/interpretations``."""
    static: dict[str, list]
    """Component column (``Archetype:field``) -> its static value (a list of instances)."""
    timelines: dict[str, list]
    """Timeline name -> one value per temporal row, in logging order (sequence: int; duration: seconds; None
    where the row has no value on that timeline)."""
    components: dict[str, list]
    """Component column -> one value per temporal row (a list of instances, or None where not logged)."""

    @property
    def rows(self) -> int:
        """Number of temporal rows."""
        return max((len(v) for v in self.timelines.values()), default=0)

    def series(self, component: str, timeline: str = "move") -> tuple[list, list]:
        """``(times, values)`` of the temporal rows that hold ``component``, in logging order."""
        values = self.components.get(component, [])
        times = self.timelines.get(timeline, [None] * len(values))
        keep = [i for i, v in enumerate(values) if v is not None]
        return [times[i] for i in keep], [values[i] for i in keep]


def load_recording(path: str | os.PathLike, *, blueprint: bool = False) -> dict[str, EntityData]:
    """Every entity of the (first) recording in an ``.rrd`` file, read with rerun's own
    :class:`rerun.chunk.RrdReader`; keys are entity paths without the leading slash. ``blueprint=True``
    reads the file's (last) blueprint instead: its views (``view/<id>``, with ``ViewBlueprint:*`` and their
    properties, such as ``view/<id>/EyeControls3D``), containers and panels, on the ``blueprint`` timeline."""
    import pyarrow as pa
    from rerun.chunk import RrdReader

    p = Path(path)
    if not p.is_file():
        raise RecordingError(f"{p}: no such recording")
    try:
        reader = RrdReader(p)
        if blueprint:
            stores = reader.blueprints()
            if not stores:
                raise RecordingError(f"{p}: the recording holds no blueprint")
            chunks = reader.stream(store=stores[-1]).to_chunks()
        else:
            chunks = reader.stream().to_chunks()
    except RecordingError:
        raise
    except Exception as exc:  # noqa: BLE001 -- rerun raises plain exceptions on a bad file
        raise RecordingError(f"{p}: not a readable rerun recording ({exc})") from exc
    temporal: dict[str, list[tuple[bytes, dict]]] = {}
    static: dict[str, dict[str, list]] = {}
    for ch in chunks:
        batch = ch.to_record_batch()
        row_ids: list[bytes] = [b""] * ch.num_rows
        cols: dict[tuple[str, str], list] = {}
        for fld, col in zip(batch.schema, batch.columns, strict=True):
            kind = (fld.metadata or {}).get(b"rerun:kind", b"").decode()
            if kind == "index" and pa.types.is_duration(fld.type):  # to seconds (as_py would drop nanoseconds)
                scale = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}[fld.type.unit]
                cols[("t", fld.name)] = [v * scale if v is not None else None for v in col.cast(pa.int64()).to_pylist()]
                continue
            if kind == "index" and pa.types.is_timestamp(fld.type):  # nanoseconds since the epoch, as int
                cols[("t", fld.name)] = col.cast(pa.int64()).to_pylist()
                continue
            values = col.to_pylist()
            if kind == "control":
                row_ids = [bytes(x) if x is not None else b"" for x in values]
            elif kind == "index":
                cols[("t", fld.name)] = values
            else:
                cols[("c", fld.name)] = values
        ep = ch.entity_path.lstrip("/")
        if ch.is_static:
            for (_, name), values in cols.items():
                if values and values[-1] is not None:
                    static.setdefault(ep, {})[name] = values[-1]
            continue
        for r in range(ch.num_rows):
            temporal.setdefault(ep, []).append((row_ids[r], {k: v[r] for k, v in cols.items()}))
    out: dict[str, EntityData] = {}
    for ep in sorted(set(temporal) | set(static)):
        rows = sorted(temporal.get(ep, []), key=lambda x: x[0])  # row ids (TUIDs) sort in logging order
        keys = sorted({k for _, d in rows for k in d})
        out[ep] = EntityData(
            path="/" + ep,
            static=static.get(ep, {}),
            timelines={k[1]: [d.get(k) for _, d in rows] for k in keys if k[0] == "t"},
            components={k[1]: [d.get(k) for _, d in rows] for k in keys if k[0] == "c"},
        )
    return out


__all__ = ["EntityData", "EpisodeRecorder", "RecordingError", "default_blueprint", "load_recording"]
