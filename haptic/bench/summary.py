"""Summary tables (markdown) and plots (PNG) of episode records."""

from __future__ import annotations

import os
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from haptic.geometry.io import atomic_write


def _group(records: Sequence[dict], keys: Sequence[str]) -> dict[tuple, list[dict]]:
    out: dict[tuple, list[dict]] = defaultdict(list)
    for r in records:
        out[tuple(r.get(k) for k in keys)].append(r)
    return dict(sorted(out.items(), key=lambda kv: tuple(str(x) for x in kv[0])))


def outcome_class(r: dict) -> str:
    """How an episode ended, failures told apart: "correct", "wrong model" (a library model that is not the
    object, or any model for an object outside the library), "wrong pose" (the right model at a pose off by
    more than the correctness tolerance), "no-match", or the outcome itself (ambiguous, budget, failed)."""
    if r["outcome"] == "recognized":
        if r.get("correct"):
            return "correct"
        return "wrong model" if r.get("recognized") != r.get("model") else "wrong pose"
    return r["outcome"]


def summary_rows(records: Sequence[dict], keys: Sequence[str] = ("library", "policy")) -> list[dict]:
    """One row per group: episodes, outcome counts, moves and path cost (mean and median) of the recognised
    episodes, and the mean path cost spent over all episodes (an episode that ran out of budget counts with
    what it spent: a lower bound on its cost to recognition)."""
    rows = []
    for key, rs in _group(records, keys).items():
        ok = [r for r in rs if r["outcome"] == "recognized"]
        correct = sum(1 for r in rs if r.get("correct"))
        moves = np.array([r["moves"] for r in ok], dtype=float)
        cost = np.array([r["path_cost"] for r in ok], dtype=float)
        dt = np.array([t for r in rs for t in r.get("decision_times_s", [])], dtype=float)
        spent = np.array([r["path_cost"] for r in rs], dtype=float)
        row = dict(zip(keys, key, strict=True))
        row.update(
            episodes=len(rs),
            correct=correct,
            correct_pct=100.0 * correct / len(rs),
            recognized=len(ok),
            wrong_model=sum(outcome_class(r) == "wrong model" for r in rs),
            wrong_pose=sum(outcome_class(r) == "wrong pose" for r in rs),
            ambiguous=sum(r["outcome"] == "ambiguous" for r in rs),
            no_match=sum(r["outcome"] == "no-match" for r in rs),
            budget=sum(r["outcome"] == "budget" for r in rs),
            failed=sum(r["outcome"] == "failed" for r in rs),
            moves_mean=float(moves.mean()) if len(moves) else float("nan"),
            moves_median=float(np.median(moves)) if len(moves) else float("nan"),
            cost_mean=float(cost.mean()) if len(cost) else float("nan"),
            cost_median=float(np.median(cost)) if len(cost) else float("nan"),
            cost_mean_all=float(spent.mean()),
            decision_ms_median=float(np.median(dt) * 1e3) if len(dt) else float("nan"),
            pose_error_mm_median=_median([r.get("pose_error_mm") for r in ok]),
            pose_error_deg_median=_median([r.get("pose_error_deg") for r in ok]),
            placements=sum(len(r.get("placements", ())) for r in rs),
            placements_ok=sum(p["status"] == "ok" for r in rs for p in r.get("placements", ())),
            all_moves=sum(r["moves"] for r in rs),
        )
        rows.append(row)
    return rows


def _median(xs) -> float:
    v = [x for x in xs if x is not None]
    return float(np.median(v)) if v else float("nan")


def markdown_table(rows: Sequence[dict]) -> str:
    """The summary rows as a markdown table."""
    if not rows:
        return "(no episodes)\n"
    group_keys = [
        k for k in rows[0] if k in ("library", "policy", "executor", "noise", "verify", "move_set", "fingers", "model")
    ]
    placing = "fingers" in group_keys
    cols = [*group_keys, "episodes", "correct %", "wrong model", "wrong pose", "ambig.", "no-match", "budget",
            "failed", "moves mean", "moves median", "cost mean", "cost median", "cost mean (all)", "decide ms",
            "pose mm", "pose deg", *(("placements (ok)", "placement share %") if placing else ())]
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for r in rows:
        vals = [str(r[k]) for k in group_keys] + [
            str(r["episodes"]),
            f"{r['correct_pct']:.1f}",
            str(r["wrong_model"]),
            str(r["wrong_pose"]),
            str(r["ambiguous"]),
            str(r["no_match"]),
            str(r["budget"]),
            str(r["failed"]),
            f"{r['moves_mean']:.2f}",
            f"{r['moves_median']:.1f}",
            f"{r['cost_mean']:.1f}",
            f"{r['cost_median']:.1f}",
            f"{r['cost_mean_all']:.1f}",
            f"{r['decision_ms_median']:.2f}",
            f"{r['pose_error_mm_median']:.3f}",
            f"{r['pose_error_deg_median']:.3f}",
        ]
        if placing:
            share = 100.0 * r["placements"] / r["all_moves"] if r["all_moves"] else 0.0
            vals += [f"{r['placements']} ({r['placements_ok']})", f"{share:.1f}"]
        lines.append("| " + " | ".join(vals) + " |")
    return "\n".join(lines) + "\n"


