"""How often ``feasible()`` of TapAffordanceGoal-v2 agrees with what the interaction then does: its own IK verdict,
and whether its reach left the object where it was (no ``"reach: ..."`` failure).

    python benchmarks/feasible.py [--draws 400] [--seed 0]

Each draw places an object at a uniform position over the part of the table within the arms' reach, picks a
behaviour and params at random, asks ``feasible`` (kinematics only) and then runs the interaction: it reached when
``info["ik"]["success"]`` (measured whatever else happens) and it did not fail with ``"reach: ..."``. Prints the
agreement and the table of (behaviour, feasible, reached) counts.
"""

from __future__ import annotations

import argparse
from collections import Counter

import numpy as np

from affordance_env.goal_env import TapAffordanceGoalEnv

#: The part of the table the arms can reach at all (x, y) [m]: a margin around every workspace.
REACH_LOW, REACH_HIGH = np.array([-0.52, -0.38]), np.array([-0.16, 0.38])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=400)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    env = TapAffordanceGoalEnv()
    rng = np.random.default_rng(args.seed)
    counts: Counter = Counter()
    for i in range(args.draws):
        env.reset(seed=args.seed * 100_000 + i, options={"position": tuple(rng.uniform(REACH_LOW, REACH_HIGH))})
        behavior, params = int(rng.integers(len(env.behaviors))), rng.uniform(-1, 1, 3).astype(np.float32)
        feasible = env.feasible(behavior, params)
        _, _, _, _, info = env.step({"behavior": behavior, "params": params})
        reached = bool(info["ik"]["success"]) and not str(info["failure"] or "").startswith("reach")
        counts[env.behaviors[behavior], feasible, reached] += 1
    agree = sum(n for (_, feasible, reached), n in counts.items() if feasible == reached)
    print(f"agreement: {agree} of {args.draws} ({agree / args.draws:.1%})")
    for (behavior, feasible, reached), n in sorted(counts.items()):
        print(f"  {behavior:8s} feasible={feasible!s:5s} reached={reached!s:5s} {n}")
    env.close()


if __name__ == "__main__":
    main()
