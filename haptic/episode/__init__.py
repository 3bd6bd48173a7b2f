"""Episodes: the spec (:mod:`.spec`), the closed loop (:mod:`.loop`) and the worlds that build an episode from
its spec (:mod:`.worlds`: the geometric executor, the simulated hand)."""

from haptic.episode.loop import EpisodeObserver, EpisodeRecord, run_loop
from haptic.episode.spec import EpisodeSpec
from haptic.episode.worlds import Episode, GeometricWorld, PhysicsWorld, build_episode, run_episode

__all__ = [
    "Episode",
    "EpisodeObserver",
    "EpisodeRecord",
    "EpisodeSpec",
    "GeometricWorld",
    "PhysicsWorld",
    "build_episode",
    "run_episode",
    "run_loop",
]
