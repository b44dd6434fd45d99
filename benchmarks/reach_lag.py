"""How much nearer to the object the arm comes than its servo targets during a stroke's or a draw's reach, by the
palm's speed: the servos' lag that ``REACH_CLEARANCE`` (:mod:`affordance_env.behaviors.stroke`) stands for.

    python benchmarks/reach_lag.py [--draws 400] [--seed 2]

The draws of ``benchmarks/feasible.py`` (an object at a uniform position within the arms' reach, a behaviour and
params at random), the right arm's behaviours only, those whose poses the IK reaches: at every control tick of the
reach, the distance between the arm's geoms and the object along the targets (kinematics) and as the arm is (after
the tick's physics steps), and the palm's speed along the targets. Over the ticks whose targets are within NEAR of
the object, before the arm first touches it, prints the largest shortfall of the arm's distance from the targets',
per band of speeds, how many fell short by more than ``REACH_CLEARANCE``, and for clearances at rest (FLOORS) the
least lag time that covers all the others (a clearance that would grow with the speed); ticks whose targets go into
the table apart (the table holds the arm off them).
"""

from __future__ import annotations

import argparse

import numpy as np

from affordance_env.behaviors import get_behavior, stroke
from affordance_env.goal_env import TapAffordanceGoalEnv
from affordance_env.kinematics import Kinematics
from affordance_env.motion import CONTROL_DT, ik_verdict
from affordance_env.registry import BEHAVIOR_ARMS

#: The part of the table the arms can reach at all (x, y) [m]: benchmarks/feasible.py's.
REACH_LOW, REACH_HIGH = np.array([-0.52, -0.38]), np.array([-0.16, 0.38])
#: Ticks whose targets are within this distance of the object are counted [m].
NEAR = 0.02
#: Clearances at rest [m] for which the lag time that covers the measured shortfalls is printed.
FLOORS = (0.0005, 0.0007, 0.001)
#: Bands of the palm's speed [m/s].
BANDS = (0.0, 0.05, 0.1, 0.2, 0.3, np.inf)


def _palm_speeds(kinematics: Kinematics, q: np.ndarray) -> np.ndarray:
    """The palm's speed [m/s] at each control tick of the joint targets ``q`` ((ticks, joints), one CONTROL_DT
    apart): its travel since the tick before (the first tick: to the next one)."""
    palm = np.array([kinematics.hand_pose(q_tick).translation for q_tick in q])
    steps = np.linalg.norm(palm[1:] - palm[:-1], axis=1) / CONTROL_DT
    return np.concatenate((steps[:1], steps)) if len(steps) else np.zeros(len(q))


def _arm_distances(env: TapAffordanceGoalEnv, behavior: int, params: np.ndarray) -> np.ndarray:
    """Run the interaction; the arm's distance from the object [m] (up to NEAR) after each control tick of its
    reach (the world calls back once per physics step call, one per tick)."""
    world = env.world
    physics, motion = world.physics, world.motion
    distances: list[float] = []

    def watch(_: float) -> None:
        if motion.phase == "reach":
            distances.append(physics.arm_object_distance(NEAR))

    world.on_step(watch)
    try:
        env.step({"behavior": behavior, "params": params})
    finally:
        world.on_step(None)
    return np.array(distances)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=400)
    parser.add_argument("--seed", type=int, default=2)
    args = parser.parse_args()
    env = TapAffordanceGoalEnv()
    world = env.world
    rng = np.random.default_rng(args.seed)
    shortfalls, speeds, held_off, reaches, near_reaches = [], [], [], 0, 0
    for i in range(args.draws):
        position = tuple(rng.uniform(REACH_LOW, REACH_HIGH))
        behavior, params = int(rng.integers(len(env.behaviors))), rng.uniform(-1, 1, 3).astype(np.float32)
        name = env.behaviors[behavior]
        if BEHAVIOR_ARMS[name] != "right":
            continue
        env.reset(seed=args.seed * 100_000 + i, options={"position": position})
        physics, motion, seen = world.physics, world.motion, world.seen
        plan = get_behavior(name, goal=True).plan(seen.geometry, seen.pose[:3], seen.yaw, physics.table_top,
                                          params.astype(float))
        start = stroke.approach_start(motion, plan, world.approach_posture(name))
        if not ik_verdict([start, *stroke.stroke_line(motion, plan, start).results])[0]:
            continue
        reach = stroke.reach_trajectory(motion, stroke.approach_above(motion, plan, start), start).q
        targets, table = np.array([physics.sweep_clearance(q, NEAR, 0.0) for q in reach], dtype=float).T
        palm_speeds = _palm_speeds(world.kinematics(name), reach)
        arm_distance = _arm_distances(env, behavior, params)[: len(reach)]
        untouched = np.minimum.accumulate(arm_distance) > 0
        n = len(arm_distance)
        near = (targets[:n] < NEAR) & untouched
        reaches += 1
        near_reaches += bool(near.any())
        shortfall = targets[:n] - arm_distance
        shortfalls += list(shortfall[near & (table[:n] >= 0.0)])
        speeds += list(palm_speeds[:n][near & (table[:n] >= 0.0)])
        held_off += list(shortfall[near & (table[:n] < 0.0)])
    shortfall, speed = np.array(shortfalls), np.array(speeds)
    print(f"{reaches} reaches, {near_reaches} with targets within {NEAR * 1e3:g} mm of the object: {len(speed)} ticks "
          f"whose targets keep out of the table, {len(held_off)} whose targets go into it (the arm came nearer than "
          f"its targets there by {max(held_off, default=0.0) * 1e3:.2f} mm at most)")
    print(f"{'palm speed [m/s]':>18} {'ticks':>6} {'largest shortfall [mm]':>23}")
    for low, high in zip(BANDS[:-1], BANDS[1:], strict=True):
        band = (speed >= low) & (speed < high)
        largest = f"{shortfall[band].max() * 1e3:.2f}" if band.any() else "-"
        print(f"{low:8.2f} - {high:<7.2f} {int(band.sum()):6d} {largest:>23}")
    capped = shortfall > stroke.REACH_CLEARANCE  # beyond what any clearance up to REACH_CLEARANCE covers
    if capped.any():
        print(f"{int(capped.sum())} ticks fell short by more than REACH_CLEARANCE ({shortfall.max() * 1e3:.2f} mm at "
              f"most), at {speed[capped].min():.2f} m/s and faster")
    for floor in FLOORS:
        covered = ~capped & (shortfall > floor)
        lag = float(np.max((shortfall[covered] - floor) / speed[covered])) if covered.any() else 0.0
        print(f"the others within {floor * 1e3:.1f} mm + {lag * 1e3:.2f} ms times the speed")
    env.close()


if __name__ == "__main__":
    main()
