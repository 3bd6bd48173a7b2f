"""Reading and writing models: native JSON, and OBJ / STL / PLY through trimesh.

A library is a directory; every model file in it is one model named by its file stem. Triangulated meshes
are merged into planar polygonal faces. Writes are atomic: a file is written beside its target and renamed,
so a failed export never leaves a half-written file.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import numpy as np

from haptic.errors import ModelError
from haptic.geometry.polyhedron import Polyhedron, newell_normal, triangulate_polygon
from haptic.geometry.tolerances import tol

NATIVE_SUFFIX = ".json"
MESH_SUFFIXES = (".obj", ".stl", ".ply")
MODEL_SUFFIXES = (NATIVE_SUFFIX, *MESH_SUFFIXES)
FORMAT_VERSION = 1

DEFAULT_LIBRARY = Path(__file__).resolve().parents[2] / "assets" / "models"


def load_model(path: str | os.PathLike, name: str | None = None) -> Polyhedron:
    """Load and validate one model file; its name is the file stem unless given."""
    path = Path(path)
    name = name or path.stem
    if not path.exists():
        raise ModelError(f"{path}: no such file")
    if path.is_dir():
        raise ModelError(f"{path}: is a directory, not a model file (use --models DIR for a library)")
    suffix = path.suffix.lower()
    if suffix not in MODEL_SUFFIXES:
        raise ModelError(f"{path}: unknown model file extension {path.suffix!r}; valid: {', '.join(MODEL_SUFFIXES)}")
    if path.stat().st_size == 0:
        raise ModelError(f"{path}: the file is empty")
    if suffix == NATIVE_SUFFIX:
        return _load_native(path, name)
    if suffix == ".obj":
        return _load_obj(path, name)
    return _load_mesh(path, name)


def _load_native(path: Path, name: str) -> Polyhedron:
    try:
        doc = json.loads(path.read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ModelError(f"{path}: not valid JSON ({exc})") from None
    if not isinstance(doc, dict) or "vertices" not in doc or "faces" not in doc:
        raise ModelError(f"{path}: a native model is a JSON object with 'vertices' and 'faces' lists")
    if not isinstance(doc["faces"], list):
        raise ModelError(f"{path}: 'faces' must be a list of vertex-index lists")
    scale = {"m": 1.0, "mm": 1e-3, "cm": 1e-2}.get(doc.get("units", "m"))
    if scale is None:
        raise ModelError(f"{path}: unknown units {doc.get('units')!r}; valid: m, cm, mm")
    try:
        vertices = np.array(doc["vertices"], dtype=float) * scale
    except (TypeError, ValueError):
        raise ModelError(f"{path}: 'vertices' must be a list of [x, y, z] numbers") from None
    return Polyhedron.from_faces(vertices, doc["faces"], name=name, source=str(path))


def _load_obj(path: Path, name: str) -> Polyhedron:
    """Wavefront OBJ read directly, so that polygonal faces (convex or not) keep their loops."""
    vertices: list[list[float]] = []
    loops: list[list[int]] = []
    try:
        text = path.read_text()
    except UnicodeDecodeError:
        raise ModelError(f"{path}: not a text OBJ file") from None
    for lineno, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        try:
            if parts[0] == "v":
                vertices.append([float(x) for x in parts[1:4]])
            elif parts[0] == "f":
                idx = [int(tok.split("/")[0]) for tok in parts[1:]]
                loops.append([i - 1 if i > 0 else len(vertices) + i for i in idx])
        except ValueError:
            raise ModelError(f"{path}: line {lineno} is not a valid OBJ '{parts[0]}' record: {line.strip()!r}") \
                from None
    if not loops:
        raise ModelError(f"{path}: the file holds no faces")
    v = np.array(vertices, dtype=float).reshape(-1, 3)
    if not np.isfinite(v).all():
        bad = int(np.flatnonzero(~np.isfinite(v).all(axis=1))[0])
        raise ModelError(f"{path}: vertex {bad} has a non-finite coordinate {v[bad].tolist()}")
    for k, loop in enumerate(loops):
        if len(loop) < 3 or min(loop) < 0 or max(loop) >= len(v):
            raise ModelError(f"{path}: face {k} names a vertex outside 1..{len(v)} or has fewer than 3")
    tris = []
    for k, loop in enumerate(loops):
        nn = newell_normal(v[loop])
        if np.linalg.norm(nn) < 2 * tol.area:
            raise ModelError(f"{path}: face {k} has zero area")
        n = nn / np.linalg.norm(nn)
        dev = np.ptp(v[loop] @ n)
        if dev > 2 * tol.planar:
            raise ModelError(
                f"{path}: face {k} is not planar: its vertices spread {dev * 1e3:.4g} mm off one plane "
                f"(tolerance {tol.planar * 1e3:g} mm)"
            )
        try:
            tris.extend(triangulate_polygon(v, tuple(loop), nn))
        except ModelError as exc:
            raise ModelError(f"{path}: {exc}") from None
    return polyhedron_from_triangles(v, np.array(tris, dtype=int), name=name, source=str(path))


def _load_mesh(path: Path, name: str) -> Polyhedron:
    import trimesh

    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for bad files
        raise ModelError(f"{path}: cannot read as a mesh ({type(exc).__name__}: {exc})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise ModelError(f"{path}: the file holds no triangles")
    vertices = np.asarray(mesh.vertices, dtype=float)
    if not np.isfinite(vertices).all():
        bad = int(np.flatnonzero(~np.isfinite(vertices).all(axis=1))[0])
        raise ModelError(f"{path}: vertex {bad} has a non-finite coordinate {vertices[bad].tolist()}")
    return polyhedron_from_triangles(vertices, np.asarray(mesh.faces, dtype=int), name=name, source=str(path))


def polyhedron_from_triangles(
    vertices: np.ndarray, triangles: np.ndarray, name: str = "model", source: str | None = None
) -> Polyhedron:
    """Merge a triangle mesh into planar polygonal faces and validate it.

    Coincident vertices are welded; edge-connected triangles in one plane become one face (single triangles
    stay faces of their own); vertices that end up in only two faces (collinear points on an edge) are dropped.
    """
    where = source or name
    v, tris = _weld(vertices, triangles)
    # degenerate triangles
    cr = np.cross(v[tris[:, 1]] - v[tris[:, 0]], v[tris[:, 2]] - v[tris[:, 0]])
    area2 = np.linalg.norm(cr, axis=1)
    bad = np.flatnonzero(area2 < 2 * tol.area)
    if len(bad):
        raise ModelError(f"{where}: triangle {int(bad[0])} has zero area (a zero-length edge or collinear corners)")
    normals = cr / area2[:, None]
    offsets = np.einsum("ij,ij->i", normals, v[tris[:, 0]])

    # undirected edge -> triangles
    edge_tris: dict[tuple[int, int], list[int]] = {}
    for t, (a, b, c) in enumerate(tris):
        for x, y in ((a, b), (b, c), (c, a)):
            edge_tris.setdefault((min(x, y), max(x, y)), []).append(t)
    for (x, y), ts in edge_tris.items():
        if len(ts) > 2:
            raise ModelError(f"{where}: edge {x}-{y} is non-manifold: {len(ts)} triangles meet on it")
        if len(ts) == 1:
            raise ModelError(f"{where}: edge {x}-{y} has only one triangle: the mesh is open (not watertight)")

    parent = list(range(len(tris)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    cos_tol = np.cos(max(tol.angle, 1e-4))
    for (_x, _y), (t0, t1) in edge_tris.items():
        if normals[t0] @ normals[t1] > cos_tol and abs(offsets[t0] - offsets[t1]) < max(tol.planar, 1e-6):
            parent[find(t0)] = find(t1)
    groups: dict[int, list[int]] = {}
    for t in range(len(tris)):
        groups.setdefault(find(t), []).append(t)

    faces: list[list[int]] = []
    for g, members in enumerate(groups.values()):
        half = set()
        for t in members:
            a, b, c = tris[t]
            half.update({(a, b), (b, c), (c, a)})
        boundary = [(x, y) for (x, y) in half if (y, x) not in half]
        nxt: dict[int, int] = {}
        for x, y in boundary:
            if x in nxt:
                raise ModelError(f"{where}: polygonal face {g} touches itself at vertex {x}")
            nxt[x] = y
        loops = []
        todo = set(nxt)
        while todo:
            start = min(todo)
            loop = [start]
            todo.discard(start)
            cur = nxt[start]
            while cur != start:
                if cur not in todo:
                    raise ModelError(f"{where}: polygonal face {g} has an inconsistent boundary at vertex {cur}")
                loop.append(cur)
                todo.discard(cur)
                cur = nxt[cur]
            loops.append(loop)
        if len(loops) != 1:
            raise ModelError(
                f"{where}: planar face {g} has {len(loops) - 1} hole(s); faces with holes are not representable — "
                "split the face into simple polygons or change the design"
            )
        faces.append(loops[0])

    # drop vertices shared by only two faces (points on a straight edge), then unused vertices
    count = np.zeros(len(v), dtype=int)
    for f in faces:
        count[f] += 1
    faces = [[i for i in f if count[i] > 2] for f in faces]
    used = sorted({i for f in faces for i in f})
    remap = {old: new for new, old in enumerate(used)}
    return Polyhedron.from_faces(v[used], [[remap[i] for i in f] for f in faces], name=name, source=source)


def _weld(vertices: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices closer than the merge tolerance."""
    key = np.round(vertices / tol.merge).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return vertices[first], inverse.reshape(-1)[triangles]


