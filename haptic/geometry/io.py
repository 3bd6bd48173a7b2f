"""Reading and writing models: native JSON, and OBJ / STL / PLY through trimesh.

A library is a directory; every model file in it is one model named by its file stem. Triangulated meshes
are merged into planar polygonal faces. Writes are atomic: a file is written beside its target and renamed,
so a failed export never leaves a half-written file.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from haptic.errors import ModelError
from haptic.geometry.polyhedron import LearnedBounds, Polyhedron, newell_normal, triangulate_polygon
from haptic.geometry.tolerances import FLOAT32_QUANTUM, Tolerances, decimal_quantum

NATIVE_SUFFIX = ".json"
MESH_SUFFIXES = (".obj", ".stl", ".ply")
MODEL_SUFFIXES = (NATIVE_SUFFIX, *MESH_SUFFIXES)
FORMAT_VERSION = 1

DEFAULT_LIBRARY = Path(__file__).resolve().parents[2] / "assets" / "models"


def load_model(path: str | os.PathLike, name: str | None = None, units: str | None = None) -> Polyhedron:
    """Load and validate one model file; its name is the file stem unless given.

    Lengths are read in the units the file declares (an OBJ ``# units:`` comment, a native model's ``units``),
    else in ``units`` ("mm", "cm" or "m"), else in those its folder's ``library.toml`` declares, else in metres
    (:func:`default_units`).
    """
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
    scale = UNITS[default_units(path.parent, units)]
    if suffix == NATIVE_SUFFIX:
        return _load_native(path, name, scale)
    if suffix == ".obj":
        return _load_obj(path, name, scale)
    return _load_mesh(path, name, scale)


UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
"""Length units a model file may declare, in metres."""
LIBRARY_FILE = "library.toml"
"""A library folder's declaration file: ``units = "mm"`` applies to every model file in the folder that does not
declare its own units."""


def check_units(units: str | None, option: str = "units=") -> str | None:
    """``units`` when it is None or one of :data:`UNITS`, else a :class:`ModelError` naming ``option`` (how the
    caller spells the setting: ``units=`` from Python, ``--units`` on the command line) and the valid values."""
    if units is None or units in UNITS:
        return units
    raise ModelError(f"{option}{units!r} is not a length unit; valid: {', '.join(UNITS)}")


def library_units(directory: str | os.PathLike | None) -> str | None:
    """The units a library folder's ``library.toml`` declares (None: no file, or no ``units`` in it).

    Raises :class:`ModelError` naming the file when it is not TOML or declares units other than :data:`UNITS`.
    """
    import tomllib

    path = Path(directory or DEFAULT_LIBRARY) / LIBRARY_FILE
    if not path.is_file():
        return None
    try:
        doc = tomllib.loads(path.read_text())
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ModelError(f"{path}: not valid TOML ({exc}); write for example: units = \"mm\"") from None
    units = doc.get("units")
    if units is not None and units not in UNITS:
        raise ModelError(f"{path}: units = {units!r} is not a length unit; valid: {', '.join(repr(u) for u in UNITS)}")
    return units


def default_units(directory: str | os.PathLike | None, units: str | None = None) -> str:
    """The units of the model files of ``directory`` that declare none: ``units`` when given (``--units``), else
    the folder's ``library.toml`` (:func:`library_units`), else metres."""
    return check_units(units) or library_units(directory) or "m"


SIZE_RANGE = (0.005, 1.0)
"""Sizes across [m] outside which a model more likely had its units misread than is meant at that size."""


def size_warning(model: Polyhedron, units: str | None = None) -> str | None:
    """A one-line warning when ``model`` (loaded with ``units``, see :func:`load_model`) is larger or smaller across
    than :data:`SIZE_RANGE`, naming its file and the units that would make its size plausible; None otherwise."""
    across = float(np.ptp(model.vertices, axis=0).max()) if model.n_vertices else 0.0
    lo, hi = SIZE_RANGE
    if lo <= across <= hi or not model.source:
        return None
    path = Path(model.source)
    read = file_units(path) or default_units(path.parent, units)
    raw = across / UNITS[read]  # the file's own numbers
    fits = [u for u, s in UNITS.items() if lo <= raw * s <= hi and u != read]
    what = "larger" if across > hi else "smaller"
    msg = f"{path}: {across * 1e3:.6g} mm across, {what} than a graspable object ({lo * 1e3:g} mm to {hi:g} m)"
    if not fits:
        return msg
    best = min(fits, key=lambda u: abs(np.log(raw * UNITS[u] / 0.1)))
    if file_units(path):
        return msg + f"; its file declares {read}: did it mean {best}?"
    return msg + f"; did you mean --units {best} (or units = \"{best}\" in {LIBRARY_FILE})?"


def file_units(path: Path) -> str | None:
    """The units a model file declares itself (an OBJ ``# units:`` comment, a native model's ``units``), or None."""
    suffix = path.suffix.lower()
    try:
        if suffix == NATIVE_SUFFIX:
            units = json.loads(path.read_text()).get("units")
            return units if units in UNITS else None
        if suffix == ".obj":
            for line in path.read_text().splitlines():
                if line.lstrip().startswith("#"):
                    declared = _obj_units(line.strip())
                    if declared is not None and declared > 0:
                        return next(u for u, s in UNITS.items() if s == declared)
    except (OSError, UnicodeDecodeError, ValueError, AttributeError):
        return None
    return None


def text_quantum(tokens: list[str]) -> float:
    """How far numbers written as ``tokens`` were rounded, in the file's units (0 when they look exact).

    The rounding of a file is that of its longest-written numbers: those with the most significant digits.
    Among them the coarsest last digit sets the quantum (half a unit in that place). Integers, and files whose
    numbers all have fewer than 4 significant digits (hand-written round values), count as exact.
    """
    best_sig, quantum = 0, 0.0
    for tok in tokens:
        mant, _, exp = tok.lower().partition("e")
        if "." not in mant:
            continue
        whole, _, frac = mant.lstrip("+-").partition(".")
        sig = len((whole + frac).lstrip("0"))
        try:
            decimals = len(frac) - (int(exp) if exp else 0)
        except ValueError:
            continue
        q = decimal_quantum(decimals)
        if sig > best_sig:
            best_sig, quantum = sig, q
        elif sig == best_sig:
            quantum = max(quantum, q)
    return quantum if best_sig >= 4 else 0.0


def _source_precision(quantum: float, vertices: np.ndarray) -> float:
    """A file's rounding [m], bounded by a ten-thousandth of the model's size (beyond that it is no solid)."""
    size = float(np.linalg.norm(np.ptp(vertices, axis=0))) if len(vertices) else 0.0
    return min(float(quantum), 1e-4 * size)


def _load_native(path: Path, name: str, default_scale: float = 1.0) -> Polyhedron:
    tokens: list[str] = []

    def number(tok: str) -> float:
        tokens.append(tok)
        return float(tok)

    try:
        doc = json.loads(path.read_text(), parse_float=number)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ModelError(f"{path}: not valid JSON ({exc})") from None
    if not isinstance(doc, dict) or "vertices" not in doc or "faces" not in doc:
        raise ModelError(f"{path}: a native model is a JSON object with 'vertices' and 'faces' lists")
    if not isinstance(doc["faces"], list):
        raise ModelError(f"{path}: 'faces' must be a list of vertex-index lists")
    scale = UNITS.get(doc["units"]) if "units" in doc else default_scale
    if scale is None:
        raise ModelError(f"{path}: unknown units {doc.get('units')!r}; valid: {', '.join(UNITS)}")
    try:
        vertices = np.array(doc["vertices"], dtype=float) * scale
    except (TypeError, ValueError):
        raise ModelError(f"{path}: 'vertices' must be a list of [x, y, z] numbers") from None
    shaped = vertices.ndim == 2 and vertices.shape[1:] == (3,) and len(vertices) > 0
    precision = _source_precision(text_quantum(tokens) * scale, vertices) if shaped else 0.0
    return Polyhedron.from_faces(vertices, doc["faces"], name=name, source=str(path), precision=precision,
                                 learned_bounds=_learned_bounds(path, doc))  # fmt: skip


def _learned_bounds(path: Path, doc: dict) -> LearnedBounds | None:
    """The data bounds a learned model's file declares (``provenance.bounds``: ``normal_rad``, ``position_m``,
    ``direction_rad``), or None when it declares none."""
    prov = doc.get("provenance")
    bounds = prov.get("bounds") if isinstance(prov, dict) else None
    if bounds is None:
        return None
    keys = ("normal_rad", "position_m", "direction_rad")
    try:
        values = [float(bounds[k]) for k in keys]
    except (TypeError, KeyError, ValueError):
        raise ModelError(f"{path}: provenance.bounds must hold the numbers {', '.join(keys)}") from None
    if not all(np.isfinite(x) and x >= 0 for x in values):
        raise ModelError(f"{path}: provenance.bounds must be finite numbers >= 0, got {values}")
    return LearnedBounds(*values)


def _obj_units(line: str) -> float | None:
    """The scale a ``# units: mm`` comment declares, or ``None`` when the comment declares none."""
    words = line.lstrip("#").replace(":", " ").replace("=", " ").split()
    if len(words) >= 2 and words[0].lower() == "units":
        return UNITS.get(words[1].lower(), -1.0)
    return None


def _load_obj(path: Path, name: str, default_scale: float = 1.0) -> Polyhedron:
    """Wavefront OBJ read directly, so that polygonal faces (convex or not) keep their loops.

    A comment ``# units: mm`` (or ``cm``, ``m``) declares the units; ``default_scale`` [m per file unit]
    otherwise. Vertices keep their file numbers (1-based) in messages.
    """
    vertices: list[list[float]] = []
    loops: list[list[int]] = []
    face_lines: list[int] = []
    tokens: list[str] = []
    scale = default_scale
    try:
        text = path.read_text()
    except UnicodeDecodeError:
        raise ModelError(f"{path}: not a text OBJ file") from None
    for lineno, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        if parts[0].startswith("#"):
            declared = _obj_units(line)
            if declared is not None:
                if declared < 0:
                    raise ModelError(f"{path}: line {lineno} declares unknown units; valid: {', '.join(UNITS)}")
                scale = declared
            continue
        try:
            if parts[0] == "v":
                if len(parts) < 4:
                    raise ModelError(
                        f"{path}: line {lineno}: a vertex needs x y z coordinates, got {len(parts) - 1}: "
                        f"{line.strip()!r}"
                    )
                vertices.append([float(x) for x in parts[1:4]])
                tokens.extend(parts[1:4])
            elif parts[0] == "f":
                idx = [int(tok.split("/")[0]) for tok in parts[1:]]
                if len(idx) < 3:
                    raise ModelError(
                        f"{path}: line {lineno}: a face needs at least 3 vertices, got {len(idx)}: {line.strip()!r}"
                    )
                if 0 in idx or (min(idx) < 0 and len(vertices) + min(idx) < 0):
                    raise ModelError(f"{path}: line {lineno}: face names vertex 0 or one before the first: {line!r}")
                loops.append([i - 1 if i > 0 else len(vertices) + i for i in idx])
                face_lines.append(lineno)
        except ValueError:
            raise ModelError(f"{path}: line {lineno} is not a valid OBJ '{parts[0]}' record: {line.strip()!r}") \
                from None
    if not loops:
        raise ModelError(f"{path}: the file holds no faces")
    v = np.array(vertices, dtype=float).reshape(-1, 3) * scale
    for k, loop in enumerate(loops):
        if max(loop) >= len(v):
            raise ModelError(
                f"{path}: line {face_lines[k]}: face names a vertex outside 1..{len(v)} (the file's vertices): "
                f"{[i + 1 for i in loop]}"
            )
    if not np.isfinite(v).all():
        bad = int(np.flatnonzero(~np.isfinite(v).all(axis=1))[0])
        raise ModelError(f"{path}: vertex {bad + 1} has a non-finite coordinate {v[bad].tolist()}")
    precision = _source_precision(text_quantum(tokens) * scale, v)
    t = Tolerances.for_model(float(np.linalg.norm(np.ptp(v, axis=0))), precision)
    tris: list[tuple[int, int, int]] = []
    polygon_of: list[int] = []
    plain = _plain_triangles(v, loops, t)  # triangles need no planarity test: check them all at once
    for k, loop in enumerate(loops):
        if plain[k]:
            tris.append((loop[0], loop[1], loop[2]))
            polygon_of.append(k)
            continue
        at = f"{path}: face {k + 1} (line {face_lines[k]})"
        if len(set(loop)) != len(loop):
            raise ModelError(f"{at} repeats a vertex in its loop {[i + 1 for i in loop]}")
        for a, b in zip(loop, loop[1:] + loop[:1], strict=True):
            if np.linalg.norm(v[a] - v[b]) < t.merge:
                raise ModelError(
                    f"{at} has a zero-length edge: vertices {a + 1} and {b + 1} are the same point "
                    f"(closer than {t.merge * 1e3:.3g} mm)"
                )
        nn = newell_normal(v[loop])
        if np.linalg.norm(nn) < 2 * t.area:
            raise ModelError(f"{at} has zero area (its vertices {[i + 1 for i in loop]} are on one line)")
        n = nn / np.linalg.norm(nn)
        dev = np.ptp(v[loop] @ n)
        if dev > 2 * t.planar:
            raise ModelError(
                f"{at} is not planar: its vertices spread {dev * 1e3:.4g} mm off one plane "
                f"(tolerance {2 * t.planar * 1e3:.3g} mm at this file's size and precision)"
            )
        try:
            pieces = triangulate_polygon(v, tuple(loop), nn, min_area=t.area)
        except ModelError as exc:
            raise ModelError(f"{at}: {exc}") from None
        tris.extend(pieces)
        polygon_of.extend([k] * len(pieces))
    labels = [str(i + 1) for i in range(len(v))]
    return polyhedron_from_triangles(
        v, np.array(tris, dtype=int), name=name, source=str(path), precision=precision, vertex_labels=labels,
        polygons=polygon_of,
    )  # fmt: skip


def _plain_triangles(v: np.ndarray, loops: list[list[int]], t: Tolerances) -> np.ndarray:
    """Per loop: is it a triangle of three distinct, well-separated, non-collinear points?"""
    plain = np.array([len(loop) == 3 for loop in loops])
    if not plain.any():
        return plain
    tri = np.array([loop for loop in loops if len(loop) == 3])
    p = v[tri]
    edges = np.linalg.norm(p - np.roll(p, -1, axis=1), axis=2).min(axis=1)
    area2 = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    distinct = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 2] != tri[:, 0])
    plain[np.flatnonzero(plain)] = distinct & (edges >= t.merge) & (area2 >= 2 * t.area)
    return plain


