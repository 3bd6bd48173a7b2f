"""Benchmarks: many episodes across models, poses, noise levels and policies; tables and plots."""

DEFAULT_EPISODES = 50
"""Random (model, pose) draws of a sweep (``haptic bench --episodes``, :func:`haptic.sweep`)."""
DEFAULT_POLICIES = ("planner", "random")
"""Policies a sweep compares on the same draws."""
DEFAULT_NOISES = (1.0,)
"""Sensor-noise levels of a sweep."""
DEFAULT_OUT = "out/bench/results.jsonl"
"""Results file of ``haptic bench``."""
