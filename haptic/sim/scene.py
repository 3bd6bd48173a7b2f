"""Scene composition with ``dm_control.mjcf``: tabletop + PUMA-like arm + four-finger hand + object.

The arm (``assets/mjcf/arm``) is attached to the stand of ``scenes/tabletop.xml``, the hand
(``assets/mjcf/hand``) to the arm's flange, and the object -- one static convex mesh geom per convex piece
(MuJoCo collides a mesh as its convex hull) -- into the scene's ``object`` body at ``world_from_object``.
:func:`export_scene` writes a standalone MJCF with its mesh files beside it that plain
``mujoco.MjModel.from_xml_path`` (and ``python -m mujoco.viewer``) loads.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
import weakref
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache, cached_property
from pathlib import Path

import mujoco
import numpy as np
import trimesh
from dm_control import mjcf
from scipy.spatial import ConvexHull, QhullError

from haptic.errors import HapticError, SceneError
from haptic.geometry import convex_decomposition, load_library, resolve_model

REPO_ROOT = Path(__file__).resolve().parents[2]
ARM_XML = REPO_ROOT / "assets" / "mjcf" / "arm" / "puma560.xml"
HAND_XML = REPO_ROOT / "assets" / "mjcf" / "hand" / "hand.xml"
TABLETOP_XML = REPO_ROOT / "scenes" / "tabletop.xml"

ARM_PREFIX = "arm/"
HAND_PREFIX = "arm/hand/"
ARM_JOINTS = ("waist", "shoulder", "elbow", "wrist_roll", "wrist_pitch", "flange_roll")
FINGERS = ("index", "middle", "ring", "thumb")
"""Finger names, in the order every per-finger array of this package uses."""
FINGER_PREFIX = {"index": "ff", "middle": "mf", "ring": "rf", "thumb": "th"}
HAND_JOINTS = tuple(f"{FINGER_PREFIX[f]}_j{k}" for f in FINGERS for k in range(4))


def _table_top_z(root: mjcf.RootElement) -> float:
    """Height of the table's top surface in the world frame [m]: its ``table_surface`` site."""
    site, table = root.find("site", "table_surface"), root.find("body", "table")
    if site is None or table is None:
        raise SceneError(f"{TABLETOP_XML}: no body 'table' with a site 'table_surface' (the table's top surface)")
    return float(table.pos[2] + site.pos[2])


def _pad_radius(root: mjcf.RootElement, prefix: str = "", finger: str = "index") -> float:
    """Radius of ``finger``'s fingertip pad (a sphere) [m]."""
    pad = root.find("geom", f"{prefix}{FINGER_PREFIX[finger]}_pad")
    if pad is None:
        raise SceneError(f"{HAND_XML}: no geom {FINGER_PREFIX[finger]}_pad (the {finger} fingertip's pad)")
    size = pad.size if pad.size is not None else pad.dclass.geom.size
    return float(size[0])


TABLE_TOP_Z = _table_top_z(mjcf.from_path(str(TABLETOP_XML)))
"""Height of the table's top surface in the world frame [m], read from scenes/tabletop.xml."""
PAD_RADIUS = _pad_radius(mjcf.from_path(str(HAND_XML)))
"""Radius of the tracing (index) fingertip's pad [m], read from assets/mjcf/hand/hand.xml."""
ROTATION_ATOL = 1e-6
"""A (3, 3) matrix is a rotation when ``RᵀR`` is the identity within this (absolute, per entry) [-]."""
ZERO_VECTOR = 1e-9
"""A vector shorter than this has no direction (round-off) [-]."""
ANTIPARALLEL = 1e-12
"""Two unit vectors whose dot product is within this of −1 are opposite (round-off) [-]."""
PARALLEL = 1e-6
"""Two unit vectors whose dot product is within this of 1 are the same direction (hull facets of one plane);
a cross product shorter than this has no direction [-]."""
PLANE_DECIMALS = 9
"""Hull facet equations are rounded to this many decimals before duplicates are merged."""
MIN_PART_POINTS = 4
"""Fewest vertices of a convex part of an object (a tetrahedron's)."""
MIN_PART_VOLUME = 1e-9
"""Smallest volume of a convex part of an object [m^3]."""
STABLE_MARGIN = 0.002
"""A resting facet is stable when the solid's centroid projects into it at least this far from its border [m]."""
OBJECT_RGBA = (0.25, 0.6, 0.35, 1.0)
"""Colour of the object's geoms (red, green, blue, alpha)."""
OBJECT_BODY = "object"
"""The body of ``scenes/tabletop.xml`` the object's geoms are placed in."""
OBJECT_CLASS = "scene"
"""The default class of the object's geoms."""

