"""Fault injection: sweeps killed at random moments, then resumed; no episode lost or duplicated.

Runs one uninterrupted reference sweep, then ``--runs`` times: starts the same sweep on a fresh results file
in its own process group, sends SIGINT, SIGTERM or SIGKILL at a random moment to the main process alone or to
the whole group (the six cases in turn, in a seeded random order), waits until every process of the group
has ended, and resumes the sweep with ``--resume``. Prints one table row per run and exits 1 when any run
lost, duplicated or changed an episode, or left a process behind.

    .venv/bin/python scripts/fault_injection.py                 # 20 runs of 12 episodes, 2 workers
    .venv/bin/python scripts/fault_injection.py --runs 3 --episodes 3
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from haptic.bench.results import read_results
from haptic.bench.runner import key_id

EXPECTED_EXIT = {"SIGINT": (130, -2), "SIGTERM": (143, -15), "SIGKILL": (-9,)}
"""Exit codes of a killed sweep: 130 / 143 once the command runs (the summary written once the sweep has
begun), the signal's own (negative) while Python starts; SIGKILL is never handled."""
SITE_FAILURE = "Fatal Python error: init_import_site"
"""What the interpreter prints when a SIGINT interrupts its own start-up while it imports ``site`` (the
packages' ``.pth`` files run there, before any module of the command): it exits 1. A few tens of milliseconds
after the start on an idle machine, up to half a second on a loaded one."""
KILL_WINDOW = 0.9
"""Kills fall in [0.3 s, this x the reference run's time]: nearly every run is killed before it ends."""
CASES = [(sig, to) for sig in ("SIGINT", "SIGTERM", "SIGKILL") for to in ("process", "group")]
TIMINGS = ("wall_time_s", "decision_times_s")
"""Record fields that measure time and so differ between runs."""


def live_in_group(pgid: int) -> list[int]:
    """Processes of group ``pgid`` that are alive (zombies waiting for their reaper do not count)."""
    pids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2 :].split()
        if int(fields[2]) == pgid and fields[0] != "Z":
            pids.append(int(entry.name))
    return pids


def wait_group_gone(pgid: int, timeout: float) -> tuple[float, int]:
    """Seconds until group ``pgid`` had no live process (or ``timeout``), and how many were left then."""
    t0 = time.perf_counter()
    while (left := live_in_group(pgid)) and time.perf_counter() - t0 < timeout:
        time.sleep(0.05)
    return time.perf_counter() - t0, len(left)


def bench_command(args: argparse.Namespace, out: Path, *extra: str) -> list[str]:
    return [
        sys.executable, "-m", "haptic.cli", "bench", "--episodes", str(args.episodes), "--policy", args.policy,
        "--seed", str(args.seed), "--workers", str(args.workers), "--no-plot", "--out", str(out), *extra,
    ]  # fmt: skip


def by_key(path: Path) -> tuple[dict[str, dict], int]:
    """Records of a results file by key (timings dropped), and the number of lines."""
    records = read_results(path) if path.exists() else []
    return {key_id(r["key"]): {k: v for k, v in r.items() if k not in TIMINGS} for r in records}, len(records)


