"""Use learned affordances: a goal, a plan, an executed interaction, then a multi-step episode to a place.

The planner uses the shipped action-conditioned effect models (``affordance_learning.load_action_model``), or
models fitted on the goal episodes of an ``affordance plan`` run::

    python examples/use_affordances.py
    affordance plan --out plan && python examples/use_affordances.py --dataset plan/dataset
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np

import affordance_env  # noqa: F401  (registers the environments)
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_env.workspace import in_workspace
from affordance_learning import load_action_model
from affordance_learning.planning.experiment import fit_models, load_training, training_frames
from affordance_learning.planning.goals import Move, describe
from affordance_learning.planning.planner import Planner


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", default=None, help="goal episodes to fit the models on (affordance plan's "
                        "OUT/dataset); default: the shipped models")
    parser.add_argument("--seed", type=int, default=3)
    args = parser.parse_args()
    if args.dataset is None:
        models = {behavior: load_action_model(behavior) for behavior in BEHAVIOR_NAMES}
    else:
        try:
            models = fit_models(training_frames(load_training(args.dataset), 1000), random_state=0)
        except (OSError, ValueError) as exc:  # no dataset there, or not one of goal episodes
            parser.error(str(exc))
    planner = Planner(models)
    env = gym.make("TapAffordanceGoal-v2")
    world = env.unwrapped

    obs, info = env.reset(seed=args.seed, options={"object_type": "sphere", "size": 0.06, "position": (-0.3, 0.05)})
    goal = Move((0.0, -1.0), 0.05)  # 5 cm to the robot's right
    choice = planner.choose(obs["observation"]["features"], goal, obs["achieved_goal"], feasible=world.feasible)
    if choice.behavior is None:  # no action it asked about was feasible: the reason says so
        print(f"goal: {describe(goal)} -> no action: {choice.reason}")
    else:
        print(f"goal: {describe(goal)} -> {choice.behavior} {np.round(choice.params, 2)}, P = {choice.probability:.2f}")
        obs, _, _, _, info = env.step({"behavior": choice.behavior, "params": choice.params.astype(np.float32)})
        moved = np.asarray(info["object"]["final_pose"][:2]) - np.asarray(info["object"]["initial_pose"][:2])
        print(f"  the {info['object']['type']} moved {np.round(100 * moved, 1)} cm")

    obs, info = env.reset(seed=args.seed)
    print(f"episode: {info['object']['type']} at {np.round(obs['achieved_goal'], 3)}, target "
          f"{np.round(obs['desired_goal'], 3)} ({100 * info['distance']:.1f} cm)")
    steps = env.spec.max_episode_steps
    for step in range(1, steps + 1):
        # A search over two interactions; the workspaces say where a behaviour can act after the first.
        choice = planner.toward(obs["observation"]["features"], obs["achieved_goal"], obs["desired_goal"],
                                world.goal_tolerance, feasible=world.feasible, steps_left=steps - step + 1,
                                reachable=in_workspace)
        if choice.behavior is None:
            print(f"  no action: {choice.reason}")
            break
        obs, reward, terminated, truncated, info = env.step(
            {"behavior": choice.behavior, "params": choice.params.astype(np.float32)})
        print(f"  step {step}: {choice.behavior:<8} {np.round(choice.params, 2)} (P within 3 cm now "
              f"{choice.probability:.2f}, within two {choice.value:.2f}) -> {100 * info['distance']:.1f} cm from "
              "the target")
        if terminated or truncated:
            break
    print("reached" if info.get("is_success") else "not reached")


if __name__ == "__main__":
    main()