OBJECT_REGION = ((0.46, 0.62), (-0.10, 0.10))
"""Where a random object centre is placed on the table: ((x_min, x_max), (y_min, y_max)) in world [m]."""

ARM_HOME = np.array([0.2069, 0.4832, 0.2084, 0.0, 0.8792, 0.2069])
"""Arm posture [rad] with the flange pointing down and the index fingertip at (0.54, 0, 0.55) m, hand pointing down."""
HAND_TRACE = np.array(
    [
        0.0,
        0.0,
        0.0,
        0.0,  # index: straight, the tracing finger
        0.0,
        1.45,
        1.6,
        1.4,  # middle: curled into the palm
        0.0,
        1.45,
        1.6,
        1.4,  # ring: curled into the palm
        0.0,
        0.9,
        0.3,
        0.3,  # thumb: folded along the palm, out of the way
    ]
)
"""Hand posture [rad] (order of ``HAND_JOINTS``) for tracing with the index finger, the others curled away."""


@dataclass(frozen=True)
class Workspace:
    """The robot's workspace as a composed scene defines it (what the planner may assume; no object)."""

    table_top_z: float
    """Height of the table's top surface in the world frame [m]."""
    pad_radius: float
    """Radius of the tracing fingertip's pad [m]."""


@dataclass(frozen=True)
class SceneObject:
    """A polyhedral object ready for MuJoCo: a name and its convex pieces."""

    name: str
    """Model name (library file stem)."""
    parts: tuple[np.ndarray, ...]
    """Vertex sets (n_i, 3) of convex pieces in the object frame [m]; their union is the solid."""

    @property
    def vertices(self) -> np.ndarray:
        """All piece vertices stacked (N, 3) in the object frame [m]."""
        return np.vstack(self.parts)


@dataclass(frozen=True)
class ComposedScene:
    """A composed scene: the object and its pose (the ground truth, evaluation only), its ``mjcf`` model and the
    MuJoCo model compiled from it."""

    object: SceneObject | None
    """The object placed on the table, or None for an empty table."""
    world_from_object: np.ndarray = field(default_factory=lambda: np.eye(4))
    """Homogeneous transform (4, 4) of the object in the world [m]."""

    @cached_property
    def mjcf_model(self) -> mjcf.RootElement:
        """The composed dm_control MJCF root (composed on first use: :meth:`compile` does without it)."""
        return _compose_mjcf(self.object, self.world_from_object)

    def to_xml_string(self) -> str:
        return self.mjcf_model.to_xml_string()

    @property
    def workspace(self) -> Workspace:
        """What the robot knows of its workspace, read from this scene (never the object)."""
        robot = _robot_scene().mjcf_model  # the table and the hand are those of every scene
        return Workspace(_table_top_z(robot), _pad_radius(robot, HAND_PREFIX))

    def compile(self) -> mujoco.MjModel:
        """The plain MuJoCo model of this scene: the same model as the composed MJCF's (:attr:`mjcf_model`) compiles
        to, built from the object-less scene parsed once per process (:func:`_robot_spec`) with the object's meshes
        and geoms added, as :func:`_compose_mjcf` adds them: the dm_control composition and its XML were most of
        the 0.1 s a scene took."""
        spec = _robot_spec().copy()
        assets: dict[str, bytes] = dict(spec.assets)
        if self.object is not None:
            pose = self.world_from_object
            slot = spec.body(OBJECT_BODY)
            slot.pos = pose[:3, 3]
            slot.quat = _pose_quat(pose)
            scene_class = spec.find_default(OBJECT_CLASS)
            for i, part in enumerate(self.object.parts):
                name = f"object_part{i}"
                stl = _mesh_asset(part).contents
                # the file named by its content, as dm_control names it: MuJoCo keeps the meshes it has read by file
                # name for the process's next compilations, and one of the same name and size would be taken for it
                file = f"{name}-{hashlib.sha1(stl).hexdigest()}.stl"
                assets[file] = stl
                spec.add_mesh(name=name, file=file)
                slot.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=name, default=scene_class,
                              rgba=OBJECT_RGBA, group=0)  # fmt: skip
        spec.modelname = _model_name(self.object)
        spec.assets = assets
        try:
            return spec.compile()
        except ValueError as exc:  # mujoco compile errors
            raise SceneError(f"scene {spec.modelname!r} does not compile: {exc}") from exc


