"""The episode recorder: the observer hooks of the loop turned into a rerun recording (file or viewer)."""

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

from haptic.episode.loop import EpisodeObserver
from haptic.errors import RecordingError
from haptic.geometry import SE3, Polyhedron
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex
from haptic.recording.blueprint import Framing, default_blueprint
from haptic.recording.drawing import (
    chain_index,
    contacts,
    decision_summary,
    decision_table,
    entity_name,
    geom_archetypes,
    log_count,
    mesh,
    move_name,
    patch,
    placement_table,
    score_color,
    subsample,
    trace_of,
    transform,
    waypoints,
    wireframe,
)
from haptic.recording.style import (
    APPLICATION_ID,
    ARROW_RADIUS,
    CANDIDATE_PROBES,
    CANDIDATE_SCALE,
    CONTACT_COLOR,
    CONTACT_NORMAL_SCALE,
    CONTACT_RADIUS,
    DEFAULT_RADIUS,
    EDGE_COLOR,
    EDGE_RADIUS,
    ESTIMATE_COLOR,
    FACE_COLOR,
    FINGER_COLORS,
    FINGERTIP_VIEW_DISTANCE,
    INTERPRETATIONS_COLOR,
    KIND_COLORS,
    MIN_VIEW_DISTANCE,
    MOVE_CONTACTS,
    MOVE_NORMALS,
    NORMAL_SCALE,
    OBJECT_VIEW_DISTANCE,
    POSE_CLASSES_COLOR,
    PROBE_HIT_COLOR,
    PROBE_MISS_COLOR,
    PROBE_RADIUS,
    ROBOT_ALPHA,
    START_TEXT,
    TRACE_MAX_POINTS,
    TRACE_RADIUS,
    TRUTH_COLOR,
    VERTEX_COLOR,
    VERTEX_RADIUS,
    VIEW_DIRECTION,
    VIEWER_PORT,
)

