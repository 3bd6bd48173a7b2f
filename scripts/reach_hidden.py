"""Whether the vertices the verification counts out of the hand's reach really are: for each episode's object at
its true resting pose, the vertices that ``--verify full`` takes as hidden (off the table, not at the end of an edge
between two faces in its reach) or cannot pin on the table, and for each of their faces out of the verification's
reach, whether any fingertip, with any wrist turn, can put its pad on that face near the vertex.

    .venv/bin/python scripts/reach_hidden.py [--objects BOX01N,BOX01P] [--seeds 1,2,3] [--models DIR]
                                             [--pairs BOX01N:1,FRAME01:3] [--json out.json] [--probe]

The verification's reach (:func:`haptic.planning.verify.reachable_features`) is the index finger's, pointing down,
on faces leaning under by at most ``PlannerConfig.max_undercut``. Here, per face at such a vertex:

- *pad positions*: points of the face within 30 mm of the vertex (a 2 mm grid) where the 12 mm pad touching it
  touches that face alone (its centre at least the pad's radius from the rest of the object) and stays 2 mm above
  the table (the executor's limit);
- *fingers*: for the nearest of those to the vertex, every finger with each of the approaches (the finger's axis
  toward the pad): straight down, along the face's inward normal, level toward the face, and down tilted 30° and
  60° toward it; the reach solver (:mod:`haptic.sim.reach`, mink) on the robot with the object at its pose (the
  truth, as a right hypothesis has it), its default clearances.

A vertex no pad position of any of its faces out of reach can touch is out of reach for a 12 mm pad whatever the
finger (a slot narrower than the pad, a face against the table); one whose pad positions no finger reaches is out
of the hand's reach; otherwise the fingers and approaches that reach are listed. For each vertex off the table, the
verification's probes at its faces' corners (:func:`corner_verdict`): whether they could place it. For every such
vertex, what the table's shadow still needs to take it on trust (:func:`shadow_verdict`): the edges and the faces'
corners at it that rise out of their shadow, and whether an edge move or a probe within the corner would measure
each. A vertex *has
enough planes in some finger's reach* when three of its faces (two besides the table's, for one on the table) are in the
verification's reach or reached here: those planes alone would place it (touching one face near it does not).
Geometry and inverse kinematics only, unless ``--probe``: then each face some finger reaches is probed on the
simulated hand by the finger :func:`haptic.executor.placement.finger_probe` picks (a level line to the nearest pad
position): measured (and how far its normal is off), or why not. Ground truth is read here (this is evaluation),
never by the executor.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter

import numpy as np

from haptic.episode.spec import EpisodeSpec, episode_pairs
from haptic.episode.worlds import build_episode
from haptic.errors import HapticError
from haptic.geometry import load_library
from haptic.geometry.distance import surface_distance
from haptic.geometry.io import atomic_write
from haptic.planning.verify import TABLE_CONTACT, out_of_reach
from haptic.sim import compose_scene
from haptic.sim.reach import FingertipTarget, ReachSolver
from haptic.sim.scene import FINGERS, PAD_RADIUS, scene_object_from_polyhedron

FIVE = "BOX01N:1,BOX01N:3,BOX01P:1,BOX01P:2,FRAME01:3"
"""The seed library's episodes whose default verification ends with vertices out of the hand's reach."""
NEAR = 0.03
"""Pad positions within this of the vertex [m] ..."""
GRID = 0.002
"""... on a grid of this spacing [m]."""
TABLE_LIMIT = 0.002
"""The pad's lowest point at least this above the table (the executor's limit) [m]."""
ON_FACE = 1e-4
"""A grid point within this of the surface is on it [m]."""
NO_PROBE = ("reflex corner", "no pad position", "no finger")
"""What :func:`shadow_verdict` says of a face corner no probe measures."""


def approaches(n: np.ndarray) -> dict[str, np.ndarray]:
    """The finger axes tried for a face of outward normal ``n`` (toward the pad, unit)."""
    down = np.array([0.0, 0.0, -1.0])
    out = {"down": down, "along -n": -n}
    level = -n.copy()
    level[2] = 0.0
    if np.linalg.norm(level) > 1e-3:
        level /= np.linalg.norm(level)
        out["level"] = level
        for deg in (30, 60):
            a = np.radians(deg)
            out[f"tilted {deg}°"] = np.cos(a) * down + np.sin(a) * level
    return out


def pad_positions(poly, pose, v: int, f: int, table_z: float) -> np.ndarray:
    """Points of face ``f`` near vertex ``v`` (world frame) where the pad touches that face alone, clear of the
    table, nearest the vertex first."""
    inv = pose.inverse()
    n = pose.rotate(poly.face_normals[f])
    vw = pose.apply(poly.vertices[v])
    a = np.cross(n, [1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.cross(n, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    g = np.arange(-NEAR, NEAR + 1e-9, GRID)
    pts = np.array([vw + x * a + y * b for x in g for y in g])
    pts = pts[np.linalg.norm(pts - vw, axis=1) <= NEAR]
    on = np.abs(surface_distance(poly, inv.apply(pts))) < ON_FACE
    centres = pts + PAD_RADIUS * n
    alone = surface_distance(poly, inv.apply(centres)) >= PAD_RADIUS - 3e-4
    clear = centres[:, 2] - PAD_RADIUS - table_z >= TABLE_LIMIT
    keep = pts[on & alone & clear]
    return keep[np.argsort(np.linalg.norm(keep - vw, axis=1))]


def probe_face(ep, f: int, pad_point: np.ndarray) -> dict:
    """A probe of face ``f`` of the episode's object by whichever finger :func:`~haptic.executor.placement.
    finger_probe` picks (the truth as the hypothesis), carried out on the hand: a line 30 mm long to the pad touching
    ``pad_point`` and 20 mm on, level toward the face (along its inward normal when it is level)."""
    from haptic.executor.placement import finger_probe
    from haptic.planning.hypothesis import Hypothesis
    from haptic.planning.moves import ProbeMove

    poly, pose = ep.true_model, ep.world_from_model
    n = pose.rotate(poly.face_normals[f])
    u = -n * np.array([1.0, 1.0, 0.0])
    u = u / np.linalg.norm(u) if np.linalg.norm(u) > 0.1 else -n
    centre = pad_point + PAD_RADIUS * n
    line = ProbeMove(centre + (PAD_RADIUS - 0.03) * u, u, 0.05)
    h = Hypothesis(model=poly.name, poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
    move = finger_probe(line, [h])
    if move is None:
        return {"status": "no finger reaches the line"}
    res = ep.executor.execute(move)
    out = {"finger": move.finger, "status": str(res.status), "reason": res.reason}
    if res.ok and res.components:
        out["error_deg"] = round(float(np.degrees(np.arccos(np.clip(res.components[0].normal @ n, -1.0, 1.0)))), 2)
    elif res.ok:
        out["status"] = "missed"
    return out


def corner_verdict(poly, pose, cfg, reach, v: int, test) -> dict:
    """What the verification's probes at the corners would do for hidden vertex ``v``
    (:class:`~haptic.planning.finger_faces.CornerProbes`, :func:`~haptic.matching.acceptance.placed_near`), with
    every vertex and edge in the pad's reach taken as measured: whether its faces span space, whether each of its
    edges or the edge's other end is in reach, and per face the lines within its corner at ``v``
    (:func:`~haptic.planning.finger_faces.corner_lines`) and the finger the reach test (``test``,
    ``PlannerConfig.finger_reach``) finds for the first it reaches: "reflex corner", "no pad position", "no finger"
    or the finger's name. Placeable when every face has a finger and the other two hold."""
    from haptic.matching.acceptance import corner_spans, corner_triangle
    from haptic.planning.finger_faces import corner_lines
    from haptic.planning.hypothesis import Hypothesis

    h = Hypothesis(model=poly.name, poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
    edges = all(int(e) in reach[1] or int(sum(poly.edges[int(e)])) - v in reach[2] for e in poly.vertex_edges[v])
    faces = {}
    for f in (int(f) for f in poly.vertex_faces[v]):
        if corner_triangle(poly, v, f) is None:
            faces[f] = "reflex corner"
            continue
        lines = corner_lines(poly, pose, v, f, cfg)
        got = next((g for g in (test(line, [h]) for line in lines) if g is not None), None)
        faces[f] = "no pad position" if not lines else "no finger" if got is None else str(got.finger)
    spans = corner_spans(poly, v)
    placeable = spans and edges and all(w not in ("reflex corner", "no pad position", "no finger")
                                        for w in faces.values())  # fmt: skip
    return {"spans": spans, "edges": edges, "faces": faces, "placeable": placeable}


def shadow_verdict(poly, pose, cfg, reach, v: int, test) -> dict:
    """What the table's shadow (:func:`~haptic.planning.verify.table_shadow`) still needs to take vertex ``v`` on
    trust, with every vertex and edge in the pad's reach taken as measured: whether ``v`` itself lies above its
    shadow (then nothing else is asked); each edge at ``v`` that rises out of its shadow, and whether it is in the
    pad's reach (an edge move measures it), only its other end is ("other end": a move of ``v`` turns the edge's
    touchable part about that end, which that end does not see), or neither; each face (off the table) whose
    corner at ``v`` rises out of its shadow, and what a probe within that corner
    (:func:`~haptic.planning.finger_faces.corner_lines`) finds: "reflex corner", "no pad position", "no finger" or
    the finger the reach test (``test``) finds for the first line it reaches. Complete when ``v`` is in its shadow,
    every such edge is in reach and every such face has a finger; ``with_other_ends`` the same with an edge's other
    end in reach counted (not sound: named for the bound)."""
    from haptic.matching.acceptance import corner_triangle
    from haptic.planning.finger_faces import corner_lines
    from haptic.planning.hypothesis import Hypothesis
    from haptic.planning.verify import cone_top, shadow_of

    h = Hypothesis(model=poly.name, poly=poly, world_from_model=pose, faces={}, edges={}, vertices={})
    z = pose.apply(poly.vertices)[:, 2] - cfg.table_z
    n = pose.rotate(poly.face_normals)
    faces = [int(f) for f in poly.vertex_faces[v]]
    above = bool(z[v] >= shadow_of(cone_top(n[faces]), cfg))
    edges, out = [], []
    for e in (int(e) for e in poly.vertex_edges[v] if not above):
        u = int(sum(poly.edges[e])) - v
        height = shadow_of(cone_top(n[[int(poly.edge_left_face[e]), int(poly.edge_right_face[e])]]), cfg)
        if max(z[v], z[u]) >= height:
            what = "in reach" if e in reach[1] else "other end" if u in reach[2] else "neither"
            edges.append({"edge": e, "to": u, "top_mm": round(float(max(z[v], z[u])) * 1000, 1),
                          "shadow_mm": round(height * 1000, 1), "what": what})
    for f in faces:
        loop = [int(u) for u in poly.faces[f]]
        if above or np.all(z[loop] <= TABLE_CONTACT):
            continue
        tri = corner_triangle(poly, v, f)
        top = float(z[loop].max()) if tri is None else float((pose.apply(tri)[:, 2] - cfg.table_z).max())
        height = shadow_of(float(n[f, 2]), cfg)
        if top < height:
            continue
        if tri is None:
            what = "reflex corner"
        else:
            lines = corner_lines(poly, pose, v, f, cfg)
            got = next((g for g in (test(line, [h]) for line in lines) if g is not None), None)
            what = "no pad position" if not lines else "no finger" if got is None else str(got.finger)
        out.append({"face": f, "top_mm": round(top * 1000, 1), "shadow_mm": round(height * 1000, 1), "what": what})
    fingers = all(x["what"] not in NO_PROBE for x in out)
    return {"above": above, "edges": edges, "faces": out,
            "complete": not above and fingers and all(x["what"] == "in reach" for x in edges),
            "with_other_ends": not above and fingers and all(x["what"] != "neither" for x in edges)}


def _shadow_kind(sh: dict) -> str:
    """A vertex's :func:`shadow_verdict` in a few words."""
    if sh["above"]:
        return "above its shadow"
    if not sh["edges"] and not sh["faces"]:
        return "in the shadow"
    if sh["complete"]:
        return "in the shadow once probed and traced"
    return "in the shadow with an edge's other end counted" if sh["with_other_ends"] else "out of the shadow"


def study(model: str, seed: int, library, probe: bool = False) -> dict:
    """The hidden and unpinnable vertices of one episode's object at its pose, and what reaches their faces (with
    ``probe``: each face some finger reaches probed on the hand, :func:`probe_face`); for each hidden vertex, what
    the probes at its faces' corners would do (:func:`corner_verdict`)."""
    from haptic.executor.placement import finger_reach

    ep = build_episode(EpisodeSpec(model=model, seed=seed, executor="physics", verify="full"), library)
    poly, pose, cfg = ep.true_model, ep.world_from_model, ep.config
    reach, hidden, unpinned = out_of_reach(poly, pose, cfg)
    z = pose.apply(poly.vertices)[:, 2] - cfg.table_z
    out = {"model": model, "seed": seed, "hidden": hidden, "unpinned": [int(v) for v in unpinned], "vertices": []}
    if not hidden and not unpinned:
        return out
    solver = ReachSolver(compose_scene(scene_object_from_polyhedron(poly), pose.as_matrix()))
    started, probed = False, set()
    test = finger_reach()
    for v in [*hidden, *unpinned]:
        faces = []
        for f in (int(f) for f in poly.vertex_faces[v]):
            if f in reach[0]:
                continue
            n = pose.rotate(poly.face_normals[f])
            lean = float(np.degrees(np.arcsin(np.clip(-n[2], -1.0, 1.0))))
            pts = pad_positions(poly, pose, v, f, cfg.table_z)
            row = {"face": f, "lean_under_deg": round(lean, 1) + 0.0, "pad_positions": len(pts), "reached": []}
            if len(pts):
                centre = pts[0] + PAD_RADIUS * n
                row["distance_mm"] = round(float(np.linalg.norm(pts[0] - pose.apply(poly.vertices[v]))) * 1000, 1)
                for finger in FINGERS:
                    for name, axis in approaches(n).items():
                        if solver.solve([FingertipTarget(finger, centre, axis)]).ok:
                            row["reached"].append(f"{finger} {name}")
                if probe and row["reached"] and f not in probed:
                    if not started:
                        started = bool(ep.executor.start().ok)
                    probed.add(f)
                    row["probe"] = probe_face(ep, f, pts[0]) if started else {"status": "the start failed"}
            faces.append(row)
        # enough planes through the vertex measurable to place it: three (two besides the table's, on the table), of
        # its faces in the verification's reach or reached here
        around = [int(f) for f in poly.vertex_faces[v]]
        on_table = [f for f in around if np.all(z[list(poly.faces[f])] <= TABLE_CONTACT)]
        measurable = [f for f in around if f in reach[0]] + [r["face"] for r in faces if r["reached"]]
        planes = len(measurable) >= min(3 - (1 if z[v] <= TABLE_CONTACT else 0), len(around) - len(on_table))
        if any(r["reached"] for r in faces):
            verdict = "reached"
        elif any(r["pad_positions"] for r in faces):
            verdict = "no finger"
        else:
            verdict = "no pad position"
        out["vertices"].append({"vertex": int(v), "height_mm": round(float(z[v]) * 1000, 1),
                                "on_table": bool(v in unpinned), "verdict": verdict, "planes": bool(planes),
                                "faces": faces,
                                "corner": corner_verdict(poly, pose, cfg, reach, v, test) if v in hidden else None,
                                "shadow": shadow_verdict(poly, pose, cfg, reach, v, test)})
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--models", default=None, metavar="DIR", help="library directory (default: the shipped one)")
    ap.add_argument("--objects", default=None, help="comma-separated model names (default: every model)")
    ap.add_argument("--seeds", default="1", help="comma-separated episode seeds")
    ap.add_argument("--pairs", default=None, help=f"OBJECT:SEED,... in place of --objects/--seeds (the seed "
                                                   f"library's five out-of-reach episodes: {FIVE})")
    ap.add_argument("--json", default=None, help="write the findings here")
    ap.add_argument("--probe", action="store_true",
                    help="probe each face some finger reaches on the hand (physics; the finger finger_probe picks)")
    args = ap.parse_args(argv)
    try:
        library = load_library(args.models) if args.models else None
        pairs = episode_pairs(args.pairs, args.objects, args.seeds, lambda: sorted(library or load_library()))
        rows, verdicts, by, fingers, probes = [], Counter(), Counter(), Counter(), Counter()
        placed = 0
        corners, shadows, shadow_parts = Counter(), Counter(), Counter()
        for model, seed in pairs:
            r = study(model, seed, library, args.probe)
            rows.append(r)
            if not r["vertices"]:
                continue
            print(f"{model} seed {seed}: hidden {r['hidden']}, unpinned on the table {r['unpinned']}", flush=True)
            for x in r["vertices"]:
                verdicts[x["verdict"]] += 1
                parts = []
                for f in x["faces"]:
                    what = ("no pad position" if not f["pad_positions"]
                            else f"{f['distance_mm']:.0f} mm from it: " + (", ".join(f["reached"]) or "no finger"))
                    if "probe" in f:
                        pr = f["probe"]
                        what += f" [probe by the {pr.get('finger', '-')}: {pr['status']}" + (
                            f", {pr['error_deg']}° off" if "error_deg" in pr else
                            f" ({pr['reason']})" if pr.get("reason") else "") + "]"
                        probes[pr["status"] if "error_deg" not in pr else "measured"] += 1
                    parts.append(f"f{f['face']} (leans under {f['lean_under_deg']:.0f}°) {what}")
                    by.update({a.split(" ", 1)[1] for a in f["reached"]})
                    fingers.update({a.split(" ", 1)[0] for a in f["reached"]})
                planes = "enough planes in some finger's reach" if x["planes"] else "too few planes"
                print(f"  v{x['vertex']} {x['height_mm']:.0f} mm up: {x['verdict']} ({planes}); " + "; ".join(parts),
                      flush=True)  # fmt: skip
                placed += x["planes"]
                if x["corner"] is not None:
                    c = x["corner"]
                    corners[c["placeable"]] += 1
                    print(f"    corners: faces {'span' if c['spans'] else 'do not span'} space, edges' other ends "
                          f"{'in reach' if c['edges'] else 'not all in reach'}; "
                          + ", ".join(f"f{f} {w}" for f, w in c["faces"].items())
                          + (" -> placeable" if c["placeable"] else " -> not placeable"), flush=True)
                sh = x["shadow"]
                shadows[_shadow_kind(sh)] += 1
                shadow_parts.update(f"edge {e['what']}" for e in sh["edges"])
                shadow_parts.update(f"face corner: {f['what'] if f['what'] in NO_PROBE else 'a finger'}"
                                    for f in sh["faces"])  # fmt: skip
                print("    table's shadow: " + ("the vertex above its shadow" if sh["above"] else "; ".join(
                    [f"e{e['edge']} to v{e['to']} rises to {e['top_mm']} mm over its {e['shadow_mm']} mm: {e['what']}"
                     for e in sh["edges"]]
                    + [f"f{f['face']}'s corner rises to {f['top_mm']} mm over its {f['shadow_mm']} mm: {f['what']}"
                       for f in sh["faces"]]) or "nothing rises out of it")
                      + f" -> {_shadow_kind(sh)}", flush=True)
        n_eps = sum(1 for r in rows if r["vertices"])
        print(f"\n{n_eps} of {len(rows)} episodes with vertices out of the verification's reach; "
              f"{sum(verdicts.values())} vertices: " + ", ".join(f"{k} {v}" for k, v in verdicts.most_common())
              + f"; {placed} with enough planes in some finger's reach to place them")
        print(f"hidden vertices the probes at their faces' corners would place: {corners[True]} of "
              f"{corners[True] + corners[False]}")
        complete = sum(1 for r in rows if r["vertices"] and all(x["planes"] for x in r["vertices"]))
        print(f"episodes whose every such vertex has enough planes in some finger's reach: {complete} of {n_eps}")
        print("the table's shadow, vertices: " + ", ".join(f"{k} {v}" for k, v in shadows.most_common()))
        print("  what rises out of it unmeasured: " + ", ".join(f"{k} {v}" for k, v in shadow_parts.most_common()))
        done = [f"{r['model']}:{r['seed']}" for r in rows
                if r["vertices"] and all(x["shadow"]["complete"] for x in r["vertices"])]  # fmt: skip
        ends = [f"{r['model']}:{r['seed']}" for r in rows
                if r["vertices"] and all(x["shadow"]["with_other_ends"] for x in r["vertices"])]  # fmt: skip
        print(f"episodes whose every such vertex the shadow would take with its corners probed and its edges traced: "
              f"{len(done)} of {n_eps} {done}; with an edge's other end counted (not sound): {len(ends)} {ends}")
        if by:
            print("approaches that reach a face out of the verification's reach (faces): "
                  + ", ".join(f"{k} {v}" for k, v in by.most_common()))
            print("fingers that reach one (faces): " + ", ".join(f"{k} {v}" for k, v in fingers.most_common()))
        if probes:
            print("probes on the hand of the faces some finger reaches: "
                  + ", ".join(f"{k} {v}" for k, v in probes.most_common()))
        if args.json:
            atomic_write(args.json, json.dumps(rows, indent=1))
        return 0
    except HapticError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