def scene_object_from_parts(name: str, parts: Sequence[np.ndarray]) -> SceneObject:
    """A :class:`SceneObject` from convex vertex sets [m]; each must span a volume."""
    checked = []
    for i, p in enumerate(parts):
        arr = np.asarray(p, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 3 or len(arr) < MIN_PART_POINTS or not np.all(np.isfinite(arr)):
            raise SceneError(f"object {name!r}, part {i}: expected an (n>=4, 3) finite vertex array, got {arr.shape}")
        try:
            hull = ConvexHull(arr)
        except QhullError as exc:
            raise SceneError(f"object {name!r}, part {i}: the vertices span no volume (flat or degenerate)") from exc
        if hull.volume < MIN_PART_VOLUME:
            raise SceneError(f"object {name!r}, part {i}: volume {hull.volume:.3g} m^3 is below "
                             f"{MIN_PART_VOLUME:.0e} m^3")
        checked.append(arr[hull.vertices])
    if not checked:
        raise SceneError(f"object {name!r}: no convex parts; give at least one (n>=4, 3) vertex array")
    return SceneObject(name=name, parts=tuple(checked))


_PIECES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""The convex pieces of each non-convex model decomposed in this process (a library's model is one object for every
episode of a process: it is decomposed once)."""


def scene_object_from_polyhedron(poly) -> SceneObject:
    """A :class:`SceneObject` from a ``haptic.geometry.Polyhedron`` (convex pieces for non-convex solids)."""
    if poly.is_convex:
        return scene_object_from_parts(poly.name, [np.asarray(poly.vertices, dtype=float)])
    parts = _PIECES.get(poly)
    if parts is None:
        parts = _PIECES[poly] = tuple(convex_decomposition(poly))
    return scene_object_from_parts(poly.name, parts)


def preload_scenes(models: Iterable = (), pieces: Mapping | None = None) -> None:
    """Parse the object-less scene (:func:`_robot_spec`) and split the non-convex ``models`` (library polyhedra) into
    their convex pieces now, as the process's first scene of each would: a process about to fork workers hands them
    the work done. ``pieces``: the convex pieces of some of the models already split (by model; another process's
    :func:`~haptic.geometry.convex_decomposition` of the same model, the same arrays), kept as they are."""
    _robot_spec()
    for poly, parts in (pieces or {}).items():
        if not poly.is_convex and poly not in _PIECES:
            _PIECES[poly] = tuple(parts)
    for poly in models:
        scene_object_from_polyhedron(poly)


def load_object(name: str, models_dir: str | os.PathLike | None = None, units: str | None = None) -> SceneObject:
    """The library model ``name`` (or a model file path) as a :class:`SceneObject`; ``units``: those of the
    files that declare none (:func:`~haptic.geometry.io.load_model`).

    Raises :class:`SceneError` naming the valid model names when ``name`` is unknown.
    """
    try:
        library = load_library(models_dir, units=units)
        poly = resolve_model(name, library, units=units)
    except HapticError as exc:
        raise SceneError(f"cannot load object {name!r}: {exc}") from exc
    return scene_object_from_polyhedron(poly)


def _solid_centroid(parts: Sequence[np.ndarray]) -> np.ndarray:
    vols, cents = [], []
    for p in parts:
        m = trimesh.convex.convex_hull(p)
        vols.append(m.volume)
        cents.append(m.center_mass)
    return np.average(np.asarray(cents), axis=0, weights=np.asarray(vols))


def _rotation_taking(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation (3, 3) taking unit vector a to unit vector b."""
    v = np.cross(a, b)
    c = float(np.dot(a, b))
    if c < -1 + ANTIPARALLEL:  # antiparallel: half turn about any axis perpendicular to a
        axis = np.cross(a, [1.0, 0.0, 0.0])
        if np.linalg.norm(axis) < PARALLEL:
            axis = np.cross(a, [0.0, 1.0, 0.0])
        axis /= np.linalg.norm(axis)
        return 2 * np.outer(axis, axis) - np.eye(3)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1 + c)


