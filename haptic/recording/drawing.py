"""What the recorder draws: rerun archetypes of models, data components, moves and the robot."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
import rerun as rr

from haptic.geometry import SE3, Polyhedron
from haptic.geometry.se3 import plane_basis
from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex
from haptic.recording.style import MAX_TABLE_ROWS, NO_COUNT, PATCH_RADIUS

if TYPE_CHECKING:
    from haptic.planning.moves import Move, MoveResult
    from haptic.planning.policies import Decision


def transform(t: SE3) -> rr.Transform3D:
    return rr.Transform3D(translation=np.asarray(t.translation, dtype=float), mat3x3=np.asarray(t.rotation))


def mesh(model: Polyhedron, color: tuple[int, ...]) -> rr.Mesh3D:
    """Flat-shaded mesh in the model frame (vertices repeated per triangle so each face keeps its normal)."""
    tris = np.asarray(model.triangles)
    pos = np.asarray(model.vertices, dtype=float)[tris].reshape(-1, 3)
    nrm = np.repeat(np.asarray(model.face_normals, dtype=float)[np.asarray(model.triangle_faces)], 3, axis=0)
    return rr.Mesh3D(
        vertex_positions=pos, triangle_indices=np.arange(len(pos)).reshape(-1, 3), vertex_normals=nrm,
        albedo_factor=color,
    )  # fmt: skip


def wireframe(model: Polyhedron, color: tuple[int, ...], radius: float) -> rr.LineStrips3D:
    v = np.asarray(model.vertices, dtype=float)
    return rr.LineStrips3D([v[list(e)] for e in np.asarray(model.edges)], colors=[color], radii=radius)


def patch(face: DataFace) -> tuple[np.ndarray, np.ndarray]:
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


def waypoints(prev: np.ndarray | None, result: MoveResult, new: np.ndarray | None) -> np.ndarray:
    """The sensed points of a move in the order they were met, from the previous sensor position to the new
    one: the geometric executor's path (it has no fingertip trajectory)."""
    pts: list[np.ndarray] = [prev] if prev is not None else []
    move = result.move
    if getattr(move, "kind", None) == "placement":  # to the first finger's line, and along it to its contact
        first = move.fingers[0]
        start = np.asarray(first.start, dtype=float)
        if result.components:
            return np.array([*pts, start, np.atleast_2d(result.components[0].points)[0]])
        return np.array([*pts, start, first.end, *pts])
    if getattr(move, "kind", None) == "probe":  # through free space to the line, along it, back after a miss
        start = np.asarray(move.start, dtype=float)
        if result.components:
            return np.array([*pts, start, *(p for c in result.components for p in np.atleast_2d(c.points))])
        return np.array([*pts, start, move.end, *pts])
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


def contacts(components: tuple[DataComponent, ...]) -> tuple[np.ndarray, np.ndarray]:
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


def subsample(a: np.ndarray, k: int) -> np.ndarray:
    """At most ``k`` rows of ``a``, evenly spaced, first and last kept."""
    if len(a) <= k:
        return a
    return a[np.unique(np.linspace(0, len(a) - 1, k).round().astype(int))]


def trace_of(result: MoveResult) -> Any:
    """The move's contact trace (``result.trace``) when it looks like one, else None."""
    tr = getattr(result, "trace", None)
    needed = ("time", "tip_in_world", "point_in_world", "normal_in_world", "force")
    if tr is None or not all(hasattr(tr, a) for a in needed):
        return None
    return tr


def score_color(r: float) -> tuple[int, int, int]:
    """Dark blue (worst) to yellow (best)."""
    r = float(min(max(r, 0.0), 1.0))
    lo, hi = np.array([40, 30, 120]), np.array([250, 230, 40])
    return tuple(int(x) for x in lo + r * (hi - lo))


def chain_index(names: list[str], chains: Any) -> list[np.ndarray]:
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


def log_count(n: float) -> float:
    """What the log10 plots show for ``n`` interpretations or pose classes (:data:`NO_COUNT` for none)."""
    return math.log10(n) if n >= 1 else NO_COUNT


def entity_name(name: Any) -> str:
    """A link name as one entity-path part (slashes and spaces replaced)."""
    return str(name).replace("/", "_").replace(" ", "_") or "_"


def _quat_xyzw(wxyz: np.ndarray) -> np.ndarray:
    return np.asarray(wxyz, dtype=float)[..., [1, 2, 3, 0]]