# ----------------------------------------------------------------------------------------------- writing


def atomic_write(path: str | os.PathLike, data: bytes | str) -> None:
    """Write a file so that readers see either the old content or the whole new content, never a part."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    mode = "wb" if isinstance(data, bytes) else "w"
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)  # mkstemp makes the file owner-only; give it the usual mode
        with os.fdopen(fd, mode) as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def to_native(poly: Polyhedron) -> str:
    """The native JSON text of a model (metres, CCW-from-outside face loops)."""
    verts = ",\n    ".join(json.dumps([round(float(x), 9) for x in p]) for p in poly.vertices)
    faces = ",\n    ".join(json.dumps(list(f)) for f in poly.faces)
    return (
        f'{{\n  "format": "haptic-polyhedron",\n  "version": {FORMAT_VERSION},\n  "name": {json.dumps(poly.name)},\n'
        f'  "units": "m",\n  "vertices": [\n    {verts}\n  ],\n  "faces": [\n    {faces}\n  ]\n}}\n'
    )


def to_obj(poly: Polyhedron) -> str:
    """Polygonal Wavefront OBJ text (faces kept as polygons)."""
    lines = [f"# {poly.name}: V={poly.n_vertices} E={poly.n_edges} F={poly.n_faces}, metres"]
    lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in poly.vertices]
    lines += ["f " + " ".join(str(i + 1) for i in f) for f in poly.faces]
    return "\n".join(lines) + "\n"


def save_model(poly: Polyhedron, path: str | os.PathLike) -> Path:
    """Write a model as native JSON, polygonal OBJ, or triangulated STL / PLY, chosen by the extension."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == NATIVE_SUFFIX:
        atomic_write(path, to_native(poly))
    elif suffix == ".obj":
        atomic_write(path, to_obj(poly))
    elif suffix in (".stl", ".ply"):
        atomic_write(path, poly.to_trimesh().export(file_type=suffix[1:]))
    else:
        raise ModelError(f"{path}: unknown model file extension {path.suffix!r}; valid: {', '.join(MODEL_SUFFIXES)}")
    return path


