"""Interactions per second of TapAffordance-v2 on one core, and where the time goes.

    python benchmarks/env.py [--episodes 200] [--repeats 3] [--width W] [--height H] [--behavior tap [grasp ...]]

Prints interactions per second (reset + step), and the share of wall time spent inside ``mj_step`` (physics),
in range images (the snapshots' and the attention's; of which ray casting) and in the 49 features, measured by
timing those calls in the same run; and the share ``mj_step`` would have if nothing but physics and perception cost
any time, the ceiling on it that perception sets. With
several behaviours, they take turns round by round in the same run (so that they share the machine's load),
and the wall time per interaction of each is compared with the first's.
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict

import mujoco
import numpy as np

import affordance_env.world as world_module
from affordance_env.camera import RangeCamera
from affordance_env.tap_env import TapAffordanceEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--width", type=int, default=None, help="range image width (default: the env's)")
    parser.add_argument("--height", type=int, default=None, help="range image height (default: the env's)")
    parser.add_argument("--behavior", nargs="+", default=["tap"], help="one or more behaviours, measured in turn")
    parser.add_argument("--repeats", type=int, default=3, help="rounds over the same interactions; best reported")
    args = parser.parse_args()

    spent: dict[str, float] = defaultdict(float)

    def timed(name, fn):
        def wrapper(*a, **k):
            start = time.perf_counter()
            try:
                return fn(*a, **k)
            finally:
                spent[name] += time.perf_counter() - start

        return wrapper

    # Time MuJoCo's own calls in place (the env's code runs unchanged, its monitor included).
    original = {"mj_step": mujoco.mj_step, "mj_multiRay": mujoco.mj_multiRay}
    taken = [0]  # physics steps as taken, not simulated time over the timestep: the grasp carries at a longer one

    def counted_step(model, data, nstep=1):
        taken[0] += nstep
        return original["mj_step"](model, data, nstep)

    mujoco.mj_step = timed("mj_step", counted_step)
    mujoco.mj_multiRay = timed("ray casting", original["mj_multiRay"])
    world_module.object_features = timed("features", world_module.object_features)
    # Every range image: the snapshots' and the attention's (ray casting included, and the arrays around it).
    original_capture = RangeCamera.capture
    RangeCamera.capture = timed("range images", original_capture)
    per_interaction = {}
    try:
        size = {k: v for k, v in (("camera_width", args.width), ("camera_height", args.height)) if v is not None}
        envs = {behavior: TapAffordanceEnv(behavior=behavior, **size) for behavior in args.behavior}
        for env in envs.values():
            env.reset(seed=0)
            env.step(np.zeros(3))
        # The same interactions each round; the behaviours take turns round by round, so that they share the
        # machine's varying load; the best round of each is its figure.
        rounds = {behavior: [] for behavior in envs}
        simulated, steps = dict.fromkeys(envs, 0.0), dict.fromkeys(envs, 0)
        for _ in range(args.repeats):
            for behavior, env in envs.items():
                spent.clear()
                simulated[behavior] = 0.0
                taken[0] = 0
                start = time.perf_counter()
                for i in range(args.episodes):
                    env.reset(seed=i)
                    env.step(np.zeros(3))
                    simulated[behavior] += env.physics.data.time  # reset starts the clock at 0
                rounds[behavior].append((time.perf_counter() - start, dict(spent)))
                steps[behavior] = taken[0]
        for behavior, env in envs.items():
            wall, best = min(rounds[behavior], key=lambda r: r[0])
            per_interaction[behavior] = wall / args.episodes
            _report(env, behavior, args, wall, best, rounds[behavior], simulated[behavior], steps[behavior])
    finally:
        mujoco.mj_step, mujoco.mj_multiRay = original["mj_step"], original["mj_multiRay"]
        RangeCamera.capture = original_capture
    first = args.behavior[0]
    for behavior in args.behavior[1:]:
        ratio = per_interaction[behavior] / per_interaction[first]
        print(f"{behavior}: {1e3 * per_interaction[behavior]:.1f} ms per interaction, "
              f"{ratio:.2f} x {first}'s {1e3 * per_interaction[first]:.1f} ms")


def _report(env: TapAffordanceEnv, behavior: str, args: argparse.Namespace, wall: float, spent: dict[str, float],
            rounds: list, simulated: float, steps: int) -> None:
    width, height = env.camera.intrinsics.width, env.camera.intrinsics.height
    print(f"{args.episodes} interactions ({behavior}, {width}x{height} range image) in {wall:.2f} s "
          f"(best of {args.repeats} rounds; all: {', '.join(f'{r[0]:.2f}' for r in rounds)} s)")
    print(f"  interactions per second (one core): {args.episodes / wall:8.1f}")
    print(f"  physics steps per interaction     : {steps / args.episodes:8.0f} ({simulated / args.episodes:.2f} s "
          "simulated)")
    per = 1e3 / args.episodes  # [ms per interaction] per second of the round
    for name, label in (("mj_step", "share of wall time in mj_step     "),
                        ("range images", "share of wall time in range images"),
                        ("ray casting", "  of which in ray casting         "),
                        ("features", "share of wall time in features    ")):
        print(f"  {label}: {100 * spent.get(name, 0.0) / wall:7.1f} %   ({per * spent.get(name, 0.0):.1f} ms per "
              "interaction)")
    measured = sum(v for k, v in spent.items() if k != "ray casting")  # ray casting is part of the range images
    print(f"  everything else (IK, control, ...): {100 * (1 - measured / wall):7.1f} %   "
          f"({per * (wall - measured):.1f} ms per interaction)")
    # What perception alone leaves to physics: the share mj_step would have if nothing else cost anything.
    perception = spent.get("range images", 0.0) + spent.get("features", 0.0)
    physics = spent.get("mj_step", 0.0)
    ceiling = 100 * physics / (physics + perception)
    print(f"  mj_step's share if nothing but physics and perception cost any time: {ceiling:.1f} %")


if __name__ == "__main__":
    main()
