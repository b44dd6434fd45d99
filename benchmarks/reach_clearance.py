"""How near a stroke's or a draw's reach may pass the object: the data of ``REACH_CLEARANCE``.

    python benchmarks/reach_clearance.py [--episodes 150]

For each line behaviour (tap, tap_back, push, draw), ``TapAffordance-v2`` with ``position_range="workspace"`` at
seeds 0 .. episodes - 1 and one random action each (drawn from seed 1): the smallest distance between the arm's
geoms and the object along the reach's servo targets (every control tick, and every ``REACH_SWEEP_STRIDE``-th as
``feasible()`` samples them), whether ``feasible()`` accepts the action when it asks no margin (no penetration of the
targets), and what the interaction then does. Prints, per margin asked on top of its other checks, how many of the
interactions it would accept still move the object before the stroke (a "reach: the arm moved the object" failure)
and how many that work it would refuse.
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np

import affordance_env  # noqa: F401 (registers the envs)
from affordance_env.behaviors import get_behavior
from affordance_env.behaviors import stroke as stroke_module
from affordance_env.motion import ik_verdict
from affordance_env.registry import BEHAVIOR_ARMS, BEHAVIOR_NAMES, ENV_ID

#: The line behaviours: the right arm's (the grasp, the left arm's, has no reach that sweeps past the object).
RIGHT_ARM = tuple(name for name in BEHAVIOR_NAMES if BEHAVIOR_ARMS[name] == "right")
MARGINS = (0.0, 0.001, 0.002, 0.003, 0.004, 0.01)  # [m]
#: Distances are measured up to this [m]: nearer than any margin asked about.
FAR = 0.05


def reach_clearance(env, behavior: str, action: np.ndarray) -> tuple[float, float]:
    """The smallest arm-object distance [m] along the reach's targets of ``behavior`` at ``action`` on the object the
    env's last observation saw: at every control tick, and at the ticks ``feasible()`` samples; NaN if the
    pre-stroke pose is out of reach. Kinematics only (the interaction's own functions, no physics step)."""
    world = env.unwrapped.world
    physics, motion = world.physics, world.motion
    b = get_behavior(behavior)
    seen = world.seen
    plan = b.plan(seen.geometry, seen.pose[:3], seen.yaw, physics.table_top, action)
    posture = world.approach_posture(behavior)
    start = stroke_module.approach_start(motion, plan, posture, check=True)
    if not ik_verdict([start])[0]:
        return float("nan"), float("nan")
    above = stroke_module.approach_above(motion, plan, start)
    targets = stroke_module.reach_trajectory(motion, above, start).q
    every = physics.sweep_clearance(targets, FAR, None)[0]
    sampled = physics.sweep_clearance(targets[:: stroke_module.REACH_SWEEP_STRIDE], FAR, None)[0]
    return every, sampled


def _feasible_without_margin(env, action: np.ndarray) -> bool:
    """``feasible()`` with ``REACH_CLEARANCE`` 0: its other checks (the IK of every pose, the table)."""
    kept = stroke_module.REACH_CLEARANCE
    stroke_module.REACH_CLEARANCE = 0.0
    try:
        return bool(env.unwrapped.feasible(action))
    finally:
        stroke_module.REACH_CLEARANCE = kept


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=150, help="interactions per behaviour (default 150)")
    args = parser.parse_args()
    rows = []  # (behavior, feasible, clearance every tick, clearance sampled, moved before, failed)
    for behavior in RIGHT_ARM:
        env = gym.make(ENV_ID, behavior=behavior, position_range="workspace")
        rng = np.random.default_rng(1)
        for seed in range(args.episodes):
            _, info = env.reset(seed=seed)
            action = rng.uniform(-1.0, 1.0, 3)
            if not info["visible"]:
                continue
            accepted = _feasible_without_margin(env, action)
            every, sampled = reach_clearance(env, behavior, action)
            *_, info = env.step(action.astype(np.float32))
            failure = info["failure"] or ""
            rows.append((behavior, accepted, every, sampled, "moved the object" in failure, bool(failure)))
        env.close()
    accepted = [r for r in rows if r[1]]
    moved = [r for r in accepted if r[4]]
    print(f"{len(rows)} interactions ({', '.join(f'{b} {sum(r[0] == b for r in rows)}' for b in RIGHT_ARM)}); "
          f"feasible() without a margin accepts {len(accepted)}, of which {len(moved)} moved the object before the "
          "stroke" + (f" (their targets passed {', '.join(f'{1000 * r[2]:.1f}' for r in moved)} mm from it)"
                      if moved else ""))
    print(f"with a margin (REACH_CLEARANCE is {1000 * stroke_module.REACH_CLEARANCE:g} mm), of those "
          f"{len(accepted)}:")
    print(f"{'margin [mm]':>12} {'every tick':>11} {'moved, let through':>19} {'working, refused':>17}")
    for margin in MARGINS:
        for label, column in (("yes", 2), (f"no, 1 in {stroke_module.REACH_SWEEP_STRIDE}", 3)):
            kept = [r for r in accepted if r[column] >= margin]
            refused = [r for r in accepted if r[column] < margin]
            print(f"{1000 * margin:12g} {label:>11} {sum(r[4] for r in kept):19d} {sum(not r[5] for r in refused):17d}")


if __name__ == "__main__":
    main()
