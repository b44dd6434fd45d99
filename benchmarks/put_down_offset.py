"""Where a pick and place's carry ends, against the plan's nominal put-down pose: the data of
``affordance_env.behaviors.grasp.PUT_DOWN_OFFSET_HAND``.

    python benchmarks/put_down_offset.py [--draws 240] [--seed 11]

Each draw places an object of 4-7 cm (the four types in turn) 20-36 cm in front of the robot, within the left
arm's reach, and runs a pick and place at random params within +-0.6 that ``feasible`` accepts. The carry brings
the held object, as it hangs, over the place asked; the palm's end of that line is compared with the nominal pose
(``p_place`` PLACE_APPROACH above the grasp's height), in the hand's frame. ``MotionExecutor.line`` and
``plan_grasp`` are wrapped to read both. Prints, per type, the mean and standard deviation of that offset [mm]
over the objects held, beside the constant the package uses.
"""

from __future__ import annotations

import argparse

import numpy as np

from affordance_env.behaviors import grasp
from affordance_env.goal_env import TapAffordanceGoalEnv
from affordance_env.motion import MotionExecutor
from affordance_env.objects import OBJECT_TYPES


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=240)
    parser.add_argument("--seed", type=int, default=11)
    args = parser.parse_args()
    ends: list[np.ndarray] = []
    plans: list[grasp.GraspPlan] = []
    line, plan_grasp = MotionExecutor.line, grasp.plan_grasp

    def traced_line(self, p_start, p_end, *rest, **kwargs):
        if self.phase == "carry":
            ends.append(np.array(p_end, dtype=float))
        return line(self, p_start, p_end, *rest, **kwargs)

    def traced_plan(*a, **kwargs):
        plans.append(plan_grasp(*a, **kwargs))
        return plans[-1]

    MotionExecutor.line, grasp.plan_grasp = traced_line, traced_plan
    env = TapAffordanceGoalEnv()
    rng = np.random.default_rng(args.seed)
    offsets: dict[str, list[np.ndarray]] = {t: [] for t in OBJECT_TYPES}
    for i in range(args.draws):
        xy = (rng.uniform(-0.36, -0.2), rng.uniform(0.0, 0.22))
        object_type = OBJECT_TYPES[i % len(OBJECT_TYPES)]
        size, params = rng.uniform(0.04, 0.07), rng.uniform(-0.6, 0.6, 3).astype(np.float32)
        env.reset(seed=1000 + i, options={"object_type": object_type, "size": size, "position": xy})
        if not env.feasible("grasp", params):
            continue
        ends.clear()
        plans.clear()
        env.step({"behavior": "grasp", "params": params})
        if not ends or not plans:  # not held: no carry
            continue
        plan = plans[-1]
        nominal = np.array([plan.p_place[0], plan.p_place[1], plan.p_grasp[2] + grasp.PLACE_APPROACH])
        offsets[object_type].append(plan.R_world_hand.T @ (ends[0] - nominal))
    print(f"{'type':<20} {'held':>4}  {'mean (x, y, z) [mm]':<24} {'sd [mm]':<22} package [mm]")
    for object_type, found in offsets.items():
        if not found:
            print(f"{object_type:<20} {0:>4}")
            continue
        d = 1000 * np.array(found)
        package = 1000 * np.array(grasp.PUT_DOWN_OFFSET_HAND[object_type])
        print(f"{object_type:<20} {len(d):>4}  {str(np.round(d.mean(axis=0), 1)):<24} "
              f"{str(np.round(d.std(axis=0), 1)):<22} {np.round(package, 1)}")


if __name__ == "__main__":
    main()
