"""The Python interface in ten lines: a library, one episode, a small sweep (the command line's defaults)."""

import haptic

library = haptic.load_library()  # the shipped models; load_library("my_cad", units="mm") for your own
print(f"{len(library)} models: {', '.join(sorted(library))}")
record = haptic.run_episode(haptic.EpisodeSpec(model="WEDGE01", seed=1))  # = haptic explore --object WEDGE01 --seed 1
print(f"WEDGE01 seed 1: {record.outcome} {record.recognized} in {record.moves} moves, path cost {record.path_cost:.1f}")
records = haptic.sweep(episodes=2, policies=["planner", "random"], verify="none")  # = haptic bench --episodes 2 ...
for r in records:
    print(f"{r['policy']:>8} {r['model']:<10} seed {r['seed']}: {r['outcome']}, {r['moves']} moves")