def _rotate(wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``v`` (3,) rotated by the unit quaternion (w, x, y, z)."""
    w, q = float(wxyz[0]), np.asarray(wxyz[1:], dtype=float)
    return v + 2.0 * np.cross(q, np.cross(q, v) + w * v)


def geom_archetypes(kind: str, geoms: list[Any], alpha: float = 1.0) -> list[tuple[str, Any]]:
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


UNSCORED = ("a random admissible move, none scored: fewer than two pose hypotheses were left to tell apart (or "
            "the verification had no move for what it lacks), or the policy is random")
"""What a decision without scored candidates was, in words."""


def decision_summary(i: int, decision: Decision, name: str) -> str:
    """One line for a decision: the move chosen (named ``name``) and among how many scored candidates, or
    :data:`UNSCORED`."""
    n = len(decision.candidates)
    return f"move {i}: chose {name} " + (f"among {n} scored candidates" if n else f"({UNSCORED})")


def decision_table(i: int, decision: Decision) -> str:
    """Markdown: the decision's candidate moves, best first, with a bar of their score against the best."""
    cands = sorted(decision.candidates, key=lambda c: -c.score if math.isfinite(c.score) else math.inf)
    head = f"**move {i}**: chose **{move_name(decision.move)}**"
    if not cands:
        return head + f" ({UNSCORED})"
    best = max((float(c.score) for c in cands if math.isfinite(c.score)), default=0.0)
    rows = [head + f" among {len(cands)} candidates", "",
            "| move | score | | exp. cost | exp. eliminated |", "|---|---|---|--:|--:|"]  # fmt: skip
    shown = cands[:MAX_TABLE_ROWS]
    for c in shown:
        name = f"**{move_name(c.move)}** (chosen)" if c.move == decision.move else move_name(c.move)
        r = float(c.score) / best if best > 0 and math.isfinite(c.score) else 0.0
        rows.append(f"| {name} | {_bar(r)} | {c.score:.3g} | {c.expected_cost:.2f} | "
                    f"{c.expected_eliminated:.2f} |")  # fmt: skip
    if len(cands) > len(shown):
        rows.append(f"| ... {len(cands) - len(shown)} more | | | | |")
    return "\n".join(rows)


def placement_table(i: int, decision: Decision) -> str:
    """Markdown: the decision's candidate placements, best first, each finger's closing direction and line."""
    cands = [c for c in decision.candidates if getattr(c.move, "kind", None) == "placement"]
    cands.sort(key=lambda c: -c.score if math.isfinite(c.score) else math.inf)
    if not cands:
        return f"**move {i}**: no placement among the candidates"
    rows = [f"**move {i}**: {len(cands)} candidate placements", "",
            "| placement | score | exp. cost | exp. eliminated | fingers: closing direction, line |",
            "|---|--:|--:|--:|---|"]  # fmt: skip
    for c in cands[:MAX_TABLE_ROWS]:
        name = f"**{move_name(c.move)}** (chosen)" if c.move == decision.move else move_name(c.move)
        fingers = "; ".join(
            f"{f.finger} ({f.direction[0]:+.2f}, {f.direction[1]:+.2f}, {f.direction[2]:+.2f}) "
            f"{100 * float(f.length):.0f} cm"
            for f in c.move.fingers
        )
        rows.append(f"| {name} | {c.score:.3g} | {c.expected_cost:.2f} | {c.expected_eliminated:.2f} | {fingers} |")
    if len(cands) > MAX_TABLE_ROWS:
        rows.append(f"| ... {len(cands) - MAX_TABLE_ROWS} more | | | | |")
    return "\n".join(rows)


def move_name(move: Move) -> str:
    """The move's kind and direction: ``face (+0.92, +0.33, -0.22)`` (a world direction; ``... across f3`` when it
    traces the other face of the edge the sensor is on), ``edge +``, ``vertex across f2``, ``probe (+0.00, -0.71,
    -0.71) 12 cm`` (the approach direction and the line's length)."""
    kind = getattr(move, "kind", "?")
    if kind == "face":
        d = np.asarray(move.direction, dtype=float)
        face = getattr(move, "face", None)
        return f"face ({d[0]:+.2f}, {d[1]:+.2f}, {d[2]:+.2f})" + (f" across f{face}" if face is not None else "")
    if kind == "edge":
        return f"edge {'+' if move.sense > 0 else '-'}"
    if kind == "vertex":
        return f"vertex across f{move.across_face}"
    if kind == "probe":
        d = np.asarray(move.direction, dtype=float)
        return f"probe ({d[0]:+.2f}, {d[1]:+.2f}, {d[2]:+.2f}) {100 * float(move.length):.0f} cm"
    if kind == "placement":
        return f"placement of {len(move.fingers)} ({', '.join(f.finger for f in move.fingers)})"
    return str(move)