def stable_resting_rotations(obj: SceneObject, margin: float = STABLE_MARGIN) -> list[np.ndarray]:
    """Rotations (3, 3) ``world_from_object`` that rest the object on a hull facet, stably.

    A facet is stable when the solid's centroid projects into it at least ``margin`` [m] from its border.
    """
    points = obj.vertices
    hull = ConvexHull(points)
    centroid = _solid_centroid(obj.parts)
    planes = np.unique(np.round(hull.equations, PLANE_DECIMALS), axis=0)
    out = []
    seen: list[np.ndarray] = []
    for n_d in planes:
        n, d = n_d[:3], n_d[3]
        if any(np.dot(n, s) > 1 - PARALLEL for s in seen):
            continue
        seen.append(n)
        p = centroid - (np.dot(n, centroid) + d) * n  # projection on the facet plane
        others = planes[np.einsum("ij,j->i", planes[:, :3], n) < 1 - PARALLEL]
        if np.all(others[:, :3] @ p + others[:, 3] <= -margin):
            out.append(_rotation_taking(n, np.array([0.0, 0.0, -1.0])))
    if not out:  # no facet is stable by the margin: fall back to the largest-area support
        out.append(_rotation_taking(hull.equations[0, :3], np.array([0.0, 0.0, -1.0])))
    return out


