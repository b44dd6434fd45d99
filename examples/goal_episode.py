"""One episode of TapAffordanceGoal-v2, choosing each interaction by trying candidates in simulation.

    python examples/goal_episode.py [--seed 3] [--candidates 12]

At each step, the behaviours' candidate actions that ``feasible()`` admits are tried from a snapshot of the world
(``get_state`` / ``set_state``) and the one that brings the object nearest the goal is executed: an oracle, the
upper baseline a planner with learned affordance models is measured against.
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np

import affordance_env  # noqa: F401 (registers the envs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--candidates", type=int, default=12, help="random actions per step, besides the canonical")
    args = parser.parse_args()
    env = gym.make("TapAffordanceGoal-v2")
    world = env.unwrapped
    rng = np.random.default_rng(args.seed)
    obs, info = env.reset(seed=args.seed)
    print(f"{info['object']['type']} of {info['object']['size'] * 100:.1f} cm at "
          f"{np.round(obs['achieved_goal'], 3)}, goal {np.round(obs['desired_goal'], 3)}: "
          f"{info['distance'] * 100:.1f} cm")
    for step in range(1, 6):
        state = world.get_state()
        candidates = [(b, np.zeros(3, np.float32)) for b in range(len(world.behaviors))]
        candidates += [(int(rng.integers(len(world.behaviors))), rng.uniform(-1, 1, 3).astype(np.float32))
                       for _ in range(args.candidates)]
        best, best_distance, tried = None, np.inf, 0
        for behavior, params in candidates:
            if not world.feasible(behavior, params):
                continue
            tried += 1
            world.set_state(state)
            _, _, _, _, trial = world.step({"behavior": behavior, "params": params})
            if trial["failure"] is None and trial["distance"] < best_distance:
                best, best_distance = (behavior, params), trial["distance"]
        world.set_state(state)
        if best is None:
            print(f"step {step}: no feasible candidate")
            break
        obs, reward, terminated, truncated, info = env.step({"behavior": best[0], "params": best[1]})
        print(f"step {step}: {info['behavior']:8s} params {np.round(best[1], 2)} ({tried} tried) -> object at "
              f"{np.round(obs['achieved_goal'], 3)}, {info['distance'] * 100:.1f} cm from the goal, reward {reward:g}")
        if terminated or truncated:
            print("goal reached" if info["is_success"] else ("off the table" if terminated else "out of steps"))
            break
    env.close()


if __name__ == "__main__":
    main()
