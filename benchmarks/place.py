"""Pick and place in the goal env: how near the asked place a held object is put down.

    python benchmarks/place.py [--episodes 100]

``TapAffordanceGoal-v2`` at seeds 0 .. episodes - 1, objects anywhere in the behaviours' workspaces: the grasp with
random params (drawn from seed 1) that ``feasible()`` accepts (up to 20 tries per object), the place asked
being where the object stood plus ``PLACE_RANGE`` times params[0:2]. Prints, over the objects the hand held, the
distance between where the object rests after the interaction and the place asked (median, 90th percentile,
max), whether it rested, and how many were not held or had no feasible place.
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np

import affordance_env  # noqa: F401 (registers the envs)
from affordance_env.behaviors.grasp import PLACE_RANGE
from affordance_env.registry import GOAL_ENV_ID


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=100)
    args = parser.parse_args()
    env = gym.make(GOAL_ENV_ID, position_range="workspace")
    world = env.unwrapped
    rng = np.random.default_rng(1)
    errors, asked_far, rested, not_held, no_place, failed = [], [], 0, 0, 0, 0
    for seed in range(args.episodes):
        _, info = env.reset(seed=seed)
        for _ in range(20):
            params = rng.uniform(-1.0, 1.0, 3)
            if world.feasible("grasp", params):
                break
        else:
            no_place += 1
            continue
        _, _, _, _, info = env.step({"behavior": "grasp", "params": params.astype(np.float32)})
        if info["failure"]:
            failed += 1
            continue
        if not info["success"]:
            not_held += 1
            continue
        start = np.asarray(info["object"]["initial_pose"][:2])
        asked = start + PLACE_RANGE * params[:2]
        errors.append(float(np.linalg.norm(np.asarray(info["object"]["pose"][:2]) - asked)))
        asked_far.append(float(np.linalg.norm(asked - start)))
        rested += info["outcome"] == "rest"
    env.close()
    e = 100 * np.array(errors)
    print(f"{len(errors)} held objects put down {np.median(asked_far) * 100:.1f} cm (median) from where they stood: "
          f"error median {np.median(e):.2f} cm, 90th percentile {np.quantile(e, 0.9):.2f}, max {e.max():.2f}; "
          f"{rested} at rest; {not_held} not held, {failed} failed, {no_place} without a feasible place "
          f"in 20 tries")


if __name__ == "__main__":
    main()
