"""What a snapshot of the world costs: ``get_state`` and ``set_state``, against one interaction in the same run.

    python benchmarks/state.py [--behavior tap grasp] [--repeats 200]

An oracle that tries K actions from one state pays one ``get_state``, K ``set_state`` and K interactions; this
prints the median cost of each call and its ratio to an interaction of the same behaviour.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from affordance_env.tap_env import TapAffordanceEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--behavior", nargs="+", default=["tap", "grasp"])
    parser.add_argument("--repeats", type=int, default=200)
    args = parser.parse_args()
    for behavior in args.behavior:
        env = TapAffordanceEnv(behavior=behavior)
        env.reset(seed=0)
        gets, sets, steps = [], [], []
        for _ in range(args.repeats):
            start = time.perf_counter()
            state = env.get_state()
            gets.append(time.perf_counter() - start)
            start = time.perf_counter()
            env.set_state(state)
            sets.append(time.perf_counter() - start)
        for _ in range(10):
            env.set_state(state)
            start = time.perf_counter()
            env.step(np.zeros(3))
            steps.append(time.perf_counter() - start)
        step = float(np.median(steps))
        print(f"{behavior}: get_state {1e3 * np.median(gets):.3f} ms, set_state {1e3 * np.median(sets):.3f} ms "
              f"(median of {args.repeats}); an interaction from there {1e3 * step:.1f} ms: a snapshot and a restore "
              f"cost {(np.median(gets) + np.median(sets)) / step:.1%} of it")
        env.close()


if __name__ == "__main__":
    main()
