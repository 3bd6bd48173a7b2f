"""Running many episodes: the plan of a sweep, local worker processes or Ray, results as they end."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import asdict, dataclass, replace

import numpy as np

from haptic.errors import BenchError


@dataclass(frozen=True)
class EpisodeSpec:
    """Everything that determines one episode (with the library's files)."""

    model: str
    """True model: a name in the library, or a path to a model file."""
    seed: int
    """Seed of the episode's generator: the pose, the start, the noise and the policy's random choices."""
    policy: str = "planner"
    """Policy name."""
    executor: str = "geometric"
    """"geometric" (ideal sensor with noise) or "physics" (MuJoCo hand)."""
    noise: float = 1.0
    """Sensor-noise level: multiplies every σ of the default noise model (0 = noiseless)."""
    models: str | None = None
    """Library directory (None: the shipped library)."""
    budget: float = 600.0
    """Cost budget: the episode ends as "budget" once its path cost passes this [units]."""
    max_moves: int = 40
    """Move budget: the episode ends as "budget" after this many moves."""
    record: str | None = None
    """Path of a rerun recording to write (None: none)."""
    verify: str = "none"
    """Verification before recognition: "none", "fast" or "full" (:mod:`haptic.matching.verify`)."""


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


def _run(spec_dict: dict) -> dict:
    from haptic.episode import run_episode

    return run_episode(EpisodeSpec(**spec_dict)).to_json()


def run_sweep(
    specs: Sequence[EpisodeSpec],
    workers: int = 1,
    backend: str = "local",
    on_result: Callable[[dict], None] | None = None,
) -> Iterator[dict]:
    """Run episodes and yield each record as it ends (completion order when ``workers`` > 1)."""
    if backend not in ("local", "ray"):
        raise BenchError(f"unknown backend {backend!r}; valid: local, ray")
    if workers < 1:
        raise BenchError(f"--workers must be at least 1, got {workers}")
    payload = [asdict(s) for s in specs]
    if backend == "ray":
        yield from _run_ray(payload)
        return
    if workers == 1:
        for p in payload:
            yield _run(p)
        return
    with ProcessPoolExecutor(max_workers=workers) as pool:
        pending = set()
        it = iter(payload)
        for p in it:
            pending.add(pool.submit(_run, p))
            if len(pending) >= 2 * workers:
                break
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                yield fut.result()
                nxt = next(it, None)
                if nxt is not None:
                    pending.add(pool.submit(_run, nxt))


def _run_ray(payload: list[dict]) -> Iterator[dict]:
    try:
        import ray
    except ImportError:
        raise BenchError("--backend ray needs Ray: pip install 'ray[default]' (or use --backend local)") from None
    if not ray.is_initialized():
        ray.init(address=os.environ.get("RAY_ADDRESS"), ignore_reinit_error=True, log_to_driver=False)
    remote = ray.remote(_run)
    refs = [remote.remote(p) for p in payload]
    while refs:
        done, refs = ray.wait(refs, num_returns=1)
        yield ray.get(done[0])


def with_models(specs: Sequence[EpisodeSpec], models: str | None) -> list[EpisodeSpec]:
    return [replace(s, models=models) for s in specs]
