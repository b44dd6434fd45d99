"""Measure each behaviour's workspace: where on the table its canonical action is reachable for every object.

For each cell of a grid over the table (``--spacing``, 2.5 cm by default) and each behaviour, the arm's inverse
kinematics plans the canonical action (``feasible``: no physics step) on a sphere, a box, a lying and a standing
cylinder of the smallest and the largest size; a cell is in the workspace when every one is reachable. Prints each
behaviour's convex hull of those cells' centres as the literal of
``affordance_env.workspace.WORKSPACES``.

    python benchmarks/workspace.py
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.spatial import ConvexHull

from affordance_env.objects import OBJECT_TYPES, object_geometry
from affordance_env.tap_env import TapAffordanceEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spacing", type=float, default=0.025, help="grid spacing [m]")
    args = parser.parse_args()
    right = TapAffordanceEnv(behavior="tap", two_arms=True)
    right.prepare_behaviors(("tap_back", "push"))
    left = TapAffordanceEnv(behavior="grasp", two_arms=True)
    low, high = right.physics.table_extent()
    top = right.physics.table_top
    h = args.spacing
    xs = np.arange(low[0] + h / 2, high[0], h)
    ys = np.arange(low[1] + h / 2, high[1], h)
    print("WORKSPACES = {")
    for name, env in (("tap", right), ("tap_back", right), ("push", right), ("grasp", left)):
        if name != "grasp":
            env.use_behavior(name)
        env.physics.reset_home()
        cells = []
        for x in xs:
            for y in ys:
                ok = True
                for object_type in OBJECT_TYPES:
                    for size in (0.04, 0.10):
                        g = object_geometry(object_type, size)
                        plan = env.interaction.plan(g, np.array([x, y, top + g.half_height]), 0.0, top, np.zeros(3))
                        ok = ok and env.interaction.reachable(env.motion, plan)
                if ok:
                    cells.append((x, y))
        points = np.array(cells)
        hull = points[ConvexHull(points).vertices]
        # The hull runs through the centres of the outermost reachable cells: inside what was found reachable.
        vertices = ", ".join(f"({x:.3f}, {y:.3f})" for x, y in hull)
        print(f'    "{name}": ({vertices}),  # {len(cells)} cells')
    print("}")


if __name__ == "__main__":
    main()
