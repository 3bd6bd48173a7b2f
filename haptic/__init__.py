"""haptic: a testbed for recognising and localising polyhedral objects by active touch.

The Python interface (:mod:`haptic.api`), with the command line's defaults::

    import haptic

    library = haptic.load_library()                      # the shipped models, by name
    spec = haptic.EpisodeSpec(model="WEDGE01", seed=1)   # = haptic explore --object WEDGE01 --seed 1
    record = haptic.run_episode(spec)                    # an EpisodeRecord; .to_json() is explore's --json
    records = haptic.sweep(episodes=20, policies=["planner", "random"])  # = haptic bench --episodes 20

Every error this package raises on purpose is a :class:`HapticError`.
"""

from haptic.errors import HapticError

__version__ = "0.1.0"
__all__ = ["EpisodeRecord", "EpisodeSpec", "HapticError", "UnitsWarning", "load_library", "run_episode", "sweep",
           "__version__"]  # fmt: skip

_API = ("EpisodeRecord", "EpisodeSpec", "UnitsWarning", "load_library", "run_episode", "sweep")


def __getattr__(name: str):
    """The interface's names load on first use, so that ``import haptic`` (and the command's ``--help``) stays
    light: numpy and the episode machinery load only when an episode is asked for."""
    if name in _API:
        from haptic import api

        return getattr(api, name)
    raise AttributeError(f"module 'haptic' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)

