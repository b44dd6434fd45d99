"""Interactions per second of TapAffordance-v0 on one core, and where the time goes.

    python benchmarks/env.py [--episodes 200] [--width 128] [--height 128] [--behavior tap]

Prints interactions per second (reset + step), and the share of wall time spent inside ``mj_step`` (physics),
in ray casting (range camera) and in the 49 features, measured by timing those calls in the same run.
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict

import mujoco
import numpy as np

import affordance_env.camera as camera_module
import affordance_env.tap_env as tap_env_module
from affordance_env.physics import TapPhysics
from affordance_env.tap_env import TapAffordanceEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--width", type=int, default=128)
    parser.add_argument("--height", type=int, default=128)
    parser.add_argument("--behavior", default="tap")
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

    original_step = TapPhysics.step

    def step(self, n: int = 1) -> None:
        start = time.perf_counter()
        mujoco.mj_step(self.model, self.data, n)
        spent["mj_step"] += time.perf_counter() - start

    TapPhysics.step = step
    camera_module.mujoco.mj_multiRay = timed("ray casting", mujoco.mj_multiRay)
    tap_env_module.compute_features = timed("features", tap_env_module.compute_features)
    try:
        env = TapAffordanceEnv(behavior=args.behavior, camera_width=args.width, camera_height=args.height)
        env.reset(seed=0)
        env.step(np.zeros(3))
        spent.clear()
        start = time.perf_counter()
        for i in range(args.episodes):
            env.reset(seed=i)
            env.step(np.zeros(3))
        wall = time.perf_counter() - start
    finally:
        TapPhysics.step = original_step
    print(f"{args.episodes} interactions ({args.behavior}, {args.width}x{args.height} range image) in {wall:.2f} s")
    print(f"  interactions per second (one core): {args.episodes / wall:8.1f}")
    print(f"  physics steps per interaction     : {env.physics.data.time / env.physics.model.opt.timestep:8.0f}")
    for name in ("mj_step", "ray casting", "features"):
        print(f"  share of wall time in {name:<12}: {100 * spent[name] / wall:7.1f} %")
    print(f"  everything else (IK, control, ...): {100 * (1 - sum(spent.values()) / wall):7.1f} %")


if __name__ == "__main__":
    main()