def export_mesh(poly: Polyhedron, path: str | os.PathLike) -> Path:
    """Write a triangulated mesh (STL or OBJ) that MuJoCo's mesh loader reads."""
    path = Path(path)
    if path.suffix.lower() not in (".stl", ".obj"):
        raise ModelError(f"{path}: MuJoCo meshes are .stl or .obj")
    mesh = poly.to_trimesh()
    atomic_write(path, mesh.export(file_type=path.suffix.lower()[1:]))
    return path


# ----------------------------------------------------------------------------------------------- libraries


def model_files(directory: str | os.PathLike) -> list[Path]:
    """The model files of a library directory, sorted by name."""
    d = Path(directory)
    if not d.exists():
        raise ModelError(f"{d}: no such model library directory")
    if not d.is_dir():
        raise ModelError(f"{d}: a model library is a directory of model files")
    return sorted(p for p in d.iterdir() if p.is_file() and p.suffix.lower() in MODEL_SUFFIXES)


def load_library(directory: str | os.PathLike | None = None) -> dict[str, Polyhedron]:
    """Every model of a library directory (default: the shipped ``assets/models``), by name."""
    files = model_files(directory or DEFAULT_LIBRARY)
    if not files:
        where = directory or DEFAULT_LIBRARY
        raise ModelError(f"{where}: the library holds no model files ({', '.join(MODEL_SUFFIXES)})")
    out: dict[str, Polyhedron] = {}
    for f in files:
        if f.stem in out:
            raise ModelError(f"{f}: model name {f.stem!r} is used by two files in the library")
        out[f.stem] = load_model(f)
    return out


def resolve_model(spec: str, library: dict[str, Polyhedron] | None = None) -> Polyhedron:
    """A model by library name, or by path to a model file (which need not be in the library)."""
    if library is not None and spec in library:
        return library[spec]
    p = Path(spec)
    if p.suffix.lower() in MODEL_SUFFIXES or p.exists():
        return load_model(p)
    names = ", ".join(sorted(library)) if library else "(empty library)"
    raise ModelError(f"unknown model {spec!r}: not a file and not in the library; valid names: {names}")