if TYPE_CHECKING:
    from haptic.episode.loop import EpisodeRecord
    from haptic.matching.recognition import Recognition
    from haptic.planning.moves import Move, MoveResult, SensorState
    from haptic.planning.policies import Decision


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
    probe_hits: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=list)
    """Probes that met the object: line start, contact and sensed normal (world) [m]."""
    probe_misses: list[np.ndarray] = field(default_factory=list)
    """Probes that met nothing: their whole line, (2, 3) [m]."""
    placed: dict[str, list[tuple[np.ndarray, np.ndarray, np.ndarray | None]]] = field(default_factory=dict)
    """Per finger, each of its closings in a placement: line start, contact (or the line's end) and sensed normal
    (None: it met nothing) (world) [m]."""
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
    status: str = "-"
    """The matcher's status after the last move ("recognized" while a verification runs)."""
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
        rec.log("world/truth", transform(world_from_model), static=True)
        rec.log("world/truth/object", mesh(true_model, TRUTH_COLOR), static=True)
        rec.log("world/truth/edges", wireframe(true_model, (120, 120, 120), rr.components.Radius.ui_points(1.0)),
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
        trace = self._begin_move(i, result)
        for c in result.components:
            s.components[c.id] = c
        kind = getattr(result.move, "kind", "start") if i > 0 else "start"
        prev = s.position
        new = np.asarray(result.state.position, dtype=float) if result.state is not None else None

        # the path: the physics trace when there is one, else the sensed waypoints
        if trace is not None and len(trace.time):
            path = subsample(np.asarray(trace.tip_in_world, dtype=float), TRACE_MAX_POINTS)
        else:
            path = waypoints(prev, result, new)
        if len(path) == 1:
            path = np.vstack([path, path])
        if len(path):
            s.strips.append(path)
            s.strip_kinds.append("probe miss" if kind == "probe" and not result.components else kind)
            rec.log(
                "world/trace/path",
                rr.LineStrips3D(
                    s.strips,
                    colors=[PROBE_MISS_COLOR if k == "probe miss" else KIND_COLORS.get(k, KIND_COLORS["start"])
                            for k in s.strip_kinds],
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
            pts = subsample(np.asarray(trace.point_in_world, dtype=float)[ok], MOVE_CONTACTS)
            nrm = subsample(np.asarray(trace.normal_in_world, dtype=float)[ok], MOVE_CONTACTS)
            self._log_trace(trace)
        else:
            pts, nrm = contacts(result.components)
        rec.log("world/contacts/points", rr.Points3D(pts, radii=CONTACT_RADIUS, colors=[CONTACT_COLOR]))
        k = subsample(np.arange(len(pts)), MOVE_NORMALS)
        rec.log(
            "world/contacts/normals",
            rr.Arrows3D(origins=pts[k], vectors=nrm[k] * CONTACT_NORMAL_SCALE * s.radius, colors=[CONTACT_COLOR],
                        radii=ARROW_RADIUS),
        )  # fmt: skip
        self._log_hand(result, trace)
        if kind == "probe":
            self._log_probe(result)
        if kind == "placement":
            self._log_placement(result)

        self._log_components()

        # the counts, on a log axis, with a marker of the move's kind
        s.cost += float(result.cost)
        n_classes = len(recognition.classes) if recognition is not None and recognition.classes else None
        self._log_counts(log_count(n_interpretations), log_count(n_classes) if n_classes is not None else None,
                         kind)  # fmt: skip
        rec.log("plots/path_cost", rr.Scalars(s.cost))
        if recognition is not None and recognition.status == "recognized" and recognition.world_from_model:
            model = next((c.model for c in recognition.classes if c.name == recognition.model), None)
            if model is not None:
                rec.log("world/estimate", transform(recognition.world_from_model))
                rec.log("world/estimate/edges", wireframe(model, ESTIMATE_COLOR, EDGE_RADIUS))
        if i not in s.decided:
            self._no_decision(i, kind, result.move)

        status = recognition.status if recognition is not None else "-"
        s.status = status
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

    def _log_placement(self, result: MoveResult) -> None:
        """Every placement's fingers so far, each finger in its own colour (``world/placements/<finger>``): a
        touch as its line from the start to the contact, the contact and its normal; a finger that met nothing as
        its whole line; a finger that failed not at all."""
        rec, s = self.stream, self._s
        faces = {c.id: c for c in result.components if isinstance(c, DataFace)}
        done = []
        for f, what in zip(result.move.fingers, result.info.get("fingers", ()), strict=False):
            if what.get("status") == "touched" and what.get("component") in faces:
                face = faces[what["component"]]
                s.placed.setdefault(f.finger, []).append(
                    (np.asarray(f.start, dtype=float), np.atleast_2d(face.points)[0], np.asarray(face.normal)))
            elif what.get("status") == "missed":
                s.placed.setdefault(f.finger, []).append((np.asarray(f.start, dtype=float), f.end, None))
            done.append(f"{f.finger} {what.get('status', '?')}")
        for finger, closings in s.placed.items():
            color = FINGER_COLORS.get(finger, KIND_COLORS["placement"])
            lines = [np.array([a, b]) for a, b, _ in closings]
            rec.log(f"world/placements/{finger}/lines",
                    rr.LineStrips3D(lines, colors=[color], radii=PROBE_RADIUS,
                                    labels=[finger] * len(lines), show_labels=False))  # fmt: skip
            touched = [(b, n) for _, b, n in closings if n is not None]
            if touched:
                pts, nrm = np.array([b for b, _ in touched]), np.array([n for _, n in touched])
                rec.log(f"world/placements/{finger}/contacts",
                        rr.Points3D(pts, radii=CONTACT_RADIUS, colors=[color], labels=[finger] * len(pts),
                                    show_labels=False))  # fmt: skip
                rec.log(f"world/placements/{finger}/normals",
                        rr.Arrows3D(origins=pts, vectors=nrm * NORMAL_SCALE * s.radius, colors=[color],
                                    radii=ARROW_RADIUS))  # fmt: skip
        rec.log("log/moves", rr.TextLog(f"placement: {', '.join(done)}", level=rr.TextLogLevel.INFO))

    def _log_probe(self, result: MoveResult) -> None:
        """Every probe so far: a hit as its line from the start to the contact, the contact and its normal
        (``world/probes/hits``, ``.../contacts``, ``.../normals``); a miss as its whole line
        (``world/probes/misses``), in another colour."""
        rec, s = self.stream, self._s
        move = result.move
        start = np.asarray(move.start, dtype=float)
        face = next((c for c in result.components if isinstance(c, DataFace)), None)
        if face is not None:
            s.probe_hits.append((start, np.atleast_2d(face.points)[0], np.asarray(face.normal, dtype=float)))
        else:
            s.probe_misses.append(np.array([start, move.end]))
        n = len(s.probe_hits) + len(s.probe_misses)
        if s.probe_hits:
            starts, pts, nrm = (np.array(x) for x in zip(*s.probe_hits, strict=True))
            labels = [f"probe hit {j}" for j in range(len(pts))]
            lines = np.stack([starts, pts], axis=1)
            rec.log("world/probes/hits", rr.LineStrips3D(lines, colors=[PROBE_HIT_COLOR], radii=PROBE_RADIUS,
                                                         labels=labels, show_labels=False))  # fmt: skip
            rec.log("world/probes/contacts", rr.Points3D(pts, radii=CONTACT_RADIUS, colors=[PROBE_HIT_COLOR],
                                                         labels=labels, show_labels=False))  # fmt: skip
            rec.log("world/probes/normals", rr.Arrows3D(origins=pts, vectors=nrm * NORMAL_SCALE * s.radius,
                                                        colors=[PROBE_HIT_COLOR], radii=ARROW_RADIUS))  # fmt: skip
        if s.probe_misses:
            labels = [f"probe miss {j}" for j in range(len(s.probe_misses))]
            rec.log("world/probes/misses", rr.LineStrips3D(s.probe_misses, colors=[PROBE_MISS_COLOR],
                                                           radii=PROBE_RADIUS, labels=labels,
                                                           show_labels=False))  # fmt: skip
        by = f" by the {move.finger}" if getattr(move, "finger", None) else ""
        rec.log("log/moves", rr.TextLog(f"probe {n}{by}: {'hit' if face is not None else 'miss'}",
                                        level=rr.TextLogLevel.INFO))  # fmt: skip

    def _begin_move(self, i: int, result: MoveResult) -> Any:
        """Move ``i``'s contact trace (None without one), after setting the clocks to it and sending the
        blueprint with the first move."""
        s = self._s
        trace = trace_of(result)
        if trace is not None and len(trace.time):
            s.sim_time = float(trace.time[-1])
        if not s.blueprint_sent:
            self._send_blueprint(trace)
        self._set_time(i)
        return trace

    def on_failed_move(self, i: int, result: MoveResult) -> None:
        """A move that failed (no components): its trace, when there is one, in ``world/trace/failed``, a cross
        on the interpretation plot (the counts unchanged) and a warning in ``log/moves``. (Called by the loop
        when :class:`~haptic.episode.loop.EpisodeObserver` has an ``on_failed_move`` hook.)"""
        rec, s = self.stream, self._s
        trace = self._begin_move(i, result)
        if trace is not None and len(trace.time):
            self._log_trace(trace)
        self._log_hand(result, trace)
        if trace is not None and len(trace.time):
            path = subsample(np.asarray(trace.tip_in_world, dtype=float), TRACE_MAX_POINTS)
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
        reason = result.reason
        rec.log(
            "log/moves",
            rr.TextLog(
                f"move {i} ({move_name(result.move)}) failed: {result.status}" + (f" ({reason})" if reason else ""),
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
                colors.append(score_color(r))
                labels.append(f"{move_name(c.move)} {c.score:.3g}")
            probes = [(c, r) for c, r in zip(cands, rel, strict=True) if getattr(c.move, "kind", None) == "probe"]
            probes = sorted(probes, key=lambda cr: -cr[1])[:CANDIDATE_PROBES]  # the best lines only: dozens hide all
            if probes:
                rec.log(
                    "world/decision/probes",
                    rr.LineStrips3D([np.array([c.move.start, c.move.end]) for c, _ in probes],
                                    colors=[score_color(r) for _, r in probes], radii=ARROW_RADIUS,
                                    labels=[f"{move_name(c.move)} {c.score:.3g}" for c, _ in probes],
                                    show_labels=False),
                )  # fmt: skip
            if origins:
                rec.log(
                    "world/decision/candidates",
                    rr.Arrows3D(origins=origins, vectors=vectors, colors=colors, labels=labels, radii=ARROW_RADIUS,
                                show_labels=False),
                )  # fmt: skip
            lines = [
                f"  {move_name(c.move):<16} score {c.score:10.4g}  cost {c.expected_cost:7.2f}  "
                f"eliminated {c.expected_eliminated:6.2f}"
                for c in sorted(cands, key=lambda c: -c.score if math.isfinite(c.score) else math.inf)
            ]
        else:
            lines = []
        if getattr(decision.move, "kind", None) == "probe":
            rec.log(
                "world/decision/chosen",
                rr.Arrows3D(origins=[decision.move.start], vectors=[decision.move.end - decision.move.start],
                            colors=[(255, 255, 255)], radii=rr.components.Radius.ui_points(2.5),
                            labels=[move_name(decision.move)], show_labels=False),
            )  # fmt: skip
        d = self._move_direction(decision.move)
        if d is not None and s.position is not None:
            rec.log(
                "world/decision/chosen",
                rr.Arrows3D(origins=[s.position], vectors=[d * CANDIDATE_SCALE * s.radius * 1.2],
                            colors=[(255, 255, 255)], radii=rr.components.Radius.ui_points(2.5),
                            labels=[move_name(decision.move)], show_labels=False),
            )  # fmt: skip
        if getattr(decision.move, "kind", None) == "placement":
            rec.log(
                "world/decision/chosen",
                rr.Arrows3D(origins=[f.start for f in decision.move.fingers],
                            vectors=[f.end - np.asarray(f.start) for f in decision.move.fingers],
                            colors=[FINGER_COLORS.get(f.finger, (255, 255, 255)) for f in decision.move.fingers],
                            radii=rr.components.Radius.ui_points(2.5),
                            labels=[f.finger for f in decision.move.fingers], show_labels=False),
            )  # fmt: skip
        if any(getattr(c.move, "kind", None) == "placement" for c in cands):
            rec.log("decision/placements",
                    rr.TextDocument(placement_table(i, decision), media_type=rr.MediaType.MARKDOWN))  # fmt: skip
        s.decision_shown = True
        rec.log("decision/scores", rr.TextDocument(decision_table(i, decision), media_type=rr.MediaType.MARKDOWN))
        rec.log(
            "log/decisions",
            rr.TextLog(
                decision_summary(i, decision, move_name(decision.move))
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

    def log_learned(self, model: Polyhedron, moves: int) -> None:
        """The model learned in the episode (its vertices in the world frame) drawn over the true one at the last
        move: its edges in the estimate's colour, its faces faintly."""
        rec = self.stream
        self._set_time(moves)
        rec.log("world/learned/object", mesh(model, (*ESTIMATE_COLOR, 70)))
        rec.log("world/learned/edges", wireframe(model, ESTIMATE_COLOR, rr.components.Radius.ui_points(2.0)))
        rec.log("log/episode", rr.TextLog(f"learned {model.name}: V {model.n_vertices}, E {model.n_edges}, "
                                          f"F {model.n_faces} (green, over the true object)"))  # fmt: skip

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

    def _no_decision(self, i: int, kind: str, move=None) -> None:
        """The candidate table at a move the planner did not choose (the start, an opening move, a verification
        move: one chosen while the matcher had recognised the object); a face move across the other face of the
        edge the sensor was on says so."""
        s = self._s
        if s.decision_shown:
            self.stream.log("world/decision", rr.Clear(recursive=True))
            s.decision_shown = False
        if i == 0:
            what = "the start"
        elif s.status == "recognized":
            what = f"a verification {kind} move (what the recognised model predicts and is not measured yet)"
            if getattr(move, "face", None) is not None:
                what += f", across data face {move.face}, the other face of the edge the sensor was on"
        else:
            what = f"an opening {kind} move"
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
                v, t = patch(f)
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
        hand = result.links
        if hand is None:
            return
        if hand.geoms and self._s.geom_links is None:
            self._log_geoms(hand.geoms)
        if not hand.poses:
            return
        if self._s.geom_links:
            self._log_link_poses(hand.poses, hand.time)
        else:
            self._log_links(hand.poses, trace, hand.time, hand.chains)

    def _log_geoms(self, geoms: Any) -> None:
        """The robot's collision geometry, static, in its links' frames (``world/robot/<link>/<kind>s``), and the
        fixed pieces of the workspace (``world/table``). Geoms of unknown kinds are skipped with a warning."""
        rec = self.stream
        groups: dict[tuple[str | None, str], list[Any]] = {}
        for g in geoms:
            groups.setdefault((getattr(g, "link", None), str(getattr(g, "kind", "?"))), []).append(g)
        links: set[str] = set()
        for (link, kind), items in groups.items():
            base = f"world/robot/{entity_name(link)}" if link is not None else "world/table"
            try:
                archetypes = geom_archetypes(kind, items, ROBOT_ALPHA if link is not None else 1.0)
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
            path = f"world/robot/{entity_name(name)}"
            if t is not None and len(t) == len(a):
                rec.send_columns(path, indexes=[rr.TimeColumn("sim_time", duration=t)],
                                 columns=rr.Transform3D.columns(translation=a[:, :3], quaternion=quat))  # fmt: skip
            rec.log(path, rr.Transform3D(translation=a[-1, :3], quaternion=quat[-1]))

    def _log_links(self, links: dict, trace: Any, times: Any = None, chains: Any = None) -> None:
        """``links`` (:attr:`HandLinks.poses`): link name -> (n, 3) positions, (n, 4, 4) poses or (n, 7) position +
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
        strips = chain_index(names, chains)
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
