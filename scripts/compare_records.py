"""Compare two sets of episode records (before and after a change): outcome, moves and path cost per episode.

    .venv/bin/python scripts/compare_records.py BEFORE AFTER [--fields outcome,moves,path_cost]

BEFORE and AFTER are ``haptic bench`` results (``.jsonl``, keyed by each record's ``key``, a field missing from an
older key read as the value episodes were run with then: ``haptic.bench.runner.key_id``) or a JSON list of
records (``scripts/physics_episodes.py --json``, keyed by model, seed and policy). Episodes in only one of
the files are counted apart (a sweep still running). Prints every difference and a summary line; exit 1 when an
episode in both differs.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def load(path: str) -> dict[str, dict]:
    text = Path(path).read_text()
    if path.endswith(".jsonl"):
        records = [json.loads(line) for line in text.splitlines() if line.strip()]
    else:
        records = json.loads(text)
    from haptic.bench.runner import key_id

    out = {}
    for r in records:
        if "key" in r:
            out[key_id(r["key"])] = r
        else:
            out[json.dumps({"model": r["model"], "seed": r["seed"], "policy": r.get("policy")}, sort_keys=True)] = r
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--fields", default="outcome,moves,path_cost")
    args = ap.parse_args(argv)
    fields = args.fields.split(",")
    before, after = load(args.before), load(args.after)
    both = sorted(set(before) & set(after))
    differ = 0
    for k in both:
        a, b = (tuple(before[k].get(f) for f in fields), tuple(after[k].get(f) for f in fields))
        if a != b:
            differ += 1
            print(f"differs: {k}: {dict(zip(fields, a, strict=True))} -> {dict(zip(fields, b, strict=True))}")
    print(f"{len(both) - differ} identical of {len(both)} episodes in both ({', '.join(fields)}); "
          f"{len(set(before) - set(after))} only before, {len(set(after) - set(before))} only after")  # fmt: skip
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
