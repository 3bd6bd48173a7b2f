"""Running many episodes: the plan of a sweep, local worker processes or Ray, results as they end."""

from __future__ import annotations

import json
import multiprocessing as mp
import multiprocessing.connection as mp_connection
import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Iterator, Sequence
from dataclasses import MISSING, asdict, fields, replace
from pathlib import Path

import numpy as np

from haptic.episode.spec import LEGACY_DEFAULTS, EpisodeSpec
from haptic.episode.worlds import run_episode
from haptic.errors import BenchError
from haptic.geometry.io import default_units
from haptic.options import DeferredInterrupts
from haptic.planning.registry import is_learned


def plan_sweep(
    names: Sequence[str],
    episodes: int,
    seed: int,
    policies: Sequence[str],
    noises: Sequence[float] = (1.0,),
    **common,
) -> list[EpisodeSpec]:
    """``episodes`` random (model, pose) draws, each run under every policy and noise level.

    The models are drawn uniformly from ``names`` with a generator seeded by ``seed``; each draw gets its own
    episode seed, shared across policies and noise levels so that they are compared on the same episodes.
    """
    rng = np.random.default_rng(seed)
    picks = rng.integers(len(names), size=episodes)
    seeds = rng.integers(2**31 - 1, size=episodes)
    return [
        EpisodeSpec(model=names[int(m)], seed=int(s), policy=p, noise=float(n), **common)
        for m, s in zip(picks, seeds, strict=True)
        for n in noises
        for p in policies
    ]


KEY_EXCLUDED = ("models", "record", "learn_name")
"""Fields of :class:`EpisodeSpec` that do not change an episode's result, left out of its key.

Every other field is part of the key, so a setting added to ``EpisodeSpec`` (with a default that gives the
behaviour from before it existed) joins the key with no other change; a field that does not change results
(an output path, say) belongs here. The library enters the key by its name (:func:`library_name`).
"""


def library_name(models: str | os.PathLike | None) -> str:
    """The name results give a library: its directory's name, "seed" for the shipped one."""
    return Path(models).resolve().name if models else "seed"


def episode_key(spec: EpisodeSpec) -> dict:
    """What defines an episode's result: the library's name and every field of ``spec`` not in KEY_EXCLUDED,
    with ``units`` the units the library's files that declare none are read in (``spec.units``, else the
    library's ``library.toml``, else "m"): a library read in other units is another library."""
    key: dict = {"library": library_name(spec.models)}
    key.update({f.name: getattr(spec, f.name) for f in fields(EpisodeSpec) if f.name not in KEY_EXCLUDED})
    key["units"] = default_units(spec.models, spec.units)
    return key


def key_id(key: dict) -> str:
    """The canonical text of a key (for comparing keys). A field missing from a key written before that
    field existed takes the value episodes were run with then (:data:`~haptic.episode.spec.LEGACY_DEFAULTS`,
    else :class:`EpisodeSpec`'s default)."""
    full = {f.name: f.default for f in fields(EpisodeSpec) if f.name not in KEY_EXCLUDED and f.default is not MISSING}
    full.update(LEGACY_DEFAULTS)
    full.update(key)
    return json.dumps(full, sort_keys=True, separators=(",", ":"))


def _run(spec_dict: dict) -> dict:
    """One episode's JSON record, with its library's name and its key."""
    spec = EpisodeSpec(**spec_dict)
    policy = None
    if is_learned(spec.policy):
        from haptic.env.learned import learned_policy

        policy = learned_policy(spec.policy, spec.max_moves, spec.budget)
    record = run_episode(spec, policy=policy).to_json()
    record["library"] = library_name(spec.models)
    record["key"] = episode_key(spec)
    return record


def run_sweep(
    specs: Sequence[EpisodeSpec],
    workers: int = 1,
    backend: str = "local",
) -> Iterator[dict]:
    """Run episodes and yield each record as it ends (completion order when ``workers`` > 1 or on Ray).

    Close the iterator (``contextlib.closing``) to stop early: local workers are killed, Ray tasks cancelled,
    and a Ray started here is shut down.
    """
    if backend not in ("local", "ray"):
        raise BenchError(f"unknown backend {backend!r}; valid: local, ray")
    if workers < 1:
        raise BenchError(f"--workers must be at least 1, got {workers}")
    payload = [asdict(replace(s, models=str(Path(s.models).resolve()) if s.models else None)) for s in specs]
    if backend == "ray":
        yield from _run_ray(payload, workers)
    elif workers == 1:
        for p in payload:
            yield _run(p)
    else:
        yield from _run_local(payload, workers)


WORKER_RETRIES = 2
"""Times an episode is run again when the worker running it dies (killed or out of memory)."""


QUEUED_PER_WORKER = 2
"""Episodes sent ahead to each local worker, so that it starts the next one without waiting for the main
process (slow to be scheduled on a busy machine)."""


