"""Cost of an interaction in TapAffordanceGoal-v2 against the same behaviour in TapAffordance-v2, same run.

    python benchmarks/goal_env.py [--episodes 40] [--repeats 3]

For each behaviour, the same objects (type, size, position drawn once) with the canonical action: in
TapAffordance-v2 an interaction is ``reset`` (place, settle, attend, snapshot) and ``step``; in the goal env it is
``step`` (the interaction, then the head turning to the object where it rests and the next snapshot), each from an
object placed by ``reset`` outside the timing. The two take turns object by object so that they share the
machine's load; the best of ``--repeats`` rounds is reported, with the ratio goal env / v1.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from affordance_env.goal_env import TapAffordanceGoalEnv
from affordance_env.objects import OBJECT_TYPES
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_env.tap_env import TapAffordanceEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=40)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    objects = [{"object_type": OBJECT_TYPES[int(rng.integers(4))], "size": float(rng.uniform(0.04, 0.10)),
                "position": tuple(np.array([-0.30, 0.03]) + rng.uniform(-0.03, 0.03, 2))}
               for _ in range(args.episodes)]
    goal = TapAffordanceGoalEnv()
    print(f"{'behaviour':10s} {'v1 [ms]':>9s} {'goal [ms]':>10s} {'ratio':>6s}")
    for name in BEHAVIOR_NAMES:
        v1 = TapAffordanceEnv(behavior=name)
        best = {"v1": np.inf, "goal": np.inf}
        for _ in range(args.repeats):
            spent = {"v1": 0.0, "goal": 0.0}
            for seed, options in enumerate(objects):
                start = time.perf_counter()
                v1.reset(seed=seed, options=options)
                v1.step(np.zeros(3))
                spent["v1"] += time.perf_counter() - start
                goal.reset(seed=seed, options={**options, "goal": (-0.45, 0.0)})
                start = time.perf_counter()
                goal.step({"behavior": name, "params": np.zeros(3)})
                spent["goal"] += time.perf_counter() - start
            best = {key: min(best[key], spent[key] / len(objects)) for key in best}
        print(f"{name:10s} {best['v1'] * 1e3:9.1f} {best['goal'] * 1e3:10.1f} {best['goal'] / best['v1']:6.2f}")
        v1.close()
    goal.close()


if __name__ == "__main__":
    main()