def _mesh_precision(path: Path, vertices: np.ndarray) -> float:
    """The rounding of a mesh file's coordinates [m]: float32 unless a PLY declares doubles."""
    if path.suffix.lower() == ".ply":
        with open(path, "rb") as fh:
            header = fh.read(4096).split(b"end_header")[0].decode("ascii", "replace")
        if any(line.split()[:2] == ["property", "double"] for line in header.splitlines()):
            return 0.0
    return _source_precision(FLOAT32_QUANTUM * float(np.abs(vertices).max(initial=0.0)), vertices)


def _load_mesh(path: Path, name: str, scale: float = 1.0) -> Polyhedron:
    """STL or PLY through trimesh; these formats declare no units: ``scale`` [m per file unit] applies."""
    import trimesh

    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for bad files
        raise ModelError(f"{path}: cannot read as a mesh ({type(exc).__name__}: {exc})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise ModelError(f"{path}: the file holds no triangles")
    vertices = np.asarray(mesh.vertices, dtype=float) * scale
    if not np.isfinite(vertices).all():
        bad = int(np.flatnonzero(~np.isfinite(vertices).all(axis=1))[0])
        raise ModelError(f"{path}: vertex {bad} has a non-finite coordinate {vertices[bad].tolist()}")
    if path.suffix.lower() == ".stl":  # STL numbers no vertices: name them by where they are
        labels = [f"({x * 1e3:.4g}, {y * 1e3:.4g}, {z * 1e3:.4g}) mm" for x, y, z in vertices]
    else:
        labels = [str(i) for i in range(len(vertices))]
    return polyhedron_from_triangles(
        vertices, np.asarray(mesh.faces, dtype=int), name=name, source=str(path),
        precision=_mesh_precision(path, vertices), vertex_labels=labels,
    )  # fmt: skip


def polyhedron_from_triangles(
    vertices: np.ndarray,
    triangles: np.ndarray,
    name: str = "model",
    source: str | None = None,
    precision: float = 0.0,
    vertex_labels=None,
    polygons=None,
) -> Polyhedron:
    """Merge a triangle mesh into planar polygonal faces and validate it.

    Vertices closer than the merge tolerance are welded; edge-connected triangles in one plane (as far as the
    coordinates' ``precision`` [m] can tell: each one's far corner within the planar tolerance of the other's
    plane) become one face, single triangles stay faces of their own; vertices that end up in only two faces
    (points on a straight edge) are dropped. ``vertex_labels`` name the input vertices in messages;
    ``polygons`` (one id per triangle), when given, says which triangles come from one written polygon.
    """
    where = source or name
    vertices = np.asarray(vertices, dtype=float)
    triangles = np.asarray(triangles, dtype=int)
    t = Tolerances.for_model(float(np.linalg.norm(np.ptp(vertices, axis=0))), precision)
    keep_ids, tris = _weld(vertices, triangles, t.merge)
    v = vertices[keep_ids]
    labels = [str(vertex_labels[i]) if vertex_labels is not None else str(i) for i in keep_ids]
    # degenerate triangles
    cr = np.cross(v[tris[:, 1]] - v[tris[:, 0]], v[tris[:, 2]] - v[tris[:, 0]])
    area2 = np.linalg.norm(cr, axis=1)
    bad = np.flatnonzero(area2 < 2 * t.area)
    if len(bad):
        corners = [labels[i] for i in tris[bad[0]]]
        same = len(set(tris[bad[0]].tolist())) < 3
        why = "two of its corners are the same point (a zero-length edge)" if same else "its corners are on a line"
        raise ModelError(f"{where}: triangle {int(bad[0])} (vertices {corners}) has zero area: {why}")
    normals = cr / area2[:, None]
    offsets = np.einsum("ij,ij->i", normals, v[tris[:, 0]])

    # undirected edge -> triangles
    edge_tris: dict[tuple[int, int], list[int]] = {}
    for k, (a, b, c) in enumerate(tris):
        for x, y in ((a, b), (b, c), (c, a)):
            edge_tris.setdefault((min(x, y), max(x, y)), []).append(k)
    for (x, y), ts in edge_tris.items():
        if len(ts) > 2:
            raise ModelError(f"{where}: edge {labels[x]}-{labels[y]} is non-manifold: {len(ts)} triangles meet on it")
        if len(ts) == 1:
            raise ModelError(
                f"{where}: edge {labels[x]}-{labels[y]} has only one triangle: the mesh is open (not watertight)"
            )

    parent = list(range(len(tris)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    if polygons is not None:  # triangles of one written polygon are one face
        first_of: dict[int, int] = {}
        for k, g in enumerate(np.asarray(polygons).tolist()):
            parent[find(k)] = find(first_of.setdefault(g, k))
    for (x, y), (t0, t1) in edge_tris.items():
        if normals[t0] @ normals[t1] <= 0:
            continue
        far0 = next(i for i in tris[t0] if i != x and i != y)
        far1 = next(i for i in tris[t1] if i != x and i != y)
        off0, off1 = abs(v[far1] @ normals[t0] - offsets[t0]), abs(v[far0] @ normals[t1] - offsets[t1])
        if min(off0, off1) <= t.planar:  # one triangle's plane holds all four corners (a sliver's is ill-defined)
            parent[find(t0)] = find(t1)
    groups: dict[int, list[int]] = {}
    for k in range(len(tris)):
        groups.setdefault(find(k), []).append(k)

    faces: list[list[int]] = []
    for g, members in enumerate(groups.values()):
        half = set()
        for k in members:
            a, b, c = tris[k]
            half.update({(a, b), (b, c), (c, a)})
        boundary = [(x, y) for (x, y) in half if (y, x) not in half]
        nxt: dict[int, int] = {}
        for x, y in boundary:
            if x in nxt:
                raise ModelError(f"{where}: polygonal face {g} touches itself at vertex {labels[x]}")
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
                    raise ModelError(
                        f"{where}: polygonal face {g} has an inconsistent boundary at vertex {labels[cur]}"
                    )
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
    return Polyhedron.from_faces(
        v[used], [[remap[i] for i in f] for f in faces], name=name, source=source, precision=precision,
        vertex_labels=[labels[i] for i in used],
    )  # fmt: skip


def _weld(vertices: np.ndarray, triangles: np.ndarray, merge: float) -> tuple[np.ndarray, np.ndarray]:
    """Weld vertices closer than ``merge`` [m]: the kept input vertex of each point, and the triangles over them."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    n = len(vertices)
    pairs = cKDTree(vertices).query_pairs(merge, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n)) if len(pairs) else None
    if graph is None:
        labels = np.arange(n)
    else:
        _, labels = connected_components(graph, directed=False)
    # each welded point is represented by its first input vertex, and numbered in that order
    first = np.full(labels.max() + 1, n)
    np.minimum.at(first, labels, np.arange(n))
    order = np.argsort(first)
    new_id = np.empty_like(order)
    new_id[order] = np.arange(len(order))
    return first[order], new_id[labels][triangles]


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


def written_coordinate(poly: Polyhedron, finest: Callable[[float], str] = lambda x: f"{float(x):.9g}"
                       ) -> Callable[[float], str]:  # fmt: skip
    """How a file written of ``poly`` writes a coordinate [m]: as ``finest`` (to a nanometre), or to the decimal
    place its :attr:`~haptic.geometry.polyhedron.Polyhedron.precision` rounds to where that is coarser, so that the
    file read back has the model's precision (:func:`text_quantum`) and its tolerances. A model scaled up carries
    its source's rounding scaled with it (:func:`~haptic.geometry.perturb.scaled_to`): the 30 mm dodecahedron of
    ``assets/libraries/polyhedra``, written to 0.5 µm, scaled to 150 mm and written to the nanometre, read back as
    not planar (a face 1.6 µm off its plane, 1 µm allowed for a file that precise)."""
    if poly.precision <= 0.0 or decimal_quantum(9) >= poly.precision:
        return finest
    decimals = max(0, math.floor(-math.log10(2.0 * poly.precision)))
    return lambda x: f"{float(x):.{decimals}f}"


def to_native(poly: Polyhedron) -> str:
    """The native JSON text of a model (metres, CCW-from-outside face loops; coordinates as
    :func:`written_coordinate` writes them)."""
    fmt = written_coordinate(poly, lambda x: json.dumps(round(float(x), 9)))
    verts = ",\n    ".join("[" + ", ".join(fmt(x) for x in p) + "]" for p in poly.vertices)
    faces = ",\n    ".join(json.dumps(list(f)) for f in poly.faces)
    return (
        f'{{\n  "format": "haptic-polyhedron",\n  "version": {FORMAT_VERSION},\n  "name": {json.dumps(poly.name)},\n'
        f'  "units": "m",\n  "vertices": [\n    {verts}\n  ],\n  "faces": [\n    {faces}\n  ]\n}}\n'
    )


def to_obj(poly: Polyhedron) -> str:
    """Polygonal Wavefront OBJ text (faces kept as polygons; coordinates as :func:`written_coordinate` writes
    them)."""
    fmt = written_coordinate(poly)
    lines = [f"# {poly.name}: V={poly.n_vertices} E={poly.n_edges} F={poly.n_faces}, metres"]
    lines += [f"v {fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in poly.vertices]
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


@dataclass(frozen=True)
class LibraryScan:
    """What a library directory holds: its valid models and, for each bad file, why it is bad."""

    directory: Path
    """The library directory."""
    models: dict[str, Polyhedron]
    """Every valid model, by name (file stem)."""
    errors: dict[Path, str]
    """Every bad model file, with its one-line error message."""
    units: str = "m"
    """The units of the files that declare none (:func:`default_units`)."""

    def size_warnings(self) -> list[str]:
        """A :func:`size_warning` for every model whose size across suggests misread units."""
        return [w for m in self.models.values() if (w := size_warning(m, self.units)) is not None]


_SCANS: dict[tuple, LibraryScan] = {}


def library_stamp(directory: str | os.PathLike | None = None) -> tuple:
    """What a library's models depend on: its directory, and the name, size and modification time of each of its
    model files and of its ``library.toml`` (the models are loaded again when any of them changes)."""
    where = Path(directory or DEFAULT_LIBRARY)
    files = model_files(where)
    decl = where / LIBRARY_FILE
    extra = [decl] if decl.is_file() else []
    return (str(where.resolve()), *((f.name, st.st_mtime_ns, st.st_size) for f in files + extra for st in (f.stat(),)))


def scan_library(
    directory: str | os.PathLike | None = None, progress: bool = False, units: str | None = None
) -> LibraryScan:
    """Import every model file of a library directory (default: the shipped ``assets/models``), keeping the
    valid models and the error of each bad file. ``units``: those of the files that declare none (else the
    library's ``library.toml``, else metres; see :func:`load_model`). A bar on stderr shows the import when
    ``progress`` is set (and stderr is a terminal).

    The scan is remembered per process while no file of the directory changes (models are immutable).
    """
    where = Path(directory or DEFAULT_LIBRARY)
    files = model_files(where)
    if not files:
        raise ModelError(f"{where}: the library holds no model files ({', '.join(MODEL_SUFFIXES)})")
    read_in = default_units(where, units)
    stamp = (read_in, *library_stamp(where))
    if stamp in _SCANS:
        return _SCANS[stamp]
    models: dict[str, Polyhedron] = {}
    errors: dict[Path, str] = {}
    it = files
    if progress:
        from tqdm import tqdm

        it = tqdm(files, desc=f"importing {where.name}", unit="file", disable=None, leave=False)
    for f in it:
        if f.stem in models:
            errors[f] = f"{f}: model name {f.stem!r} is used by two files in the library"
            continue
        try:
            models[f.stem] = load_model(f, units=read_in)
        except ModelError as exc:
            errors[f] = str(exc)
    scan = LibraryScan(where, models, errors, read_in)
    _SCANS.clear()  # one library is in use at a time; keep memory flat
    _SCANS[stamp] = scan
    return scan


def load_library(
    directory: str | os.PathLike | None = None, skip_invalid: bool = False, units: str | None = None
) -> dict[str, Polyhedron]:
    """Every model of a library directory (default: the shipped ``assets/models``), by name; ``units`` as in
    :func:`scan_library`.

    A library with bad files is refused, naming every bad file and why, unless ``skip_invalid``: then the valid
    models are returned (and the caller says which files were skipped, from :func:`scan_library`).
    """
    scan = scan_library(directory, units=units)
    if scan.errors and not skip_invalid:
        n = len(scan.errors)
        raise ModelError(
            f"{scan.directory}: {n} of {n + len(scan.models)} model files are invalid "
            f"({'; '.join(scan.errors.values())}); fix or remove them, or pass --skip-invalid to use the "
            f"{len(scan.models)} valid models"
        )
    if not scan.models:
        raise ModelError(f"{scan.directory}: no valid model in the library ({len(scan.errors)} invalid files)")
    return dict(scan.models)


def resolve_model(spec: str, library: dict[str, Polyhedron] | None = None, units: str | None = None) -> Polyhedron:
    """A model by library name, or by path to a model file (which need not be in the library; read in
    ``units`` as :func:`load_model` says)."""
    if library is not None and spec in library:
        return library[spec]
    p = Path(spec)
    if p.suffix.lower() in MODEL_SUFFIXES or p.exists():
        return load_model(p, units=units)
    names = ", ".join(sorted(library)) if library else "(empty library)"
    raise ModelError(f"unknown model {spec!r}: not a file and not in the library; valid names: {names}")