def _run_local(payload: list[dict], workers: int) -> Iterator[dict]:
    """Worker processes of this machine; each dies with the main process (see :func:`_die_with_parent`)."""
    ctx = mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")
    todo = deque(range(len(payload)))
    attempts = [0] * len(payload)
    pool: dict = {}  # connection -> (process, the episodes sent to it in order, the first one running)
    try:
        while todo or any(jobs for _, jobs in pool.values()):
            while len(pool) < min(workers, len(todo) + len(pool)):
                here, there = ctx.Pipe()
                proc = ctx.Process(target=_worker, args=(there, os.getpid()), daemon=True)
                proc.start()
                there.close()
                pool[here] = (proc, deque())
            for conn, (_, jobs) in pool.items():
                while len(jobs) < QUEUED_PER_WORKER and todo:
                    jobs.append(todo.popleft())
                    conn.send(payload[jobs[-1]])
            for conn in mp_connection.wait(list(pool)):
                proc, jobs = pool[conn]
                try:
                    ok, value = conn.recv()
                except (EOFError, OSError):  # the worker died
                    proc.join(1.0)
                    del pool[conn]
                    conn.close()
                    if not jobs:
                        continue
                    running = jobs[0]
                    attempts[running] += 1
                    if attempts[running] > WORKER_RETRIES:
                        raise BenchError(
                            f"a worker died {attempts[running]} times running episode {payload[running]['model']} "
                            f"seed {payload[running]['seed']} (exit code {proc.exitcode}); the finished episodes "
                            "are kept"
                        ) from None
                    todo.extendleft(reversed(jobs))
                    continue
                jobs.popleft()
                if not ok:
                    raise value
                yield value
    finally:
        for conn, (proc, _) in pool.items():
            if proc.is_alive():
                proc.kill()
            conn.close()
        for proc, _ in pool.values():
            proc.join(5.0)


def _worker(conn, parent_pid: int) -> None:
    """Run the episodes sent on ``conn`` until it closes. Interrupts are the main process's to handle: a
    worker ignores SIGINT (Ctrl-C reaches the whole process group) and dies with the main process."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_parent(parent_pid)
    while True:
        try:
            payload = conn.recv()
        except (EOFError, OSError):
            return
        try:
            reply = (True, _run(payload))
        except Exception as exc:  # the main process raises it
            reply = (False, exc)
        try:
            conn.send(reply)
        except Exception as exc:  # an exception that does not pickle
            conn.send((False, BenchError(f"episode {payload['model']} seed {payload['seed']}: {exc!r}")))


def _die_with_parent(parent_pid: int) -> None:
    """End this process when ``parent_pid`` (its parent) ends, even by SIGKILL: the kernel's parent-death
    signal on Linux, and everywhere a thread that exits once the process has another parent."""
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent_pid:  # the parent died before the signal was armed
        os._exit(1)

    def watch() -> None:
        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, name="die-with-parent", daemon=True).start()


RAY_OBJECT_STORE_BYTES = 128 * 1024**2
"""Object store of a Ray started here: episodes pass only small records [bytes]."""
RAY_MEMORY_BYTES = 2 * 1024**3
"""Memory a Ray started here offers its tasks [bytes]."""
RAY_TASK_RETRIES = 3
"""Times Ray runs an episode again when the worker or node running it dies."""


def ray_available() -> bool:
    """Whether Ray can be imported (``pip install -e '.[ray]'``)."""
    try:
        import ray  # noqa: F401
    except ImportError:
        return False
    return True


def start_ray(workers: int) -> bool:
    """Join the Ray cluster named by ``RAY_ADDRESS``, else start one on this machine with ``workers`` CPUs,
    no dashboard and small memory limits (it starts in seconds). Returns False when Ray was already running
    in this process (nothing to shut down)."""
    import ray

    if ray.is_initialized():
        return False
    common = {"log_to_driver": False, "configure_logging": False}
    address = os.environ.get("RAY_ADDRESS")
    main_thread = threading.current_thread() is threading.main_thread()
    on_sigterm = signal.getsignal(signal.SIGTERM) if main_thread else None
    try:
        if address:
            ray.init(address=address, **common)
        else:
            ray.init(
                num_cpus=workers, include_dashboard=False, object_store_memory=RAY_OBJECT_STORE_BYTES,
                _memory=RAY_MEMORY_BYTES, **common,
            )
    except (ConnectionError, RuntimeError, ValueError) as exc:
        where = f"the Ray cluster at RAY_ADDRESS={address}" if address else "a Ray on this machine"
        raise BenchError(f"cannot start or join {where}: {exc}") from None
    finally:
        if on_sigterm is not None:  # ray.init takes SIGTERM over; the caller's handler stops Ray just as well
            signal.signal(signal.SIGTERM, on_sigterm)
    return True


def _run_ray(payload: list[dict], workers: int) -> Iterator[dict]:
    """Episodes as Ray tasks (see :func:`start_ray`); a Ray started here is shut down at the end. A task
    whose worker dies is retried by Ray; each record is yielded once, as its task ends."""
    if not ray_available():
        raise BenchError("--backend ray needs Ray: pip install -e '.[ray]' (or use --backend local)")
    import ray

    started = start_ray(workers)
    pending: dict = {}
    # An exception raised by a signal handler inside Ray's compiled calls turns into a SystemError there: the
    # signals are noted and raised again between calls, where the caller's handlers take them as usual.
    held = DeferredInterrupts().__enter__()
    try:
        remote = ray.remote(num_cpus=1, max_retries=RAY_TASK_RETRIES)(_run)
        window = max(8, 2 * int(ray.cluster_resources().get("CPU", workers)))
        it = iter(payload)
        while True:
            while len(pending) < window and (p := next(it, None)) is not None:
                pending[remote.remote(p)] = p
            if not pending:
                break
            done, _ = ray.wait(list(pending), num_returns=1, timeout=0.25)
            if held.noted:
                held.release()
            if done:
                del pending[done[0]]
                yield ray.get(done[0])
    finally:
        if started:
            ray.shutdown()  # its workers end with it; cancelling tasks first raced their completion inside Ray
        else:
            for ref in pending:  # a cluster's workers go on: the tasks left are cancelled
                ray.cancel(ref, force=True)
        held.release()