def compact_table(rows: Sequence[dict]) -> str:
    """The summary rows in a few columns for a terminal: the settings that differ between rows (the policy
    always), episodes, correct, wrong (model or pose), other endings, and the mean path cost and moves of the
    recognised episodes. The markdown table (:func:`markdown_table`) has the rest."""
    if not rows:
        return "(no episodes)\n"
    keys = [k for k in rows[0] if k in ("library", "executor", "noise", "verify", "move_set", "fingers", "model")
            and len({str(r[k]) for r in rows}) > 1] + ["policy"]  # fmt: skip
    head = [*keys, "episodes", "correct", "wrong", "other", "mean cost", "mean moves"]
    body = []
    for r in rows:
        other = r["ambiguous"] + r["no_match"] + r["budget"] + r["failed"]
        body.append([*(str(r[k]) for k in keys), str(r["episodes"]), f"{r['correct']} ({r['correct_pct']:.0f}%)",
                     str(r["wrong_model"] + r["wrong_pose"]), str(other), f"{r['cost_mean']:.1f}",
                     f"{r['moves_mean']:.1f}"])  # fmt: skip
    widths = [max(len(x) for x in col) for col in zip(head, *body, strict=True)]
    n_keys = len(keys)

    def line(cells: Sequence[str]) -> str:
        return "  ".join(c.ljust(w) if i < n_keys else c.rjust(w)
                         for i, (c, w) in enumerate(zip(cells, widths, strict=True))).rstrip()  # fmt: skip

    return "\n".join([line(head), *(line(b) for b in body)]) + "\n"


def plot_interpretations_vs_cost(records: Sequence[dict], path: str | os.PathLike, title: str = "") -> Path:
    """Median pose classes remaining against cumulative path cost, one curve per policy (and library).

    Each episode is a step function (count after each move at the cost spent so far); curves are medians over
    episodes on a common cost grid, with the inter-quartile band shaded.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    groups = _group(records, ("library", "policy"))
    fig, ax = plt.subplots(figsize=(7.5, 4.5), dpi=120)
    finals = [r["cum_cost"][-1] for r in records if r.get("cum_cost")]
    max_cost = float(np.percentile(finals, 95)) if finals else 1.0  # the long tail would squash the rest
    grid = np.linspace(0, max_cost, 200)
    for (library, policy), rs in groups.items():
        curves = []
        for r in rs:
            costs = np.asarray(r.get("cum_cost", []), dtype=float)
            counts = np.asarray(r.get("classes", r.get("interpretations", [])), dtype=float)
            if len(costs) == 0 or len(counts) != len(costs):
                continue
            idx = np.searchsorted(costs, grid, side="right") - 1
            curves.append(np.where(idx >= 0, counts[np.clip(idx, 0, None)], np.nan))
        if not curves:
            continue
        c = np.array(curves)
        med = np.nanmedian(c, axis=0)
        lo, hi = np.nanpercentile(c, 25, axis=0), np.nanpercentile(c, 75, axis=0)
        label = f"{policy}" if len(groups) <= 5 else f"{library}/{policy}"
        if len({k[0] for k in groups}) > 1:
            label = f"{library}/{policy}"
        (line,) = ax.step(grid, med, where="post", label=label)
        ax.fill_between(grid, lo, hi, step="post", alpha=0.15, color=line.get_color())
    ax.set_yscale("log")
    ax.set_xlabel("cumulative path cost [units]")
    ax.set_ylabel("pose classes left (interpretations\nuntil poses are known); median, IQR")
    ax.set_title(title or "Interpretations remaining vs path cost")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    atomic_write(path, buf.getvalue())
    return Path(path)