def _episodes_in(summary: Path) -> int:
    """Episodes counted by a summary table (its "episodes" column)."""
    lines = [line.split("|") for line in summary.read_text().splitlines() if line.startswith("|")]
    if not lines:
        return 0
    column = [c.strip() for c in lines[0]].index("episodes")
    return sum(int(r[column]) for r in lines[2:])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--episodes", type=int, default=12)
    ap.add_argument("--policy", default="planner")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=3, help="seed of the sweep and of the kill moments")
    ap.add_argument("--dir", default=None, help="where results go (default: a temporary directory)")
    args = ap.parse_args(argv)
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "disable")}
    work = Path(args.dir or tempfile.mkdtemp(prefix="haptic-faults-"))
    work.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)

    ref = work / "reference.jsonl"
    ref.unlink(missing_ok=True)
    t0 = time.perf_counter()
    subprocess.run(bench_command(args, ref), env=env, check=True, capture_output=True)
    ref_wall = time.perf_counter() - t0
    reference, _ = by_key(ref)
    print(f"reference: {len(reference)} episodes in {ref_wall:.1f} s (start-up included); "
          f"kills at a random moment in [0.3, {KILL_WINDOW * ref_wall:.1f}] s")
    print()
    print("| run | signal | to | at [s] | exit | lines kept | summary | left over | group gone [s] | resumed ran | "
          "lost | duplicated | differ |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    cases = [CASES[i] for i in rng.permutation(len(CASES))]
    bad = killed = 0
    totals = {"lost": 0, "duplicated": 0, "differ": 0, "left": 0}
    for run in range(args.runs):
        sig_name, to = cases[run % len(cases)]
        sig = getattr(signal, sig_name)
        out = work / f"run{run:02d}.jsonl"
        for stale in (out, out.with_suffix(".md")):
            stale.unlink(missing_ok=True)
        at = float(rng.uniform(0.3, KILL_WINDOW * ref_wall))
        err_path = out.with_suffix(".stderr")
        with err_path.open("wb") as err:
            proc = subprocess.Popen(bench_command(args, out), env=env, start_new_session=True,
                                    stdout=subprocess.DEVNULL, stderr=err)  # fmt: skip
            try:
                proc.wait(timeout=at)
                at = float("nan")  # it ended before the kill
            except subprocess.TimeoutExpired:
                (os.killpg if to == "group" else os.kill)(proc.pid, sig)
                killed += 1
            code = proc.wait(timeout=120)
        in_startup = code == 1 and sig_name == "SIGINT" and SITE_FAILURE in err_path.read_text(errors="replace")
        gone_s, left = wait_group_gone(proc.pid, timeout=15.0)
        for pid in live_in_group(proc.pid):  # leave nothing behind, whatever the result
            os.kill(pid, signal.SIGKILL)
        _, kept = by_key(out)
        summary = out.with_suffix(".md")
        summed = summary.exists()
        summary_ok = code not in (130, 143) or kept == (_episodes_in(summary) if summed else 0)
        # an early end is checked by the resume alone; so is a sweep that had finished its work when the signal
        # came (every episode kept, the summary written: it exits 0, as the signal found nothing to interrupt)
        finished = code == 0 and summed and kept == len(reference)
        exit_ok = code in EXPECTED_EXIT[sig_name] or at != at or finished or in_startup
        resumed = subprocess.Popen(bench_command(args, out, "--resume"), env=env, start_new_session=True,
                                   stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)  # fmt: skip
        stdout, _ = resumed.communicate(timeout=600)
        ran = next((line.split("running ")[-1] for line in stdout.splitlines() if "running " in line), "?")
        _, left2 = wait_group_gone(resumed.pid, timeout=15.0)
        records, lines = by_key(out)
        lost = len(set(reference) - set(records))
        duplicated = lines - len(records)
        differ = sum(records[k] != reference[k] for k in set(records) & set(reference))
        left += left2
        totals["lost"] += lost
        totals["duplicated"] += duplicated
        totals["differ"] += differ
        totals["left"] += left
        bad += bool(lost or duplicated or differ or left or resumed.returncode != 0 or not exit_ok or not summary_ok)
        shown = f"{code} (in start-up)" if in_startup else str(code)
        print(f"| {run + 1} | {sig_name} | {to} | {at:.2f} | {shown} | {kept} | {'yes' if summed else '-'} | {left} | "
              f"{gone_s:.2f} | {ran} | {lost} | {duplicated} | {differ} |")
    print()
    print(f"{args.runs} runs of {len(reference)} episodes ({killed} killed, the others ended first): "
          f"{totals['lost']} lost, {totals['duplicated']} duplicated, {totals['differ']} differing from the "
          f"uninterrupted run, {totals['left']} processes left over; {bad} bad runs")
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
