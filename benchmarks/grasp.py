"""The grasp's critical size: canonical grasps over the env's objects, success by size.

    python benchmarks/grasp.py [--episodes 90] [--size-range LOW HIGH] [--timestep DT]

Runs ``TapAffordance-v2`` with ``behavior="grasp"`` for seeds 0 .. episodes-1 (the env draws type, size, position
and yaw; the action is the canonical 0) and prints: the share of valid interactions (``info["failure"] is
None``), the success rate (``info["success"]``) over all valid grasps and per third of the sizes drawn, the
largest size held and the smallest dropped per object type, the object's rise at the end of the hold for
successes and failures (how clearly the lift threshold separates them), the outcome of every seed in one line
(X held, . not held, F failed), how much of a held object the hand hides from the final snapshot (taken at the
end of the hold: the share of the object's pixels that a camera seeing through the robot has and the range camera
does not), and the wall time and physics steps per interaction. ``--timestep`` simulates the grasp at another
timestep than the grasp variant's (to compare outcomes seed by seed).
"""

from __future__ import annotations

import argparse
import time
from collections import Counter

import numpy as np

import affordance_env.scene
from affordance_env.camera import RangeCamera
from affordance_env.objects import OBJECT_TYPES
from affordance_env.tap_env import TapAffordanceEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=90)
    parser.add_argument("--size-range", type=float, nargs=2, default=None, metavar=("LOW", "HIGH"),
                        help="object size range [m] (default: the env's)")
    parser.add_argument("--timestep", type=float, default=None, help="simulation timestep [s] (default: the "
                        f"grasp variant's, {affordance_env.scene.GRASP_TIMESTEP})")
    args = parser.parse_args()

    if args.timestep is not None:
        affordance_env.scene.GRASP_TIMESTEP = args.timestep  # read when the env builds its model
    kwargs = {} if args.size_range is None else {"size_range": tuple(args.size_range)}
    env = TapAffordanceEnv(behavior="grasp", **kwargs)
    rows, failures, steps, line = [], Counter(), 0, []
    step = env.physics.step

    def counted_step(n: int = 1) -> None:
        nonlocal steps
        steps += n
        step(n)

    env.physics.step = counted_step
    # At the final snapshot, the object's pixels as a camera that sees through the robot (geom group 0 only: the
    # table and the object) has them: what the hand hides.
    world, camera = env.world, env.camera
    through = RangeCamera(env.physics.model, width=camera.intrinsics.width, height=camera.intrinsics.height,
                          fovy_deg=env.options.camera_fovy, geom_groups=(0,), support="table_top")
    look, unhidden = world.look, []

    def look_through(rng):
        unhidden.append(int(through.capture(world.physics.data).mask_of(world.physics.active_geom).sum()))
        return look(rng)

    world.look = look_through
    hidden = []
    start = time.perf_counter()
    for seed in range(args.episodes):
        env.reset(seed=seed)
        info = env.step(np.zeros(3))[4]
        result = env.last_result
        if info["success"] and result.final is not None and unhidden[-1] > 0:
            hidden.append(1.0 - result.final.features.n_pixels / unhidden[-1])
        line.append("F" if info["failure"] is not None else "X" if info["success"] else ".")
        if info["failure"] is not None:
            failures[info["failure"].split(":")[0]] += 1
            continue
        rows.append((info["object"]["type"], info["object"]["size"], info["success"], info["grasp"]["rise"]))
    wall = time.perf_counter() - start
    n = args.episodes
    print(f"{n} canonical grasps, sizes {env.options.size_range[0]:.3f}-{env.options.size_range[1]:.3f} m, "
          f"timestep {env.physics.model.opt.timestep * 1e3:g} ms")
    print(f"  valid: {len(rows)}/{n} ({100 * len(rows) / n:.0f} %)"
          + (f"; failures: {dict(failures)}" if failures else ""))
    sizes = np.array([r[1] for r in rows])
    success = np.array([r[2] for r in rows])
    rise = np.array([r[3] for r in rows])
    print(f"  success: {100 * success.mean():.0f} % of the valid grasps")
    edges = np.quantile(sizes, [1 / 3, 2 / 3])
    third = np.digitize(sizes, edges, right=True)
    rates = [success[third == k].mean() for k in range(3)]
    for k, name in enumerate(("smallest", "middle", "largest")):
        in_third = sizes[third == k]
        print(f"  {name:8s} third ({100 * in_third.min():.1f}-{100 * in_third.max():.1f} cm, {in_third.size:2d}): "
              f"{100 * rates[k]:.0f} % held")
    print(f"  smallest third minus largest third: {rates[0] - rates[2]:.2f}")
    for object_type in OBJECT_TYPES:
        held = [100 * r[1] for r in rows if r[0] == object_type and r[2]]
        dropped = [100 * r[1] for r in rows if r[0] == object_type and not r[2]]
        print(f"  {object_type:20s} held up to {max(held, default=float('nan')):4.1f} cm, "
              f"not held from {min(dropped, default=float('nan')):4.1f} cm ({len(held)} held, {len(dropped)} not)")
    if success.any() and (~success).any():
        print(f"  rise at the end of the hold: held {100 * rise[success].min():.1f}-{100 * rise[success].max():.1f}"
              f" cm, not held {100 * rise[~success].min():.1f}-{100 * rise[~success].max():.1f} cm")
    print(f"  seeds 0-{n - 1}: {''.join(line)}")
    if hidden:
        print(f"  share of a held object's pixels the hand hides at the final snapshot: median "
              f"{100 * np.median(hidden):.0f} %, largest {100 * max(hidden):.0f} % ({len(hidden)} held)")
    print(f"  {1e3 * wall / n:.0f} ms wall per interaction (one core), {steps / n:.0f} physics steps")


if __name__ == "__main__":
    main()
