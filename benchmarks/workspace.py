"""Measure each behaviour's workspace: where on the table its canonical action is reachable for every object.

For each cell of a grid over the table (``--spacing``, 2.5 cm by default) and each behaviour, the arm's inverse
kinematics plans the canonical action (no physics step) on a sphere, a box, a lying and a standing cylinder of the
smallest and the largest size, at the yaws the env draws (0 and +-0.25 rad); a cell is in the workspace when every
one is reachable and each of them, placed there in the scene with both arms, is seen by the head after it attends
(:func:`affordance_env.attention.attend`, with its search). Prints each behaviour's largest convex polygon of those
cells as the literal of ``affordance_env.workspace.WORKSPACES``: runs of cells along y, one or more per x.

    python benchmarks/workspace.py
"""

from __future__ import annotations

import argparse

import numpy as np

from affordance_env.behaviors import get_behavior
from affordance_env.objects import OBJECT_TYPES, object_geometry
from affordance_env.registry import BEHAVIOR_ARMS
from affordance_env.tap_env import TapAffordanceEnv
from affordance_env.world import World

YAWS = (0.0, -0.25, 0.25)  # the env's yaw jitter: boxes and lying cylinders are drawn within +-0.25 rad
SIZES = (0.04, 0.10)


def reachable(world: World, name: str, x: float, y: float) -> bool:
    """Whether the canonical action of behaviour ``name`` (of the world's one arm) is reachable on every object at
    (x, y)."""
    behavior, physics = get_behavior(name), world.physics
    top = physics.table_top
    # The object out of the scene (a metre under the table): a workspace is where the arm's IK reaches every pose;
    # whether a stroke's reach sweeps through the object is asked per object and action (feasible()).
    physics.reset_home()
    physics.set_object_pose(np.array([0.0, 0.0, -1.0, 1.0, 0.0, 0.0, 0.0]))
    for object_type in OBJECT_TYPES:
        for size in SIZES:
            g = object_geometry(object_type, size)
            for yaw in YAWS if object_type in ("box", "horizontal_cylinder") else (0.0,):
                plan = behavior.plan(g, np.array([x, y, top + g.half_height]), yaw, top, np.zeros(3))
                if not behavior.reachable(world.motion, plan, world.approach_posture(name)):
                    return False
    return True


def seen(env: TapAffordanceEnv, x: float, y: float) -> bool:
    """Whether every object placed at (x, y) is seen by the head once it attends."""
    for object_type in OBJECT_TYPES:
        for size in SIZES:
            _, info = env.reset(seed=0, options={"object_type": object_type, "size": size, "position": (x, y)})
            if not info["visible"]:
                return False
    return True


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spacing", type=float, default=0.025, help="grid spacing [m]")
    args = parser.parse_args()
    # one world per arm, each in the scene with both arms
    worlds = {arm: World([name for name, a in BEHAVIOR_ARMS.items() if a == arm], two_arms=True, camera_width=80,
                         camera_height=60) for arm in sorted(set(BEHAVIOR_ARMS.values()))}
    low, high = worlds["right"].table.low, worlds["right"].table.high
    h = args.spacing
    grid = np.array([(x, y) for x in np.arange(low[0] + h / 2, high[0], h)
                     for y in np.arange(low[1] + h / 2, high[1], h)])
    reach = {}
    for name, arm in BEHAVIOR_ARMS.items():
        reach[name] = np.array([reachable(worlds[arm], name, x, y) for x, y in grid])
    candidates = np.any(list(reach.values()), axis=0)
    visible = np.zeros(len(grid), dtype=bool)
    looking = TapAffordanceEnv(behavior="tap", two_arms=True, camera_width=80, camera_height=60)
    visible[candidates] = [seen(looking, x, y) for x, y in grid[candidates]]
    print(f"# {candidates.sum()} cells reachable by some behaviour, {visible.sum()} of them seen by the head")
    print(f"SPACING = {h}")
    print("WORKSPACES = {")
    for name in reach:
        ok = reach[name] & visible
        runs = []
        for x in np.unique(grid[ok, 0]):
            ys = np.sort(grid[ok & (grid[:, 0] == x), 1])
            breaks = np.flatnonzero(np.diff(ys) > 1.5 * h)
            for first, last in zip(np.r_[0, breaks + 1], np.r_[breaks, len(ys) - 1], strict=True):
                runs.append(f"({x:.4f}, {ys[first]:.4f}, {ys[last]:.4f})")
        print(f'    "{name}": (  # {int(ok.sum())} cells')
        for i in range(0, len(runs), 4):
            print("        " + ", ".join(runs[i:i + 4]) + ",")
        print("    ),")
    print("}")


if __name__ == "__main__":
    main()
