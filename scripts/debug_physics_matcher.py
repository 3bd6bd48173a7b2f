"""Run one physics episode and replay its data components through a tree holding only the true model.

    .venv/bin/python scripts/debug_physics_matcher.py BOX01 1 [--save tests/matching/data/NAME.json]

Prints every move and component, the interpretation count after each component, the number of surviving
*true* interpretations (the pairing scored against ground truth -- the count alone hides a true leaf pruned
while symmetric twins survive), and the counts with loosened bounds. ``--save`` writes the components, the true
pose and pairing as a JSON fixture (``haptic.matching.components.to_json``).
"""

import argparse
from dataclasses import replace

import numpy as np

from haptic.episode.evaluate import score_components
from haptic.episode.loop import EpisodeObserver
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.geometry import SE3, load_library
from haptic.matching.components import to_json
from haptic.matching.tree import InterpretationTree

np.set_printoptions(precision=4, suppress=True)
ap = argparse.ArgumentParser()
ap.add_argument("model")
ap.add_argument("seed", type=int)
ap.add_argument("--save", help="write the components and the truth as a JSON fixture")
args = ap.parse_args()
lib = load_library()
comps, start = [], {}


def on_start(model, pose):
    start["T"] = pose.as_matrix()


def on_move(i, res, n, rec):
    print("move", i, res.move.kind, res.status, round(res.distance, 4), "n", n)
    for c in res.components:
        comps.append(c)
        extra = {k: getattr(c, k) for k in ("start_vertex", "end_vertex", "length") if hasattr(c, k)}
        print("   ", c.kind, c.id, c.adjacent, extra)


def on_failed(i, res):
    print("FAILED", i, res.move, res.status, res.reason)


spec = EpisodeSpec(model=args.model, seed=args.seed, executor="physics")
obs = EpisodeObserver(on_start=on_start, on_move=on_move, on_failed_move=on_failed)
r = run_episode(spec, library=lib, observer=obs)
print(r.outcome, r.interpretations, r.perception)

model = lib[args.model]
T = np.asarray(start["T"], dtype=float)
scores = {s.id: s for s in score_components(comps, model, SE3.from_matrix(T)).components}
truth = []
for i in sorted(scores):
    s = scores[i]
    row = [s.kind, -1 if s.true_id is None else int(s.true_id)]
    if s.kind == "edge" and s.true_id is not None:
        b = [c for c in comps if c.id == i][-1].direction
        row.append(int(np.sign(b @ (T[:3, :3] @ model.edge_directions[s.true_id]))))
    truth.append(row)


def true_count(tree):
    ok = np.ones(tree.count, dtype=bool)
    for d in range(tree.assignments.shape[1]):
        kind, local, *sense = truth[d]
        ok &= tree.assignments[:, d] == local
        if sense:
            ok &= (tree.senses[:, d] == 0) | (tree.senses[:, d] == sense[0])
    return int(ok.sum())


t = InterpretationTree({args.model: model})
for c in comps:
    n = t.add(c)
    print(c.kind, c.id, "->", n, "true", true_count(t))


def trial(name, f):
    tr = InterpretationTree({args.model: model})
    print(name, [tr.add(f(c)) for c in comps])


def loose(c, kinds, **scale):
    return replace(c, **{k: v * getattr(c, k) for k, v in scale.items()}) if c.kind in kinds else c


trial("loose edges x3", lambda c: loose(c, ("edge",), position_bound=3, direction_bound=3, length_bound=3))
trial("no side points", lambda c: replace(c, side_points=()) if c.kind == "edge" else c)
trial("loose vertex x3", lambda c: loose(c, ("vertex",), position_bound=3))
trial("loose faces x3", lambda c: loose(c, ("face",), normal_bound=3, position_bound=3))
for c in comps:
    if c.kind == "edge":
        print(c.id, c.point, c.direction, c.length, c.side_points, c.position_bound, c.direction_bound, c.length_bound)
    if c.kind == "face":
        print(c.id, c.normal, c.points[:2], len(c.points), c.normal_bound, c.position_bound)
    if c.kind == "vertex":
        print(c.id, c.position, c.position_bound)
if args.save:
    with open(args.save, "w") as fh:
        fh.write(to_json(comps, model=args.model, world_from_model=T.tolist(), truth=truth) + "\n")
    print("saved", args.save)