def random_object_pose(obj: SceneObject, rng: np.random.Generator) -> np.ndarray:
    """A seeded random ``world_from_object`` (4, 4): resting stably on the table, random yaw, within reach."""
    rotations = stable_resting_rotations(obj)
    r0 = rotations[int(rng.integers(len(rotations)))]
    yaw = rng.uniform(0.0, 2 * np.pi)
    rz = np.array([[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    rot = rz @ r0
    (x0, x1), (y0, y1) = OBJECT_REGION
    xy = np.array([rng.uniform(x0, x1), rng.uniform(y0, y1)])
    v = obj.vertices @ rot.T
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    t = np.array([xy[0] - centre[0], xy[1] - centre[1], TABLE_TOP_Z - v[:, 2].min()])
    out = np.eye(4)
    out[:3, :3] = rot
    out[:3, 3] = t
    return out


def _check_pose(world_from_object: np.ndarray) -> np.ndarray:
    t = np.asarray(world_from_object, dtype=float)
    if t.shape != (4, 4) or not np.all(np.isfinite(t)):
        raise SceneError(f"world_from_object: expected a finite (4, 4) transform, got shape {t.shape}")
    r = t[:3, :3]
    if not np.allclose(r.T @ r, np.eye(3), atol=ROTATION_ATOL) or np.linalg.det(r) < 0:
        raise SceneError("world_from_object: the upper-left (3, 3) block must be a proper rotation")
    return t


def _mesh_asset(part: np.ndarray) -> mjcf.Asset:
    mesh = trimesh.convex.convex_hull(part)
    return mjcf.Asset(contents=mesh.export(file_type="stl"), extension=".stl")


def _load_xml(path: Path) -> mjcf.RootElement:
    try:
        return mjcf.from_path(str(path))
    except Exception as exc:  # dm_control raises several parser error types
        raise SceneError(f"{path}: cannot parse MJCF: {exc}") from exc


def compose_scene(
    obj: SceneObject | None = None,
    world_from_object: np.ndarray | None = None,
    *,
    seed: int = 0,
) -> ComposedScene:
    """Compose tabletop + arm + hand (+ object). Without a pose, the object gets a seeded random one.

    The composed model carries a keyframe ``home`` (``ARM_HOME`` + ``HAND_TRACE``).
    """
    pose = np.eye(4)
    if obj is not None:
        pose = (
            random_object_pose(obj, np.random.default_rng(seed))
            if world_from_object is None
            else (_check_pose(world_from_object))
        )
    return ComposedScene(object=obj, world_from_object=pose)


def _pose_quat(pose: np.ndarray) -> np.ndarray:
    """The unit quaternion (w, x, y, z) of the rotation of ``pose`` (4, 4)."""
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, pose[:3, :3].reshape(-1).copy())
    return quat


def _model_name(obj: SceneObject | None) -> str:
    return f"haptic_{obj.name}" if obj is not None else "haptic_empty"


def _compose_mjcf(obj: SceneObject | None, pose: np.ndarray) -> mjcf.RootElement:
    """The dm_control composition of tabletop + arm + hand (+ ``obj`` at ``pose``, a checked transform)."""
    scene = _load_xml(TABLETOP_XML)
    arm = _load_xml(ARM_XML)
    hand = _load_xml(HAND_XML)
    arm.model = ARM_PREFIX.rstrip("/")
    hand.model = "hand"

    flange = arm.find("site", "flange")
    mount = scene.find("site", "arm_mount")
    slot = scene.find("body", OBJECT_BODY)
    if flange is None or mount is None or slot is None:
        raise SceneError(f"{ARM_XML} / {TABLETOP_XML}: sites 'flange', 'arm_mount' and body 'object' are required")
    flange.attach(hand)
    mount.attach(arm)

    if obj is not None:
        slot.pos = pose[:3, 3]
        slot.quat = _pose_quat(pose)
        for i, part in enumerate(obj.parts):
            mesh_name = f"object_part{i}"
            scene.asset.add("mesh", name=mesh_name, file=_mesh_asset(part))
            slot.add(
                "geom",
                name=f"object_part{i}",
                type="mesh",
                mesh=mesh_name,
                dclass=OBJECT_CLASS,
                rgba=OBJECT_RGBA,
                group=0,
            )
    scene.model = _model_name(obj)

    n_arm = len(ARM_JOINTS)
    ctrl = np.zeros(n_arm + len(HAND_JOINTS))
    ctrl[n_arm:] = HAND_TRACE
    scene.keyframe.add("key", name="home", qpos=np.concatenate([ARM_HOME, HAND_TRACE]), ctrl=ctrl)
    return scene


@cache
def _robot_scene() -> ComposedScene:
    """The scene without an object, composed once per process."""
    return ComposedScene(object=None)


@cache
def _robot_spec() -> mujoco.MjSpec:
    """The scene without an object as a MuJoCo spec, parsed once per process from its composed MJCF (copy it
    before adding to it)."""
    robot = _robot_scene().mjcf_model
    try:
        spec = mujoco.MjSpec.from_string(robot.to_xml_string(), assets=robot.get_assets())
        model = spec.copy().compile()
    except ValueError as exc:  # mujoco parse and compile errors
        raise SceneError(f"scene {robot.model!r} does not compile: {exc}") from exc
    # the built-in textures (the sky's gradient, the floor's checker) as the pixels they compile to: generating
    # them is most of a compilation, and they are the same in every scene
    for i, texture in enumerate(spec.textures):
        if texture.builtin != mujoco.mjtBuiltin.mjBUILTIN_NONE:
            start = model.tex_adr[i]
            size = model.tex_width[i] * model.tex_height[i] * model.tex_nchannel[i]
            texture.builtin = mujoco.mjtBuiltin.mjBUILTIN_NONE
            texture.data = model.tex_data[start : start + size].tobytes()
    return spec


def export_scene(scene: ComposedScene, path: str | os.PathLike) -> Path:
    """Write ``scene`` as a standalone MJCF at ``path`` with its mesh files beside it; return the path.

    Files are written to a temporary directory first; the XML is renamed into place last, so a failure
    never leaves a half-written scene behind.
    """
    out = Path(path)
    if out.suffix.lower() != ".xml":
        raise SceneError(f"{out}: the export path must name an .xml file, e.g. out/scene.xml")
    out_dir = out.parent if str(out.parent) else Path(".")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SceneError(f"{out_dir}: cannot create the export directory: {exc}") from exc
    tmp = Path(tempfile.mkdtemp(prefix=".scene-", dir=out_dir))
    try:
        mjcf.export_with_assets(scene.mjcf_model, str(tmp), out_file_name=out.name)
        try:
            mujoco.MjModel.from_xml_path(str(tmp / out.name))
        except ValueError as exc:
            raise SceneError(f"{out}: the exported scene does not load in MuJoCo: {exc}") from exc
        for f in sorted(tmp.iterdir()):
            if f.name != out.name:
                os.replace(f, out_dir / f.name)
        os.replace(tmp / out.name, out)
    except OSError as exc:
        raise SceneError(f"{out}: cannot write the scene: {exc}") from exc
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return out
